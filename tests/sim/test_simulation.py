import json
import math

import numpy as np
import pytest

import drakecreep.sim.simulation as simulation
from drakecreep.errors import InputError
from drakecreep.params import with_value
from drakecreep.report.plots import plot_feed
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate


@pytest.fixture(scope="module")
def low_feed(paper):
    return simulate(with_value(paper, "simulation.steady_start", 0.5), Scenario(feed=1e-4, load_case=3, duration=1.5))


def test_stick_slip_at_low_feed(low_feed):
    m = low_feed.metrics
    assert low_feed.ok
    assert m.creep and m.stick_slip_cycles >= 20
    assert m.min_speed <= 0.0  # the table stops
    assert m.fluctuation_rate > 0.5


@pytest.mark.parametrize("feed", [1e-3, 5e-3])
def test_smooth_sliding_well_above_the_critical_speed(paper, feed):
    r = simulate(paper, Scenario(feed=feed, load_case=3, duration=2.0))  # the preset's window: t >= 1 s
    m = r.metrics
    assert not m.creep
    assert m.fluctuation_rate < 0.01
    assert m.mean_speed == pytest.approx(feed, rel=1e-3)


def test_determinism(short_paper):
    scenario = Scenario(feed=1e-4, load_case=1, duration=0.5)
    a, b = simulate(short_paper, scenario), simulate(short_paper, scenario)
    for name in a.signals:
        np.testing.assert_array_equal(a.signals[name], b.signals[name])
    assert a.metrics == b.metrics


def test_save_writes_csv_json_yaml_and_the_plot_reads_it(low_feed, tmp_path):
    paths = low_feed.save(tmp_path)
    header = paths["timeseries"].read_text().splitlines()[0].split(",")
    assert header[0] == "t_s" and "table_speed_m_per_s" in header
    data = np.loadtxt(paths["timeseries"], delimiter=",", skiprows=1)
    assert data.shape == (len(low_feed.time), len(header))
    summary = json.loads(paths["metrics"].read_text())["summary"]
    assert summary["stick_slip_cycles"] == low_feed.metrics.stick_slip_cycles
    plot_feed(low_feed, tmp_path / "speed.png")
    assert (tmp_path / "speed.png").stat().st_size > 10_000


def test_a_failing_run_keeps_what_was_computed(short_paper, monkeypatch):
    real = simulation.make_simulator

    def failing(system, context, sim, *args):
        simulator = real(system, context, sim, *args)

        class Breaks:
            def AdvanceTo(self, t):
                simulator.AdvanceTo(t / 2)
                raise RuntimeError("integrator gave up\nmore detail")

            def get_integrator(self):
                return simulator.get_integrator()

            def set_monitor(self, monitor):
                simulator.set_monitor(monitor)

        return Breaks()

    monkeypatch.setattr(simulation, "make_simulator", failing)
    r = simulate(short_paper, Scenario(feed=1e-3, duration=1.0))
    assert not r.ok and "integrator gave up" in r.status and "\n" not in r.status
    assert r.time[-1] == pytest.approx(0.5, abs=1e-3)
    assert r.metrics is not None and r.metrics.window_end == pytest.approx(0.5, abs=1e-3)


def test_a_divergence_is_said_in_drakes_first_sentence_not_cut_off_mid_word():
    """Drake's step-size failure goes on with several sentences of advice; the status was its first 120 characters
    ('... This is typically an indication that some part ')."""
    drake = RuntimeError("Error control wants to select step smaller than minimum allowed (1e-09). This is typically "
                         "an indication that some part of your system *with continuous state* is going unstable "
                         "and/or is producing excessively large derivatives.\nmore")
    assert simulation.integration_failure(drake) == ("diverged: the integrator needed a step below 1e-09 s (Error "
                                                     "control wants to select step smaller than minimum allowed (1e-09))")
    assert simulation.integration_failure(RuntimeError("gave up. Here.\nmore")) == "gave up. Here."
    assert simulation.integration_failure(RuntimeError()) == "RuntimeError"


def test_bad_scenarios():
    with pytest.raises(InputError, match="feed"):
        Scenario(feed=0.0)
    with pytest.raises(InputError, match="duration"):
        Scenario(duration=float("nan"))
    with pytest.raises(InputError, match="load_case"):
        Scenario(load_case=-1)


