"""drake_replay.replay_drakecreep (kind: drakecreep): the compiled fast path against the leaf systems."""

import dataclasses
import math

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.gap.drake_replay import replay_drakecreep, replay_params
from drakecreep.gap.measured import ControllerMeta, MeasuredMeta, MeasuredRun, SensorMeta
from drakecreep.gap.truth import out_and_back
from drakecreep.params import preset, with_value

N = 300


def _rig():
    rig = preset("paper")
    for path, value in (("friction.law", "stribeck"), ("friction.regularization_velocity", 1e-4),
                        ("simulation.accuracy", 1e-4), ("motor.current_loop_time_constant", 0.0),
                        ("disturbance.lead_error_amplitude", 1e-6)):
        rig = with_value(rig, path, value)
    return rig


def _run(params, sensors=SensorMeta()):
    meta = MeasuredMeta(u_units="N", u_gain=1.0, params=params, controller=ControllerMeta(kind="drakecreep"),
                        sensors=sensors)
    t = np.arange(N) * 1e-3
    x_ref = out_and_back(0.02, 0.0, n=N, dt=1e-3, leg=0.12, starts=(0.02, 0.15))
    f_ext = 30.0 * np.sin(2 * np.pi * 7.0 * t)
    return MeasuredRun(t=t, x_ref=x_ref, x_motor=x_ref, u=np.zeros(N), meta=meta, f_ext=f_ext)


def test_compiled_replay_agrees_with_the_leaf_systems():
    """Same equations, same integrator: positions agree to 10 nm, the force command to two encoder counts.

    One count of the motor encoder at the table is ``lead / counts``; the velocity loop differences the
    counts over one period, so a count read one step earlier or later (the two integrators' step sequences
    differ in the last digits) moves the command by ``kv count / period``.
    """
    rig = _rig()
    run = _run(rig)
    fast = replay_drakecreep(run)
    slow = replay_drakecreep(run, backend="leaf")
    assert np.max(np.abs(fast.x_motor - slow.x_motor)) < 1e-8
    assert np.max(np.abs(fast.x_table - slow.x_table)) < 1e-8
    count = rig.screw.lead / rig.sensors.encoder_counts_per_rev
    per_count = rig.controller.velocity_gain * count / rig.controller.velocity_period
    assert np.max(np.abs(fast.u - slow.u)) <= 2 * per_count
    assert np.max(np.abs(slow.u)) > 100 * per_count  # the comparison is not trivial
    assert np.array_equal(fast.force, fast.u + run.f_ext)


def test_declared_sensor_resolutions_replace_the_params_files():
    rig = _rig()
    declared = SensorMeta(encoder_resolution=rig.screw.lead / 2**16, scale_resolution=1e-6)
    p = replay_params(_run(rig, declared))
    assert p.sensors.encoder_counts_per_rev == 2**16 and p.sensors.scale_resolution == 1e-6
    ideal = replay_params(_run(rig, declared), quantize=False)
    assert ideal.sensors.encoder_counts_per_rev == 0 and ideal.sensors.scale_resolution == 0.0
    assert replay_params(_run(rig)).sensors == rig.sensors  # 0 = not declared
    with pytest.raises(InputError) as err:
        replay_params(_run(rig, SensorMeta(encoder_resolution=rig.screw.lead / (2**16 + 0.5))))
    assert err.value.field == "sensors.encoder_resolution"
    # beyond the params' counts per revolution (2**40), or a scale beyond its range: named by the metadata's key
    # (1e-30 m was 'encoder_counts_per_rev: got 4999999999999999791559868416')
    with pytest.raises(InputError) as err:
        replay_params(_run(rig, SensorMeta(encoder_resolution=1e-30)))
    assert err.value.field == "sensors.encoder_resolution" and "or 0 for none" in err.value.allowed
    with pytest.raises(InputError) as err:
        replay_params(_run(rig, SensorMeta(scale_resolution=1.0)))
    assert err.value.field == "sensors.scale_resolution" and "0.001" in err.value.allowed
    with pytest.raises(InputError, match="backend"):
        replay_drakecreep(_run(rig), backend="fast")


