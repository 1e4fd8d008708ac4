"""The figures of a long run (more than 20 s at 1 kHz: exported with its bucketed view), readable at
any length: each signal's envelope (its minimum and maximum per time bucket, a band) over the whole
run, and for the tracking figures a zoom on each controller's worst window, the few seconds around
its largest error on that joint, drawn sample by sample. Values that do not exist yet (the desired
trajectory before tracking starts) are gaps. Same file names and page size as the short run's."""
import numpy as np

from figure_base import ERROR_UNITS, JOINTS, THETA, band, decorate, new_figure, save
from run_data import ZOOM_HALF_WIDTH, envelope, is_long, within, worst_window


def bucket_seconds(columns):
    """The time one envelope bucket spans, s (for the titles)."""
    u = columns.buckets["utime"]
    return (u["max"][-1] - u["min"][0]) * 1e-6 / len(u["min"])


def plot_tracking(plt, runs, out_dir, written):
    for j, (joint, unit) in enumerate(JOINTS):
        fig, axes = new_figure(plt, 2, len(runs), "Tracking of the %s: envelope (min-max) over the run, "
                                                  "and the worst window" % joint)
        for k, (label, channels) in enumerate(runs.items()):
            top, zoom = axes[0][k], axes[1][k]
            state = channels.get("EXC_STATE", {})
            ctrl = channels.get("EXC_CONTROLLER", {})
            if is_long(ctrl):
                band(top, *envelope(ctrl, "q_desired_%d" % j, only_commanded=True), "black", "desired")
            if is_long(state):
                band(top, *envelope(state, "q_active_%d" % j), "tab:blue", "actual")
            worst = worst_window(ctrl, j)
            title = "%s: no tracking" % label
            if worst:
                t_w, e_w = worst
                t0, t1 = t_w - ZOOM_HALF_WIDTH, t_w + ZOOM_HALF_WIDTH
                top.axvspan(t0, t1, color="tab:red", alpha=0.25, label="worst window")
                zoom.plot(*within(ctrl, t0, t1, "q_desired_%d" % j, only_commanded=True), "--",
                          color="black", label="desired")
                if state:
                    zoom.plot(*within(state, t0, t1, "q_active_%d" % j), color="tab:blue", label="actual")
                zoom.axvline(t_w, color="tab:red", linewidth=0.8)
                title = "%s: worst |e| %.3g %s at %.2f s" % (label, 1e3 * e_w, ERROR_UNITS[j], t_w)
            decorate(top, "time [s]", "%s %s" % (joint, unit), title="%s: whole run" % label,
                     fontsize="small")
            decorate(zoom, "time [s]", "%s %s" % (joint, unit), title=title, fontsize="small")
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
