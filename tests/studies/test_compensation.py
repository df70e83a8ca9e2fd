import math

import pytest

from drakecreep.model.compensators import compensator_model, rigid_inertia
from drakecreep.studies.compensation import (
    DEFAULT_METHODS, creep_boundary, evaluate, robustness, summary_markdown, with_method,
)
from drakecreep.sim.compiled import compile_diagram
from drakecreep.model.diagram import build_diagram
from drakecreep.errors import InputError
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate

METHODS = ("static", "lugre", "dob", "dither")


@pytest.fixture(scope="module")
def one_mm_s(paper):
    p = with_value(paper, "simulation.steady_start", 0.6)
    scenario = Scenario(feed=1e-3, load_case=3, duration=1.2)
    return {m: simulate(with_method(p, m), scenario) for m in ("none",) + METHODS}


@pytest.mark.parametrize("method", METHODS)
def test_compensator_compiles_and_adds_its_torque(short_paper, method):
    feed_drive = build_diagram(with_method(short_paper, method), Scenario(feed=1e-3, load_case=3, duration=0.3))
    assert "compensation_torque" in feed_drive.signal_names
    assert compile_diagram(feed_drive).plant is not None


@pytest.mark.parametrize("method", ["lugre", "dob"])
def test_compiled_compensator_matches_leaf_systems(short_paper, method):
    p = with_method(short_paper, method)
    scenario = Scenario(feed=1e-3, load_case=3, duration=0.4)
    fast, leaf = simulate(p, scenario, backend="compiled"), simulate(p, scenario, backend="leaf")
    assert fast.signals["compensation_torque"][-1] == pytest.approx(leaf.signals["compensation_torque"][-1], rel=1e-3)


def test_static_and_lugre_supply_the_friction_the_integrator_held(short_paper, one_mm_s):
    model = compensator_model(short_paper, 3)
    friction = model.g(1e-3) + model.viscous * 1e-3
    ratio = short_paper.screw.lead / (2 * math.pi)
    held = one_mm_s["none"].signals["integrator"][-1]
    for m in ("static", "lugre"):
        r = one_mm_s[m]
        assert r.signals["compensation_torque"][-1] / ratio == pytest.approx(friction, rel=1e-3)
        assert held - r.signals["integrator"][-1] == pytest.approx(friction, rel=0.02)


def test_dob_takes_over_the_whole_load_torque(short_paper, one_mm_s):
    r = one_mm_s["dob"]
    ratio = short_paper.screw.lead / (2 * math.pi)
    assert r.signals["compensation_torque"][-1] / ratio == pytest.approx(one_mm_s["none"].signals["integrator"][-1], rel=1e-3)
    assert abs(r.signals["integrator"][-1]) < 1.0
    assert rigid_inertia(short_paper) > short_paper.motor.rotor_inertia


def test_dither_adds_its_own_ripple_above_creep(one_mm_s):
    assert one_mm_s["dither"].metrics.max_fluctuation > 10 * one_mm_s["none"].metrics.max_fluctuation


def test_motor_side_compensators_cut_but_do_not_remove_the_paper_rig_creep(short_paper):
    # issue 15 defect 2: with the ball nut's drag on the screw (its physical place, catalogue-sized: 148 N of
    # the 157 N at load case 3), most of the friction is on the motor side of the screw's spring, within a
    # motor torque's reach. At 0.1 mm/s the table still sticks and slips (the guides' share on the ~70 Hz
    # screw mode), but the model-based compensators and dither cut the fluctuation ~2x (measured 0.42-0.46 of
    # none in this 1 s run) while feedforward at the reference speed does not. With the nut lumped on the
    # table (the former default) no compensator changed the stick fraction by more than 10 %.
    rows = {r["method"]: r for r in evaluate(short_paper, ("none",) + METHODS, feeds_mm_s=(0.1,), load_cases=(3,),
                                             duration=1.0)}
    assert all(r["creep"] for r in rows.values())
    for method in ("lugre", "dob", "dither"):
        assert rows[method]["fluctuation_vs_none"] < 0.6, method
    assert rows["static"]["fluctuation_vs_none"] > 0.9


@pytest.fixture(scope="module")
def within_reach():
    """The ``rigid_axis`` preset: friction within the loop's reach (rigid transmission, kv below the slope)."""
    rows = evaluate(preset("rigid_axis"), DEFAULT_METHODS, feeds_mm_s=(0.02, 0.05, 0.1), load_cases=(3,),
                    duration=2.0)
    return {(r["label"], r["feed_mm_s"]): r for r in rows}


