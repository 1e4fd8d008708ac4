"""The figures of a run (plot-run): tracking per joint with the controllers side by side (the paper's
Figs. 4-7 and 9-12), tracking error, soil force (Fig. 8), soil estimates, loop timing, and the
robustness chart. A long run's are drawn by long_figures.py (envelope and worst window)."""
import json
import math

import long_figures
from figure_base import ERROR_UNITS, JOINTS, THETA, decorate, new_figure, plot_runs, save
from plot_failure import fail
from run_data import commanded, is_long, seconds
from worst_windows import PHASE_COLOURS, zoom, zoom_phases


def any_long(runs):
    return any(is_long(channels.get(c, {})) for channels in runs.values()
               for c in ("EXC_STATE", "EXC_CONTROLLER"))


def plot_tracking(plt, runs, out_dir, written, summary=None):
    """Desired against actual per joint; each phase's worst error the summary names is marked at its
    moment, its figure in the legend (a long run: a zoom on it, long_figures.py)."""
    if any_long(runs):
        return long_figures.plot_tracking(plt, runs, out_dir, written, summary)
    phases = [p for p in zoom_phases(runs, summary) if p is not None]
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
            for phase in phases:
                z = zoom(ctrl, summary, label, phase, j)
                if z.time is not None:
                    ax.axvline(z.time, color=PHASE_COLOURS[phase], linewidth=0.8,
                               label="%s worst |e| %.4g %s at %.3f s" % (phase, 1e3 * z.error, ERROR_UNITS[j], z.time))
            decorate(ax, "time [s]", "%s %s" % (joint, unit), title=label, fontsize="small")
        save(plt, fig, out_dir, "tracking_%s.png" % joint, written)


def plot_errors(plt, runs, out_dir, written):
    if any_long(runs):
        return long_figures.plot_errors(plt, runs, out_dir, written)
    fig, axes = new_figure(plt, 2, 2, "Tracking error e = q - q_d")
    for j, (joint, unit) in enumerate(JOINTS):
        ax = axes[j // 2][j % 2]
        # In mm (mrad for the swing), as every table gives it.
        plot_runs(ax, runs, "EXC_CONTROLLER", lambda ctrl: [1e3 * e for e in ctrl["error_%d" % j]])
        decorate(ax, "time [s]", "error [%s]" % ERROR_UNITS[j], title=joint)
    save(plt, fig, out_dir, "tracking_error.png", written)


def plot_soil_force(plt, runs, out_dir, written):
    if any_long(runs):
        return long_figures.plot_soil_force(plt, runs, out_dir, written)
    fig, axes = new_figure(plt, 2, 1, "Soil force at the bucket tip (swing plane)")
    for a, axis_name in enumerate(("x", "z")):
        ax = axes[a][0]
        plot_runs(ax, runs, "EXC_STATE", lambda state: [f * 1e-3 for f in state["soil_force_%d" % a]])
        decorate(ax, "time [s]", "F_soil %s [kN]" % axis_name)
    save(plt, fig, out_dir, "soil_force.png", written)


def plot_soil_estimates(plt, runs, out_dir, written):
    if any_long(runs):
        return long_figures.plot_soil_estimates(plt, runs, out_dir, written)
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


def last_of_stage(timing, stage):
    """The row of the stage's last message (it holds the run's statistics), None without one."""
    rows = [r for r, s in enumerate(timing["stage"]) if s == stage]
    return rows[-1] if rows else None


def plot_timing(plt, runs, out_dir, written):
    # Stage 0 of EXC_TIMING, the whole firmware cycle; the summary's "control step" is stage 2 (the
    # update: estimate, path, law, the stages after it and the monitors), a part of it: both are
    # named, so that the figures are not taken for one another.
    fig, axes = new_figure(plt, 1, 1, "Firmware cycle timing: the whole cycle (read, update, write, telemetry encode)")
    ax = axes[0][0]
    drawn = False
    for label, channels in runs.items():
        timing = channels.get("EXC_TIMING", {})
        if timing and timing.get("stage"):
            r = last_of_stage(timing, 0)
            if r is not None:
                width = timing["bin_width_us"][r]
                bins = [timing["bins_%d" % b][r] for b in range(64)]
                edges = [b * width for b in range(64)]
                text = "%s: whole cycle p99 %.1f us, max %.1f us" % (label, timing["p99_us"][r], timing["max_us"][r])
                u = last_of_stage(timing, 2)
                if u is not None:
                    text += "; control step (update) p99 %.1f us" % timing["p99_us"][u]
                bars = ax.bar(edges, bins, width=width, align="edge", alpha=0.5, label=text)
                # The last bin also holds every longer cycle: said at its bar.
                if bins[-1] > 0:
                    last = bars[-1]
                    ax.annotate("%s: %d at >= %g us" % (label, bins[-1], edges[-1]),
                                (last.get_x() + last.get_width() / 2, last.get_height()),
                                ha="right", va="bottom", fontsize=7, rotation=90)
                drawn = True
                continue
        state = channels.get("EXC_STATE", {})
        stamps = state.get("log_utime", []) if state and state.buckets is None else []
        if len(stamps) > 2:
            # No timing counters in the log: the intervals at which states were logged.
            intervals = [b - a for a, b in zip(stamps, stamps[1:])]
            ax.hist(intervals, bins=64, alpha=0.5, label="%s: logged state interval" % label)
            drawn = True
    ax.set_yscale("log")
    decorate(ax, "duration [us]", "cycles", legend=drawn)
    save(plt, fig, out_dir, "loop_timing.png", written)


def plot_robustness(plt, path, out_dir):
    import matplotlib.ticker as ticker
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
            # A run that never tracked has no RMS (null): no bar, a mark at the foot of the panel.
            bars = ax.bar(xs, [1e3 * r[c]["rms_error"][joint] if r[c].get("rms_error") else math.nan for r in rows],
                          width, label=c)
            # A run the firmware stopped (its safe state) is hatched and marked: its RMS covers only
            # the time before the stop.
            for bar, r in zip(bars, rows):
                if not r[c].get("rms_error"):
                    ax.annotate("never tracked", (bar.get_x() + bar.get_width() / 2, 0.02),
                                xycoords=("data", "axes fraction"), ha="center", va="bottom", fontsize=7, rotation=90)
                elif not r[c].get("ok", True):
                    bar.set_hatch("//")
                    bar.set_edgecolor("black")
                    ax.annotate("stopped", (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                                ha="center", va="bottom", fontsize=7, rotation=90)
        ax.set_yscale("log")
        # Labels at 1, 2 and 5 of each decade, as plain numbers: a panel spanning less than a
        # decade still carries several readable values.
        ax.yaxis.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: "%g" % v))
        ax.yaxis.set_minor_formatter(ticker.NullFormatter())
        ax.set_title(joint)
        ax.set_ylabel("RMS error [mm]")
        ax.set_xticks(range(len(rows)))
        ax.set_xticklabels(variants, rotation=35, ha="right", fontsize=8)
        ax.grid(True, axis="y", which="both", alpha=0.3)
        ax.legend(fontsize=8)
    written = []
    save(plt, fig, out_dir, "robustness.png", written)
    return written
