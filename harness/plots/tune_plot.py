#!/usr/bin/python3
"""Plot of a `vobench tune` result (matplotlib, Agg backend, PNG).

  tune_plot.py DIR PNG    objective per evaluation and the best so far (top); every parameter's
                          position in its search range per evaluation (bottom). Reads
                          DIR/evaluations.csv and DIR/summary.json.
"""
import csv
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def unit(value, p):
    """Position of a value in [min, max] (log scale where the parameter is searched so)."""
    lo, hi = p["min"], p["max"]
    if p["log"]:
        return math.log(value / lo) / math.log(hi / lo)
    return (value - lo) / (hi - lo)


def main(argv):
    if len(argv) != 3:
        print(__doc__)
        return 2
    run_dir, png = argv[1], argv[2]
    with open(run_dir + "/evaluations.csv") as f:
        rows = list(csv.DictReader(f))
    with open(run_dir + "/summary.json") as f:
        summary = json.load(f)
    evals = [int(r["eval"]) for r in rows]
    score = [float(r["objective"]) for r in rows]
    best = [float(r["best_objective"]) for r in rows]
    objective = summary["objective"]

    fig, (a, b) = plt.subplots(2, 1, figsize=(9, 7), sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    a.plot(evals, score, "o", color="tab:blue", markersize=4, label="evaluation")
    a.step(evals, best, where="post", color="tab:red", linewidth=2, label="best so far")
    a.axhline(score[0], color="0.5", linestyle="--", linewidth=1, label="default (evaluation 0)")
    best_eval = summary["optimizer"]["best_eval"]
    a.plot([best_eval], [score[best_eval]], "*", color="tab:red", markersize=14, label="best")
    if min(score) > 0 and max(score) / min(score) > 20:
        a.set_yscale("log")
    a.set_ylabel("training objective (%s of %s + %g x lost)" % (
        objective["aggregate"], objective["metric"], objective["lost_frame_penalty"]))
    a.grid(True, alpha=0.3)
    a.legend(fontsize=8)
    a.set_title("vobench tune %s: %s, %d evaluations" % (
        summary["name"], summary["optimizer"]["algorithm"], len(rows)))

    for p in summary["parameters"]:
        column = p["key"] + (":scale" if p["type"] == "scale" else "")
        b.plot(evals, [unit(float(r[column]), p) for r in rows], ".-", linewidth=0.6, markersize=4,
               label=column)
    b.axvline(best_eval, color="tab:red", alpha=0.4)
    b.set_ylim(-0.05, 1.05)
    b.set_xlabel("evaluation")
    b.set_ylabel("position in range (0 = min, 1 = max)")
    b.grid(True, alpha=0.3)
    b.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
