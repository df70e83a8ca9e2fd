import numpy as np

from drakecreep.report import loop_plots
from drakecreep.servo.polemap import PoleMap


def test_pole_map_png(tmp_path):
    K = np.array([2e6, 4e6, 8e6])
    Y = np.tile(np.array([[-100.0], [0.0], [100.0]]), (1, 3))
    pm = PoleMap(feed=1e-4, mass=40.0, friction_drop=8.0, stiffness=K, damping=Y, closed_loop=-Y / 50 + 0.5,
                 mechanism=-Y / 50, nominal=(4e6, 10.0), sim_stiffness=np.array([2e6, 8e6]),
                 sim_damping=np.array([-50.0, 50.0]), sim_creep=np.array([True, False]))
    path = loop_plots.plot_pole_map(pm, tmp_path / "map.png")
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000


import math  # noqa: E402

import pytest  # noqa: E402

from drakecreep.params import preset  # noqa: E402
from drakecreep.scenario import Scenario  # noqa: E402
from drakecreep.servo.loops import analyze_loops  # noqa: E402


@pytest.fixture(scope="module")
def analysis():
    return analyze_loops(preset("paper"), Scenario(feed=1e-3, load_case=3, duration=1.0))


@pytest.fixture
def figures(monkeypatch):
    """The figures the plot functions close, kept for inspection."""
    kept = []
    monkeypatch.setattr(loop_plots.plt, "close", lambda fig: kept.append(fig))
    return kept


def _texts(fig):
    return [t.get_text() for ax in fig.axes for t in ax.texts] + \
           [label for ax in fig.axes for label in ax.get_legend_handles_labels()[1]]


def test_bode_marks_and_labels_the_margins_the_analysis_computed(analysis, figures, tmp_path):
    loop_plots.plot_bode(analysis, tmp_path / "bode.png")
    texts = " | ".join(_texts(figures[0]))
    for loop in ("velocity", "position"):
        m = analysis.margins["sampled"][loop]
        assert f"PM {m['phase_margin_deg']:.1f} deg" in texts
        assert f"GM {m['gain_margin_dB']:.1f} dB" in texts
        assert f"crossover {m['crossover_Hz']:.3g} Hz" in texts
    phase_axis = figures[0].axes[1]
    lo, hi = phase_axis.get_ylim()
    assert -420 < lo < -180 and hi <= 90  # one wrap band, not -540 and below


def test_nyquist_is_smooth_and_shows_the_margin_points(analysis, figures, tmp_path):
    loop_plots.plot_nyquist(analysis, tmp_path / "nyq.png")
    ax = figures[0].axes[0]
    curve = max(ax.lines, key=lambda line: len(line.get_xdata()))
    x, y = np.asarray(curve.get_xdata()), np.asarray(curve.get_ydata())
    inside = (np.abs(x) < 2.5) & (np.abs(y) < 2.0)
    both = inside[1:] & inside[:-1]
    steps = np.hypot(np.diff(x), np.diff(y))[both]
    assert both.sum() > 500 and steps.max() < 0.05  # no visible corners inside the zoom
    labels = " | ".join(_texts(figures[0]))
    assert "PM " in labels and "GM " in labels and "1/Ms circle" in labels


def test_root_locus_zooms_on_the_dominant_poles_with_a_full_range_inset(analysis, figures, tmp_path):
    loop_plots.plot_gain_locus(analysis, tmp_path / "rl.png")
    fig = figures[0]
    for variant in analysis.loops:
        L = analysis.loops[variant]["velocity"]
        ax = next(a for a in fig.axes if a.get_title().startswith(f"velocity loop, {variant}"))
        x0, x1 = ax.get_xlim()
        y0, y1 = ax.get_ylim()
        import control

        poles = control.feedback(L, 1).poles()
        s = np.log(poles.astype(complex)) / L.dt if L.isdtime(strict=True) else poles
        dominant = poles[np.abs(s) < 2 * np.pi * 100]  # below 100 Hz: the ones a tuner reads
        assert dominant.size >= 2
        assert np.all((dominant.real >= x0) & (dominant.real <= x1) & (dominant.imag >= y0) & (dominant.imag <= y1))
        # zoomed in: narrower than the full range the inset shows (z: the unit disc, s: 1800 1/s)
        assert (x1 - x0) < (2.3 if L.isdtime(strict=True) else 1800) * 0.6
        assert any(child.get_title() == "full range" for child in ax.child_axes)
    assert all(math.isfinite(v) for v in (x0, x1, y0, y1))
