"""The figures of a run (plot-run): tracking per joint with the controllers side by side (the paper's
Figs. 4-7 and 9-12), tracking error, soil force (Fig. 8), soil estimates, loop timing, and the
robustness chart. Every PNG is exactly 1200 x 700 pixels."""
import json
import math
import os

from plot_failure import fail

FIG_INCHES = (12.0, 7.0)


FIG_DPI = 100  # every PNG is exactly 1200 x 700 pixels


JOINTS = [("swing", "angle [rad]"), ("boom", "cylinder length [m]"),
          ("arm", "cylinder length [m]"), ("bucket", "cylinder length [m]")]


THETA = ["M_x [kg]", "B_x [N s/m]", "K_x [N/m]", "M_z [kg]", "B_z [N s/m]", "K_z [N/m]"]


TIMING_STAGES = {0: "whole cycle", 1: "read", 2: "update", 3: "write", 4: "plant step",
                 5: "cycle interval"}


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


def save(plt, fig, out_dir, name, written):
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(os.path.join(out_dir, name), dpi=FIG_DPI)  # no bbox_inches: keep the exact pixel size
    written.append(name)
    plt.close(fig)


def decorate(ax, xlabel, ylabel=None, title=None, legend=True, **legend_options):
    """A panel's labels and title, a light grid and (legend=True) its legend."""
    if title is not None:
        ax.set_title(title)
    ax.set_xlabel(xlabel)
    if ylabel is not None:
        ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    if legend:
        ax.legend(loc="best", **legend_options)


def plot_runs(ax, runs, channel, values):
    """One line per run that logged `channel`: values(its columns) against time, labelled by the run."""
    for label, channels in runs.items():
        columns = channels.get(channel, {})
        if columns:
            ax.plot(seconds(columns), values(columns), label=label)


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
            decorate(ax, "time [s]", "%s %s" % (joint, unit), title=label)
        save(plt, fig, out_dir, "tracking_%s.png" % joint, written)


def plot_errors(plt, runs, out_dir, written):
    fig, axes = new_figure(plt, 2, 2, "Tracking error e = q - q_d")
    for j, (joint, unit) in enumerate(JOINTS):
        ax = axes[j // 2][j % 2]
        plot_runs(ax, runs, "EXC_CONTROLLER", lambda ctrl: ctrl["error_%d" % j])
        decorate(ax, "time [s]", "error, %s" % unit, title=joint)
    save(plt, fig, out_dir, "tracking_error.png", written)


def plot_soil_force(plt, runs, out_dir, written):
    fig, axes = new_figure(plt, 2, 1, "Soil force at the bucket tip (swing plane)")
    for a, axis_name in enumerate(("x", "z")):
        ax = axes[a][0]
        plot_runs(ax, runs, "EXC_STATE", lambda state: [f * 1e-3 for f in state["soil_force_%d" % a]])
        decorate(ax, "time [s]", "F_soil %s [kN]" % axis_name)
    save(plt, fig, out_dir, "soil_force.png", written)


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
        decorate(ax, "time [s]", title=name, fontsize="small")
    save(plt, fig, out_dir, "soil_estimates.png", written)


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
    ax.set_yscale("log")
    decorate(ax, "duration [us]", "cycles", legend=drawn)
    save(plt, fig, out_dir, "loop_timing.png", written)


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
    save(plt, fig, out_dir, "robustness.png", written)
    return written


def work_cycles(summary):
    """{controller: [cycle, ...]} from an excavator-sim summary whose task repeats (else {})."""
    if not isinstance(summary, dict):
        return {}
    found = {k: v["cycles"] for k, v in summary.items()
             if isinstance(v, dict) and isinstance(v.get("cycles"), list) and len(v["cycles"]) > 1}
    order = {"pid": 0, "adaptive": 1}
    return dict(sorted(found.items(), key=lambda kv: (order.get(kv[0], 2), kv[0])))


def plot_work_cycles(plt, summary, out_dir, written):
    """work_cycles.png: per cycle and controller, RMS error of boom, arm and bucket, and the peak soil
    force: whether a law learns from pass to pass (the adaptive law's estimates carry over)."""
    cycles = work_cycles(summary)
    if not cycles:
        return
    fig, axes = new_figure(plt, 2, 2, "Work cycles: tracking error and soil force per cycle")
    panels = [("boom", "RMS error boom [mm]"), ("arm", "RMS error arm [mm]"),
              ("bucket", "RMS error bucket [mm]"), (None, "peak soil force [kN]")]
    for ax, (joint, label) in zip([a for row in axes for a in row], panels):
        for controller, rows in cycles.items():
            xs = list(range(1, len(rows) + 1))
            ys = [1e3 * r["rms_error"][joint] if joint else 1e-3 * r["peak_soil_force"] for r in rows]
            ax.plot(xs, ys, "o-", label=controller)
        ax.set_xticks(range(1, max(len(r) for r in cycles.values()) + 1))
        decorate(ax, "cycle", label)
    save(plt, fig, out_dir, "work_cycles.png", written)
