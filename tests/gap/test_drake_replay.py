"""The replay through the Drake diagram (drakecreep.gap.drake_replay) on a slice of the EMPS estimation run."""

import dataclasses
import math

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.gap.drake_replay import DrakeReplay, axis_from_idim, drake_replay_errors, replay_drakecreep
from drakecreep.gap.idim import PUBLISHED_IDIM
from drakecreep.gap.measured import ControllerMeta, MeasuredMeta, MeasuredRun, load_emps
from drakecreep.gap.replay import replay
from drakecreep.model.sensors import quantize


@pytest.fixture(scope="module")
def run():
    return load_emps("estimation").runs[0].slice(0, 1500)


@pytest.fixture(scope="module")
def nominal(run):
    return DrakeReplay(run).simulate(axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-4))


def test_controller_follows_the_documented_law(run, nominal):
    """u[k] recomputed from the simulated motor position (counts, 2-tap mean, difference, clip) is the logged u."""
    c = run.meta.controller
    q = quantize(nominal.x_motor, run.meta.sensors.encoder_resolution)
    qf = 0.5 * q[1:] + 0.5 * q[:-1]
    dq = np.diff(qf) / run.dt
    u = np.clip(c.kp * c.kv * (run.x_ref[2:] - q[2:]) - c.kv * dq, -c.saturation, c.saturation)
    assert np.max(np.abs(u - nominal.u[2:])) < 1e-9 * c.saturation
    # the force held over sample k is gain * u[k] (no delay) plus f_ext
    assert np.allclose(nominal.force, run.u_gain * nominal.u)


def test_rigid_drake_replay_matches_the_exact_stepper(run, nominal):
    """Same plant, same controller: the Drake diagram and the exact piecewise stepper agree."""
    exact = replay(run, PUBLISHED_IDIM, quantize=True)
    travel = np.ptp(run.x_motor)
    assert np.max(np.abs(nominal.x_motor - exact.x_sim)) < 2e-4 * travel
    assert np.linalg.norm(nominal.u - exact.u_sim) < 0.03 * np.linalg.norm(exact.u_sim)


def test_compiled_and_leaf_paths_agree(run, nominal):
    leaf = DrakeReplay(run, compiled=False).simulate(axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-4))
    assert np.max(np.abs(leaf.x_motor - nominal.x_motor)) < 1e-9
    assert np.max(np.abs(leaf.u - nominal.u)) < 1e-6


def test_parameters_change_without_rebuild(run, nominal):
    rep = DrakeReplay(run)
    heavy = rep.simulate(axis_from_idim(dict(PUBLISHED_IDIM, M=2 * PUBLISHED_IDIM["M"]), regularization_velocity=1e-4))
    again = rep.simulate(axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-4))
    assert np.max(np.abs(again.x_motor - nominal.x_motor)) < 1e-9
    assert drake_replay_errors(heavy)["force"] > drake_replay_errors(again)["force"]


def test_force_level_error_removes_a_friction_level_and_nothing_else(run):
    """A run recorded with 1.3 times the nominal friction: the plain force error sees it, the error with the run's
    own friction level (``force_level``) hardly does; a heavier table is not a friction level, and stays."""
    import dataclasses

    base = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-4)
    rep = DrakeReplay(run)

    def measured(params):
        sim = rep.simulate(params)
        return dataclasses.replace(run, x_motor=sim.x_motor, u=sim.u)

    rough = measured(dict(base, coulomb=1.3 * base["coulomb"], viscous=1.3 * base["viscous"]))
    err = drake_replay_errors(DrakeReplay(rough).simulate(base))
    assert err["force"] > 5.0 and err["force_level"] < 0.2 * err["force"]
    heavy = measured(dict(base, mass=1.5 * base["mass"]))
    err = drake_replay_errors(DrakeReplay(heavy).simulate(base))
    assert err["force"] > 1.0 and err["force_level"] > 0.7 * err["force"]


