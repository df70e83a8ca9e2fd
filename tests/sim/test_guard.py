"""Runs that would never end: the divergence guard, the wall-clock limit and Ctrl-C keep what was computed."""

import json
import os
import signal
import time

import numpy as np
import pytest

import drakecreep.sim.simulation as simulation
from drakecreep.cli import main
from drakecreep.errors import InputError
from drakecreep.params import with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import MAX_TABLE_SPEED, simulate


@pytest.fixture(scope="module")
def diverging(paper):
    """A velocity loop 4000x too stiff with the torque limit raised 10^4x: the discrete loop is unstable."""
    p = with_value(paper, "controller.velocity_gain", 5e8)
    p = with_value(p, "controller.velocity_integral_gain", 5e10)
    p = with_value(p, "motor.peak_torque", 1e5)
    return with_value(p, "simulation.steady_start", 0.3)


def test_divergence_stops_the_run_quickly_with_partial_results(diverging):
    start = time.perf_counter()
    r = simulate(diverging, Scenario(feed=1e-3, load_case=1, duration=1.0))
    assert time.perf_counter() - start < 30
    assert not r.ok and r.status.startswith("diverged at t = ") and "\n" not in r.status
    assert 0 < r.time[-1] < 0.1 and len(r.time) > 2  # kept up to the stop
    assert r.metrics is None  # no creep metrics of a run that left the physics


def test_the_guard_does_not_touch_a_healthy_run(short_paper):
    r = simulate(short_paper, Scenario(feed=1e-3, load_case=3, duration=0.6))
    assert r.ok
    assert abs(r.signals["table_speed"]).max() < MAX_TABLE_SPEED / 100


