import math

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.gap import truth as T
from drakecreep.gap.replay import RigidModel, replay


def _limit_truth():
    """One stiff body (600 Hz), Fs = Fc, stiff bristles, no noise, drift, delay or quantisation."""
    tr = T.Truth(kind="p_p_cascade", axis="rigid", M=95.0, table_share=0.5, f_axial=600.0, zeta_axial=0.1,
                 lead=5e-3, Fc=20.0, Fv=200.0, motor_friction_share=0.3, offset=-3.0, Fs_ratio=1.0, vs=1e-3,
                 sigma0=2e7, sigma1=0.0, current_lag=1e-7, noise_N=0.0, lowpass_noise_N=0.0, encoder=1e-12,
                 scale=1e-12, drift_sd=0.0)
    tr.sigma1 = 2 * 0.5 * math.sqrt(tr.sigma0 * tr.m2)
    return tr


def test_limit_case_agrees_with_the_exact_rigid_replay():
    """Two independent implementations (RK-free semi-implicit Euler + LuGre vs exact Coulomb steps).

    Measured differences (3000-sample runs): position 0.2-1.1 um RMS against a tracking error of
    39-786 um RMS; force 0.3-1.6 N RMS against 19-55 N RMS (largest at the lowest speed, where LuGre's
    presliding and the smooth bearing friction differ from the exact stick rule).
    """
    tr = _limit_truth()
    n = 1200
    refs = np.array([T.out_and_back(v, 0.05, n=n, leg=0.5, starts=(0.1, 0.65)) for v in (0.005, 0.05, 0.15)])
    pulses = np.zeros_like(refs)
    sim = T.simulate_truth(tr, refs, pulses, np.random.default_rng(0))
    for run in T.make_runs(tr, refs, pulses, sim):
        rp = replay(run, RigidModel(M=tr.M, Fv=tr.Fv, Fc=tr.Fc, offset=tr.offset), initial_velocity=0.0)
        e = run.x_motor - rp.x_sim
        track = np.sqrt(np.mean((run.x_motor - run.x_ref) ** 2))
        assert np.sqrt(np.mean(e ** 2)) < 0.05 * track
        assert np.sqrt(np.mean(e ** 2)) < 2e-6
        fe = run.force - rp.force_sim
        assert np.sqrt(np.mean(fe ** 2)) < 0.1 * np.sqrt(np.mean(run.force ** 2))


def test_batch_equals_single_and_the_twin_differs_only_by_the_effect():
    rng = np.random.default_rng(3)
    tr = T.draw_truth(rng, "drakecreep", "flexible", ("cogging",))
    refs, pulses, _ = T.draw_profiles(rng, 2, n=300)
    drift, noise = T.noise_draws(tr, 2, 300, rng)
    both = T.simulate_batch([(tr, refs, pulses, drift, noise, True), (tr, refs, pulses, drift, noise, False)])
    single = T.simulate_batch([(tr, refs, pulses, drift, noise, True)])[0]
    np.testing.assert_array_equal(both[0]["x_motor"], single["x_motor"])
    assert not np.array_equal(both[0]["u"], both[1]["u"])
    q = tr.encoder
    x = single["x_motor"]
    assert np.max(np.abs(x / q - np.round(x / q))) < 1e-6
    # the flexible axis: the scale differs from the motor encoder by more than its quantisation
    assert np.max(np.abs(single["x_table"] - single["x_motor"])) > tr.scale


def test_draw_truth_rejects_unknown_names():
    rng = np.random.default_rng(0)
    with pytest.raises(InputError, match="kind"):
        T.draw_truth(rng, "pid", "rigid")
    with pytest.raises(InputError, match="withheld"):
        T.draw_truth(rng, "p_p_cascade", "rigid", ("gremlins",))


def test_out_of_library_orders_are_not_integer():
    for s in range(20):
        tr = T.draw_truth(np.random.default_rng(s), "p_p_cascade", "rigid", ("bearing_defect",))
        o = tr.effects["bearing_defect"]["order"]
        assert 0.3 <= o - math.floor(o) <= 0.7


def _limit_drive():
    """The default drive without the terms the truth lacks (motor drag, nut friction), at a fine tolerance."""
    import dataclasses

    from drakecreep.params import DriveParams

    p = DriveParams()
    return dataclasses.replace(
        p, motor=dataclasses.replace(p.motor, viscous_damping=0.0),
        nut=dataclasses.replace(p.nut, preload_torque=0.0, load_friction_coefficient=0.0),
        simulation=dataclasses.replace(p.simulation, steady_start=0.5, accuracy=1e-6, max_step=1e-4))


