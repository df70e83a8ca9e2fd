"""Plots of simulation results (report layer: mm/s, um and N on the axes)."""

from pathlib import Path

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from drakecreep.errors import InputError
from drakecreep.model.lumped import lumped
from drakecreep.paper.creep import critical_speed_of
from drakecreep.params import field_unit, preset, with_value
from drakecreep.files import write_atomic
from drakecreep.sim.sweep import SCENARIO_FIELDS

__all__ = ["plot_feed", "feed_title", "zoom_window", "plot_stability_map", "axis_label", "column_label"]


def zoom_window(result, span=None):
    """A short window at the end of the run showing a few stick-slip cycles (or 0.1 s)."""
    t = result.time
    m = result.metrics
    if span is None:
        span = 0.1
        if m is not None and m.stick_slip_frequency > 0:
            span = min(0.5, max(0.02, 8.0 / m.stick_slip_frequency))
    return max(t[0], t[-1] - span), t[-1]


def plot_feed(result, path):
    """Speed (whole run and a zoom), forces and travel error of one feed, saved as a PNG.

    Parameters
    ----------
    result : drakecreep.sim.simulation.SimulationResult
    path : str or Path
    """
    s, t = result.signals, result.time
    m, sc, p = result.metrics, result.scenario, result.params
    fx = p.load_case(sc.load_case).fx
    t0, t1 = zoom_window(result)
    z = (t >= t0) & (t <= t1)
    fig, axes = plt.subplots(4, 1, figsize=(9, 10), constrained_layout=True)

    def speeds(ax, mask, zero_line=True):
        ax.plot(t[mask], s["motor_velocity"][mask] * 1e3, color="0.6", lw=0.8, label="motor (at the table)")
        ax.plot(t[mask], s["table_speed"][mask] * 1e3, color="C0", lw=1.0, label="table")
        ax.plot(t[mask], s["v_ref"][mask] * 1e3, "k--", lw=0.8, label="reference")
        if zero_line:
            ax.axhline(0.0, color="k", lw=0.5)
        ax.set_ylabel("speed (mm/s)")
        ax.ticklabel_format(axis="y", useOffset=False)

    ax = axes[0]
    speeds(ax, slice(None))
    if m is not None:
        ax.axvspan(m.window_start, m.window_end, color="C2", alpha=0.07, lw=0, label="metrics window")
    ax.axvspan(t0, t1, color="C1", alpha=0.15, lw=0, label="zoom below")
    ax.legend(loc="lower right", fontsize=8, ncol=5)
    ax.set_title("whole run", fontsize=9)
    ax = axes[1]
    # in the zoom, show zero only when the table gets near it, so a small fluctuation stays visible
    speeds(ax, z, zero_line=bool(np.min(s["table_speed"][z] * np.sign(sc.feed)) < 0.2 * abs(sc.feed)))
    ax.set_title(f"zoom {t0:.3f}-{t1:.3f} s", fontsize=9)
    ax = axes[2]
    ax.plot(t[z], s["spring_force"][z] - fx, color="C1", lw=0.9, label="screw force - axial load Fx")
    ax.plot(t[z], s["friction_force"][z], color="C3", lw=0.9, label="friction force")
    ax.set_ylabel("force (N)")
    ax.ticklabel_format(axis="y", useOffset=False)
    ax.set_title(f"zoom: forces on the table (Fx = {fx:g} N)", fontsize=9)
    ax.legend(loc="lower right", fontsize=8, ncol=2)
    ax = axes[3]
    travel_ref = s["x_ref"] - s["x_ref"][0]
    ax.plot(t, (travel_ref - (s["table_position"] - s["table_position"][0])) * 1e6, color="C4", lw=0.9,
            label="table")
    ax.plot(t, (travel_ref - (s["motor_position"] - s["motor_position"][0])) * 1e6, color="0.6", lw=0.8,
            label="motor")
    ax.set_ylabel("travel error (um)")
    ax.set_xlabel("time (s)")
    ax.set_title("reference travel minus travel", fontsize=9)
    ax.legend(loc="lower right", fontsize=8, ncol=2)
    fig.suptitle(feed_title(result), fontsize=10)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


#: metric column suffix -> unit shown on a plot
_SUFFIX_UNITS = {"_percent": "%", "_mm_s": "mm/s", "_um": "um", "_Hz": "Hz", "_N": "N", "_s": "s"}