def test_force_error_at_constant_speed_is_over_those_samples_alone(run, nominal):
    """``force_constant_speed``: the force error over the samples the regime classifier labels constant speed;
    a force error elsewhere changes ``force`` and not it; a run that never cruises has no such key."""
    from drakecreep.gap.idim import filtered_derivatives, relative_error
    from drakecreep.gap.residuals import classify_regimes

    err = drake_replay_errors(nominal)
    _, dq, _ = filtered_derivatives(run.x_motor, run.dt, 100.0, 4)
    sel = classify_regimes(np.arange(run.n) * run.dt, run.x_ref, dq) == "constant_speed"
    assert 100 < np.count_nonzero(sel) < run.n
    assert err["force_constant_speed"] == pytest.approx(relative_error(run.force[sel], nominal.force[sel]))
    off = dataclasses.replace(nominal, force=np.where(sel, nominal.force, nominal.force + 5.0))
    moved = drake_replay_errors(off)
    assert moved["force"] > err["force"] + 1.0
    assert moved["force_constant_speed"] == pytest.approx(err["force_constant_speed"])
    t = np.arange(run.n) * run.dt
    swinging = dataclasses.replace(run, x_ref=run.x_ref[0] + 0.01 * np.sin(2 * np.pi * 2.0 * t))
    assert "force_constant_speed" not in drake_replay_errors(dataclasses.replace(nominal, run=swinging))


def test_force_error_over_each_piece_of_a_run_is_over_that_quarter_alone(run, nominal):
    """``force_piece_<i>``: the force error over the i-th of RUN_PIECES equal windows; the pieces' squared errors,
    weighted by their force's energy, add up to the whole run's; a force error in one quarter moves that piece and
    no other; a run too short for the pieces has none."""
    from drakecreep.gap.drake_replay import RUN_PIECES, piece_keys

    err = drake_replay_errors(nominal)
    keys = piece_keys()
    assert len(keys) == RUN_PIECES == 4 and all(k in err for k in keys)
    edges = np.linspace(0, run.n, RUN_PIECES + 1).astype(int)
    energy = [float(np.sum(np.asarray(run.force[a:b]) ** 2)) for a, b in zip(edges[:-1], edges[1:])]
    whole = sum(err[k] ** 2 * w for k, w in zip(keys, energy)) / sum(energy)
    assert whole == pytest.approx(err["force"] ** 2, rel=1e-9)
    third = np.zeros(run.n, dtype=bool)
    third[edges[2]:edges[3]] = True
    moved = drake_replay_errors(dataclasses.replace(nominal, force=np.where(third, nominal.force + 5.0, nominal.force)))
    assert moved["force_piece_2"] > err["force_piece_2"] + 1.0
    assert all(moved[k] == pytest.approx(err[k]) for k in keys if k != "force_piece_2")
    short = run.slice(0, 60)
    res = DrakeReplay(short).simulate(axis_from_idim(PUBLISHED_IDIM))
    assert not any(k in drake_replay_errors(res) for k in keys)


def test_force_error_in_a_mode_band_sees_an_oscillation_there_and_nothing_else(run, nominal):
    """``force_band_<lo>-<hi>_Hz``: the force error in each octave of ``MODE_BANDS_HZ``. A 40 Hz oscillation the
    simulation adds moves the error of the band around 40 Hz (``mode_band(40)``) and hardly that of a band two
    octaves away; the same oscillation out of phase with one in the measurement counts twice, not zero; bands
    above 0.45 of a slower run's sample rate are left out."""
    from drakecreep.gap.drake_replay import MODE_BANDS_HZ, mode_band

    assert mode_band(40.0) == "band_28.3-56.6_Hz" and mode_band(1.0) == "band_3.54-7.07_Hz"
    assert mode_band(5000.0) == "band_226-453_Hz"
    for f in (5.0, 12.0, 40.0, 150.0, 300.0):  # each mode at least a quarter octave inside its band
        lo, hi = (float(x) for x in mode_band(f)[5:-3].split("-"))
        assert lo * 2 ** 0.25 <= f * 1.01 and f <= hi / 2 ** 0.25 * 1.01
    err = drake_replay_errors(nominal)
    keys = [k for k in err if k.startswith("force_band_")]
    assert len(keys) == len(MODE_BANDS_HZ)
    assert drake_replay_errors(nominal, bands=False) == {k: v for k, v in err.items() if k not in keys}
    t = np.arange(run.n) * run.dt
    wave = 3.0 * np.sin(2 * np.pi * 40.0 * t)
    moved = drake_replay_errors(dataclasses.replace(nominal, force=nominal.force + wave))
    at, far = "force_" + mode_band(40.0), "force_" + mode_band(10.0)
    assert moved[at] > err[at] + 10.0 and moved[far] == pytest.approx(err[far], abs=0.5)
    # the measurement oscillates too: the model's oscillation in phase shrinks that band's error, out of phase grows it
    shaken = dataclasses.replace(run, u=run.u + wave / run.u_gain)
    in_phase = drake_replay_errors(dataclasses.replace(nominal, run=shaken, force=nominal.force + wave))
    opposed = drake_replay_errors(dataclasses.replace(nominal, run=shaken, force=nominal.force - wave))
    without = drake_replay_errors(dataclasses.replace(nominal, run=shaken))
    assert in_phase[at] < 0.5 * without[at] < 0.5 * opposed[at]
    slow = dataclasses.replace(nominal, run=dataclasses.replace(run, t=4.0 * (run.t - run.t[0])))
    assert {k for k in drake_replay_errors(slow) if k.startswith("force_band_")} == \
        {"force_band_" + f"{lo:.3g}-{hi:.3g}_Hz" for lo, hi in MODE_BANDS_HZ if lo < 0.45 * 250.0}