def test_coarser_declared_encoder_changes_the_replay():
    """The declared resolution is what the replay counts with: a 2^10-count encoder shows in the command."""
    rig = _rig()
    fine = replay_drakecreep(_run(rig))
    coarse = replay_drakecreep(_run(rig, SensorMeta(encoder_resolution=rig.screw.lead / 2**10)))
    count = rig.screw.lead / 2**10
    assert np.max(np.abs(coarse.u - fine.u)) > rig.controller.velocity_gain * count / rig.controller.velocity_period
    assert math.isfinite(coarse.wall_time) and dataclasses.is_dataclass(coarse)


def test_lead_error_is_fixed_to_the_screw_not_to_the_run():
    """A run that starts at ``x0`` meets the lead error at phase ``phi + 2 pi x0 / P``: its replay is the replay of
    the same run started at 0 with that phase, and differs from a run at another position."""
    from drakecreep.gap.drake_replay import at_origin

    rig = with_value(_rig(), "disturbance.lead_error_phase", 0.4)
    period = rig.disturbance.lead_error_period
    x0 = 0.123 * period + 3 * period  # an eighth of a period off, three periods along
    at0 = _run(rig)
    moved = dataclasses.replace(at0, x_ref=at0.x_ref + x0, x_motor=at0.x_motor + x0)
    shifted = _nut_moved(with_value(rig, "disturbance.lead_error_phase",
                                    math.remainder(0.4 + 2 * math.pi * x0 / period, 2 * math.pi)), x0)
    a = replay_drakecreep(moved, rig)
    b = replay_drakecreep(at0, shifted)
    assert np.max(np.abs((a.x_table - x0) - b.x_table)) < 1e-12 and np.max(np.abs(a.u - b.u)) < 1e-6
    plain = replay_drakecreep(at0, rig)
    assert np.max(np.abs(plain.x_table - b.x_table)) > 0.2 * rig.disturbance.lead_error_amplitude
    assert at_origin(rig, 0.0) is rig
    off = with_value(rig, "disturbance.lead_error_amplitude", 0.0)
    assert at_origin(off, x0) == _nut_moved(off, x0)
    with pytest.raises(InputError, match="disturbance.lead_error_phase"):
        with_value(rig, "disturbance.lead_error_phase", 7.0)


def test_the_friction_map_is_fixed_to_the_guides_not_to_the_run():
    """A run that starts at ``x0`` meets the friction map ``x0`` along its travel: its replay is the replay of the
    same run started at 0 with the map's travel moved back by ``x0``, and differs from the run at 0 with the map as
    written; the leaf systems replay the map as the compiled diagram does."""
    from drakecreep.gap.drake_replay import at_origin

    rig = with_value(_rig(), "disturbance.lead_error_amplitude", 0.0)  # the map alone
    for path, value in (("friction.position_map_0", 0.3), ("friction.position_map_2", -0.25),
                        ("friction.position_map_start", 0.05), ("friction.position_map_end", 0.09)):
        rig = with_value(rig, path, value)
    x0 = 0.0637
    at0 = _run(rig)
    moved = dataclasses.replace(at0, x_ref=at0.x_ref + x0, x_motor=at0.x_motor + x0)
    shifted = _nut_moved(with_value(with_value(rig, "friction.position_map_start", 0.05 - x0),
                                    "friction.position_map_end", 0.09 - x0), x0)
    assert at_origin(rig, x0) == shifted
    assert at_origin(rig, -x0).friction.position_map_end == pytest.approx(0.09 + x0)  # moved up: the end first
    a = replay_drakecreep(moved, rig)
    b = replay_drakecreep(at0, shifted)
    assert np.max(np.abs((a.x_motor - x0) - b.x_motor)) < 1e-12 and np.max(np.abs(a.u - b.u)) < 1e-6
    plain = replay_drakecreep(at0, rig)
    assert np.max(np.abs(plain.u - b.u)) > 1.0  # N: the guides' friction at another level
    leaf = replay_drakecreep(moved, rig, backend="leaf")
    assert np.max(np.abs(leaf.u - a.u)) < 0.05 * np.max(np.abs(plain.u - b.u))


def _started_elsewhere(rig, period, name):
    """A run of ``rig`` at 0, the same run started ``x0`` (three and an eighth periods) along, and ``rig`` with the
    phases of ``name`` (its fundamental 0.4 rad, its second harmonic -1.3 rad in ``rig``) moved to ``x0``."""
    x0 = 0.123 * period + 3 * period
    at0 = _run(rig)
    moved = dataclasses.replace(at0, x_ref=at0.x_ref + x0, x_motor=at0.x_motor + x0)
    shifted = with_value(with_value(rig, f"disturbance.{name}_phase",
                                    math.remainder(0.4 + 2 * math.pi * x0 / period, 2 * math.pi)),
                         f"disturbance.{name}_2_phase", math.remainder(-1.3 + 4 * math.pi * x0 / period, 2 * math.pi))
    return at0, moved, _nut_moved(shifted, x0), x0


