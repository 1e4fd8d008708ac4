#!/usr/bin/python3
"""plot-run: draws the paper's figures from a run's telemetry CSVs and writes a report page.

Input: one or more CSV directories written by `excavator-log export run.lcm --csv DIR`. Each
controller's run is recognised by its channel suffix (EXC_STATE__pid.csv is channel EXC_STATE/pid)
or, without a suffix, by the directory name. A long channel's CSV is its bucketed view (run_data.py);
memory does not grow with the run. Output (in --out): PNG files of a fixed pixel size and
report.md embedding them with the summary table (--summary JSON: excavator-sim's as a table of
figures per controller, any other rendered generically) and the RMS
tracking errors computed from the CSVs.

Figures (paper: Kim, Yoo, Lee): tracking_<joint>.png, desired against actual with one panel per
controller side by side (Figs. 4-7 free motion, 9-12 digging); tracking_error.png; soil_force.png
(the zig-zag of Fig. 8); soil_estimates.png (Theta_hat against the true values); loop_timing.png
(histogram of the control cycle). A run of more than 20 s at 1 kHz is drawn as its envelope (min
and max over time) with a zoom on each controller's worst window per phase: the moment the summary
names as that phase's worst error (the plant's), its figure in the title (worst_windows.py); a short
run's tracking figures mark those moments. A task that repeats adds
work_cycles.png (per-cycle errors, soil force and estimates) and cycle_errors.png (each cycle's
error over the cycle's time).

`plot-run --robustness JSON --out DIR` draws robustness.png from `excavator-sim robustness --json`.
"""
import argparse
import json
import os
import sys

from cycle_figures import plot_cycle_errors, plot_work_cycles
from plot_failure import fail
from report_page import write_report
from run_data import discover_runs
from run_figures import (plot_errors, plot_robustness, plot_soil_estimates, plot_soil_force,
                         plot_timing, plot_tracking)


def load_matplotlib():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        return plt
    except ImportError as error:
        fail("matplotlib is not available (%s); install python3-matplotlib" % error)


def main(argv):
    if argv and argv[0] == "--robustness":
        parser = argparse.ArgumentParser(prog="plot-run --robustness",
                                         description="Draw robustness.png from excavator-sim robustness's JSON.")
        parser.add_argument("--robustness", required=True, metavar="JSON")
        parser.add_argument("--out", required=True, help="output directory for robustness.png")
        args = parser.parse_args(argv)
        plt = load_matplotlib()
        os.makedirs(args.out, exist_ok=True)
        written = plot_robustness(plt, args.robustness, args.out)
        print("plot-run: wrote %s in %s" % (", ".join(written), args.out))
        return 0
    parser = argparse.ArgumentParser(
        prog="plot-run",
        description="Draw the paper's figures (tracking, soil force, soil estimates, loop timing) "
                    "from telemetry CSVs written by `excavator-log export`, and a report.md.")
    parser.add_argument("csv_dirs", nargs="+", metavar="CSV_DIR",
                        help="directory of CSVs from excavator-log export (several: one per run)")
    parser.add_argument("--out", required=True, help="output directory for the PNGs and report.md")
    parser.add_argument("--summary", help="JSON file with the run's summary table (any keys)")
    parser.add_argument("--title", default="Excavator run report", help="report title")
    args = parser.parse_args(argv)

    summary = None
    if args.summary:
        try:
            with open(args.summary) as f:
                summary = json.load(f)
        except (OSError, ValueError) as error:
            fail("%s: cannot read the summary JSON (%s)" % (args.summary, error))
    runs = discover_runs(args.csv_dirs)
    plt = load_matplotlib()
    os.makedirs(args.out, exist_ok=True)
    written = []
    plot_tracking(plt, runs, args.out, written, summary)
    plot_errors(plt, runs, args.out, written)
    plot_soil_force(plt, runs, args.out, written)
    plot_soil_estimates(plt, runs, args.out, written)
    plot_timing(plt, runs, args.out, written)
    plot_work_cycles(plt, summary, args.out, written)
    plot_cycle_errors(plt, runs, summary, args.out, written)
    report = write_report(runs, summary, args.title, args.out, written)
    print("plot-run: runs %s; wrote %d figures and %s" % (", ".join(runs), len(written), report))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