@pytest.mark.parametrize("params, scenario, field", [
    ("paper", Scenario(), "params"), ({"table": {"mass": 40.0}}, Scenario(), "params"), (None, Scenario(), "params"),
    (None, 1e-3, "params"), ("rig", {"feed": 1e-3}, "params"), ("paper_params", 1e-3, "scenario"),
    ("paper_params", None, "scenario"), ("paper_params", {"feed": 1e-3}, "scenario")])
def test_a_preset_name_mapping_or_number_for_the_objects_is_named(paper, params, scenario, field):
    """A script's preset name, mapping or feed where the objects go ended in 'AttributeError: 'str' object has no
    attribute 'simulation'' (found by the fuzzing pass)."""
    params = paper if params == "paper_params" else params
    with pytest.raises(InputError, match=f"^{field}: got .*; allowed: a {'DriveParams' if field == 'params' else 'Scenario'}"):
        simulate(params, scenario)
    with pytest.raises(InputError, match=f"^{field}: "):
        simulation.check_run(params, scenario)


def test_steady_window_must_fit(paper):
    with pytest.raises(InputError, match="steady_start"):
        simulate(paper, Scenario(duration=0.5))


@pytest.mark.parametrize("settings", [{"simulation.max_step": 1e-9},
                                      {"controller.velocity_period": 1e-9, "controller.position_period": 1e-9}])
def test_settings_that_force_billions_of_steps_are_refused_before_the_run(short_paper, settings):
    # a max_step or a sampled controller's period of 1e-9 s forced 1e9 steps per simulated second: a run of days
    p = short_paper
    for path, value in settings.items():
        p = with_value(p, path, value)
    with pytest.raises(InputError, match=f"^{list(settings)[0]}: .*[(]at most 2e[+]07"):
        simulate(p, Scenario(duration=1.0), wall_limit=5.0)  # (it ran to the wall limit: status 'stopped')


def test_gms_friction_runs_in_the_drake_diagram_and_sticks_at_low_feed():
    """friction.law: gms plugs into NutTable like LuGre (N states); the compiled path runs it."""
    from drakecreep.params import preset, with_value
    from drakecreep.scenario import Scenario
    from drakecreep.sim.simulation import simulate

    p = with_value(preset("paper"), "friction.law", "gms")
    # the law's plumbing is tested here; the convergence check (a second, 10x tighter run) has its own tests
    p = with_value(p, "simulation.convergence_check", False)
    r = simulate(p, Scenario(feed=0.1e-3, load_case=3, duration=1.3))
    assert r.ok
    # with the nut's friction on the screw (issue 15, defect 2) the cycles are slower than when this test was
    # written (10+ in the 0.3 s window then, 5 now); the mean speed over so short a window of stick-slip is
    # not the feed (8.9e-5 m/s here; 2.6 % off over a 1 s window, measured, too slow for a unit test)
    assert r.metrics.creep and r.metrics.stick_slip_cycles >= 3


def test_accuracy_defaults_per_friction_law(paper):
    assert paper.simulation.accuracy == 0.0  # the presets leave it to the friction law
    assert simulation.target_accuracy(with_value(paper, "friction.law", "lugre")) == 1e-4
    for law in ("stribeck", "coulomb"):
        assert simulation.target_accuracy(with_value(paper, "friction.law", law)) == 1e-5
    assert simulation.target_accuracy(with_value(paper, "simulation.accuracy", 3e-6)) == 3e-6


def test_convergence_check_catches_a_missed_stick_slip(short_paper):
    """Static Stribeck at 0.5 mm/s reads smooth at accuracy 1e-4 (measured) but stick-slips at 1e-5 and
    1e-6: the check sees the verdict change, reruns at 1e-5 and confirms it against 1e-6."""
    p = with_value(with_value(short_paper, "friction.law", "stribeck"), "simulation.accuracy", 1e-4)
    # measured with the nut's former place and size (on the table, 0.01 N m, 0.01); with the nut on the
    # screw this drive no longer creeps at 0.5 mm/s, at any accuracy
    for path, value in (("friction.nut_friction_on", "table"), ("nut.preload_torque", 0.01),
                        ("nut.load_friction_coefficient", 0.01)):
        p = with_value(p, path, value)
    r = simulate(p, Scenario(feed=0.5e-3, load_case=3, duration=0.6))
    assert r.metrics.creep and r.metrics.stick_slip_cycles >= 10
    assert r.metrics.converged is True
    assert r.stats["accuracy"] == pytest.approx(1e-5)
    summary = r.summary()
    assert summary["converged"] is True and summary["creep"] is True