def test_cli_diverging_run_one_line_exit_1_results_saved(diverging, tmp_path, capsys, monkeypatch):
    from drakecreep.params import save_params

    path = tmp_path / "div.yaml"
    save_params(diverging, path)
    code = main(["simulate", "--params", str(path), "--load-case", "1", "--duration", "1", "--no-plot",
                 "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 1 and len(err.strip().splitlines()) == 1 and "diverged" in err
    body = json.loads((tmp_path / "out" / "metrics.json").read_text())
    assert body["summary"]["status"].startswith("diverged") and "timeseries.csv" in body["files"]


@pytest.mark.parametrize("limit", [0.3, np.float32(0.3), np.int64(1)])  # NumPy's numbers too (were refused)
def test_wall_clock_limit(short_paper, limit):
    r = simulate(short_paper, Scenario(feed=1e-3, load_case=3, duration=60.0), wall_limit=limit)
    assert r.status.startswith("stopped at t = ") and "wall-clock" in r.status
    assert r.time[-1] < 60.0


def _runs_with_deadlines(monkeypatch, expire_at=None):
    """Record the deadline each of simulate's runs gets; the run numbered ``expire_at`` (0 = the run, 1 = the
    convergence check's probe, 2 = its rerun) gets one already passed, as if the command's limit ran out there."""
    real, deadlines = simulation._run, []

    def run(*args):
        *head, deadline = args
        deadlines.append(deadline)
        if len(deadlines) - 1 == expire_at:
            deadline = time.perf_counter() - 1.0
        return real(*head, deadline)

    monkeypatch.setattr(simulation, "_run", run)
    return deadlines


def test_the_wall_clock_limit_is_the_whole_commands(short_paper, monkeypatch):
    """The limit applied to each of the up to three runs of a command (the run, the convergence check's probe,
    its rerun): a 10 s --max-wall could compute for 30 s. Every run gets the one deadline."""
    deadlines = _runs_with_deadlines(monkeypatch)
    start = time.perf_counter()
    r = simulate(short_paper, Scenario(feed=1e-3, load_case=3, duration=0.6), wall_limit=100.0)
    assert r.ok and r.metrics.converged is not None and len(deadlines) >= 2
    assert len(set(deadlines)) == 1 and start < deadlines[0] - 100.0 < time.perf_counter()


def test_a_limit_reached_in_the_convergence_check_keeps_the_complete_run(short_paper, monkeypatch):
    _runs_with_deadlines(monkeypatch, expire_at=1)
    r = simulate(short_paper, Scenario(feed=1e-3, load_case=3, duration=0.6), wall_limit=100.0)
    assert not r.ok and "wall-clock limit of 100 s reached in the convergence check" in r.status
    assert r.time[-1] == pytest.approx(0.6) and r.metrics is not None and r.metrics.converged is None


def test_a_limit_reached_in_the_rerun_keeps_the_complete_run_unconverged(short_paper, monkeypatch):
    _runs_with_deadlines(monkeypatch, expire_at=2)
    monkeypatch.setattr(simulation, "_agree", lambda *args: (False, 1e-3, False))  # the check disagrees
    r = simulate(short_paper, Scenario(feed=1e-3, load_case=3, duration=0.6), wall_limit=100.0)
    assert not r.ok and "reached in the convergence check's rerun at accuracy" in r.status
    assert r.time[-1] == pytest.approx(0.6) and r.metrics.converged is False


@pytest.mark.parametrize("limit", [0, -1.0, np.float64("nan"), True, np.bool_(True), "5", 1j])
def test_a_wall_clock_limit_that_is_no_positive_number_is_refused(short_paper, limit):
    with pytest.raises(InputError, match="wall_limit"):
        simulate(short_paper, Scenario(feed=1e-3, duration=0.1), wall_limit=limit)


@pytest.mark.parametrize("sent, code, said", [(signal.SIGINT, 130, "interrupted (Ctrl-C)"),
                                               # a SIGTERM (kill, timeout, a job scheduler) ended Python at once
                                               (signal.SIGTERM, 143, "interrupted (SIGTERM)")])
def test_ctrl_c_or_sigterm_keeps_what_was_computed(sent, code, said, short_paper, tmp_path, capsys, monkeypatch,
                                                   ctrl_c_as_at_a_terminal):
    # a real signal, sent from inside the run once it is under way (as a user's Ctrl-C would arrive)
    real = simulation._guard

    def guard(simulator, root, read_speeds, bounds, wall_limit, *args):
        report = real(simulator, root, read_speeds, bounds, wall_limit, *args)
        inner = simulator.get_monitor() if hasattr(simulator, "get_monitor") else None
        done = []

        def monitor(context):
            if context.get_time() > 0.4 and not done:
                done.append(1)
                os.kill(os.getpid(), sent)
            return inner(context) if inner else None

        if inner is not None:
            simulator.set_monitor(monitor)
        return report

    monkeypatch.setattr(simulation, "_guard", guard)
    from drakecreep.params import save_params

    path = tmp_path / "p.yaml"
    save_params(short_paper, path)
    main_code = main(["simulate", "--params", str(path), "--duration", "30", "--no-plot", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert main_code == code and said in err
    body = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert body["summary"]["status"].startswith(said)
    assert 0.4 < body["summary"]["sim_time_s"] < 30


def test_slow_run_notice_projects_and_names_the_fix():
    # 0.21 of 5 s in 15 s: 6 min at this pace (the paper preset at 1 m/s on Runge-Kutta 3)
    line = simulation.slow_run_notice(0.21, 5.0, 15.0, 780_000, "runge_kutta3")
    assert "6 min" in line and "mean step 2.7e-07 s" in line and "radau3" in line and "\n" not in line
    assert "radau3 in a" not in simulation.slow_run_notice(0.21, 5.0, 15.0, 100, "radau3")  # already implicit
    assert simulation.slow_run_notice(4.0, 5.0, 15.0, 1000, "runge_kutta3") is None  # 19 s in all: no notice


def test_a_slow_run_gets_one_notice_and_a_quick_one_none(short_paper, monkeypatch):
    lines = []
    simulate(short_paper, Scenario(feed=1e-3, load_case=3, duration=0.6), notice=lines.append)
    assert lines == []  # the default threshold: 0.6 s of this run project a few seconds
    monkeypatch.setattr(simulation, "SLOW_NOTICE", 0.0)
    monkeypatch.setattr(simulation, "SLOW_NOTICE_AFTER", 0.0)
    r = simulate(short_paper, Scenario(feed=1e-3, load_case=3, duration=0.6), notice=lines.append)
    assert r.ok and len(lines) == 2  # once per run: the run and its convergence probe
    assert all(line.startswith("slow run: ") and "of 0.6 s simulated" in line for line in lines)