def _nut_moved(params, x0):
    """``params`` with the nut ``x0`` further from the thrust bearing (where a run started at ``x0`` has it)."""
    return with_value(params, "screw.nut_start_distance", params.screw.nut_start_distance + x0)


def test_cogging_is_fixed_to_the_motor_not_to_the_run():
    """A run that starts at ``x0`` meets the cogging at ``phi + 2 pi x0 / P`` and its second harmonic at
    ``phi2 + 4 pi x0 / P``: its replay is that of the same run started at 0 with those phases (the start in
    equilibrium either way), and differs from the run at 0 with the phases as written."""
    from drakecreep.gap.drake_replay import at_origin

    rig = with_value(_rig(), "disturbance.lead_error_amplitude", 0.0)  # the cogging alone
    for path, value in (("disturbance.cogging_force", 4.0), ("disturbance.cogging_phase", 0.4),
                        ("disturbance.cogging_2_force", 1.5), ("disturbance.cogging_2_phase", -1.3)):
        rig = with_value(rig, path, value)
    at0, moved, shifted, x0 = _started_elsewhere(rig, rig.disturbance.cogging_period, "cogging")
    assert at_origin(rig, x0) == shifted
    a = replay_drakecreep(moved, rig)
    b = replay_drakecreep(at0, shifted)
    assert np.max(np.abs((a.x_motor - x0) - b.x_motor)) < 1e-12 and np.max(np.abs(a.u - b.u)) < 1e-6
    plain = replay_drakecreep(at0, rig)
    assert np.max(np.abs(plain.u - b.u)) > 1.0  # N: the cogging's 4 N at another phase


def test_the_lead_errors_second_harmonic_is_fixed_to_the_screw_too():
    """The second harmonic turns twice per period: a run from ``x0`` meets it at ``phi2 + 4 pi x0 / P``."""
    rig = with_value(with_value(with_value(_rig(), "disturbance.lead_error_phase", 0.4),
                                "disturbance.lead_error_2_amplitude", 0.7e-6), "disturbance.lead_error_2_phase", -1.3)
    at0, moved, shifted, x0 = _started_elsewhere(rig, rig.disturbance.lead_error_period, "lead_error")
    a = replay_drakecreep(moved, rig)
    b = replay_drakecreep(at0, shifted)
    assert np.max(np.abs((a.x_table - x0) - b.x_table)) < 1e-12 and np.max(np.abs(a.u - b.u)) < 1e-6
    one = replay_drakecreep(at0, with_value(shifted, "disturbance.lead_error_2_amplitude", 0.0))
    assert np.max(np.abs(one.x_table - b.x_table)) > 0.5e-6  # the harmonic moves the table


def test_a_fractional_computation_delay_is_replayed_on_the_leaf_systems():
    """The compiled path takes one sampling offset; a params file with 1.5 samples of delay is replayed anyway,
    on the leaf systems (same result as asking for them), and differs from 1 and 2 samples."""
    rig = with_value(_rig(), "controller.computation_delay", 1.5)
    run = _run(rig)
    auto = replay_drakecreep(run)
    leaf = replay_drakecreep(run, backend="leaf")
    assert np.array_equal(auto.u, leaf.u)
    for whole in (1.0, 2.0):
        other = replay_drakecreep(run, with_value(rig, "controller.computation_delay", whole))
        assert np.max(np.abs(other.u - auto.u)) > 1.0


