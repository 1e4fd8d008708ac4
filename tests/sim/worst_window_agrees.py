"""The report's worst windows and the run's summary give one number: a short dig through the path the
report takes (excavator-sim's run and summary, `excavator-log report --summary`, whose export keeps
the detail rows and whose plot-run draws the figures), exported as a long run (--bucket-rows) so that
the tracking figures zoom, then the figures plot-run draws from that export, read on the figure
objects as a reader reads them. For every joint and every phase of the summary (tracking, hold, stop)
the zoom of that phase must
- name the phase in its title;
- quote the summary's worst error (max_error, the plant's truth) to the title's 4 significant digits
  (relative 5e-4; mm, mrad for the swing), and its time to the printed ms;
- mark the summary's moment (worst_time) within 1 us;
- draw logged rows within 5 ms of that moment and across the window (the export kept them).
    worst_window_agrees.py EXCAVATOR_SIM EXCAVATOR_LOG PLOT_RUN_DIR SCENE WORK"""
import importlib.machinery
import json
import os
import re
import shutil
import subprocess
import sys

sim, excavator_log, plot_run_dir, scene, work = sys.argv[1:6]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)

# 13 s of the dig: its path ends at 10.05 s, then the hold settles and holds.
run_dir = os.path.join(work, "run")
subprocess.run([sim, "run", scene, "--controller", "adaptive", "--duration", "13", "--quiet", "--no-report",
                "--out", run_dir], check=True, stdout=subprocess.DEVNULL)
summary_path = os.path.join(run_dir, "summary.json")
report_dir = os.path.join(work, "report")
subprocess.run([excavator_log, "report", os.path.join(run_dir, "run.lcm"), "--out", report_dir, "--summary",
                summary_path, "--bucket-rows", "2000", "--buckets", "200"], check=True, stdout=subprocess.DEVNULL)
with open(summary_path) as f:
    summary = json.load(f)

# plot-run's own entry (the command line excavator-log ran) over the report's CSVs, keeping the
# tracking figures as objects instead of writing them; the other figures are not drawn.
sys.path.insert(0, plot_run_dir)
import matplotlib

matplotlib.use("Agg")
import long_figures

# The program itself, as the build tree holds it (plot-run, its modules beside it).
plot_run = importlib.machinery.SourceFileLoader("plot_run", os.path.join(plot_run_dir, "plot-run")).load_module()

kept = {}


def keep(plt_, fig, out_dir, name, written):
    kept[name] = fig
    written.append(name)


long_figures.save = keep
for name in ("plot_errors", "plot_soil_force", "plot_soil_estimates", "plot_timing", "plot_work_cycles",
             "plot_cycle_errors"):
    setattr(plot_run, name, lambda *args, **kwargs: None)
plot_run.write_report = lambda *args, **kwargs: "(not written)"
plot_run.main([os.path.join(report_dir, "csv"), "--out", os.path.join(work, "figures"), "--summary", summary_path])

TITLE = re.compile(r"^(?P<label>\w+)(?:, (?P<phase>\w+))?: worst \|e\| (?P<value>[-0-9.e+]+) (?P<unit>mm|mrad) "
                   r"at (?P<time>[-0-9.]+) s")
failures = []
checked = 0
run = summary["adaptive"]
for joint, unit in (("swing", "mrad"), ("boom", "mm"), ("arm", "mm"), ("bucket", "mm")):
    fig = kept.get("tracking_%s.png" % joint)
    if fig is None:
        failures.append("tracking_%s.png: not drawn as a long run's figure" % joint)
        continue
    zooms = []
    for ax in fig.axes:
        m = TITLE.match(ax.get_title())
        if m:
            zooms.append((m, ax))
    titles = [ax.get_title() for ax in fig.axes]
    for phase in ("tracking", "hold", "stop"):
        figures = run["phases"].get(phase)
        if not figures:
            continue
        checked += 1
        error, t = 1e3 * figures["max_error"][joint], figures["worst_time"][joint]
        where = "tracking_%s.png, %s phase (summary: worst |e| %.6g %s at %.3f s)" % (joint, phase, error, unit, t)
        named = [(m, ax) for m, ax in zooms if m.group("phase") == phase]
        if not named:
            # A zoom that names no phase is read as the tracking figure's worst.
            named = [(m, ax) for m, ax in zooms if m.group("phase") is None and phase == "tracking"]
            failures.append("%s: no zoom names the phase; the titles: %s" % (where, titles))
        if not named:
            continue
        m, ax = named[0]
        value, at = float(m.group("value")), float(m.group("time"))
        if m.group("unit") != unit:
            failures.append("%s: the title's unit is %s" % (where, m.group("unit")))
        if abs(value - error) > 5e-4 * abs(error) + 1e-9:
            failures.append("%s: the title quotes %s %s, not the summary's figure" % (where, m.group("value"), unit))
        if abs(at - t) > 5e-4:
            failures.append("%s: the title's moment is %s s" % (where, m.group("time")))
        marks = [line for line in ax.lines if len(set(line.get_xdata())) == 1]
        if not any(abs(float(line.get_xdata()[0]) - t) <= 1e-6 for line in marks):
            failures.append("%s: no mark at the summary's moment (marks at %s s)" % (
                where, [float(line.get_xdata()[0]) for line in marks]))
        curves = [line for line in ax.lines if len(set(line.get_xdata())) > 1]
        if not curves:
            failures.append("%s: the zoom draws no logged rows" % where)
            continue
        xs = sorted(float(x) for line in curves for x in line.get_xdata())
        if not any(abs(x - t) <= 5e-3 for x in xs):
            failures.append("%s: no logged row within 5 ms of the moment (rows %.3f .. %.3f s)" % (where, xs[0], xs[-1]))
        end = run["simulated_seconds"]  # the rows span the run's 0 .. end to within 10 ms
        if xs[0] > max(0.01, t - 1.5) or xs[-1] < min(end - 0.01, t + 1.5):
            failures.append("%s: the logged rows span only %.3f .. %.3f s" % (where, xs[0], xs[-1]))

if checked < 8:
    failures.append("only %d joint-phase figures in the summary to check (expected tracking and hold of 4 joints)"
                    % checked)
for failure in failures:
    print("FAIL: " + failure)
print("%d joint-phase worst windows checked against the summary, %d failures" % (checked, len(failures)))
sys.exit(1 if failures else 0)