def test_force_error_below_the_cutoff_leaves_out_a_fast_ripple_and_keeps_a_slow_one(run, nominal):
    """``force_lowpass``: the force residual through the IDIM's 100 Hz low-pass over the whole measured force. A
    300 Hz ripple the simulation adds (as an encoder-count ripple of a 4 kHz speed loop does) grows ``force`` and
    hardly ``force_lowpass``; a 10 Hz one grows both alike; and the part below adds to the part above in energy."""
    t = np.arange(run.n) * run.dt
    err = drake_replay_errors(nominal, bands=False)
    assert 0.0 < err["force_lowpass"] < err["force"]
    ripple = 0.3 * np.linalg.norm(run.force) / math.sqrt(run.n / 2)  # 30 % of the force's RMS as an amplitude
    fast = drake_replay_errors(dataclasses.replace(nominal, force=nominal.force + ripple * np.sin(2 * np.pi * 300 * t)),
                               bands=False)
    slow = drake_replay_errors(dataclasses.replace(nominal, force=nominal.force + ripple * np.sin(2 * np.pi * 10 * t)),
                               bands=False)
    assert fast["force"] > err["force"] + 5.0 and fast["force_lowpass"] == pytest.approx(err["force_lowpass"], abs=0.5)
    assert slow["force_lowpass"] > err["force_lowpass"] + 5.0
    assert slow["force_lowpass"] == pytest.approx(slow["force"], rel=0.1)
    assert fast["force_lowpass"] ** 2 <= fast["force"] ** 2


@pytest.mark.parametrize("sampled", [False, True], ids=["error_controlled", "sampled"])
@pytest.mark.parametrize("delay, shift", [(1.0, 1), (0.5, 0), (1.5, 1), (2.0, 2)])
def test_computation_delay_holds_older_outputs(run, delay, shift, sampled):
    """At the end of sample interval k the applied force is u[k - floor(delay)]; a fraction switches it later
    (both replays: the leaf controller's second event, and the sampled replay's averaged tick)."""
    from drakecreep.gap.drake_replay import make_replay

    short = run.slice(0, 300)

    def replay(d):
        return make_replay(short, delay=d, free=(), sampled=sampled).simulate(axis_from_idim(PUBLISHED_IDIM))

    res = replay(delay)
    assert np.allclose(res.force[shift:], run.u_gain * res.u[:res.u.size - shift])
    if delay % 1:
        whole, later = replay(delay - 0.5), replay(delay + 0.5)
        gap_lo = np.abs(res.x_motor - whole.x_motor).max()
        gap_hi = np.abs(res.x_motor - later.x_motor).max()
        assert 0 < gap_lo < np.abs(later.x_motor - whole.x_motor).max()
        assert 0 < gap_hi < np.abs(later.x_motor - whole.x_motor).max()


def test_two_mass_axis_with_a_stiff_screw_is_the_rigid_axis(run, nominal):
    stiff = DrakeReplay(run, flexible=True, max_step=2e-4).simulate(axis_from_idim(
        PUBLISHED_IDIM, regularization_velocity=1e-4, stiffness=1e9, damping=2e4, motor_mass_fraction=0.2))
    assert np.max(np.abs(stiff.x_motor - nominal.x_motor)) < 1e-4 * np.ptp(run.x_motor)
    soft = DrakeReplay(run, flexible=True).simulate(axis_from_idim(
        PUBLISHED_IDIM, regularization_velocity=1e-4, stiffness=2e6, damping=200.0))
    assert np.max(np.abs(soft.x_table - soft.x_motor)) > 1e-6  # the screw stretches