def test_an_asymmetric_friction_is_an_offset_on_both_legs_compiled_and_leaf():
    """Levels (1 + a) moving +x and (1 - a) moving -x: the force command rises by ``a_c Fc + a_v Fv |v|`` on
    the out leg and on the back leg alike (what an identification reads as an offset); the compiled diagram
    carries it as the leaf systems do."""
    from drakecreep.model.nut_table import friction_levels

    rig = _rig()
    asym = with_value(with_value(rig, "friction.coulomb_asymmetry", 0.3), "friction.viscous_asymmetry", 0.5)
    sym_run, run = _run(rig), _run(asym)
    fast, slow, base = replay_drakecreep(run), replay_drakecreep(run, backend="leaf"), replay_drakecreep(sym_run)
    count = rig.screw.lead / rig.sensors.encoder_counts_per_rev
    assert np.max(np.abs(fast.u - slow.u)) <= 2 * rig.controller.velocity_gain * count / rig.controller.velocity_period
    fc = friction_levels(asym, asym.load_case(0))[0]  # the replay is unloaded (load case 0)
    expected = 0.3 * fc + 0.5 * asym.friction.viscous * 0.02
    for lo, hi in ((0.06, 0.11), (0.19, 0.24)):  # cruise at 20 mm/s out, then back
        window = (run.t >= lo) & (run.t <= hi)
        assert np.mean(fast.u[window] - base.u[window]) == pytest.approx(expected, rel=0.05)


@pytest.mark.parametrize("load_case, constant_force, feedback", [(3, 0.0, "motor"), (0, 25.0, "motor"),
                                                                   (3, 0.0, "table")])
def test_a_run_under_an_axial_load_replays_from_where_it_started(load_case, constant_force, feedback):
    """At rest under an axial load (the load case's fx, ``loads.constant_force``) the screw is wound up and the
    motor encoder reads that: a run recorded so, replayed with its own params, starts in the same equilibrium,
    not with a step of the reference. The force command agrees to within a few encoder counts from the first
    sample (one count of the encoder's grid is where the run's first reading cannot say the motor was), and the
    whole run moves by the constant force. With the scale closing the position loop the table's first reading is
    the origin."""
    rig = with_value(with_value(_rig(), "loads.constant_force", constant_force), "controller.position_feedback",
                     feedback)
    blank = _run(rig)
    sim = replay_drakecreep(blank, load_case=load_case)
    run = dataclasses.replace(blank, x_motor=sim.x_motor, x_table=sim.x_table, u=sim.u)
    assert abs(sim.x_motor[0] - sim.x_table[0]) > 1e-8  # the screw wound up at rest: the case is not trivial
    again = replay_drakecreep(run, load_case=load_case)
    count = rig.screw.lead / rig.sensors.encoder_counts_per_rev
    per_count = rig.controller.velocity_gain * count / rig.controller.velocity_period
    assert np.max(np.abs(again.u - sim.u)) <= 3 * per_count
    assert np.max(np.abs(again.x_motor - sim.x_motor)) <= 2 * count
    if constant_force:  # at rest before the first leg the drive holds the constant force
        base = replay_drakecreep(_run(_rig()))
        assert np.mean(sim.u[:15] - base.u[:15]) == pytest.approx(constant_force, rel=0.02)


def test_the_replay_errors_carry_the_screws_transmission_on_runs_with_a_scale():
    """``transmission``: the error of ``x_table - x_motor`` less its mean, measured against replayed, [%]; only on
    runs with a linear scale whose measured transmission moves. A replay of a run measured by the rig itself
    (the 1 um lead error in both) has none; the same run replayed without the lead error misses the error's share
    of the transmission (the rest is the windup under the 30 N external force, which both replays carry)."""
    from drakecreep.gap.drake_replay import drake_replay_errors
    from drakecreep.gap.residuals import transmission_position

    rig = _rig()
    sim = replay_drakecreep(_run(rig), rig)
    run = dataclasses.replace(_run(rig), x_motor=sim.x_motor, x_table=sim.x_table)
    d = transmission_position(run.x_motor, run.x_table)
    assert abs(d.mean()) < 1e-18 and np.ptp(d) > rig.disturbance.lead_error_amplitude  # the error, whole
    same = drake_replay_errors(replay_drakecreep(run, rig), bands=False)
    assert same["transmission"] < 0.1
    without = drake_replay_errors(replay_drakecreep(run, with_value(rig, "disturbance.lead_error_amplitude", 0.0)),
                                  bands=False)
    assert without["transmission"] > 100 * same["transmission"] and without["transmission"] > 10.0
    assert "transmission" not in drake_replay_errors(replay_drakecreep(_run(rig), rig), bands=False)  # no scale
    rigid = dataclasses.replace(run, x_table=run.x_motor.copy())  # a scale that reads the motor: nothing moves
    assert "table_position" in drake_replay_errors(replay_drakecreep(rigid, rig), bands=False)
    assert "transmission" not in drake_replay_errors(replay_drakecreep(rigid, rig), bands=False)


