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

FIG_INCHES = (12.0, 7.0)
FIG_DPI = 100  # every PNG is exactly 1200 x 700 pixels
JOINTS = [("swing", "angle [rad]"), ("boom", "cylinder length [m]"),
          ("arm", "cylinder length [m]"), ("bucket", "cylinder length [m]")]
THETA = ["M_x [kg]", "B_x [N s/m]", "K_x [N/m]", "M_z [kg]", "B_z [N s/m]", "K_z [N/m]"]
TIMING_STAGES = {0: "whole cycle", 1: "read", 2: "update", 3: "write", 4: "plant step",
                 5: "cycle interval"}


def fail(message):
    sys.stderr.write("plot-run: %s\n" % message)
    sys.exit(2)


def load_matplotlib():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        return plt
    except ImportError as error:
        fail("matplotlib is not available (%s); install python3-matplotlib" % error)


def read_csv(path):
    """Columns of a CSV as lists of floats (text columns are kept as strings)."""
    with open(path, newline="") as f:
        reader = csv.reader(f)
        try:
            header = next(reader)
        except StopIteration:
            return {}
        columns = {name: [] for name in header}
        for line_no, row in enumerate(reader, start=2):
            if len(row) != len(header):
                fail("%s line %d: %d fields, header has %d" % (path, line_no, len(row), len(header)))
            for name, value in zip(header, row):
                try:
                    columns[name].append(float(value))
                except ValueError:
                    columns[name].append(value)
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


def seconds(columns):
    return [u * 1e-6 for u in columns.get("utime", [])]


def commanded(ctrl, column):
    """The column where the firmware commands the machine (hold or track); NaN before, so that the
    desired trajectory is not drawn at 0 while the firmware starts up."""
    modes = ctrl.get("mode", [])
    return [v if i < len(modes) and modes[i] in (2.0, 3.0) else float("nan")
            for i, v in enumerate(ctrl[column])]


def new_figure(plt, rows, cols, title):
    fig, axes = plt.subplots(rows, cols, figsize=FIG_INCHES, dpi=FIG_DPI, squeeze=False)
    fig.suptitle(title)
    return fig, axes


def save(fig, out_dir, name, written):
    path = os.path.join(out_dir, name)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(path, dpi=FIG_DPI)  # no bbox_inches: keep the exact pixel size
    written.append(name)
    return path


def plot_tracking(plt, runs, out_dir, written):
    for j, (joint, unit) in enumerate(JOINTS):
        fig, axes = new_figure(plt, 1, len(runs), "Tracking of the %s (desired vs actual)" % joint)
        for k, (label, channels) in enumerate(runs.items()):
            ax = axes[0][k]
            state = channels.get("EXC_STATE", {})
            ctrl = channels.get("EXC_CONTROLLER", {})
            if ctrl:
                ax.plot(seconds(ctrl), commanded(ctrl, "q_desired_%d" % j), "--", color="black",
                        label="desired")
            if state:
                ax.plot(seconds(state), state["q_active_%d" % j], color="tab:blue", label="actual")
            ax.set_title(label)
            ax.set_xlabel("time [s]")
            ax.set_ylabel("%s %s" % (joint, unit))
            ax.grid(True, alpha=0.3)
            ax.legend(loc="best")
        save(fig, out_dir, "tracking_%s.png" % joint, written)
        plt.close(fig)


