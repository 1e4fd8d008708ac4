"""What the figures tell a reader, checked on the figure objects plot-run draws (Debian's
/usr/bin/python3 with matplotlib): the robustness chart's log axes carry several readable values on
each panel, loop_timing.png names the stage of its p99 (the whole cycle) beside the summary's
control step and labels its last bin (which holds every longer cycle), and tracking errors are
drawn in mm (mrad for the swing), as every table gives them.
    figure_labels.py PLOT_RUN_DIR WORK"""
import json
import os
import sys

sys.path.insert(0, sys.argv[1])
work = sys.argv[2]
os.makedirs(work, exist_ok=True)

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import figure_base
import run_figures
from run_data import Columns

kept = []


def keep(plt_, fig, out_dir, name, written):
    fig.canvas.draw()
    kept.append((name, fig))
    written.append(name)


run_figures.save = keep
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)


# Robustness: RMS values within less than a decade (0.3 to 0.8 mm), as a law's variants often are.
rows = [{"variant": v, "pid": {"ok": True, "rms_error": {"boom": x, "arm": x * 1.3, "bucket": x * 1.1}},
         "adaptive": {"ok": True, "rms_error": {"boom": x * 0.9, "arm": x, "bucket": x}}}
        for v, x in (("nominal", 3e-4), ("heavy", 5e-4), ("noisy", 6e-4))]
path = os.path.join(work, "robustness.json")
with open(path, "w") as f:
    json.dump({"robustness": rows}, f)
run_figures.plot_robustness(plt, path, work)
_, fig = kept[-1]
for ax in fig.axes:
    lo, hi = ax.get_ylim()
    labels = [t.get_text() for t in ax.yaxis.get_ticklabels() if t.get_visible() and t.get_text()
              and lo <= t.get_position()[1] <= hi]
    check(len(labels) >= 2, "robustness panel %s: %d y tick labels in view (%s)" % (ax.get_title(), len(labels), labels))
    for text in labels:
        try:
            float(text.replace("\u2212", "-"))
        except ValueError:
            check(False, "robustness panel %s: tick label '%s' is not a plain number" % (ax.get_title(), text))

# Loop timing: a whole-cycle histogram whose last bin holds cycles beyond the range, and the update stage.
bins = [0] * 64
bins[5], bins[10], bins[63] = 900, 90, 3
timing = {"stage": [0, 2], "bin_width_us": [0.5, 0.5], "p99_us": [6.0, 2.6], "max_us": [40.0, 12.0]}
for b in range(64):
    timing["bins_%d" % b] = [bins[b], 0]
runs = {"pid": {"EXC_TIMING": Columns(timing)}}
run_figures.plot_timing(plt, runs, work, [])
_, fig = kept[-1]
ax = fig.axes[0]
legend = " ".join(t.get_text() for t in ax.get_legend().get_texts())
check("whole cycle p99 6.0 us" in legend, "loop_timing: the legend does not say its p99 is the whole cycle's: " + legend)
check("control step (update) p99 2.6 us" in legend, "loop_timing: the legend does not give the control step's p99: " + legend)
notes = [t.get_text() for t in ax.texts]
check(any("3 at >= 31.5 us" in n for n in notes), "loop_timing: the last bin is not labelled: %s" % notes)

# Tracking errors: drawn in mm (mrad for the swing).
t = [1000 * k for k in range(5)]
ctrl = {"utime": t, "mode": [3] * 5}
for j in range(4):
    ctrl["error_%d" % j] = [0.002 * (j + 1)] * 5
run_figures.plot_errors(plt, {"pid": {"EXC_CONTROLLER": Columns(ctrl)}}, work, [])
_, fig = kept[-1]
for j, ax in enumerate(fig.axes[:4]):
    unit = figure_base.ERROR_UNITS[j]
    check(ax.get_ylabel() == "error [%s]" % unit, "tracking_error panel %d: y label '%s'" % (j, ax.get_ylabel()))
    y = list(ax.get_lines()[0].get_ydata())
    check(abs(y[0] - 2.0 * (j + 1)) < 1e-9, "tracking_error panel %d: drawn %g for an error of %g m" % (j, y[0], 0.002 * (j + 1)))

for f in failures:
    print("FAIL:", f)
print("figure_labels.py: %d checks failed" % len(failures))
sys.exit(1 if failures else 0)