def _limit_truth_of(p):
    """The PI-cascade truth of params ``p`` on its two bodies (rotor + coupling + screw inertia reflected to the
    table, table + nut, the chain's axial stiffness and damping at the start position with the shaft's share of its
    compliance there, the guides' LuGre levels)."""
    from drakecreep.model.nut_table import friction_levels, moving_mass
    from drakecreep.model.screw import axial_damping, axial_stiffness, screw_inertia, shaft_axial_stiffness

    lead = p.screw.lead
    m1 = (p.motor.rotor_inertia + p.motor.coupling_inertia + screw_inertia(p.screw)) * (2 * math.pi / lead) ** 2
    m2 = moving_mass(p)
    k, c = axial_stiffness(p.screw, p.nut, 0.0), axial_damping(p.screw, p.nut, 0.0)
    mu = m1 * m2 / (m1 + m2)
    fc, fs = friction_levels(p, p.load_case(0))
    g = p.controller
    return T.Truth(kind="drakecreep", axis="flexible", M=m1 + m2, table_share=m2 / (m1 + m2),
                   f_axial=math.sqrt(k / mu) / (2 * math.pi), zeta_axial=c / (2 * math.sqrt(k * mu)), lead=lead, Fc=fc,
                   Fv=p.friction.viscous, motor_friction_share=0.0, offset=0.0, Fs_ratio=fs / fc,
                   vs=p.friction.stribeck_velocity, sigma0=p.friction.bristle_stiffness,
                   sigma1=p.friction.bristle_damping, current_lag=p.motor.current_loop_time_constant, noise_N=0.0,
                   lowpass_noise_N=0.0, encoder=lead / p.sensors.encoder_counts_per_rev,
                   scale=p.sensors.scale_resolution, drift_sd=0.0,
                   gains={"kp": g.position_gain, "kv": g.velocity_gain, "ki": g.velocity_integral_gain,
                          "ff": g.velocity_feedforward, "sat": p.motor.peak_torque * 2 * math.pi / lead},
                   shaft_share=k / shaft_axial_stiffness(p.screw, 0.0), chain_at=0.0,
                   nut_start=p.screw.nut_start_distance)


def _drake_run(p, feed, n):
    """The Drake diagram's reference, motor position and force command on the truth's ``n`` samples."""
    from drakecreep.scenario import Scenario
    from drakecreep.sim.simulation import simulate

    res = simulate(p, Scenario(feed=feed, load_case=0, duration=n * T.DT))
    assert res.ok
    t = np.arange(n) * T.DT
    s = res.signals
    return tuple(np.interp(t, res.time, s[k]) for k in ("x_ref", "motor_position", "force_command"))


def test_limit_case_agrees_with_the_drake_diagram():
    """The PI-cascade truth against the project's Drake diagram (default drive, unloaded, 10 mm/s feed).

    Same parameters mapped onto the two bodies, no motor drag and no nut friction (the truth has no such terms).
    Measured: motor position 0.07 um RMS apart against a 1.9 um RMS tracking error, force command 0.21 N RMS
    apart against 7.3 N RMS, mean forces within 0.01 N.
    """
    p = _limit_drive()
    tr = _limit_truth_of(p)
    n = 1000
    x_ref, xm, f = _drake_run(p, 0.01, n)
    sim = T.simulate_truth(tr, x_ref[None, :], np.zeros((1, n)), np.random.default_rng(0))
    track = np.sqrt(np.mean((xm - x_ref) ** 2))
    assert np.sqrt(np.mean((sim["x_motor"][0] - xm) ** 2)) < 0.05 * track
    ef = sim["u"][0, 100:] - f[100:]
    assert np.sqrt(np.mean(ef ** 2)) < 0.06 * np.sqrt(np.mean(f[100:] ** 2))
    assert abs(sim["u"][0, 500:].mean() - f[500:].mean()) < 0.01 * abs(f[500:].mean())