def test_bad_metadata_is_refused_before_work(run):
    slow = dataclasses.replace(run.meta, controller=dataclasses.replace(run.meta.controller, sample_time=2e-3))
    with pytest.raises(InputError, match="sample_time"):
        DrakeReplay(dataclasses.replace(run, meta=slow))
    own = dataclasses.replace(run.meta, controller=ControllerMeta(kind="drakecreep"), params=None)
    with pytest.raises(InputError, match="params"):
        replay_drakecreep(dataclasses.replace(run, meta=own))
    with pytest.raises(InputError, match="delay"):
        DrakeReplay(run, delay=-1)


def _own_run(params, feed=0.01, duration=0.15):
    """A ``kind: drakecreep`` run recorded from the project's own simulation at the position loop's 1 kHz, with
    ``u[k]`` the force command computed at ``t_k`` (the measured-format convention): the simulation is logged at
    the speed loop's period, and a log entry holds the command *before* that instant's update, so ``u[k]`` is the
    entry one speed tick after ``t_k``."""
    from drakecreep.scenario import Scenario
    from drakecreep.sim.simulation import simulate

    tick = params.controller.velocity_period
    p = dataclasses.replace(params, simulation=dataclasses.replace(params.simulation, log_period=tick,
                                                                    steady_start=0.05))
    sim = simulate(p, Scenario(feed=feed, load_case=0, duration=duration), backend="compiled")
    s = sim.signals
    step = int(round(1e-3 / tick))
    k = np.arange(0, sim.time.size - 1, step)
    meta = MeasuredMeta(u_units="N", u_gain=1.0, params=p, controller=ControllerMeta(kind="drakecreep"))
    return MeasuredRun(t=sim.time[k], x_ref=s["x_ref"][k], x_motor=s["motor_position"][k],
                       u=s["force_command"][k + 1], meta=meta, x_table=s["table_position"][k]), s["force_command"][k]


def test_drakecreep_kind_replays_its_own_simulation():
    """A run simulated by the project's diagram, replayed through it from its measured reference, comes back."""
    from drakecreep.params import preset

    run, _ = _own_run(preset("rigid_axis"))
    back = replay_drakecreep(run)
    assert np.max(np.abs(back.x_motor - run.x_motor)) < 1e-7
    assert np.max(np.abs(back.x_table - run.x_table)) < 1e-7
    assert np.linalg.norm(back.u - run.u) < 0.01 * np.linalg.norm(run.u)
    # the integrator stops at every speed-loop tick at least (analysis/bench_replay_drakecreep.py --speeds)
    ticks = (run.t[-1] - run.t[0]) / preset("rigid_axis").controller.velocity_period
    assert back.integrator_steps >= ticks


def test_drakecreep_kind_run_in_amperes_replays_the_same_force():
    """A run recorded in A (u_gain N per A, the motor's) replays to the force of the same run in N, and its u to
    the command over the gain: the command was multiplied by the gain once more (a 1131 N/A drive's held-out
    force error was 1e5 %)."""
    from drakecreep.params import preset

    p = preset("rigid_axis")
    run, _ = _own_run(p)
    gain = p.motor.torque_constant * 2.0 * math.pi / p.screw.lead
    amps = dataclasses.replace(run, u=run.u / gain, meta=dataclasses.replace(run.meta, u_units="A", u_gain=gain))
    newtons, back = replay_drakecreep(run), replay_drakecreep(amps)
    assert np.array_equal(back.force, newtons.force)
    assert np.allclose(back.u, newtons.u / gain, rtol=1e-12, atol=0.0)
    assert np.linalg.norm(back.force - amps.force) < 0.01 * np.linalg.norm(amps.force)


def test_drakecreep_kind_force_is_the_command_computed_at_the_sample():
    """With the speed loop at 4 kHz and the position loop at 1 kHz the force moves within a sample by a step that
    grows with the acceleration: the command computed at ``t_k`` is not the one that was applied just before. The
    replay's ``u[k]`` is the former (``u[k]`` of the measured format). A ramp with a short acceleration phase: the
    pre-update command differs from the replay by far more than the replay from the convention's."""
    from drakecreep.params import preset, with_value

    p = with_value(preset("rigid_axis"), "simulation.acceleration_time", 0.02)
    run, before = _own_run(p, feed=0.05, duration=0.1)
    back = replay_drakecreep(run)
    on = np.linalg.norm(back.u - run.u)
    assert on < 0.01 * np.linalg.norm(run.u)
    assert np.linalg.norm(back.u - before) > 5 * on


