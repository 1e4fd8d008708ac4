#!/usr/bin/python3
"""plot-run: draws the paper's figures from a run's telemetry CSVs and writes a report page.

Input: one or more CSV directories written by `excavator-log export run.lcm --csv DIR`. Each
controller's run is recognised by its channel suffix (EXC_STATE__pid.csv is channel EXC_STATE/pid)
or, without a suffix, by the directory name. Output (in --out): PNG files of a fixed pixel size and
report.md embedding them with the summary table (--summary JSON: excavator-sim's as a table of
figures per controller, any other rendered generically) and the RMS
tracking errors computed from the CSVs.

Figures (paper: Kim, Yoo, Lee): tracking_<joint>.png, desired against actual with one panel per
controller side by side (Figs. 4-7 free motion, 9-12 digging); tracking_error.png; soil_force.png
(the zig-zag of Fig. 8); soil_estimates.png (Theta_hat against the true values); loop_timing.png
(histogram of the control cycle).

`plot-run --robustness JSON --out DIR` draws robustness.png from `excavator-sim robustness --json`.
"""
import argparse
import csv
import json
import math
import os
import sys

from plot_failure import fail
from report_page import write_report
from run_figures import (plot_errors, plot_robustness, plot_soil_estimates, plot_soil_force,
                         plot_timing, plot_tracking, plot_work_cycles)


def load_matplotlib():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        return plt
    except ImportError as error:
        fail("matplotlib is not available (%s); install python3-matplotlib" % error)


# Rows kept per CSV for the figures: a run of any length is drawn from at most this many rows (every
# k-th), so the report's memory does not grow with the run; the RMS figures use every row.
MAX_ROWS = 20000


def read_csv(path, max_rows=MAX_ROWS):
    """Columns of a CSV as lists of floats (text columns are kept as strings), every k-th row of a
    long file (k in columns["__stride__"]); columns["__rms__"] holds the exact RMS of every error_*
    column over all rows."""
    with open(path, newline="") as f:
        rows = sum(1 for _ in f) - 1
    stride = max(1, math.ceil(rows / max_rows)) if rows > 0 else 1
    with open(path, newline="") as f:
        reader = csv.reader(f)
        try:
            header = next(reader)
        except StopIteration:
            return {}
        columns = {name: [] for name in header}
        errors = [i for i, name in enumerate(header) if name.startswith("error_")]
        sum_sq = [0.0] * len(errors)
        counted = [0] * len(errors)
        for line_no, row in enumerate(reader, start=2):
            if len(row) != len(header):
                fail("%s line %d: %d fields, header has %d" % (path, line_no, len(row), len(header)))
            for k, i in enumerate(errors):
                try:
                    v = float(row[i])
                except ValueError:
                    continue
                if not math.isnan(v):
                    sum_sq[k] += v * v
                    counted[k] += 1
            if (line_no - 2) % stride:
                continue
            for name, value in zip(header, row):
                try:
                    columns[name].append(float(value))
                except ValueError:
                    columns[name].append(value)
    columns["__stride__"] = stride
    columns["__rms__"] = {header[i]: math.sqrt(sum_sq[k] / counted[k]) if counted[k] else float("nan")
                          for k, i in enumerate(errors)}
    return columns


def discover_runs(csv_dirs):
    """{run label: {channel base name: columns}} from the CSV directories."""
    runs = {}
    for directory in csv_dirs:
        if not os.path.isdir(directory):
            fail("%s: not a directory (expected the output of excavator-log export)" % directory)
        names = sorted(n for n in os.listdir(directory) if n.endswith(".csv"))
        if not any(n.startswith("EXC_STATE") for n in names):
            fail("%s: no EXC_STATE*.csv (is this an excavator-log export directory?)" % directory)
        for name in names:
            stem = name[:-4]
            base, _, suffix = stem.partition("__")
            label = suffix if suffix else os.path.basename(os.path.normpath(directory))
            runs.setdefault(label, {})[base] = read_csv(os.path.join(directory, name))
    # The baseline first, the adaptive law second, as in the paper's side-by-side figures.
    order = {"pid": 0, "adaptive": 1}
    return dict(sorted(runs.items(), key=lambda kv: (order.get(kv[0], 2), kv[0])))


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
    plot_tracking(plt, runs, args.out, written)
    plot_errors(plt, runs, args.out, written)
    plot_soil_force(plt, runs, args.out, written)
    plot_soil_estimates(plt, runs, args.out, written)
    plot_timing(plt, runs, args.out, written)
    plot_work_cycles(plt, summary, args.out, written)
    report = write_report(runs, summary, args.title, args.out, written)
    print("plot-run: runs %s; wrote %d figures and %s" % (", ".join(runs), len(written), report))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