def test_rigid_axis_creeps_without_compensation(within_reach):
    assert all(within_reach[("none", f)]["creep"] for f in (0.02, 0.05, 0.1))


@pytest.mark.parametrize("feed", [0.05, 0.1])
def test_lugre_removes_creep_within_reach(within_reach, feed):
    # the test, on the drive where the friction is within the loop's reach: nominal model. Since issue 15
    # the compensators run at the loop rate on the encoder speed with the one-sample computation delay; LuGre
    # still removes the creep (0.0002x none, as with the ideal tachometer)
    r = within_reach[("lugre", feed)]
    assert not r["creep"]
    assert r["fluctuation_vs_none"] < 0.05
    assert r["following_error_max_um"] < 0.3 * within_reach[("none", feed)]["following_error_max_um"]


@pytest.mark.parametrize("method", ["static-measured", "dob"])
def test_speed_feedback_compensators_need_the_ideal_tachometer_within_reach(within_reach, method):
    # Issue 15 changed this result. On the ideal continuous tachometer without computation delay, static-measured
    # and the DOB removed the creep at 0.05 and 0.1 mm/s (0.0003x and 0.001-0.002x none, asserted < 0.05x before).
    # On the encoder speed at the loop rate with the one-sample delay (the default now) both creep again at
    # 0.1 mm/s: measured 0.60x (static-measured) and 0.64x (DOB) none, stuck 25-27 % of the time (both converged).
    # The ideal variant, run here as well, still removes it: the loss is the sampled, delayed speed feedback.
    r = within_reach[(method, 0.1)]
    assert r["creep"] and r["fluctuation_vs_none"] > 0.3
    p = with_value(with_value(preset("rigid_axis"), "compensation.speed_source", "ideal"),
                   "controller.computation_delay", 0.0)
    ideal = {row["label"]: row for row in evaluate(p, ("none", method), feeds_mm_s=(0.1,), load_cases=(3,),
                                                   duration=2.0)}
    assert not ideal[method]["creep"] and ideal[method]["fluctuation_vs_none"] < 0.05


def test_feedforward_and_dither_do_not_remove_creep_within_reach(within_reach):
    # static feedforward at the reference speed is a constant at a constant feed: it cannot change
    # the negative slope that drives the stick-slip; dither helps only at the lowest feed
    for feed in (0.05, 0.1):
        assert within_reach[("static", feed)]["creep"] and within_reach[("static", feed)]["fluctuation_vs_none"] > 0.9
        assert within_reach[("dither", feed)]["creep"] and within_reach[("dither", feed)]["fluctuation_vs_none"] > 0.9
    assert within_reach[("dither", 0.02)]["fluctuation_vs_none"] < 0.5
    # (the former claim "the measured-speed model chatters about zero speed at 0.02 mm/s" was an integrator
    # artefact: 2149 % at accuracy 1e-4, 115 % at 1e-5, and 1e-5 vs 1e-6 still disagree -- the convergence
    # check of issue 15 reports it unconverged, so nothing is asserted about that row)


def test_lugre_lowers_the_critical_speed_within_reach():
    rigid = preset("rigid_axis")
    none, lugre = creep_boundary(rigid, "none", 3), creep_boundary(rigid, "lugre", 3)
    assert 0.1e-3 < none < 0.3e-3
    assert lugre < 0.25 * none


def test_variant_rows_are_labelled_and_summarised(within_reach):
    rows = list(within_reach.values())
    assert {r["label"] for r in rows} == set(DEFAULT_METHODS)
    assert within_reach[("static-measured", 0.05)]["method"] == "static-measured"
    text = summary_markdown(rows, critical=[dict(method="dob", load_case=3, critical_mm_s=0.0, lowest_tested_mm_s=0.01)])
    assert "| static-measured | 3 | 0.05 |" in text
    assert "no creep down to 0.01" in text


def test_with_method_applies_a_variant(short_paper):
    p = with_method(short_paper, "static-measured")
    assert p.compensation.method == "static" and p.compensation.velocity_blend == 1.0
    assert with_method(short_paper, "static-measured", velocity_blend=0.5).compensation.velocity_blend == 0.5