def plot_errors(plt, runs, out_dir, written):
    fig, axes = new_figure(plt, 2, 2, "Tracking error e = q - q_d")
    for j, (joint, unit) in enumerate(JOINTS):
        ax = axes[j // 2][j % 2]
        for label, channels in runs.items():
            ctrl = channels.get("EXC_CONTROLLER", {})
            if ctrl:
                ax.plot(seconds(ctrl), ctrl["error_%d" % j], label=label)
        ax.set_title(joint)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("error, %s" % unit)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best")
    save(fig, out_dir, "tracking_error.png", written)
    plt.close(fig)


def plot_soil_force(plt, runs, out_dir, written):
    fig, axes = new_figure(plt, 2, 1, "Soil force at the bucket tip (swing plane)")
    for a, axis_name in enumerate(("x", "z")):
        ax = axes[a][0]
        for label, channels in runs.items():
            state = channels.get("EXC_STATE", {})
            if state:
                ax.plot(seconds(state), [f * 1e-3 for f in state["soil_force_%d" % a]], label=label)
        ax.set_ylabel("F_soil %s [kN]" % axis_name)
        ax.set_xlabel("time [s]")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best")
    save(fig, out_dir, "soil_force.png", written)
    plt.close(fig)


def plot_soil_estimates(plt, runs, out_dir, written):
    fig, axes = new_figure(plt, 2, 3, "Soil parameter estimates Theta_hat (dashed: true)")
    for i, name in enumerate(THETA):
        ax = axes[i // 3][i % 3]
        for label, channels in runs.items():
            ctrl = channels.get("EXC_CONTROLLER", {})
            if not ctrl:
                continue
            estimate = ctrl["theta_hat_%d" % i]
            if all(v == 0.0 for v in estimate):
                continue  # a controller without an estimator (the PID baseline publishes zeros)
            t = seconds(ctrl)
            line, = ax.plot(t, estimate, label=label)
            truth = ctrl["theta_true_%d" % i]
            if any(not math.isnan(v) for v in truth):
                ax.plot(t, truth, "--", color=line.get_color(), alpha=0.7)
        ax.set_title(name)
        ax.set_xlabel("time [s]")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    save(fig, out_dir, "soil_estimates.png", written)
    plt.close(fig)


def plot_timing(plt, runs, out_dir, written):
    fig, axes = new_figure(plt, 1, 1, "Control loop timing")
    ax = axes[0][0]
    drawn = False
    for label, channels in runs.items():
        timing = channels.get("EXC_TIMING", {})
        if timing and timing.get("stage"):
            # The last message of the whole-cycle counter holds the run's histogram.
            rows = [r for r, s in enumerate(timing["stage"]) if s == 0]
            if rows:
                r = rows[-1]
                width = timing["bin_width_us"][r]
                bins = [timing["bins_%d" % b][r] for b in range(64)]
                edges = [b * width for b in range(64)]
                ax.bar(edges, bins, width=width, align="edge", alpha=0.5,
                       label="%s: p99 %.1f us, max %.1f us" % (label, timing["p99_us"][r],
                                                               timing["max_us"][r]))
                drawn = True
                continue
        state = channels.get("EXC_STATE", {})
        stamps = state.get("log_utime", [])
        if len(stamps) > 2:
            # No timing counters in the log: the intervals at which states were logged.
            intervals = [b - a for a, b in zip(stamps, stamps[1:])]
            ax.hist(intervals, bins=64, alpha=0.5, label="%s: logged state interval" % label)
            drawn = True
    ax.set_xlabel("duration [us]")
    ax.set_ylabel("cycles")
    ax.set_yscale("log")
    ax.grid(True, alpha=0.3)
    if drawn:
        ax.legend(loc="best")
    save(fig, out_dir, "loop_timing.png", written)
    plt.close(fig)


def rms(values):
    finite = [v for v in values if isinstance(v, float) and not math.isnan(v)]
    return math.sqrt(sum(v * v for v in finite) / len(finite)) if finite else float("nan")


def format_value(value):
    if isinstance(value, float):
        return "%.6g" % value
    if isinstance(value, (list, tuple)):
        return ", ".join(format_value(v) for v in value)
    if isinstance(value, dict):
        return "; ".join("%s: %s" % (k, format_value(v)) for k, v in value.items())
    return str(value)


SIM_JOINTS = (("swing", "mrad"), ("boom", "mm"), ("arm", "mm"), ("bucket", "mm"))


def sim_runs(summary):
    """The per-controller runs of an excavator-sim summary (objects with an rms_error per joint)."""
    if not isinstance(summary, dict):
        return {}
    runs = {k: v for k, v in summary.items() if isinstance(v, dict) and isinstance(v.get("rms_error"), dict)}
    order = ["pid", "adaptive", "slotine_li"]  # the baseline first, as in the paper's figures
    return dict(sorted(runs.items(), key=lambda kv: (order.index(kv[0]) if kv[0] in order else len(order), kv[0])))


def sim_table(runs):
    """excavator-sim's summary as engineers read it: one row per figure, one column per controller."""
    names = list(runs)
    lines = ["| quantity | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]

    def row(label, get):
        cells = []
        for r in runs.values():
            try:
                cells.append(get(r))
            except (KeyError, TypeError, ValueError):
                cells.append("n/a")
        lines.append("| %s | " % label + " | ".join(cells) + " |")

    for key, what in (("rms_error", "RMS error"), ("max_error", "max error")):
        for joint, unit in SIM_JOINTS:
            row("%s %s (%s)" % (what, joint, unit), lambda r, k=key, j=joint: "%.4g" % (1e3 * r[k][j]))
    row("peak soil force (kN)", lambda r: "%.1f" % (1e-3 * r["peak_soil_force"]))
    row("shear re-anchorings", lambda r: "%d" % r["reanchor_count"])
    for q in ("median", "p99", "max"):
        row("control step %s (us)" % q, lambda r, q=q: "%.1f" % r["control_step_us"][q])
    row("heap allocations in the loop", lambda r: "%d" % r["heap_allocations_in_loop"])
    row("simulated (s)", lambda r: "%.3g" % r["simulated_seconds"])
    for name in ("M_x", "B_x", "K_x", "M_z", "B_z", "K_z"):
        row("soil estimate %s (true)" % name,
            lambda r, n=name: "%.4g (%.4g)" % (r["theta_hat"][n], r["theta_true"][n]))
    row("status", lambda r: "ok" if r.get("ok", True) else "FAILED: %s" % r.get("failure", ""))
    return lines


def summary_table(summary):
    """Markdown for any JSON: a table of runs x keys if every value is an object, else key/value."""
    lines = []
    if isinstance(summary, dict) and summary and all(isinstance(v, dict) for v in summary.values()):
        keys = []
        for v in summary.values():
            keys += [k for k in v if k not in keys]
        lines.append("| quantity | " + " | ".join(summary) + " |")
        lines.append("|---|" + "---|" * len(summary))
        for k in keys:
            lines.append("| %s | " % k + " | ".join(format_value(v.get(k, "")) for v in summary.values())
                         + " |")
    elif isinstance(summary, dict):
        lines.append("| quantity | value |")
        lines.append("|---|---|")
        for k, v in summary.items():
            lines.append("| %s | %s |" % (k, format_value(v)))
    else:
        lines.append(format_value(summary))
    return lines


def write_report(runs, summary, title, out_dir, written):
    lines = ["# %s" % title, ""]
    if summary is not None:
        runs_in_summary = sim_runs(summary)
        table = sim_table(runs_in_summary) if runs_in_summary else summary_table(summary)
        lines += ["## Summary", ""]
        if isinstance(summary, dict) and isinstance(summary.get("setup"), str):
            lines += ["Scene `%s`: %s." % (summary.get("scene", "?"), summary["setup"]), ""]
        lines += table + [""]
    # From the log: the controller's own error e (estimated state against q_d) over every logged
    # cycle, hold included; the summary's figures are the plant's true state while tracking.
    lines += ["## RMS of the controller's error e over the whole log (telemetry)", ""]
    lines.append("| joint | " + " | ".join(runs) + " |")
    lines.append("|---|" + "---|" * len(runs))
    for j, (joint, unit) in enumerate(JOINTS):
        cells = []
        for channels in runs.values():
            ctrl = channels.get("EXC_CONTROLLER", {})
            cells.append("%.4g" % rms(ctrl["error_%d" % j]) if ctrl else "n/a")
        lines.append("| %s (%s) | " % (joint, unit.split("[")[-1].rstrip("]")) + " | ".join(cells)
                     + " |")
    lines.append("")
    captions = {
        "tracking_error.png": "Tracking error of each active joint",
        "soil_force.png": "Soil force at the tip (the zig-zag of the paper's Fig. 8)",
        "soil_estimates.png": "Soil parameter estimates against the true values",
        "loop_timing.png": "Control loop timing histogram",
    }
    lines += ["## Figures", ""]
    for name in written:
        caption = captions.get(name, "Tracking of the %s, desired against actual" %
                               name[len("tracking_"):-4])
        lines += ["### %s" % caption, "", "![%s](%s)" % (caption, name), ""]
    path = os.path.join(out_dir, "report.md")
    with open(path, "w") as f:
        f.write("\n".join(lines))
    return path


def plot_robustness(plt, path, out_dir):
    """robustness.png from `excavator-sim robustness --json`: RMS error per variant, one panel per
    joint, one bar per controller (log scale: the variants span two decades)."""
    try:
        with open(path) as f:
            rows = json.load(f)["robustness"]
    except (OSError, ValueError, KeyError, TypeError) as error:
        fail("%s: not an excavator-sim robustness JSON (%s)" % (path, error))
    variants = [r["variant"] for r in rows]
    controllers = [c for c in ("pid", "adaptive", "slotine_li") if c in rows[0]] if rows else []
    fig, axes = new_figure(plt, 1, 3, "Robustness: RMS tracking error on the dig pass per variant")
    width = 0.8 / max(1, len(controllers))
    for ax, joint in zip(axes[0], ("boom", "arm", "bucket")):
        for k, c in enumerate(controllers):
            xs = [i + (k - (len(controllers) - 1) / 2) * width for i in range(len(rows))]
            bars = ax.bar(xs, [1e3 * r[c]["rms_error"][joint] for r in rows], width, label=c)
            # A run the firmware stopped (its safe state) is hatched and marked: its RMS covers only
            # the time before the stop.
            for bar, r in zip(bars, rows):
                if not r[c].get("ok", True):
                    bar.set_hatch("//")
                    bar.set_edgecolor("black")
                    ax.annotate("stopped", (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                                ha="center", va="bottom", fontsize=7, rotation=90)
        ax.set_yscale("log")
        ax.set_title(joint)
        ax.set_ylabel("RMS error [mm]")
        ax.set_xticks(range(len(rows)))
        ax.set_xticklabels(variants, rotation=35, ha="right", fontsize=8)
        ax.grid(True, axis="y", which="both", alpha=0.3)
        ax.legend(fontsize=8)
    written = []
    save(fig, out_dir, "robustness.png", written)
    return written


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
    report = write_report(runs, summary, args.title, args.out, written)
    print("plot-run: runs %s; wrote %d figures and %s" % (", ".join(runs), len(written), report))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