SAMPLED_CASES = {
    "stiff_stiction": (False, 0.0, dict(regularization_velocity=1e-4)),
    "every_force_term": (False, 0.0, dict(regularization_velocity=1e-3, coulomb_asym=0.5, time_ripple_cos=2.0,
                                          ripple_frequency=7.0, stribeck_extra=3.0, stribeck_velocity=5e-3,
                                          position_ripple_sin=1.0, friction_ripple_cos=0.1, friction_drift=0.01)),
    "axial_mode_58hz": (True, 0.0, dict(regularization_velocity=1e-3, stiffness=2e6, damping=300.0)),
    "one_sample_delay": (False, 1.0, dict(regularization_velocity=1e-3)),
    "lugre_bristles": (False, 0.0, dict(regularization_velocity=1e-3, bristle_stiffness=5e6, stribeck_extra=4.0,
                                        stribeck_velocity=2e-3)),
    "lugre_two_mass": (True, 0.0, dict(regularization_velocity=1e-3, stiffness=2e6, damping=300.0,
                                       bristle_stiffness=2e7, bristle_damping_ratio=0.5)),
    # 70 % of the friction sticks, the rest is the regularized law (the bristles' rate 1 / 0.7 faster)
    "lugre_share": (False, 0.0, dict(regularization_velocity=1e-3, bristle_stiffness=5e6, bristle_share=0.7)),
    # a fractional delay: the switch at t_k + f h falls inside a tick, which takes the two outputs' average
    "fractional_delay": (False, 2.35, dict(regularization_velocity=1e-3)),
    "fractional_delay_two_mass": (True, 0.35, dict(regularization_velocity=1e-3, stiffness=2e6, damping=300.0)),
    "fractional_delay_lugre": (False, 1.7, dict(regularization_velocity=1e-3, bristle_stiffness=5e6,
                                                stribeck_extra=4.0, stribeck_velocity=2e-3)),
}


@pytest.mark.parametrize("case", sorted(SAMPLED_CASES))
def test_sampled_replay_agrees_with_the_continuous_replay(run, case):
    """The fast discrete-time replay (controller + fixed sub-steps of the axis in one SymbolicVectorSystem) against
    the error-controlled Drake replay: positions within 2e-5 of the travel, force error within 0.02 points of %
    (0.05 with LuGre bristles: their step converges at first order where the sticking table crosses v = 0; the
    reference is then integrated at accuracy 1e-8)."""
    from drakecreep.gap.drake_replay import SampledReplay

    flexible, delay, extra = SAMPLED_CASES[case]
    p = axis_from_idim(PUBLISHED_IDIM, **extra)
    lugre = extra.get("bristle_stiffness", 0.0) > 0
    ref = DrakeReplay(run, flexible=flexible, delay=delay, accuracy=1e-8 if lugre else 1e-4).simulate(p)
    fast = SampledReplay(run, flexible=flexible, delay=delay, free=("viscous", "coulomb")).simulate(p)
    travel = np.ptp(run.x_motor)
    assert np.max(np.abs(fast.x_motor - ref.x_motor)) < 2e-5 * travel
    assert np.max(np.abs(fast.x_table - ref.x_table)) < 2e-5 * travel
    assert abs(drake_replay_errors(fast)["force"] - drake_replay_errors(ref)["force"]) < (0.05 if lugre else 0.02)
    assert np.linalg.norm(fast.u - ref.u) < 0.01 * np.linalg.norm(ref.u)


def test_sampled_replay_rebuilds_for_new_fixed_values_and_finer_steps(run):
    """Free parameters change in the context; a new value of a substituted one, or a stiffer friction, rebuilds."""
    from drakecreep.gap.drake_replay import SampledReplay

    rep = SampledReplay(run, free=("viscous",))
    p = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3)
    a = rep.simulate(p)
    m1 = rep.substeps
    b = rep.simulate(dict(p, coulomb=2 * p["coulomb"], regularization_velocity=1e-4))
    assert rep.substeps > m1
    again = rep.simulate(p)
    assert np.max(np.abs(again.x_motor - a.x_motor)) < 1e-5 * np.ptp(run.x_motor)
    assert drake_replay_errors(b)["force"] != drake_replay_errors(a)["force"]
    for bad in (-0.5, float("nan"), True):
        with pytest.raises(InputError, match="delay"):
            SampledReplay(run, delay=bad)
    with pytest.raises(InputError):
        SampledReplay(run, free=("no_such",))


