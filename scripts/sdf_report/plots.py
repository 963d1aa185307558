"""Figures of the report (matplotlib, Agg backend): log-log curves and the colour bar of the
grids' heat maps, written as PNG into the report directory."""

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)
from matplotlib.colors import Normalize  # noqa: E402
from matplotlib.ticker import LogFormatterSciNotation  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

DPI = 110
MARKERS = "osD^vP*Xph<>"  # a marker per curve: curves that nearly coincide stay distinguishable


class Curve:
    """One line of a log-log plot: points (x, y), a label and a dashed flag (BCC)."""

    def __init__(self, label, xs, ys, dashed=False):
        pairs = sorted(zip(xs, ys))
        self.label = label
        self.xs = [p[0] for p in pairs]
        self.ys = [p[1] for p in pairs]
        self.dashed = dashed


def log_log(path, title, xlabel, ylabel, curves, markers=None):
    """Writes a log-log plot of `curves`; `markers`: optional (label, xs, ys) drawn as crosses
    (e.g. the thesis's figures)."""
    fig, ax = plt.subplots(figsize=(9.5, 4.8))
    for i, c in enumerate(curves):
        ax.plot(c.xs, c.ys, marker=MARKERS[i % len(MARKERS)], markersize=5, fillstyle="none",
                linestyle="--" if c.dashed else "-", label=c.label)
    if markers:
        label, xs, ys = markers
        ax.scatter(xs, ys, marker="x", color="k", zorder=5, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    for axis in (ax.xaxis, ax.yaxis):
        # An axis spanning less than 1.5 decades gets values at some minor ticks too, not one label.
        axis.set_minor_formatter(LogFormatterSciNotation(labelOnlyBase=False, minor_thresholds=(1.5, 0.4)))
    ax.tick_params(which="minor", labelsize=7)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)  # beside: no curve hidden
    _save(fig, path)


def heat_map_colour_bar(path, max_degrees):
    """The legend of the grids' normal-error heat maps (harness/render/heat_map.h): viridis from
    0 to max_degrees (larger angles clamped to the top colour) with tick values, and the
    magenta of pixels that only one of the two images hits. Returns the tick labels."""
    fig, ax = plt.subplots(figsize=(7.5, 0.95))
    fig.subplots_adjust(left=0.04, right=0.70, bottom=0.5, top=0.92)
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=Normalize(0.0, max_degrees), cmap="viridis"),
                       cax=ax, orientation="horizontal", extend="max")
    bar.set_ticks([max_degrees * i / 4 for i in range(5)])
    bar.set_label("angle between reconstructed and true normal (degrees; above %g shown as %g)"
                  % (max_degrees, max_degrees), fontsize=8)
    bar.ax.tick_params(labelsize=8)
    fig.legend(handles=[Patch(color=(1, 0, 1), label="hit in one image only"),
                        Patch(facecolor="white", edgecolor="0.6", label="background")],
               loc="center right", fontsize=8, frameon=False)
    fig.canvas.draw()  # places the ticks
    ticks = [t.get_text() for t in bar.ax.get_xticklabels() if t.get_text()]
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return ticks


def _save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def remove_old_plots(out_dir):
    """PNG files of an earlier report in out_dir (everything the report writes is regenerated)."""
    for name in os.listdir(out_dir):
        if name.endswith(".png"):
            os.remove(os.path.join(out_dir, name))


def wall_against_kernel(path, title, series):
    """Wall time against kernel time, log-log: `series` is [(label, [(name, kernel, wall)])],
    one marker per series (a machine), each point named; the line wall = kernel is where the
    user waits for nothing but the computation, wall = 10 x kernel and 100 x beside it."""
    fig, ax = plt.subplots(figsize=(9.5, 5.6))
    kernels = [k for _, points in series for _, k, _ in points]
    walls = [w for _, points in series for _, _, w in points]
    x_lo, x_hi = min(kernels) / 3, max(kernels) * 3
    y_lo, y_hi = min(x_lo, min(walls) / 3), max(walls) * 3
    for factor, style in ((1, "-"), (10, "--"), (100, ":")):
        ax.plot([x_lo, x_hi], [x_lo * factor, x_hi * factor], linestyle=style, color="0.6", linewidth=1,
                label="wall = kernel" if factor == 1 else "wall = %d x kernel" % factor)
    for i, (label, points) in enumerate(series):
        ax.scatter([k for _, k, _ in points], [w for _, _, w in points], marker=MARKERS[i % len(MARKERS)], s=36,
                   zorder=5, label=label)
        for name, k, w in points:
            ax.annotate(name, (k, w), textcoords="offset points", xytext=(5, 3), fontsize=7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(x_lo, x_hi)
    ax.set_ylim(y_lo, y_hi)
    ax.set_xlabel("kernel (or compute) time, s")
    ax.set_ylabel("what the user waits (wall time), s")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    _save(fig, path)
