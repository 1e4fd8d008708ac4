#!/usr/bin/python3
"""The charts of a merged sweep (excavator-sim sweep-merge calls this; matplotlib, Agg).

usage: plot_sweep.py [--stability] [--robustness] DIR
  reads DIR/sweep.csv and DIR/sweep.json (its "chart": the runs' columns, the grids' axes, the search)
  --stability   stability.png: per grid, one axis: worst joint's RMS error against the value, a cross
                where the run failed; two axes: a map per controller, each cell the worst RMS error
                (colour) or why it failed (P: the plant's checks stopped it, F: the firmware's safe
                state); with a search knob, the value found instead of the error
  --robustness  robustness.png: the random draws' spread, RMS error of each joint per controller
                over the cases (sorted), failed runs counted in the legend
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

JOINTS = ("swing", "boom", "arm", "bucket")


def num(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


def worst(row, run):
    vals = [num(row.get("%s_rms_%s" % (run, j))) for j in JOINTS]
    vals = [v for v in vals if not math.isnan(v)]
    return max(vals) if vals else math.nan


def failed_mark(row, run):
    failure = row.get(run + "_failure", "")
    return "P" if failure.startswith("plant stopped") else "F"


def short(knob):
    return knob.split(".")[-1]


def grid_rows(rows, axes, knobs):
    """The rows of one grid: exactly its axes set among the spec's knobs."""
    return [r for r in rows if all(r.get(k, "") != "" for k in axes)
            and all(r.get(k, "") == "" for k in knobs if k not in axes)]


def value_of(row, run, search):
    return num(row.get(run + "_search")) if search else worst(row, run)


def line_panel(ax, rows, axis, runs, search):
    for i, run in enumerate(runs):
        pts = sorted((num(r[axis]), value_of(r, run, search), r[run + "_ok"] == "1") for r in rows)
        ys = [p[1] if not math.isnan(p[1]) else 1e-7 for p in pts]
        line, = ax.plot([p[0] for p in pts], [max(y, 1e-7) for y in ys], marker="o", ms=4, label=run, color="C%d" % i)
        bad = [(p[0], max(y, 1e-7)) for p, y in zip(pts, ys) if not p[2]]
        if bad:
            ax.plot(*zip(*bad), "x", color=line.get_color(), ms=12, mew=2)
    ax.set_yscale("log")
    xs = [num(r[axis]) for r in rows]
    if xs and min(xs) > 0 and max(xs) / min(xs) >= 50:
        ax.set_xscale("log")
    ax.set_xlabel(short(axis))
    ax.set_ylabel(("%s found" % short(search)) if search else "worst joint RMS error (m / rad); x = failed")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)


def map_panel(fig, ax, rows, axes, run, search):
    xs = sorted({num(r[axes[1]]) for r in rows})
    ys = sorted({num(r[axes[0]]) for r in rows})
    grid = [[math.nan] * len(xs) for _ in ys]
    marks = []
    for r in rows:
        i, j = ys.index(num(r[axes[0]])), xs.index(num(r[axes[1]]))
        if r[run + "_ok"] == "1":
            v = value_of(r, run, search)
            grid[i][j] = math.log10(v) if v > 0 else math.nan
        else:
            marks.append((j, i, failed_mark(r, run)))
    image = ax.imshow(grid, origin="lower", cmap="viridis", aspect="auto")
    fig.colorbar(image, ax=ax, label="log10 " + ("%s found" % short(search) if search else "worst RMS error (m / rad)"))
    for j, i, m in marks:
        ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, color="#d62728" if m == "P" else "#ff7f0e"))
        ax.text(j, i, m, ha="center", va="center", fontsize=10, weight="bold", color="white")
    ax.set_xticks(range(len(xs)))
    ax.set_xticklabels(["%g" % x for x in xs], rotation=30, fontsize=8)
    ax.set_yticks(range(len(ys)))
    ax.set_yticklabels(["%g" % y for y in ys], fontsize=8)
    ax.set_xlabel(axes[1])
    ax.set_ylabel(axes[0])
    ax.set_title("%s (P: plant stopped, F: firmware safe state)" % run, fontsize=9)


def stability(out, rows, chart):
    runs, grids, search = chart["runs"], chart["grids"], chart.get("search", "")
    knobs = sorted({k for g in grids for k in g})
    panels = [(g, None) for g in grids if len(g) == 1] + [(g, run) for g in grids if len(g) == 2 for run in runs]
    if not panels:
        return None
    cols = min(len(panels), 4 if all(len(g) == 1 for g, _ in panels) else 2)
    nrows = (len(panels) + cols - 1) // cols
    fig, axs = plt.subplots(nrows, cols, figsize=(5.5 * cols, 4.5 * nrows), squeeze=False)
    for k, (axes, run) in enumerate(panels):
        ax = axs[k // cols][k % cols]
        sel = grid_rows(rows, axes, knobs)
        if run is None:
            line_panel(ax, sel, axes[0], runs, search)
        else:
            map_panel(fig, ax, sel, axes, run, search)
    for k in range(len(panels), nrows * cols):
        axs[k // cols][k % cols].axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "stability.png"), dpi=100)
    plt.close(fig)
    return "stability.png"


def robustness(out, rows, chart):
    runs = chart["runs"]
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.8), squeeze=False)
    for ax, joint in zip(axs[0], ("boom", "arm", "bucket")):
        for i, run in enumerate(runs):
            vals = sorted(1e3 * num(r["%s_rms_%s" % (run, joint)]) for r in rows if r[run + "_ok"] == "1")
            failed = sum(1 for r in rows if r[run + "_ok"] != "1")
            if vals:
                ax.plot([100.0 * (k + 1) / len(rows) for k in range(len(vals))], vals, color="C%d" % i,
                        label="%s (%d of %d failed)" % (run, failed, len(rows)))
        ax.set_yscale("log")
        ax.set_xlabel("cases (%), sorted by RMS error")
        ax.set_ylabel("RMS error [mm]")
        ax.set_title(joint)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Robustness over %d random draws: RMS tracking error per joint" % len(rows))
    fig.tight_layout()
    fig.savefig(os.path.join(out, "robustness.png"), dpi=100)
    plt.close(fig)
    return "robustness.png"


def main(argv):
    flags = [a for a in argv if a.startswith("--")]
    dirs = [a for a in argv if not a.startswith("--")]
    if "--help" in flags:
        print(__doc__.strip())
        return 0
    if len(dirs) != 1 or not flags or any(f not in ("--stability", "--robustness") for f in flags):
        print(__doc__.strip(), file=sys.stderr)
        return 2
    out = dirs[0]
    with open(os.path.join(out, "sweep.json")) as f:
        chart = json.load(f)["chart"]
    with open(os.path.join(out, "sweep.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    written = []
    if "--stability" in flags:
        written.append(stability(out, rows, chart))
    if "--robustness" in flags:
        written.append(robustness(out, rows, chart))
    print("plot_sweep: wrote %s in %s" % (", ".join(w for w in written if w), out))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