def test_replays_side_by_side_in_threads_are_the_serial_ones_in_order(run):
    """simulate_each in two threads: each run's result is bit for bit its serial one, in the order given, for the
    sampled replay and for the leaf path (whose Python controller takes the GIL back inside AdvanceTo). The threaded
    call is each replay's second simulation: the error-controlled one starts from a fresh integrator every time
    (one that kept its last step-size guess moved the motor by 1e-13 m)."""
    from drakecreep.gap.drake_replay import SampledReplay, set_replay_threads, simulate_each

    p = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3)
    runs = [run.slice(0, 500), run.slice(500, 1100), run.slice(1100, 1500)]
    for make in (lambda r: SampledReplay(r, free=("coulomb",)), lambda r: DrakeReplay(r, compiled=False)):
        replays = [make(r) for r in runs]
        previous = set_replay_threads(1)
        try:
            serial = simulate_each(replays, p)
            set_replay_threads(2)
            threaded = simulate_each(replays, p)
        finally:
            set_replay_threads(previous)
        assert all(res.run is r for res, r in zip(threaded, runs)) and len(threaded) == len(runs)
        for a, b in zip(serial, threaded):
            assert np.array_equal(a.x_motor, b.x_motor) and np.array_equal(a.force, b.force)
        previous = set_replay_threads(2)
        try:  # the same replay twice runs one after the other (one context cannot simulate twice at once)
            twice = simulate_each([replays[0], replays[0]], p)
        finally:
            set_replay_threads(previous)
        assert all(np.array_equal(res.x_motor, serial[0].x_motor) for res in twice)
    for bad in (0, -1, 1.5, True, "2"):
        with pytest.raises(InputError, match="replay threads"):
            set_replay_threads(bad)


def test_a_replay_that_needs_more_than_max_substeps_is_returned_diverged_at_once(run):
    """A least-squares step to an astronomically stiff bristle asks for more ticks
    per sample than any axis needs: the replay returns all-NaN samples at once instead of hanging (held-out run
    18's nominal fit asked for more than 1e18 ticks per sample), and the identification's residual treats that as
    a very poor fit. Physical values stay under :data:`MAX_SUBSTEPS`: LuGre bristles of 2e7 N/m, an axial mode
    at 9 kHz (30 times the mode search's top)."""
    from drakecreep.gap.drake_replay import MAX_SUBSTEPS, SampledReplay, axis_parameters
    from drakecreep.gap.identify import _Problem

    p = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3)
    rep = SampledReplay(run, free=("bristle_stiffness",))
    assert rep.substeps_for(axis_parameters(**dict(p, bristle_stiffness=2e7))) <= 10
    m_red = p["mass"] * 0.2 * 0.8
    k9 = (2 * np.pi * 9e3) ** 2 * m_red
    flex = SampledReplay(run, flexible=True, free=())
    assert flex.substeps_for(axis_parameters(**dict(p, stiffness=k9, motor_mass_fraction=0.2))) <= MAX_SUBSTEPS
    fresh = SampledReplay(run, free=("bristle_stiffness",))

    def no_build(vec, m):  # a hang starts by building a diagram with m ticks per sample
        raise AssertionError(f"built a diagram with {m} ticks per sample")

    fresh._build = no_build
    for stiff in (1e40, 1e300):
        res = fresh.simulate(dict(p, bristle_stiffness=stiff))
        assert res.x_motor.shape == (run.n,) and np.all(np.isnan(res.x_motor)) and np.all(np.isnan(res.force))
    ok = rep.simulate(dict(p, bristle_stiffness=2e7))
    assert np.all(np.isfinite(ok.force))
    residual = _Problem.residual_of([rep.simulate(dict(p, bristle_stiffness=1e40))])
    assert np.all(np.isfinite(residual)) and np.all(np.abs(residual) > 0)
    # a log-scaled step past exp's range gives inf, which the axis refuses: the fit's problem replays it as
    # diverged instead of raising mid-fit
    from drakecreep.model.axis import AXIS_PARAMETERS

    base = dict(zip(AXIS_PARAMETERS, axis_parameters(**dict(p, bristle_stiffness=2e7))))
    prob = _Problem([rep], base, ("bristle_stiffness",))
    far = prob.residual(np.array([800.0]))  # exp(800) = inf
    assert far.shape == prob.residual(prob.to_x(base)).shape
    assert np.all(np.isfinite(far)) and np.max(np.abs(far)) > 100.0


