#!/usr/bin/python3
"""Plot of a `vobench breakpoint` result (matplotlib, Agg backend, PNG).

  breakpoint_plot.py DIR PNG    the metric against the varied key: every evaluated point (its
                                seeds' values small and grey when there are several; crossed
                                points red, the others blue; a point whose run failed as an x at
                                the top), the condition's value as a dashed line, the bracket
                                shaded. Reads DIR/breakpoint.json.
"""
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(argv):
    if len(argv) != 3:
        print(__doc__)
        return 2
    run_dir, png = argv[1], argv[2]
    with open(run_dir + "/breakpoint.json") as f:
        b = json.load(f)
    key = b["vary"]["key"]
    until = b["until"]
    result = b["result"]
    points = b["points"]

    fig, ax = plt.subplots(figsize=(8, 5))
    values = [p["value"] for p in points if p["value"] is not None]
    top = max(values + [until["value"]]) if values else until["value"]
    seeds = len(b["seeds"])
    if seeds > 1:
        xs, ys = [], []
        for p in points:
            for r in p["runs"]:
                if r["metric"] is not None:
                    xs.append(p["x"])
                    ys.append(r["metric"])
        ax.plot(xs, ys, ".", color="0.6", markersize=4, label="a seed's run")
    # Crossed by the condition, or by a run that lost tracking or failed (the value may be below).
    groups = (("not crossed", "o", "tab:blue", lambda p: not p["crossed"]),
              ("crossed", "o", "tab:red", lambda p: p["crossed"] and p["why"] == "condition met"),
              ("crossed: a run lost tracking or failed", "s", "tab:purple",
               lambda p: p["crossed"] and p["why"] != "condition met"))
    for label, marker, color, member in groups:
        sel = [p for p in points if member(p) and p["value"] is not None]
        if sel:
            ax.plot([p["x"] for p in sel], [p["value"] for p in sel], marker, color=color,
                    label=label + (" (%s of %d seeds)" % (b["aggregate"], seeds) if seeds > 1 else ""))
    failed = [p for p in points if p["value"] is None or any(r["failed"] for r in p["runs"])]
    if failed:
        ax.plot([p["x"] for p in failed], [top * 1.05 if top > 0 else 1.0] * len(failed), "x",
                color="k", markersize=9, label="a run failed (counts as crossed)")
    # The metric along the key, in the key's order.
    curve = sorted((p["x"], p["value"]) for p in points if p["value"] is not None)
    if curve:
        ax.plot([c[0] for c in curve], [c[1] for c in curve], "-", color="0.4", linewidth=0.8)
    ax.axhline(until["value"], color="tab:red", linestyle="--", linewidth=1,
               label="condition %s" % until["text"])
    if result["bracket"] is not None:
        lo, hi = result["bracket"]
        ax.axvspan(lo, hi, color="tab:orange", alpha=0.3,
                   label="bracket [%g, %g]" % (lo, hi))
        ax.axvline(result["threshold"], color="tab:orange", linewidth=1.5)
    for p in points:
        ax.annotate(str(p["index"]), (p["x"], p["value"] if p["value"] is not None else top),
                    textcoords="offset points", xytext=(3, 4), fontsize=7, color="0.3")
    ax.set_xlabel(key)
    ax.set_ylabel(until["metric"])
    if values and min(values) > 0 and max(values) / min(values) > 100:
        ax.set_yscale("log")
    status = {"bracketed": "threshold ~ %g" % result["threshold"] if result["threshold"] is not None
              else "", "crossed_at_low": "crossed already at the low end",
              "not_crossed": "not crossed in the range"}.get(result["status"], result["status"])
    if not result["monotone"]:
        status += " (not monotone)"
    ax.set_title("vobench breakpoint %s: %s until %s\n%s, %d evaluations" % (
        b["scenario"], key, until["text"], status, len(points)), fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=90)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