def test_robustness_labels_every_mismatch(short_paper):
    rows = robustness(short_paper, ("dob",), feeds_mm_s=(1.0,), duration=0.8)
    assert [r["label"] for r in rows] == ["none", "dob nominal", "dob inertia_factor x0.7", "dob inertia_factor x1.3"]
    assert all(r["status"] == "ok" for r in rows)


def test_bad_method_is_an_input_error(short_paper):
    with pytest.raises(InputError):
        with_method(short_paper, "magic")
    with pytest.raises(InputError):
        creep_boundary(short_paper, "magic", 3)
    with pytest.raises(InputError):
        with_value(short_paper, "compensation.coulomb_factor", -1.0)


def test_every_run_is_checked_before_any_runs(short_paper, monkeypatch):
    """A run ``simulate`` would refuse is refused before the pool starts (it was refused in a worker)."""
    import drakecreep.processes
    import drakecreep.studies.compensation as compensation

    def no_work(*args, **kwargs):
        raise AssertionError("a run started")

    monkeypatch.setattr(drakecreep.processes, "process_pool", no_work)
    monkeypatch.setattr(compensation, "simulate", no_work)
    bad = with_value(short_paper, "simulation.log_period", 1e-9)
    with pytest.raises(InputError, match=r"simulation\.log_period: got 1e-09"):
        evaluate(bad, ("none", "dob"), feeds_mm_s=(1.0,), load_cases=(1,), duration=2.0, workers=2)
    with pytest.raises(InputError, match="simulation.log_period"):
        robustness(bad, ("dob",), feeds_mm_s=(1.0,), duration=2.0, workers=1)
    with pytest.raises(InputError, match="load_case"):
        evaluate(short_paper, ("none",), feeds_mm_s=(1.0,), load_cases=(9,), duration=2.0, workers=2)


@pytest.mark.parametrize("duration", [1e-300, 0.0099, 0.01, 0.0999, 1e9, float("nan")])
def test_a_run_too_short_to_measure_names_the_duration(paper, monkeypatch, duration):
    """1e-300 s was refused as 'simulation.log_period: got 0.00025; allowed: <= 2.5e-302 s', a field nobody set;
    0.01 s gave verdicts measured on the 0.05 s acceleration ramp: the window (steady_start, or the run's last
    half) starts after the ramp, so 0.1 s at least."""
    import drakecreep.studies.compensation as compensation

    def no_work(*args, **kwargs):
        raise AssertionError("a run was checked or started")

    monkeypatch.setattr(compensation, "check_run", no_work)
    for study in (lambda: evaluate(paper, ("none",), feeds_mm_s=(1.0,), load_cases=(1,), duration=duration),
                  lambda: robustness(paper, ("dob",), feeds_mm_s=(1.0,), duration=duration)):
        with pytest.raises(InputError) as err:
            study()
        assert err.value.field == "duration"
        assert "allowed: a time in [0.1, 3600] s (the metrics window" in str(err.value)
        assert "acceleration_time = 0.05 s" in str(err.value)
    assert compensation.check_duration(paper, 0.1) == 0.1


def test_without_a_ramp_the_window_needs_only_its_samples(paper):
    """With no acceleration ramp the least run is the window's 20 samples of the 0.25 ms log on either side."""
    from drakecreep.studies.compensation import check_duration

    no_ramp = with_value(paper, "simulation.acceleration_time", 0.0)
    assert check_duration(no_ramp, 0.01) == 0.01
    with pytest.raises(InputError, match=r"a time in \[0.01, 3600\] s"):
        check_duration(no_ramp, 0.0099)


def test_write_report_is_atomic(tmp_path, monkeypatch):
    import drakecreep.files
    from drakecreep.studies.compensation import write_report

    row = dict(label="none", method="none", load_case=3, feed_mm_s=1.0, status="ok", max_fluctuation_mm_s=1e-3,
               fluctuation_rate_percent=0.1, stick_fraction=0.0, creep=False, following_error_max_um=1.0,
               following_error_rms_um=1.0, converged=True, fluctuation_vs_none=1.0, stick_fraction_vs_none=0.0)
    paths = write_report(tmp_path, [row, dict(row, feed_mm_s=2.0)])
    before = {name: p.read_bytes() for name, p in paths.items()}

    def fail(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(drakecreep.files.os, "replace", fail)
    with pytest.raises(OSError):
        write_report(tmp_path, [dict(row, feed_mm_s=5.0)])
    assert {name: p.read_bytes() for name, p in paths.items()} == before  # no file half-replaced
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in paths.values())