def test_sampled_replay_keeps_a_limit_cycle_the_default_accuracy_misses():
    """A stiff two-mass axis (212 Hz mode) under the P-P loop limit-cycles at saturation: the sampled replay and the
    error-controlled replay at accuracy 1e-6 agree on it, the error-controlled replay at its default 1e-4 does not
    (found while ranking the axial mode; the sampled path is the one the fits use)."""
    from drakecreep.gap.drake_replay import SampledReplay

    run = load_emps("estimation").runs[0].slice(3000, 4000)
    p = dict(mass=95.87, viscous=174.4, coulomb=21.0, offset=-0.54, regularization_velocity=4.2e-4,
             stiffness=2.70e7, damping=2088.0)
    tight = DrakeReplay(run, flexible=True, accuracy=1e-6).simulate(p)
    fast = SampledReplay(run, flexible=True, free=()).simulate(p)
    sat = run.meta.controller.saturation
    assert np.ptp(tight.u[-300:]) > 1.9 * sat and np.ptp(fast.u[-300:]) > 1.9 * sat
    # at saturation the cycle's phase drifts between integrators: both errors are those of a limit cycle
    assert drake_replay_errors(fast)["force"] > 100 and drake_replay_errors(tight)["force"] > 100
    loose = DrakeReplay(run, flexible=True).simulate(p)
    assert np.ptp(loose.u[-300:]) < 0.5 * sat and drake_replay_errors(loose)["force"] < 20


@pytest.mark.parametrize("path", ["simulation.max_step", "controller.velocity_period"])
def test_a_drakecreep_run_whose_params_force_billions_of_steps_is_refused_before_the_replay(path):
    """A metadata params file with a max_step (or a speed-loop period) of 1e-9 s replayed an 8 s run for days."""
    from drakecreep.gap.drake_replay import check_replayable
    from drakecreep.params import preset, with_value

    p = with_value(preset("rigid_axis"), path, 1e-9)
    if path == "controller.velocity_period":
        p = with_value(p, "controller.position_period", 1e-9)
    t = np.arange(8000) * 1e-3
    x = 1e-3 * np.sin(t)
    meta = MeasuredMeta(u_units="N", u_gain=1.0, params=p, controller=ControllerMeta(kind="drakecreep"))
    run = MeasuredRun(t=t, x_ref=x, x_motor=x, u=np.cos(t), meta=meta)
    with pytest.raises(InputError, match=f"^{path}: got 1e-09; .*for a 7.999 s run"):
        check_replayable(run)
    check_replayable(dataclasses.replace(run, meta=dataclasses.replace(meta, params=preset("rigid_axis"))))


@pytest.mark.parametrize("m", [2, 4])
def test_a_run_logged_every_few_ticks_is_replayed_on_the_controllers_tick(run, m):
    """A measurement made by the sampled replay itself at 1 ms (the EMPS slice's reference), logged every ``m``
    ticks: :func:`make_replay` runs the controller on its 1 ms tick (the reference linear between logged samples)
    and returns the logged samples, which follow the 1 ms replay's to 8.7e-5 of the travel RMS (u to 3.1 %) at
    m = 4, the reference's corners between logged samples being lost; the same controller run on the logged
    samples (a sample time of m ms) misses the force by four times more or worse (4.6 times at m = 2)."""
    from drakecreep.gap.drake_replay import LoggedReplay, SampledReplay, make_replay
    from drakecreep.gap.measured import at_controller_rate, controller_ticks

    values = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-4)
    full = make_replay(run, free=()).simulate(values)
    made = dataclasses.replace(run, x_motor=full.x_motor, u=full.u)
    logged = MeasuredRun(t=made.t[::m], x_ref=made.x_ref[::m], x_motor=made.x_motor[::m], u=made.u[::m],
                         meta=made.meta, label="logged")
    assert controller_ticks(made) == 1 and controller_ticks(logged) == m
    tick = at_controller_rate(logged)
    assert tick.n == (logged.n - 1) * m + 1 and tick.meta.controller.sample_time == pytest.approx(1e-3, rel=1e-6)
    assert np.array_equal(tick.x_ref[::m], logged.x_ref) and np.max(np.abs(tick.t[::m] - logged.t)) < 1e-3 * logged.dt
    rep = make_replay(logged, free=())
    assert isinstance(rep, LoggedReplay) and rep.run is logged
    got = rep.simulate(values)
    again = make_replay(made, free=()).simulate(values)
    assert got.run is logged and got.x_motor.size == got.u.size == got.force.size == logged.n
    travel = np.ptp(made.x_motor)
    assert np.sqrt(np.mean((got.x_motor - again.x_motor[::m]) ** 2)) < 1.5e-4 * travel
    assert np.linalg.norm(got.u - again.u[::m]) < 0.05 * np.linalg.norm(again.u[::m])
    slow = dataclasses.replace(logged, meta=dataclasses.replace(logged.meta, controller=dataclasses.replace(
        logged.meta.controller, sample_time=m * 1e-3)))
    assert controller_ticks(slow) == 1
    wrong = make_replay(slow, free=()).simulate(values)
    assert drake_replay_errors(got)["force"] < 0.25 * drake_replay_errors(wrong)["force"]
    # the replay classes themselves take a run logged every tick: make_replay is the way in
    with pytest.raises(InputError, match="logged every"):
        SampledReplay(logged)


