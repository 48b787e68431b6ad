#!/usr/bin/python3
"""Plots for vobench reports (matplotlib, Agg backend, PNG).

  plot.py match-eval CSV PNG          precision / recall / F1 vs stride, one line per matcher
  plot.py trajectory GT_TUM EST_TUM PNG [--outline-file CSV] [--navigation-file CSV]
                                      top-down trajectory, estimate vs ground truth; CSV: the
                                      scene's walls (wall,x0_m,y0_m,x1_m,y1_m), written by the
                                      harness from the MJCF (harness/plots/plots.h, SceneOutlineCsv);
                                      a closed-loop run's navigation.csv: the robot's believed
                                      and driven paths instead (the wheel axle)
  plot.py errors RUN_DIR PNG          translation / rotation error along the path (per_frame.csv)
  plot.py timing RUN_DIR PNG          per-stage time per frame (per_frame.csv)
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def match_eval(csv_path, png):
    rows = read_csv(csv_path)
    matchers = []
    for r in rows:
        if r["matcher"] not in matchers:
            matchers.append(r["matcher"])
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    for name in matchers:
        rs = sorted((r for r in rows if r["matcher"] == name), key=lambda r: int(r["stride"]))
        s = [int(r["stride"]) for r in rs]
        style = "-o" if name.startswith("svd") else "--s"
        for ax, key in zip(axes, ("precision", "recall", "f1")):
            ax.plot(s, [float(r[key]) for r in rs], style, label=name, linewidth=2 if name == "svd_ncc_gabor" else 1)
    for ax, key in zip(axes, ("precision", "recall", "F1")):
        ax.set_xlabel("frame stride (larger = less overlap)")
        ax.set_ylabel(key)
        ax.grid(True, alpha=0.3)
        ax.set_ylim(0, 1.02)
    axes[0].legend(fontsize=8, loc="lower left")
    fig.suptitle("Matcher quality against simulator ground truth (correct = within 2 px)")
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def read_tum(path):
    out = []
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                out.append([float(v) for v in line.split()])
    return out


def read_outline(path):
    """The walls of a scene, top-down: one (x0, y0, x1, y1) segment per row (metres)."""
    return [tuple(float(r[k]) for k in ("x0_m", "y0_m", "x1_m", "y1_m")) for r in read_csv(path)]


def outline_polylines(segments, tol=1e-6):
    """Segments chained into polylines where their ends meet (drawn with joins, not end caps)."""
    def near(a, b):
        return abs(a[0] - b[0]) <= tol and abs(a[1] - b[1]) <= tol
    left = [((x0, y0), (x1, y1)) for x0, y0, x1, y1 in segments]
    lines = []
    while left:
        line = list(left.pop(0))
        grown = True
        while grown:
            grown = False
            for i, (a, b) in enumerate(left):
                if near(a, line[-1]) or near(b, line[-1]):
                    line.append(b if near(a, line[-1]) else a)
                    left.pop(i)
                    grown = True
                    break
        if len(line) > 2 and near(line[0], line[-1]):  # a closed loop: start at its lowest (x, y)
            k = min(range(len(line) - 1), key=lambda i: line[i])
            line = line[k:-1] + line[:k + 1]
        lines.append(line)
    return lines


def trajectory(gt_path, est_path, png, outline_file=None, navigation_file=None):
    gt, est = read_tum(gt_path), read_tum(est_path)
    fig, ax = plt.subplots(figsize=(6.5, 6.5))
    walls = outline_polylines(read_outline(outline_file)) if outline_file else []
    if walls:
        # One line (one legend entry), the polylines separated by NaN breaks.
        xs, ys = [], []
        for line in walls:
            xs += [p[0] for p in line] + [float("nan")]
            ys += [p[1] for p in line] + [float("nan")]
        ax.plot(xs, ys, color="0.6", linewidth=1, label="hallway walls")
    if navigation_file:
        # The closed loop: what the follower steered on and where the robot really drove.
        rows = read_csv(navigation_file)
        ax.plot([float(r["true_x_m"]) for r in rows], [float(r["true_y_m"]) for r in rows], "k-",
                linewidth=2, label="true path (driven)")
        ax.plot([float(r["believed_x_m"]) for r in rows], [float(r["believed_y_m"]) for r in rows],
                "r--", linewidth=1.5, label="believed path (VO, steered on)")
        ax.plot(float(rows[0]["true_x_m"]), float(rows[0]["true_y_m"]), "go", label="start")
        ax.plot(float(rows[-1]["true_x_m"]), float(rows[-1]["true_y_m"]), "ks", label="stopped")
    else:
        ax.plot([p[1] for p in gt], [p[2] for p in gt], "k-", linewidth=2, label="ground truth")
        ax.plot([p[1] for p in est], [p[2] for p in est], "r--", linewidth=1.5, label="VO estimate")
        ax.plot(gt[0][1], gt[0][2], "go", label="start")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title("Closed loop: the robot on its VO (world frame, wheel axle)" if navigation_file
                 else "Top-down trajectory (world frame)")
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def errors(run_dir, png):
    rows = read_csv(run_dir + "/per_frame.csv")
    d = [float(r["gt_distance_m"]) for r in rows]
    fig, (a, b) = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    a.plot(d, [float(r["translation_error_m"]) for r in rows], "b-")
    a.set_ylabel("translation error (m)")
    b.plot(d, [float(r["rotation_error_deg"]) for r in rows], "m-")
    b.set_ylabel("rotation error (deg)")
    b.set_xlabel("distance travelled (m)")
    for ax in (a, b):
        ax.grid(True, alpha=0.3)
    # Frames without a measured motion (lost or re-initialised); older files lack the column.
    lost = [float(r["gt_distance_m"]) for r in rows
            if r.get("motion_measured", "1" if r["status"] != "lost" else "0") == "0"
            and r["status"] != "initializing"]
    for x in lost:
        a.axvline(x, color="r", alpha=0.2)
    fig.suptitle("Error along the path (estimate vs ground truth, from the first frame)")
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def timing(run_dir, png):
    rows = read_csv(run_dir + "/per_frame.csv")
    stages = [k for k in rows[0].keys() if k.endswith("_ms") and k != "total_ms"]
    f = [int(r["frame"]) for r in rows]
    fig, ax = plt.subplots(figsize=(9, 4))
    bottom = [0.0] * len(rows)
    for s in stages:
        v = [float(r[s]) for r in rows]
        ax.bar(f, v, bottom=bottom, width=1.0, label=s[:-3])
        bottom = [x + y for x, y in zip(bottom, v)]
    ax.set_xlabel("frame")
    ax.set_ylabel("time (ms)")
    ax.legend(fontsize=8, ncol=4)
    ax.grid(True, alpha=0.3)
    ax.set_title("Per-stage VO time per frame")
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    cmd = argv[1]
    if cmd == "match-eval":
        match_eval(argv[2], argv[3])
    elif cmd == "trajectory":
        outline_file = argv[argv.index("--outline-file") + 1] if "--outline-file" in argv else None
        navigation_file = (argv[argv.index("--navigation-file") + 1]
                           if "--navigation-file" in argv else None)
        trajectory(argv[2], argv[3], argv[4], outline_file, navigation_file)
    elif cmd == "errors":
        errors(argv[2], argv[3])
    elif cmd == "timing":
        timing(argv[2], argv[3])
    else:
        print(__doc__)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