def test_a_ctrl_c_or_sigterm_in_the_convergence_check_stops_the_run_unchecked(short_paper, monkeypatch):
    """It was read as a disagreement: the whole run simulated again at the tighter accuracy, 'converged', exit 0."""
    calls, run = [], simulation._run

    def interrupted_second(*args, **kwargs):
        calls.append(args[3])  # the accuracy
        out = run(*args, **kwargs)
        if len(calls) == 2:  # the convergence check's probe, as a SIGTERM leaves it
            out.status = "interrupted (SIGTERM) at t = 0.1 s"
        return out

    monkeypatch.setattr(simulation, "_run", interrupted_second)
    r = simulate(short_paper, Scenario(feed=1e-4, load_case=3, duration=0.5))
    assert len(calls) == 2 and calls[1] < calls[0]  # the run, then its tighter probe; no rerun
    assert r.status.startswith("interrupted (SIGTERM)") and "in the convergence check" in r.status
    assert r.metrics is not None and r.metrics.converged is None  # kept, and said not checked


def test_convergence_check_reports_disagreement_and_can_be_off(short_paper):
    p = with_value(short_paper, "simulation.convergence_tolerance", 1e-9)  # no two accuracies agree to 1e-12 m/s
    r = simulate(p, Scenario(feed=1e-4, load_case=3, duration=0.5))
    assert r.metrics.creep and r.metrics.converged is False
    assert r.summary()["converged"] is False
    # the verdict held (it creeps at every accuracy); only the amplitude missed the tolerance
    assert r.stats["convergence_verdict_agrees"] is True
    assert r.stats["convergence_fluctuation_change_mm_s"] > r.stats["convergence_tolerance_mm_s"] == pytest.approx(1e-10)
    off = simulate(with_value(short_paper, "simulation.convergence_check", False), Scenario(feed=1e-4, duration=0.5))
    assert off.metrics.converged is None and "convergence_runs" not in off.stats


    assert r.metrics.mean_speed == pytest.approx(0.1e-3, rel=0.05)


def test_to_dataframe_has_si_columns_and_matches_the_saved_csv(low_feed, tmp_path):
    import pandas as pd

    frame = low_feed.to_dataframe()
    assert frame.columns[0] == "t_s" and "table_speed_m_per_s" in frame and "spring_force_N" in frame
    np.testing.assert_array_equal(frame["table_speed_m_per_s"].to_numpy(), low_feed.signals["table_speed"])
    saved = pd.read_csv(low_feed.save(tmp_path)["timeseries"])
    assert list(saved.columns) == list(frame.columns)
    np.testing.assert_allclose(saved["table_speed_m_per_s"], frame["table_speed_m_per_s"], rtol=1e-9, atol=1e-15)


def test_closed_loop_applies_the_command_one_sample_late(short_paper):
    """Issue 15: the simulated drive applies force[k - 1] over [t_k, t_k+1) with the preset's one-sample delay.

    The log samples at the velocity period; the applied torque logged at t_k is the force command logged at
    t_(k-1) (through the lead), on both backends; without delay they are the same sample.
    """
    p = with_value(with_value(short_paper, "simulation.steady_start", 0.05), "simulation.convergence_check", False)
    p = with_value(p, "simulation.log_period", p.controller.velocity_period)
    r = p.screw.lead / (2 * math.pi)
    scenario = Scenario(feed=1e-3, load_case=3, duration=0.1)
    assert p.controller.computation_delay == 1.0
    for backend in ("compiled", "leaf"):
        s = simulate(p, scenario, backend=backend).signals
        applied, newest = s["torque_command"] / r, s["force_command"]
        assert np.ptp(newest) > 1.0  # the ramp's transient moves the command
        np.testing.assert_allclose(applied[1:], newest[:-1], rtol=1e-12)
    s0 = simulate(with_value(p, "controller.computation_delay", 0.0), scenario).signals
    np.testing.assert_allclose(s0["torque_command"] / r, s0["force_command"], rtol=1e-12)


def test_fractional_delay_runs_on_the_leaf_systems_and_is_refused_by_the_fast_path(short_paper):
    p = with_value(with_value(short_paper, "simulation.steady_start", 0.05), "simulation.convergence_check", False)
    p = with_value(p, "controller.computation_delay", 0.5)
    scenario = Scenario(feed=1e-3, load_case=3, duration=0.1)
    with pytest.raises(InputError) as err:
        simulate(p, scenario, backend="compiled")
    assert err.value.field == "controller.computation_delay"
    assert simulate(p, scenario, backend="leaf").ok
