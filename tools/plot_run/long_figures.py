"""The figures of a long run (more than 20 s at 1 kHz: exported with its bucketed view), readable at
any length: each signal's envelope (its minimum and maximum per time bucket, a band) over the whole
run, and for the tracking figures a zoom on each controller's worst window per phase, the few seconds
around the moment the run's summary names as that phase's worst error on that joint (worst_windows.py),
drawn sample by sample. Values that do not exist yet (the desired trajectory before tracking starts)
are gaps. Same file names and page size as the short run's."""
import numpy as np

from figure_base import ERROR_UNITS, JOINTS, THETA, band, decorate, new_figure, save
from run_data import ZOOM_HALF_WIDTH, envelope, is_long, within
from worst_windows import PHASE_COLOURS, logged_error_at, zoom, zoom_phases


def bucket_seconds(columns):
    """The time one envelope bucket spans, s (for the titles)."""
    u = columns.buckets["utime"]
    return (u["max"][-1] - u["min"][0]) * 1e-6 / len(u["min"])


def broken_at_gaps(t, values):
    """The rows with a NaN between two that lie more than 10 logged periods apart (the detail rows of
    separate windows), so that a line is not drawn across time the log kept no rows of."""
    t, values = np.asarray(t, dtype=float), np.asarray(values, dtype=float)
    if len(t) < 3:
        return t, values
    steps = np.diff(t)
    gaps = np.nonzero(steps > 10 * np.median(steps))[0] + 1
    return np.insert(t, gaps, np.nan), np.insert(values, gaps, np.nan)


def zoom_title(label, z, unit):
    """A worst window's title: the summary's figure of that phase (the plant's), or the firmware's own
    worst (said so), or why there is none."""
    name = label if z.phase is None else "%s, %s" % (label, z.phase)
    if z.error is None:
        return "%s: %s" % (name, z.missing)
    figure = "%.4g %s" % (1e3 * z.error, unit)
    if z.time is None:
        return "%s: worst |e| %s (%s)" % (name, figure, z.missing)
    if z.source == "firmware":
        return "%s: worst |e| %s at %.3f s\n(firmware's estimate, hold and track: no summary)" % (name, figure, z.time)
    return "%s: worst |e| %s at %.3f s" % (name, figure, z.time)


def plot_tracking(plt, runs, out_dir, written, summary=None):
    phases = zoom_phases(runs, summary)
    for j, (joint, unit) in enumerate(JOINTS):
        fig, axes = new_figure(plt, 1 + len(phases), len(runs),
                               "Tracking of the %s: envelope (min-max) over the run, and the worst window%s" % (
                                   joint, " of each phase (the summary's worst error)" if phases != [None] else ""))
        for k, (label, channels) in enumerate(runs.items()):
            top = axes[0][k]
            state = channels.get("EXC_STATE", {})
            ctrl = channels.get("EXC_CONTROLLER", {})
            if is_long(ctrl):
                band(top, *envelope(ctrl, "q_desired_%d" % j, only_commanded=True), "black", "desired")
            if is_long(state):
                band(top, *envelope(state, "q_active_%d" % j), "tab:blue", "actual")
            for row, phase in enumerate(phases, start=1):
                ax = axes[row][k]
                z = zoom(ctrl, summary, label, phase, j)
                title = zoom_title(label, z, ERROR_UNITS[j])
                if z.time is not None:
                    colour = PHASE_COLOURS[phase]
                    t0, t1 = z.time - ZOOM_HALF_WIDTH, z.time + ZOOM_HALF_WIDTH
                    top.axvspan(t0, t1, color=colour, alpha=0.25,
                                label="worst window" if phase is None else "%s worst" % phase)
                    rows, desired = within(ctrl, t0, t1, "q_desired_%d" % j, only_commanded=True) if ctrl else ([], [])
                    # The log's own error there (the firmware's estimate) beside the summary's (the plant's).
                    logged = logged_error_at(ctrl, z.time, j)
                    if len(rows):
                        ax.plot(*broken_at_gaps(rows, desired), "--", color="black", label="desired")
                        if state:
                            ax.plot(*broken_at_gaps(*within(state, t0, t1, "q_active_%d" % j)), color="tab:blue",
                                    label="actual (as logged)")
                        ax.ticklabel_format(axis="y", useOffset=False)
                    ax.axvline(z.time, color=colour, linewidth=0.8,
                               label="worst; logged |e| there %.4g %s" % (1e3 * logged[0], ERROR_UNITS[j])
                               if logged and z.source == "plant" else "worst")
                    ax.set_xlim(t0, t1)
                    if logged is None:
                        # The export kept no rows at that moment (a log exported without the summary): the
                        # figure stands, the zoom says why it has no curve there.
                        title += "; no logged rows at it"
                decorate(ax, "time [s]", "%s %s" % (joint, unit), title=title, fontsize="small")
                ax.title.set_fontsize("small")
            decorate(top, "time [s]", "%s %s" % (joint, unit), title="%s: whole run" % label,
                     fontsize="small")
            top.title.set_fontsize("small")
        save(plt, fig, out_dir, "tracking_%s.png" % joint, written)