def test_a_lead_errors_push_on_the_drive_is_the_drake_diagrams():
    """A 40 um lead error at 10 mm/s, in the truth and in the Drake diagram (``LeadError``): the force it adds to
    the drive command below 20 Hz. At this speed its inertial force is small and the push is mostly the nut's
    friction reaching the motor through the error's gearing, ``F (1 + e')`` (docs 3ce). Measured: 0.385 N RMS
    (Drake) and 0.365 N (truth), 0.045 N RMS apart; without the ``e'`` term in the truth it gave 0.199 N, 0.260 N
    apart."""
    import dataclasses

    from drakecreep.gap.idim import filtered_derivatives

    amplitude, n = 40e-6, 1500
    p = _limit_drive()
    with_error = dataclasses.replace(p, disturbance=dataclasses.replace(
        p.disturbance, lead_error_amplitude=amplitude, lead_error_period=p.screw.lead))
    x_ref, _, f_off = _drake_run(p, 0.01, n)
    _, _, f_on = _drake_run(with_error, 0.01, n)
    assert x_ref[0] == 0.0  # both error laws have their phase 0 at position 0
    tr = _limit_truth_of(p)
    u = {}
    for on in (False, True):
        tr.effects = {"lead_error": {"amplitude_m": amplitude, "phase": 0.0, "h2": 0.0, "phase2": 0.0}} if on else {}
        u[on] = T.simulate_truth(tr, x_ref[None, :], np.zeros((1, n)), np.random.default_rng(0))["u"][0]

    def push(on, off):
        return filtered_derivatives(on - off, T.DT, 20.0)[0][600:]  # at the feed speed

    drake, truth = push(f_on, f_off), push(u[True], u[False])
    assert np.std(drake) > 0.3  # the push is there
    assert np.std(truth) == pytest.approx(np.std(drake), rel=0.15)
    assert np.std(truth - drake) < 0.2 * np.std(drake)


def _clean_pair(withheld, effects, speed=0.02, n=1500):
    """One run with and without ``withheld`` (no noise, drift or pulses); drive force [N] and table position."""
    tr = T.draw_truth(np.random.default_rng(11), "p_p_cascade", "rigid", withheld)
    tr.effects.update(effects)
    refs = T.out_and_back(speed, 0.05, n=n, leg=0.6, starts=(0.1, 0.8))[None, :]
    zero = np.zeros_like(refs)
    a, b = T.simulate_batch([(tr, refs, zero, np.ones(1), zero, True), (tr, refs, zero, np.ones(1), zero, False)])
    return tr, a["u"][0] * T.GTAU, b["u"][0] * T.GTAU, a["x_table"][0], np.gradient(refs[0], T.DT)


def test_cable_carrier_is_a_force_of_position_the_same_in_both_directions():
    """The drive force it adds (with minus without) follows k d + q (d / 0.1)^2, d = x - x_n, on the way out and
    back alike (not friction: no sign change with the direction)."""
    cc = {"stiffness_N_m": 200.0, "quadratic_N": 4.0, "neutral_m": 0.06}
    tr, f, f0, x, v = _clean_pair(("cable_carrier",), {"cable_carrier": cc})
    cruise = np.abs(v) > 0.9 * 0.02
    d = x - cc["neutral_m"]
    model = cc["stiffness_N_m"] * d + cc["quadratic_N"] * (d / 0.1) ** 2
    for leg in (v > 0, v < 0):
        m = cruise & leg
        err = (f - f0)[m] - model[m]
        assert np.sqrt(np.mean(err ** 2)) < 0.1 * np.sqrt(np.mean(model[m] ** 2))


def test_drive_saturation_applies_less_than_the_recorded_command():
    """With a knee F_k the applied force is F_k tanh(F_cmd / F_k): the recorded command must exceed the
    effect-free one so that the applied force matches it."""
    tr, f, f0, x, v = _clean_pair(("drive_saturation",), {"drive_saturation": {"knee_N": 40.0}}, speed=0.1)
    big = np.abs(f0) > 20.0
    assert big.sum() > 100
    assert np.mean(np.abs(f[big])) > 1.1 * np.mean(np.abs(f0[big]))
    applied = 40.0 * np.tanh(f / 40.0)
    assert np.sqrt(np.mean((applied - f0)[big] ** 2)) < 0.2 * np.sqrt(np.mean((f - f0)[big] ** 2))


def test_load_friction_raises_the_table_friction_by_its_steady_factor():
    """In steady sliding the nut carries the table's friction, ``F_ax = f_t``, so the table's friction becomes
    ``f_t / (1 - mu)``: the drive force rises by ``f_t mu / (1 - mu)`` over the twin's. Measured on the
    constant-speed legs of the runs above 20 mm/s: within 1-2 % of that (the former form, ``mu |F_ax|`` in the
    LuGre target, gave 6 times it at 76 mm/s through ``sigma1 dz/dt``)."""
    tr = _limit_truth()
    tr.effects = {"load_friction": {"mu": 0.3}}
    n = 1500
    refs = np.array([T.out_and_back(v, 0.05, n=n, leg=0.6, starts=(0.1, 0.8)) for v in (0.03, 0.08)])
    pulses = np.zeros_like(refs)
    sims = [T.simulate_truth(tr, refs, pulses, np.random.default_rng(0), with_effects=w) for w in (True, False)]
    share = 1 - tr.motor_friction_share
    for k, v in enumerate((0.03, 0.08)):
        dx = np.gradient(sims[0]["x_motor"][k], T.DT)
        legs = np.abs(dx - v) < 0.02 * v  # the forward leg's constant speed
        rise = np.median(sims[0]["u"][k][legs] - sims[1]["u"][k][legs]) * T.GTAU
        f_t = share * (tr.Fc + tr.Fv * v)
        assert rise == pytest.approx(f_t * 0.3 / 0.7, rel=0.05)