def feed_title(result):
    """The title of :func:`plot_feed`: the run's scenario and model, its metrics, its status when it failed."""
    p, sc, m = result.params, result.scenario, result.metrics
    title = (
        f"feed {sc.feed * 1e3:g} mm/s, load case {sc.load_case}, {p.friction.law} friction, "
        f"{'sampled' if p.controller.sampled else 'continuous'} cascade"
    )
    stats = result.stats or {}
    if stats.get("model") == "multibody":
        title += (f", multibody model (N = {stats.get('n_segments')}, "
                  f"{'rigid' if stats.get('rigid_joints') else 'Tables 1-2'} fixed joints)")
    if m is not None:
        title += (
            f"\nmax fluctuation {m.max_fluctuation * 1e3:.3g} mm/s ({m.fluctuation_rate * 100:.3g} %), "
            f"stick {m.stick_fraction * 100:.1f} %, {m.stick_slip_cycles} stick-slip cycles"
        )
    if not result.ok:
        title += f"\n{result.status}"
    return title


def column_label(column):
    """A table column as an axis label: ``fluctuation_rate_percent`` -> ``fluctuation rate (%)``."""
    for suffix, unit in _SUFFIX_UNITS.items():
        if column.endswith(suffix):
            return f"{column[:-len(suffix)].replace('_', ' ')} ({unit})"
    return column.replace("_", " ")


def axis_label(params, path):
    """A swept parameter as an axis label with its SI unit: ``nut.axial_stiffness (N/m)``."""
    if path in SCENARIO_FIELDS:
        return {"feed": "feed (m/s)", "load_case": "load case", "duration": "duration (s)"}.get(path, path)
    try:
        unit = field_unit(params, path)
    except InputError:
        return path
    return f"{path} ({unit})" if unit not in ("", "-") else path


def plot_stability_map(table, x, path, *, y="feed", color="fluctuation_rate_percent", base=None, load_case=None,
                       log_x=True, log_y=True, title=None):
    """Scatter map of a sweep (``x`` x ``y``, colour = ``color``) with the analytic ``v0`` curve.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep table.
    x : str
        Swept parameter path on the horizontal axis.
    path : path
        PNG to write (atomically).
    y : str
        Vertical axis; ``"feed"`` is drawn in mm/s.
    color : str
        Metric column for the colour.
    base : DriveParams, optional
        When given (and ``y == "feed"``), the paper's ``v0`` for ``base`` with ``x`` set to each value
        is drawn as a line; cases that creep (``creep`` column) are ringed.
    load_case : int, optional
        Load case for ``v0`` (default: the table's first).
    """
    for name in (x, y, color):
        if name not in table.columns:
            raise InputError("column", name, "one of " + ", ".join(map(str, table.columns)))
    scale_y = 1e3 if y == "feed" else 1.0
    fig, ax = plt.subplots(figsize=(7, 5))
    values = table[color].astype(float)
    positive = values[values > 0]
    norm = None
    if len(positive) and positive.max() / max(positive.min(), 1e-300) > 100:
        from matplotlib.colors import LogNorm

        norm = LogNorm(vmin=max(positive.min(), positive.max() * 1e-6), vmax=positive.max())
        values = values.clip(lower=norm.vmin)
    sc = ax.scatter(table[x], table[y] * scale_y, c=values, cmap="viridis", norm=norm, s=36, marker="s")
    fig.colorbar(sc, ax=ax, label=column_label(color))
    if "creep" in table.columns:
        creeping = table[table["creep"].fillna(False).astype(bool)]
        ax.scatter(creeping[x], creeping[y] * scale_y, facecolors="none", edgecolors="red", s=80,
                   linewidths=1.0, label="creep (stick-slip in simulation)")
    if base is not None and y == "feed":
        lc = int(table["load_case"].iloc[0]) if load_case is None else load_case
        xs = np.sort(table[x].astype(float).unique())
        if len(xs) > 1:
            dense = np.geomspace(xs[0], xs[-1], 60) if log_x and xs[0] > 0 else np.linspace(xs[0], xs[-1], 60)
        else:
            dense = xs
        v0 = []
        for value in dense:
            drive = with_value(base, x, float(value)) if x not in SCENARIO_FIELDS else base
            v0.append(critical_speed_of(lumped(drive, lc)))
        ax.plot(dense, np.array(v0) * 1e3, "k--", label="paper eq. 11: v0 (C1 at v0)")
    if log_x:
        ax.set_xscale("log")
    if log_y:
        ax.set_yscale("log")
    reference = base if base is not None else preset("paper")
    ax.set_xlabel(axis_label(reference, x))
    ax.set_ylabel("feed (mm/s)" if y == "feed" else axis_label(reference, y))
    ax.set_title(title or f"stability map: {color}")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    plt.close(fig)
    return Path(path)
