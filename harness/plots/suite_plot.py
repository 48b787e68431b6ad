#!/usr/bin/python3
"""Summary plot of a vobench suite (matplotlib, Agg backend, PNG).

  suite_plot.py SUMMARY_CSV PNG [--panel COLUMN LABEL]...

One panel per --panel (a summary.csv column and its axis label, from vobench's metric
registry; default: end-pose error (% of the path) and ATE RMSE (m)) per run variant (scenario,
seed, stride), one bar per VO configuration; failed or missing runs are marked with an x.
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def number(text):
    try:
        v = float(text)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def main(argv):
    panels = []
    rest = argv[3:]
    while len(rest) >= 3 and rest[0] == "--panel":
        panels.append((rest[1], rest[2]))
        rest = rest[3:]
    if len(argv) < 3 or rest:
        print(__doc__)
        return 2
    if not panels:
        panels = [("end_pose_error_pct", "end-pose error (% of path)"), ("ate_rmse_m", "ATE RMSE (m)")]
    with open(argv[1]) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        print("suite_plot.py: no runs in " + argv[1])
        return 1
    configs, variants = [], []
    for r in rows:
        v = "%s\nseed %s, stride %s" % (r["scenario"], r["seed"], r["stride"])
        r["_variant"] = v
        if r["config"] not in configs:
            configs.append(r["config"])
        if v not in variants:
            variants.append(v)
    width = 0.8 / len(configs)
    fig, axes = plt.subplots(len(panels), 1, figsize=(max(7.0, 1.1 * len(variants) + 2), 3.75 * len(panels)),
                             sharex=True, squeeze=False)
    axes = axes[:, 0]
    for ax, (key, label) in zip(axes, panels):
        top = 0.0
        for k, c in enumerate(configs):
            xs, ys, bad = [], [], []
            for i, v in enumerate(variants):
                match = [r for r in rows if r["config"] == c and r["_variant"] == v]
                if not match:
                    continue
                x = i - 0.4 + width * (k + 0.5)
                y = number(match[0][key]) if match[0]["status"] == "ok" else None
                if y is None:
                    bad.append(x)
                else:
                    xs.append(x)
                    ys.append(y)
                    top = max(top, y)
            ax.bar(xs, ys, width=width * 0.95, label=c)
            if bad:
                ax.plot(bad, [0] * len(bad), "rx", markersize=8)
        ax.set_ylabel(label)
        ax.grid(True, axis="y", alpha=0.3)
        if top > 0 and min(number(r[key]) or top for r in rows if r["status"] == "ok") < top / 50:
            ax.set_yscale("log")
    axes[0].legend(fontsize=8, ncol=min(4, len(configs)))
    axes[1].set_xticks(range(len(variants)))
    axes[1].set_xticklabels(variants, fontsize=8)
    fig.suptitle("Suite results per scenario variant and VO configuration (x = failed / missing)")
    fig.tight_layout()
    fig.savefig(argv[2], dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