def test_a_run_that_cannot_be_replayed_is_named_by_its_label():
    """A file holds several runs, and a diagnosis reads two files: 'controller.sample_time: got 0.001' and 'run: got
    '10 samples'' did not say which run (found by the fuzzing pass)."""
    from drakecreep.gap.drake_replay import check_replayable

    t = np.arange(40) * 2e-3
    meta = MeasuredMeta(u_units="V", u_gain=35.0, controller=ControllerMeta(kp=100.0, kv=200.0, sample_time=0.8e-3))
    run = MeasuredRun(t=t, x_ref=1e-3 * t, x_motor=1e-3 * t, u=np.cos(t), meta=meta, label="b")
    with pytest.raises(InputError, match=r"^controller.sample_time \(run b\): got 0.0008; allowed: the run's sample "
                                         r"time 0.002 s, a whole fraction of it \(the log taken every few controller "
                                         r"ticks\) or a whole multiple of it \(the log taken several times a "
                                         r"tick\)$"):
        check_replayable(run)
    with pytest.raises(InputError, match="^run b: got '10 samples'; allowed: at least 20 samples$"):
        check_replayable(dataclasses.replace(run.slice(0, 10), meta=dataclasses.replace(
            meta, controller=ControllerMeta(kp=100.0, kv=200.0, sample_time=2e-3))))

def test_a_runs_time_origin_does_not_change_its_replay(run, nominal):
    """A run starts at its first sample, whatever its clock reads (a negative start included): both controller
    kinds replay the same run shifted in time to the same outputs, a time-fixed force ripple included."""
    from drakecreep.params import preset, with_value

    shifted = dataclasses.replace(run, t=run.t - 7.25)
    again = DrakeReplay(shifted).simulate(axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-4))
    assert np.array_equal(again.x_motor, nominal.x_motor) and np.array_equal(again.u, nominal.u)
    rippled = with_value(with_value(preset("rigid_axis"), "disturbance.force_ripple", 5.0),
                         "disturbance.ripple_frequency", 37.0)
    own, _ = _own_run(rippled)
    back = replay_drakecreep(own)
    back_shifted = replay_drakecreep(dataclasses.replace(own, t=own.t - 3.1))
    assert np.max(np.abs(back.u)) > 0
    assert np.max(np.abs(back_shifted.x_motor - back.x_motor)) < 1e-12
    assert np.max(np.abs(back_shifted.u - back.u)) < 1e-9 * np.max(np.abs(back.u))


def test_a_rigid_axis_fed_back_by_its_table_is_replayed_alike_by_every_path(run):
    """controller.feedback: table: the fast replay of a rigid axis built the table's position (x + e(x), an Expression)
    and wrapped it in Expression() again, a TypeError, so every diagnosis of such a run ended in 'internal error:
    TypeError: __init__(): incompatible constructor arguments'; the compiled continuous replay fed back the motor
    position, without the lead error. All three paths now agree with the leaf systems' replay."""
    from drakecreep.gap.drake_replay import SampledReplay

    table_run = dataclasses.replace(run, x_table=run.x_motor, meta=dataclasses.replace(
        run.meta, controller=dataclasses.replace(run.meta.controller, feedback="table")))
    p = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3, lead_error_cos=2e-5, lead=0.0125)
    leaf = DrakeReplay(table_run, compiled=False).simulate(p)
    travel = np.ptp(run.x_motor)
    for other in (DrakeReplay(table_run).simulate(p), SampledReplay(table_run, free=("viscous",)).simulate(p)):
        assert np.max(np.abs(other.x_table - leaf.x_table)) < 2e-6 * travel  # the lead error is 2e-4 of it
        assert np.linalg.norm(other.u - leaf.u) < 0.001 * np.linalg.norm(leaf.u)
    motor_fed = DrakeReplay(run, compiled=False).simulate(p)
    assert np.max(np.abs(motor_fed.x_table - leaf.x_table)) > 1e-5  # the feedback is the table's
