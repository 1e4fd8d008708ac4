"""What every figure of plot-run shares: the page size (every PNG is exactly 1200 x 700 pixels), the
joints and soil parameters, a new figure, a panel's labels, saving, a line per run and an envelope."""
import os

from run_data import seconds

FIG_INCHES = (12.0, 7.0)


FIG_DPI = 100  # every PNG is exactly 1200 x 700 pixels


JOINTS = [("swing", "angle [rad]"), ("boom", "cylinder length [m]"),
          ("arm", "cylinder length [m]"), ("bucket", "cylinder length [m]")]
ERROR_UNITS = ["mrad", "mm", "mm", "mm"]  # a joint's error in the tables: 1e3 x rad or m


THETA = ["M_x [kg]", "B_x [N s/m]", "K_x [N/m]", "M_z [kg]", "B_z [N s/m]", "K_z [N/m]"]


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
    if not ax.has_data():
        # An empty panel (no soil in the scene, no estimator in the law) says so rather than looking
        # like a plotting failure.
        ax.text(0.5, 0.5, "nothing logged for this panel", transform=ax.transAxes, ha="center", va="center",
                color="0.5")
    elif legend and ax.get_legend_handles_labels()[1]:
        ax.legend(loc="best", **legend_options)


def plot_runs(ax, runs, channel, values):
    """One line per run that logged `channel`: values(its columns) against time, labelled by the run."""
    for label, channels in runs.items():
        columns = channels.get(channel, {})
        if columns:
            ax.plot(seconds(columns), values(columns), label=label)


def band(ax, t, lo, hi, color=None, label=None, scale=1.0):
    """An envelope: the band between the minimum and maximum per time bucket (gaps where there is no
    value), its edges drawn thin so that a narrow band still shows. Returns its colour."""
    edge, = ax.plot(t, lo * scale, color=color, linewidth=0.6, label=label)
    color = edge.get_color()
    ax.plot(t, hi * scale, color=color, linewidth=0.6)
    ax.fill_between(t, lo * scale, hi * scale, color=color, alpha=0.3, linewidth=0)
    return color