def plot_bands(plt, runs, channel, panels, title, name, out_dir, written, scale=1.0):
    """One panel per (column, ylabel) of `panels` (2 x 2 or 2 x 1), a band per run that logged the
    channel."""
    rows = 2
    cols = (len(panels) + 1) // 2
    fig, axes = new_figure(plt, rows, cols, title)
    step = 0.0
    for p, (column, ylabel) in enumerate(panels):
        ax = axes[p // cols][p % cols]
        for label, channels in runs.items():
            columns = channels.get(channel, {})
            if is_long(columns) and column in columns.buckets:
                band(ax, *envelope(columns, column), label=label, scale=scale)
                step = bucket_seconds(columns)
        decorate(ax, "time [s]", ylabel, fontsize="small")
    fig.suptitle("%s (band: min-max per %.3g s)" % (title, step))
    save(plt, fig, out_dir, name, written)


def plot_errors(plt, runs, out_dir, written):
    # In mm (mrad for the swing), as every table gives it.
    plot_bands(plt, runs, "EXC_CONTROLLER",
               [("error_%d" % j, "%s error [%s]" % (joint, ERROR_UNITS[j])) for j, (joint, _) in enumerate(JOINTS)],
               "Tracking error e = q - q_d", "tracking_error.png", out_dir, written, scale=1e3)


def plot_soil_force(plt, runs, out_dir, written):
    plot_bands(plt, runs, "EXC_STATE", [("soil_force_0", "F_soil x [kN]"), ("soil_force_1", "F_soil z [kN]")],
               "Soil force at the bucket tip (swing plane)", "soil_force.png", out_dir, written, scale=1e-3)


def plot_soil_estimates(plt, runs, out_dir, written):
    fig, axes = new_figure(plt, 2, 3, "Soil parameter estimates Theta_hat, envelope (dashed: true)")
    for i, name in enumerate(THETA):
        ax = axes[i // 3][i % 3]
        for label, channels in runs.items():
            ctrl = channels.get("EXC_CONTROLLER", {})
            if not is_long(ctrl):
                continue
            t, lo, hi = envelope(ctrl, "theta_hat_%d" % i)
            if np.all(lo == 0.0) and np.all(hi == 0.0):
                continue  # a controller without an estimator (the PID baseline publishes zeros)
            color = band(ax, t, lo, hi, label=label)
            t, _, truth = envelope(ctrl, "theta_true_%d" % i)
            if np.any(~np.isnan(truth)):
                ax.plot(t, truth, "--", color=color, alpha=0.7)
        decorate(ax, "time [s]", title=name, fontsize="small")
    save(plt, fig, out_dir, "soil_estimates.png", written)
