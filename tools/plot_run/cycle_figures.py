"""The figures of a task that repeats (plot-run): work_cycles.png, the per-cycle figures of the
summary (RMS and worst error per joint, cycle time, peak soil force, soil estimates), one line per
controller, and cycle_errors.png, each cycle's error over the cycle's own time (from the telemetry:
every sample, or a long run's envelope), one colour per cycle."""
import numpy as np

from figure_base import ERROR_UNITS, decorate, new_figure, save
from run_data import bucket_times, within
from work_cycles import CYCLE_JOINTS, THETA_NAMES, has_estimates, milli, work_cycles


def estimate_ratios(rows, truth, names):
    """{name: [estimate / true value per cycle]} (the estimate itself where the truth is unknown)."""
    ratios = {}
    for k in names:
        true = truth.get(k) if isinstance(truth, dict) else None
        known = isinstance(true, (int, float)) and true != 0
        ratios[k] = [r["theta_hat"][k] / true if known else r["theta_hat"][k] for r in rows]
    return ratios


def plot_work_cycles(plt, summary, out_dir, written):
    """work_cycles.png: whether a law learns from pass to pass (the adaptive law's estimates carry
    over; PID has no memory)."""
    cycles = work_cycles(summary)
    if not cycles:
        return
    fig, axes = new_figure(plt, 3, 4, "Work cycles: error per joint, cycle time, soil force and estimates "
                                      "per cycle")
    n = max(len(r) for r in cycles.values())
    for controller, rows in cycles.items():
        xs = list(range(1, len(rows) + 1))
        for j, joint in enumerate(CYCLE_JOINTS):
            axes[0][j].plot(xs, [milli(r["rms_error"][joint]) for r in rows], "o-", label=controller)
            axes[1][j].plot(xs, [milli(r["max_error"][joint]) for r in rows], "o-", label=controller)
        axes[2][0].plot(xs, [r["end"] - r["start"] for r in rows], "o-", label=controller)
        axes[2][1].plot(xs, [1e-3 * r["peak_soil_force"] for r in rows], "o-", label=controller)
        if has_estimates(rows):
            truth = summary[controller].get("theta_true")
            for ax, names in ((axes[2][2], THETA_NAMES[:3]), (axes[2][3], THETA_NAMES[3:])):
                for k, values in estimate_ratios(rows, truth, names).items():
                    ax.plot(xs, values, "o-", label="%s %s" % (controller, k))
    for j, joint in enumerate(CYCLE_JOINTS):
        decorate(axes[0][j], "cycle", "RMS error [%s]" % ERROR_UNITS[j], title=joint, fontsize="small")
        decorate(axes[1][j], "cycle", "worst error [%s]" % ERROR_UNITS[j], fontsize="small")
    decorate(axes[2][0], "cycle", "cycle time [s]", fontsize="small")
    decorate(axes[2][1], "cycle", "peak soil force [kN]", fontsize="small")
    for ax, axis in ((axes[2][2], "x"), (axes[2][3], "z")):
        ax.axhline(1.0, color="gray", linewidth=0.8)
        decorate(ax, "cycle", "estimate / true", title="soil estimates (%s), cycle's end" % axis,
                 legend=bool(ax.lines[1:]), fontsize="x-small")
    for row in axes:
        for ax in row:
            ax.set_xticks(range(1, n + 1) if n <= 12 else np.linspace(1, n, 7).round())
    save(plt, fig, out_dir, "work_cycles.png", written)


def cycle_error(columns, column, t0, t1):
    """(t, |e|) in [t0, t1]: every sample, or a long run's largest |e| per time bucket."""
    if columns.buckets is None:
        t, e = within(columns, t0, t1, column)
        return t, np.abs(e)
    b = columns.buckets
    t = bucket_times(columns)
    keep = (t >= t0) & (t <= t1)
    return t[keep], np.fmax(np.abs(b[column]["min"]), np.abs(b[column]["max"]))[keep]


def plot_cycle_errors(plt, runs, summary, out_dir, written):
    """cycle_errors.png: one row per controller, one column per joint; each cycle's |e| against the
    time since the cycle began, from light (the first cycle) to dark (the last)."""
    cycles = {k: v for k, v in work_cycles(summary).items() if runs.get(k, {}).get("EXC_CONTROLLER")}
    if not cycles:
        return
    fig, axes = new_figure(plt, len(cycles), 4, "Tracking error |e| within each work cycle "
                                                "(colour: the first cycle light, the last dark)")
    colours = plt.get_cmap("viridis_r")
    for row, (controller, rows) in enumerate(cycles.items()):
        ctrl = runs[controller]["EXC_CONTROLLER"]
        for j, joint in enumerate(CYCLE_JOINTS):
            ax = axes[row][j]
            for c, r in enumerate(rows):
                t, e = cycle_error(ctrl, "error_%d" % j, r["start"], r["end"])
                label = "cycle %d" % (c + 1) if c in (0, len(rows) - 1) or len(rows) <= 6 else None
                ax.plot(t - r["start"], 1e3 * e, color=colours(0.15 + 0.85 * c / max(1, len(rows) - 1)),
                        linewidth=0.8, label=label)
            decorate(ax, "time in the cycle [s]", "|e| [%s]" % ERROR_UNITS[j],
                     title="%s: %s" % (controller, joint), fontsize="x-small")
    save(plt, fig, out_dir, "cycle_errors.png", written)
