"""The figures of a task that repeats (plot-run): work_cycles.png, the per-cycle figures of the
summary, one line per controller."""
from figure_base import decorate, new_figure, save
from work_cycles import work_cycles


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