def test_backlash_is_a_lost_motion_between_motor_and_table():
    """With a lost motion ``b`` the motor runs ``b`` further than the table on the way out and back: the motor-
    minus-table position of the forward and backward cruise differs by ``b`` more than the twin's (whose
    difference is the spring's deflection under the friction)."""
    tr = T.draw_truth(np.random.default_rng(11), "p_p_cascade", "rigid", ("backlash",))
    tr.effects["backlash"] = {"lost_motion_m": 12e-6}
    refs = T.out_and_back(0.02, 0.05, n=1500, leg=0.6, starts=(0.1, 0.8))[None, :]
    zero = np.zeros_like(refs)
    v = np.gradient(refs[0], T.DT)
    cruise = np.abs(v) > 0.9 * 0.02
    gaps = []
    for sim in T.simulate_batch([(tr, refs, zero, np.ones(1), zero, w) for w in (True, False)]):
        d = sim["x_motor"][0] - sim["x_table"][0]
        gaps.append(np.mean(d[cruise & (v > 0)]) - np.mean(d[cruise & (v < 0)]))
    assert gaps[0] - gaps[1] == pytest.approx(12e-6, rel=0.05)
    assert abs(gaps[1]) < 1e-6


def test_a_loop_near_its_stability_limit_is_converged_in_the_substeps(monkeypatch):
    """The truth's step (``SUBSTEPS`` per sample) against one four times finer, where it matters most: a loop near
    its stability limit, whose oscillation grows or decays with a few degrees of phase at the axial mode.

    Development dataset 97106042 (flexible, a 3-sample delay; docs/gap_benchmark.md 3ci), the first 1.5 s of its
    two runs near the thrust bearing: 152 Hz oscillations of 7.4 and 8.2 N RMS at 24 substeps, 7.4 and 9.9 N at 96
    (the effect-free twin's strongest peaks: 0.9 and 0.6 N, at 23 and 47 Hz). When the current loop's lag was
    advanced before the kick (the force a substep early), they were 21 and 28 N at 24 substeps, 9.9 and 12.5 N at
    96, and 41 and 64 N at the 12 substeps the truth then took.
    """
    from drakecreep.gap import benchmark as B
    from drakecreep.gap.residuals import dominant_oscillation

    n = 1500
    tr, refs, pulses, drift, noise = B._draw(97106042, ("control_delay",), "drakecreep", "flexible", B.N_SAMPLES)
    job = (tr, refs[:2, :n], pulses[:2, :n], drift[:2], noise[:2, :n], True)

    def rms():
        runs = T.make_runs(tr, refs[:2, :n], pulses[:2, :n], T.simulate_batch([job])[0])
        return np.array([dominant_oscillation(r.force, r.dt)["rms"] for r in runs])

    coarse = rms()
    monkeypatch.setattr(T, "SUBSTEPS", 4 * T.SUBSTEPS)
    fine = rms()
    assert np.all(fine > 5.0)  # the oscillation is there
    np.testing.assert_allclose(coarse, fine, rtol=0.25)


def test_the_terms_left_out_where_they_are_zero_change_no_bit():
    """``simulate_batch`` leaves out the terms that are zero in every column (about twice as fast,
    ``analysis/bench_truth.py``): the null and each withheld effect alone, on either kind and axis, give the same
    bits on a short out-and-back with a force pulse as every term evaluated."""
    rng = np.random.default_rng(11)
    refs = T.out_and_back(0.02, 0.05, n=60, leg=0.025, starts=(0.004, 0.032))[None, :]
    pulses = np.zeros_like(refs)
    pulses[0, 20:30] = 15.0
    for i, withheld in enumerate(((),) + tuple((w,) for w in T.WITHHELD)):
        tr = T.draw_truth(rng, T.CONTROLLER_KINDS[(i // 2) % 2], T.AXES[i % 2], withheld)
        drift, noise = T.noise_draws(tr, 1, refs.shape[1], rng)
        job = [(tr, refs, pulses, drift, noise, True)]
        fast, every = T.simulate_batch(job)[0], T.simulate_batch(job, skip_zero_terms=False)[0]
        for key in ("x_motor", "x_table", "u"):
            np.testing.assert_array_equal(fast[key], every[key], err_msg=f"{withheld} {key}")
        assert np.ptp(every["u"]) > 0  # the loop acted