def test_the_nut_is_replayed_where_the_run_was():
    """A run's positions are the params file's table coordinates: a run that starts ``x0`` along is the run at 0
    with the nut ``x0`` further from the thrust bearing (a softer shaft), exactly, and not the run at 0."""
    from drakecreep.model.screw import axial_stiffness

    rig = with_value(_rig(), "disturbance.lead_error_amplitude", 0.0)
    at0 = _run(rig)
    x0 = 0.3
    moved = dataclasses.replace(at0, x_ref=at0.x_ref + x0, x_motor=at0.x_motor + x0)
    a = replay_drakecreep(moved, rig)
    b = replay_drakecreep(at0, _nut_moved(rig, x0))
    assert np.max(np.abs((a.x_table - x0) - b.x_table)) < 1e-12 and np.max(np.abs(a.u - b.u)) < 1e-6
    plain = replay_drakecreep(at0, rig)
    # the shaft between the bearing and the nut is 0.1 m long at 0 and 0.4 m at x0: the chain (the bearing's
    # 9.4 N/um in series) is 3.1 % softer, and the table lags the motor by at least half that much more
    softer = axial_stiffness(rig.screw, rig.nut, 0.0) / axial_stiffness(rig.screw, rig.nut, x0) - 1.0
    lag = lambda r: np.max(np.abs(r.x_motor - r.x_table))  # noqa: E731
    assert softer > 0.02 and lag(a) > (1.0 + 0.5 * softer) * lag(plain) > 0


def test_a_run_that_leaves_the_screw_is_refused_before_any_replay():
    """Positions that put the nut beyond either end of the shaft name the run, the positions and the range."""
    from drakecreep.gap.drake_replay import check_travel
    from drakecreep.gap.drive_fit import check_run

    rig = _rig()
    at0 = _run(rig)
    off = rig.screw.length - rig.screw.nut_start_distance
    for shift in (off, -rig.screw.nut_start_distance - 0.001):
        far = dataclasses.replace(at0, x_ref=at0.x_ref + shift, x_motor=at0.x_motor + shift)
        for check in (lambda: check_travel(far, rig), lambda: replay_drakecreep(far, rig), lambda: check_run(far, rig)):
            with pytest.raises(InputError) as err:
                check()
            assert err.value.field == f"x_motor (run {far.label})"
            assert f"between {-rig.screw.nut_start_distance:.6g} and {off:.6g} m" in err.value.allowed
    check_travel(at0, rig)  # the run at 0 stays on the screw


def test_a_delay_that_makes_the_truths_axial_mode_unstable_does_so_in_the_replay():
    """Development dataset 9014 (flexible, the truth's delay of 2 samples = 8 speed-loop ticks): its truth
    oscillates at its axial mode, 207 Hz. Its exact params file (:func:`drakecreep.gap.benchmark.declared_params`
    without a drawn factor) with those 8 ticks does too, with the nut where the run was (0.094 m); one sample less
    (4 ticks) does not. Before the nut followed the run, the replay at 8 ticks was stable (docs/gap_benchmark.md
    3cb)."""
    from drakecreep.gap import benchmark as B
    from drakecreep.gap.residuals import OSCILLATION_SHARE, dominant_oscillation, oscillates_at

    ds = B.generate_dataset(9014, withheld=("control_delay",), kind="drakecreep", axis="flexible")
    assert ds.truth.effects["control_delay"]["delay_samples"] == 2
    run = ds.train[0]
    measured = dominant_oscillation(run.force, run.dt)
    assert measured["share"] > OSCILLATION_SHARE and abs(measured["freq_Hz"] - ds.truth.f_axial) < 10.0
    exact = B.declared_params(ds.truth)
    delayed = replay_drakecreep(run, with_value(exact, "controller.computation_delay", 8.0))
    assert oscillates_at(delayed.force, run.dt, measured["freq_Hz"])[0]
    shorter = replay_drakecreep(run, with_value(exact, "controller.computation_delay", 4.0))
    assert dominant_oscillation(shorter.force, run.dt)["share"] < OSCILLATION_SHARE
    # the replay as it was: the nut at the diagram's table position 0, i.e. 0.094 m nearer the bearing
    nearer = _nut_moved(with_value(exact, "controller.computation_delay", 8.0), -float(run.x_motor[0]))
    assert dominant_oscillation(replay_drakecreep(run, nearer).force, run.dt)["share"] < OSCILLATION_SHARE
