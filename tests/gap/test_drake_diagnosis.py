"""diagnose_drake: a typed diagnosis on runs with a known, withheld effect."""

import dataclasses

import math

import numpy as np
import pytest

from drakecreep.errors import InputError
import drakecreep.gap.drake_diagnosis as D
from drakecreep.gap.drake_diagnosis import DrakeDiagnosis, diagnose_drake, load_model
from drakecreep.gap.drake_replay import DrakeReplay, axis_from_idim, set_replay_threads
from drakecreep.gap.idim import PUBLISHED_IDIM
from drakecreep.gap.measured import load_emps

TRUTH = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3, coulomb_asym=4.0, viscous_asym=-40.0)


def _simulated(truth, starts, n, prefix):
    """EMPS slices at ``starts`` of ``n`` samples replayed from ``truth``, 0.5 N of white noise on the force:
    ``(runs, noise floor of each run's relative force error [%])``."""
    full = load_emps("estimation").runs[0]
    out, floor = [], []
    for seed, a in enumerate(starts):
        run = full.slice(a, a + n)
        res = DrakeReplay(run).simulate(truth)
        noise = np.random.default_rng(seed).normal(0.0, 0.5, res.u.size)
        out.append(dataclasses.replace(run, x_motor=res.x_motor, u=res.u + noise / run.u_gain, label=f"{prefix}{a}"))
        floor.append(100 * np.linalg.norm(noise) / np.linalg.norm(out[-1].force))
    return out, floor


@pytest.fixture(scope="module")
def runs():
    return _simulated(TRUTH, (0, 3000, 6000, 9000, 12000), 1000, "w")[0]


def test_the_withheld_asymmetry_is_claimed_and_the_drift_is_not(runs, tmp_path):
    diag = diagnose_drake(runs[:2], runs[2:], effects=("asymmetric_friction", "thermal_drift"), max_nfev=4)
    assert isinstance(diag, DrakeDiagnosis)
    assert diag.claimed == ("asymmetric_friction",)
    assert diag.ranking[0].name == "asymmetric_friction" and diag.ranking[0].passes
    assert diag.ranking[0].log_ratio > diag.ranking[0].threshold >= diag.null[0] > 0
    assert f"training-run null {diag.null[0]:.3f}" in diag.summary()[0]
    # the null is the largest size of the signed moves it keeps, one per training run
    assert len(diag.null_moves) == 2 and diag.null == D.null_of_moves(diag.null_moves)
    # while moving, coulomb_asym * s(v)^2 is a constant like the offset: only their sum is well determined
    p = diag.model["parameters"]
    assert abs(p["coulomb_asym"] + p["offset"] - (4.0 + PUBLISHED_IDIM["offset"])) < 0.3
    assert abs(p["viscous_asym"] + 40.0) < 8.0
    params, flexible, delay = load_model(diag.save_model(tmp_path / "augmented.yaml"))
    assert params == pytest.approx(diag.model["parameters"]) and not flexible and delay == 0.0
    assert any("claimed: asymmetric_friction" in line for line in diag.summary())


def test_candidates_fitted_in_worker_processes_give_the_same_diagnosis():
    """Both stages in the pool: the ranking fits, and the greedy step's second claim (the candidate refitted on top
    of the first beside its equal-effort reference)."""
    truth = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3, coulomb_asym=8.0, viscous_asym=-40.0,
                           time_ripple_cos=3.0, time_ripple_sin=0.0, ripple_frequency=7.0)
    runs = _simulated(truth, (0, 3000, 6000, 9000, 12000), 1000, "r")[0]
    # (the delay has no screen: it goes to the pool first)
    kwargs = dict(effects=("asymmetric_friction", "time_ripple", "control_delay"), max_nfev=3)
    serial = diagnose_drake(runs[:2], runs[2:], **kwargs)
    previous = set_replay_threads(3)
    try:
        pooled = diagnose_drake(runs[:2], runs[2:], workers=2, **kwargs)  # two threads in each process
        assert set_replay_threads(3) == 3  # restored after the run
    finally:
        set_replay_threads(previous)
    assert serial.claimed == ("time_ripple", "asymmetric_friction")  # the greedy step's refit ran
    assert [r.name for r in pooled.ranking] == [r.name for r in serial.ranking]
    assert [r.gain for r in pooled.ranking] == pytest.approx([r.gain for r in serial.ranking], rel=1e-9, abs=1e-12)
    assert pooled.claimed == serial.claimed
    assert pooled.model["parameters"] == pytest.approx(serial.model["parameters"], rel=1e-9)
    assert [pooled.test_errors[k]["force"] for k in serial.test_errors] == pytest.approx(
        [serial.test_errors[k]["force"] for k in serial.test_errors], rel=1e-9)


def test_bad_requests(runs):
    with pytest.raises(InputError, match="effects"):
        diagnose_drake(runs[:2], runs[2:], effects=("backlash",))
    with pytest.raises(InputError, match="runs"):
        diagnose_drake(runs[:2], runs[2:3])
    with pytest.raises(InputError, match="workers"):
        diagnose_drake(runs[:2], runs[2:], effects=("stribeck",), workers=0)


def test_the_lugre_nominal_fits_the_share_of_the_friction_that_sticks():
    """An axis whose bristles carry 60 % of the Coulomb level (the rest a regularized law, as the benchmark's truth
    has its motor-side friction): the LuGre nominal fits ``bristle_share`` (0.45 here with six evaluations, 0.449
    with fifteen: the share trades against the bristle stiffness) and replays the held-out runs better than the
    nominal whose friction all sticks (held-out force error 1.69 % against 2.23 %, noise floor 0.9-1.1 %)."""
    from drakecreep.gap.drake_effects import score_parameters
    from drakecreep.gap.identify import identify

    truth = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3, bristle_stiffness=1e7, bristle_share=0.6)
    runs, _ = _simulated(truth, (0, 3000, 6000, 9000, 12000), 800, "b")
    assert D.NOMINAL_FRICTION["lugre"][-1] == "bristle_share"
    share = identify(runs[:2], D.NOMINAL_FRICTION["lugre"], max_nfev=6)
    whole = identify(runs[:2], D.NOMINAL_FRICTION["lugre"][:-1], max_nfev=6)
    assert whole.parameters["bristle_share"] == 1.0 and 0.3 < share.parameters["bristle_share"] < 0.8
    assert score_parameters(runs[2:], share.parameters)[1] < 0.85 * score_parameters(runs[2:], whole.parameters)[1]


def test_a_sticking_axis_gets_the_lugre_nominal():
    """Runs of an axis with LuGre bristles (it sticks): the LuGre nominal replays the held-out runs better than the
    regularized one (less error energy above the noise's own, 0.5 N of white noise on the force), ``auto`` keeps it
    (lower training cost) and finds the bristle stiffness's order of magnitude.

    Until session 27 this asked for the excess energy to be at least halved: it was 0.47 of the regularized
    nominal's. Two new axis parameters reordered the terms of the compiled axis's symbolic sums, which moved the
    error-controlled replay that makes these runs by about 5e-6 of the force, and the ratio became 0.51. The
    factor was never robust: on the same axis with the four slices shifted by 500, 1500, 2500 and 4000 samples,
    ``auto`` kept the regularized nominal twice, and the LuGre nominal it kept replayed worse once (1.40) and better
    once (0.86) (docs/gap_diagnosis.md, "LuGre nominal"). Only the direction is asserted."""
    truth = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3, bristle_stiffness=1e7)
    runs, floor = _simulated(truth, (0, 3000, 6000, 9000), 800, "s")
    kwargs = dict(effects=("thermal_drift",), max_nfev=4, screen=True)
    auto = diagnose_drake(runs[:2], runs[2:], friction="auto", **kwargs)
    plain = diagnose_drake(runs[:2], runs[2:], friction="regularized", **kwargs)
    assert auto.friction == "lugre" and plain.friction == "regularized"
    assert 3e6 < auto.nominal.parameters["bristle_stiffness"] < 3e7
    excess = lambda d: sum(e["force"] ** 2 - f ** 2 for e, f in zip(d.nominal_test_errors.values(), floor[2:]))  # noqa: E731
    assert excess(auto) < excess(plain)
    assert any("lugre friction" in line for line in auto.summary())
    with pytest.raises(InputError, match="friction"):
        diagnose_drake(runs[:2], runs[2:], friction="coulomb")


def test_gains_are_measured_at_equal_effort(monkeypatch):
    """Effect-free runs and a nominal that is not converged (Coulomb at half and viscous at twice the truth, two
    evaluations). Every candidate refits the nominal friction with its own parameters, so against that nominal each
    "gains" several points of % on the held-out runs, far above the claim bar; against the nominal refitted alone by
    the same evaluations (``_refit``) none gains, and ``diagnose_drake``, started from the same poor nominal, claims
    nothing."""
    from scipy import stats

    from drakecreep.gap.drake_effects import score_parameters
    from drakecreep.gap.identify import identify

    truth = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3)
    runs, _ = _simulated(truth, (0, 3000, 6000, 9000, 12000), 1000, "n")
    train, test = runs[:2], runs[2:]
    poor = {"coulomb": 0.5 * truth["coulomb"], "viscous": 2.0 * truth["viscous"]}
    first = identify(train, D.NOMINAL_PARAMETERS, max_nfev=2, fixed=poor)
    reference = D._refit(train, first, first.fitted, 2)
    first_test, _ = score_parameters(test, first.parameters)
    reference_test, _ = score_parameters(test, reference.parameters)
    bar = stats.t.ppf(1 - D.ALPHA, len(test) - 1)
    for name in ("asymmetric_friction", "thermal_drift"):
        fit = D.fit_candidate(name, train, test, first, 2, None)
        # on the plain error (the error with each run's own friction level also absorbs much of a poor nominal's
        # friction, so it would hide what equal effort is for)
        assert D._passes(first_test, fit.test_errors, bar, "plain").passes
        assert not D._passes(reference_test, fit.test_errors, bar, "plain").passes

    def poorly_started(runs, uncertain, **kw):
        if kw.get("fixed") is None:  # the first nominal fit (the equal-effort refit starts from its values)
            kw["fixed"] = poor
        return identify(runs, uncertain, **kw)

    monkeypatch.setattr(D, "identify", poorly_started)
    diag = diagnose_drake(train, test, effects=("asymmetric_friction", "thermal_drift"), max_nfev=2, screen=False)
    assert diag.claimed == ()


def test_a_gain_that_each_run_s_own_friction_level_explains_is_not_claimed():
    """The claim rules on per-run held-out errors: a candidate that shrinks the plain force error by 10 % in every
    run but not the error with each run's own friction level (it fits the level the held-out runs happen to
    have) passes ``plain`` only; one that shrinks both passes ``both``."""

    def errors(force, level):
        return {f"r{i}": {"force": f, "force_level": g} for i, (f, g) in enumerate(zip(force, level))}

    reference = errors([10.0, 11.0, 12.0], [5.0, 5.5, 6.0])
    drifted = errors([9.0, 9.95, 10.8], [5.0, 5.52, 5.99])
    real = errors([9.0, 9.95, 10.8], [4.5, 4.96, 5.41])
    bar = 2.92
    assert D._passes(reference, drifted, bar, "plain").passes
    assert not D._passes(reference, drifted, bar, "level").passes and not D._passes(reference, drifted, bar, "both").passes
    assert D._passes(reference, real, bar, "both").passes
    # errors without the level (a replay that has no friction parameters) decide on the plain error alone
    plain_only = {k: {"force": v["force"]} for k, v in drifted.items()}
    assert D._passes({k: {"force": v["force"]} for k, v in reference.items()}, plain_only, bar, "both").passes


def test_the_level_test_alone_claims_when_the_plain_mean_is_above_its_null():
    """``drift_robust`` (:data:`CLAIM_RULE`), on per-run log ratios of spent held-out rows: held-out run 16's
    bearing defect 33007005 (level ratios positive in every run, plain ones of mixed sign, plain mean 0.29 above
    its null 0.027) passes, where ``both`` missed it; run 16's backlash 33012003, outside the library (level test
    passes, plain mean 0.032 under its null 0.063), and run 14's null 29013006 (the plain test alone passes: an
    asymmetric friction fitting the held-out runs' levels) do not."""

    def errors(plain, level):
        return {f"r{i}": {"force": 10.0 * np.exp(-a), "force_level": 6.0 * np.exp(-b)}
                for i, (a, b) in enumerate(zip(plain, level))}

    reference = errors([0.0] * 5, [0.0] * 5)
    bar = 2.13
    bearing = errors([0.061, 0.358, -0.059, 1.11, -0.017], [0.458, 0.662, 0.144, 1.588, 0.293])
    backlash = errors([0.049, 0.042, 0.068, 0.004, -0.003], [0.225, 0.124, 0.173, 0.05, 0.042])
    null_asym = errors([0.244, 0.349, 0.037, 0.083, 0.307], [0.197, 0.323, -0.294, 0.081, 0.278])
    assert D.CLAIM_RULE == "drift_robust"
    t = D._passes(reference, bearing, bar, null=(0.027, 0.006))
    assert t.passes and t.level_alone and not D._passes(reference, bearing, bar, "both", null=(0.027, 0.006)).passes
    assert "(passes alone: the plain mean is above the training-run null" in D._verdict(t)
    real = errors([0.3, 0.35, 0.32, 0.4, 0.28], [0.3, 0.35, 0.32, 0.4, 0.28])  # both tests pass: not alone
    t = D._passes(reference, real, bar, null=(0.027, 0.006))
    assert t.passes and not t.level_alone and "passes alone" not in D._verdict(t)
    assert not D._passes(reference, bearing, bar, null=(0.30, 0.006)).passes  # plain mean 0.29 under the null
    # no training-run null (one training run): no bar for the plain mean, both tests must pass
    assert not D._passes(reference, bearing, bar, null=(0.0, 0.0)).passes
    assert D._passes(reference, backlash, bar, "level", null=(0.063, 0.059)).passes
    assert not D._passes(reference, backlash, bar, null=(0.063, 0.059)).passes
    assert D._passes(reference, null_asym, bar, "plain", null=(0.046, 0.021)).passes
    assert not D._passes(reference, null_asym, bar, null=(0.046, 0.021)).passes


def test_a_consistent_gain_below_the_training_run_null_is_not_claimed():
    """A candidate that shrinks every held-out run's error by 2 % passes the significance test (the same in every
    run: a tiny standard error) but not a training-run null of 0.05: the nominal's held-out log error moves more
    than that when one training run is left out. The bar it had to exceed is recorded."""

    def errors(force):
        return {f"r{i}": {"force": f, "force_level": 0.6 * f} for i, f in enumerate(force)}

    reference = errors([10.0, 11.0, 12.0, 9.0, 8.0])
    sliver = errors([9.8, 10.76, 11.77, 8.81, 7.85])
    bar = 2.13
    t = D._passes(reference, sliver, bar)
    assert t.passes and t.threshold == pytest.approx(bar * t.log_ratio_se)
    t = D._passes(reference, sliver, bar, null=(0.05, 0.04))
    assert not t.passes and t.threshold == 0.05 and t.level_threshold == 0.04
    assert 0.015 < t.log_ratio < 0.025 and 0.015 < t.level_log_ratio < 0.025
    real = errors([7.0, 8.0, 9.5, 6.0, 6.5])
    assert D._passes(reference, real, bar, null=(0.05, 0.04)).passes


def test_a_candidate_is_held_to_the_smaller_of_the_nominal_null_and_its_own(monkeypatch):
    """Development dataset 11009 (a drive saturating at SNR 59, docs/gap_benchmark.md 3bc): its candidate's
    held-out log ratios (plain mean +0.41) fall below the nominal's training-run null of 0.83 / 0.46, which is the
    saturation's own bias on the nominal; its own model moves by 0.10 / 0.11 with a training run left out, and it
    is claimed against that. An own null above the nominal's changes nothing; a candidate that does not refit the
    friction (the axial mode, the delay) or whose plain mean is not positive never computes one."""
    from types import SimpleNamespace

    def errors(plain, level):
        return {f"r{i}": {"force": 10.0 * np.exp(-a), "force_level": 6.0 * np.exp(-b)}
                for i, (a, b) in enumerate(zip(plain, level))}

    reference = errors([0.0] * 5, [0.0] * 5)
    fit = SimpleNamespace(test_errors=errors([0.295, 0.758, 0.619, -0.002, 0.392], [0.413, 0.799, 0.423, 0.037, 0.389]),
                          parameters={})
    nominal_null = (0.828, 0.457)
    computed = []

    def own_moves(test, f):
        computed.append(f)
        return ((-0.104, 0.05), (0.02, -0.111))

    monkeypatch.setattr(D, "candidate_moves", own_moves)

    def claim(name, f, null, known=()):
        return D._claim_test(reference, f.test_errors, name, 2.13, null, D._own_null((), f, known), rule="drift_robust")

    assert not D._passes(reference, fit.test_errors, 2.13, null=nominal_null).passes
    t = claim("drive_saturation", fit, nominal_null)
    assert t.passes and t.own_null == pytest.approx((0.104, 0.111)) and computed == [fit]
    assert t.threshold == pytest.approx(max(0.104, 2.13 * t.log_ratio_se))
    assert "held to its own training-run null 0.104 (0.111 with each run's level)" in D._verdict(t)
    # computed once: the greedy step's first claim passes the ranking's own null back
    assert claim("drive_saturation", fit, nominal_null, known=(0.104, 0.111)).passes and len(computed) == 1
    # an own null above the nominal's: the nominal's decides, and none is recorded
    monkeypatch.setattr(D, "candidate_moves", lambda test, f: ((0.9, 0.9),))
    t = claim("drive_saturation", fit, nominal_null)
    assert not t.passes and t.own_null == ()
    # no jackknife (one training run): the nominal's
    monkeypatch.setattr(D, "candidate_moves", lambda test, f: None)
    assert not claim("drive_saturation", fit, nominal_null).passes
    # not for a candidate that holds the friction fixed or is searched, nor for a negative plain mean
    monkeypatch.setattr(D, "candidate_moves", own_moves)
    assert not claim("control_delay", fit, nominal_null).passes
    assert not D._refits("axial_mode") and not D._refits("control_delay") and D._refits("drive_saturation")
    worse = SimpleNamespace(test_errors=errors([-0.3] * 5, [0.4] * 5), parameters={})
    assert not claim("drive_saturation", worse, nominal_null).passes
    assert len(computed) == 1
    # a passing candidate needs no own null
    assert claim("drive_saturation", fit, (0.05, 0.05)).own_null == ()


def test_the_training_run_null_is_the_largest_move_of_the_nominal_with_one_training_run_left_out(runs):
    from drakecreep.gap.drake_effects import score_parameters
    from drakecreep.gap.identify import identify

    train, test = runs[:2], runs[2:]
    nominal = identify(train, D.NOMINAL_PARAMETERS, max_nfev=3)
    nom_test, _ = score_parameters(test, nominal.parameters)
    null = D.training_run_null(test, nominal, nom_test)
    assert len(nominal.jackknife) == 2 and all(v > 0 for v in null)
    moves = []
    for values in nominal.jackknife:
        moved, _ = score_parameters(test, dict(nominal.parameters, **values))
        moves.append(abs(np.mean([np.log(moved[k]["force"] / nom_test[k]["force"]) for k in nom_test])))
    assert null[0] == pytest.approx(max(moves))
    # the signed moves, one per left-out training run in order, are what the null is the largest size of
    signed = D.training_run_moves(test, nominal, nom_test)
    assert len(signed) == 2 and [abs(m[0]) for m in signed] == pytest.approx(moves)
    assert D.null_of_moves(signed) == pytest.approx(null)
    assert D.null_of_moves([(0.1, float("nan")), (-0.3, float("nan"))]) == (0.3, 0.0)
    # a candidate's own moves are the same statistic of its own fit's jackknife; none without one
    from drakecreep.gap.drake_effects import EffectFit

    fit = EffectFit(name="x", parameters=dict(nominal.parameters), identified=nominal, delay=nominal.delay,
                    flexible=nominal.flexible, train_force_error=0.0, test_force_error=0.0, test_errors=nom_test,
                    seconds=0.0)
    assert np.allclose(D.candidate_moves(test, fit), signed)
    assert D.candidate_moves(test, dataclasses.replace(fit, identified=None)) is None
    assert D.candidate_moves(test, None) is None
    # one training run: no jackknife, no null (the significance test alone decides)
    one = identify(train[:1], D.NOMINAL_PARAMETERS, max_nfev=3)
    assert D.training_run_moves(test, one, score_parameters(test, one.parameters)[0]) == ()
    assert D.training_run_null(test, one, score_parameters(test, one.parameters)[0]) == (0.0, 0.0)


def test_a_saturating_drive_is_claimed_with_its_mass_against_a_reference_of_equal_effort():
    """A drive that applies ``F / sqrt(1 + (F / 150 N)^2)`` of the command: the IDIM mass of the nominal is too
    large (it reads the unapplied command as inertia; about 150 kg against 95 kg). The candidate carries the mass its inverse-dynamics fit
    found beside the limit (``screen_refits``), and is measured against its own reference, the nominal with the
    screen's reference mass refitted by the same evaluations (``reference_errors``), not against the nominal."""
    truth = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3, inverse_drive_limit=1.0 / 150.0)
    runs = _simulated(truth, (0, 3000, 6000, 9000, 12000), 1000, "s")[0]
    diag = diagnose_drake(runs[:2], runs[2:], effects=("drive_saturation", "thermal_drift"), max_nfev=3)
    assert diag.nominal.parameters["mass"] > 1.3 * truth["mass"]  # what the candidate has to undo
    sat = {r.name: r for r in diag.ranking}["drive_saturation"]
    assert sat.reference_errors is not None and sat.reference_errors != diag.nominal_test_errors
    assert diag.claimed == ("drive_saturation",)
    assert diag.model["parameters"]["mass"] == pytest.approx(truth["mass"], rel=0.05)
    assert 1.0 / diag.model["parameters"]["inverse_drive_limit"] == pytest.approx(150.0, rel=0.1)
    assert sat.log_ratio > 1.0  # the held-out error shrinks by more than e
    assert {r.name: r for r in diag.ranking}["thermal_drift"].reference_errors is None
    line = next(x for x in diag.summary() if x.strip().startswith("drive_saturation"))
    assert "against its own reference: the nominal with mass" in line and "(candidate: mass" in line


def test_a_stribeck_fit_may_start_from_its_own_friction_against_a_reference_that_may_too():
    """A Stribeck candidate offers its own inverse-dynamics friction as a second closed-loop start (``own_start``;
    the nominal's friction, fitted without it, can lack any viscous term). Its fit starts from whichever of the two
    replays the training runs better, and so does its equal-effort reference, from the nominal's own
    inverse-dynamics values or the nominal: the candidate is measured against that reference
    (``reference_errors``), not against the nominal. A candidate without a second start has no such reference."""
    truth = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3, stribeck_extra=30.0,
                           stribeck_velocity=0.01)
    runs = _simulated(truth, (0, 3000, 6000, 9000, 12000), 1000, "s")[0]
    diag = diagnose_drake(runs[:2], runs[2:], effects=("stribeck", "thermal_drift"), max_nfev=3)
    rows = {r.name: r for r in diag.ranking}
    strib = rows["stribeck"]
    assert strib.screen.alternative_start and strib.screen.reference_alternative
    assert strib.closed_loop_start in ("inverse_dynamics", "nominal")
    assert strib.reference_errors is not None and set(strib.reference_errors) == set(diag.nominal_test_errors)
    assert diag.claimed[:1] == ("stribeck",)
    assert rows["thermal_drift"].reference_errors is None


def test_the_equal_effort_refit_keeps_the_warnings_of_the_fit_it_starts_from(runs):
    """The nominal a user reads is the first fit refitted (``_refit``); the first fit's warnings (here a viscous
    friction lifted from a start of 0) are not raised again from its values, so the refit carries them."""
    from drakecreep.gap.identify import identify

    first = identify(runs[:2], ("viscous", "coulomb", "offset"), max_nfev=2, fixed={"viscous": 0.0})
    assert any(w.startswith("viscous starts at") for w in first.warnings)
    nominal = D._refit(runs[:2], first, first.fitted, 1)
    assert set(first.warnings) <= set(nominal.warnings)
    assert len(set(nominal.warnings)) == len(nominal.warnings)


def test_skewed_gains_in_every_run_pass_by_the_sign_flip_null_and_one_run_worse_by_t():
    """Development seed 11002's drive saturation: errors x0.55, 0.91, 0.91, 0.98, 0.98 (every run better, one much
    more) miss the t bar and pass the sign-flip null; development seed 4003's lead error (one run a hair worse,
    three much better) passes by t. The training-run null still applies to both."""

    def errors(ratios):
        return {f"r{i}": {"force": 10.0 * r, "force_level": 6.0 * r} for i, r in enumerate(ratios)}

    reference = errors([1.0] * 5)
    bar = 2.13
    skewed = errors(np.exp(-np.array([0.602, 0.09, 0.09, 0.017, 0.016])))
    t = D._passes(reference, skewed, bar)
    assert t.log_ratio < bar * t.log_ratio_se and t.p_sign_flip == pytest.approx(1 / 32) and t.passes
    assert not D._passes(reference, skewed, bar, null=(0.2, 0.2)).passes
    one_worse = errors(np.exp(-np.array([0.004, -0.003, 1.165, 1.115, 1.011])))
    t = D._passes(reference, one_worse, bar)
    assert t.p_sign_flip > 0.05 and t.log_ratio > bar * t.log_ratio_se and t.passes


def test_a_time_ripple_must_shrink_the_error_at_constant_speed_too():
    """Held-out run 13's null (seed 27013004; docs/gap_benchmark.md, 3u): a 5.6 Hz ripple fitted a model error
    that repeats at the same instants of every run (the runs share their timing), shrinking the whole runs'
    errors by 4-10 % but not the error at constant speed, where a force at a fixed time frequency is as well.
    With its regime the candidate fails; shrinking both, it passes; a held-out run without constant-speed
    samples fails it; a candidate without a regime is decided as before."""

    def errors(ratios, cruise):
        return {f"r{i}": {"force": 10.0 * r, "force_level": 6.0 * r, "force_constant_speed": 4.0 * c}
                for i, (r, c) in enumerate(zip(ratios, cruise))}

    reference = errors([1.0] * 5, [1.0] * 5)
    bar = 2.13
    moves = np.exp(-np.array([0.077, 0.105, 0.086, 0.050, 0.04]))
    locked = errors(moves, np.exp(-np.array([0.01, -0.02, 0.0, -0.03, 0.01])))
    assert D._passes(reference, locked, bar).passes
    t = D._passes(reference, locked, bar, regime="constant_speed")
    assert not t.passes and t.regime == "constant_speed" and abs(t.regime_log_ratio) < 0.01
    real = errors(moves, moves ** 1.2)
    t = D._passes(reference, real, bar, regime="constant_speed")
    assert t.passes and t.regime_log_ratio > 0.05 and t.regime_p_sign_flip == pytest.approx(1 / 32)
    missing = {k: dict(v) for k, v in real.items()}
    del missing["r3"]["force_constant_speed"]
    t = D._passes(reference, missing, bar, regime="constant_speed")
    assert not t.passes and np.isnan(t.regime_log_ratio)
    assert "no constant speed in every held-out run" in D._verdict(t)
    assert D.DRAKE_EFFECTS["time_ripple"].regime == "constant_speed"
    assert not any(e.regime for n, e in D.DRAKE_EFFECTS.items() if n not in ("time_ripple", "axial_mode"))


def test_an_asymmetric_friction_that_fails_the_level_test_passes_by_its_constant_speed_fallback():
    """Held-out run 21's withheld asymmetry (seed 41001006; docs/gap_benchmark.md, 3af): the plain test passed, the
    level test did not (two runs worse with their own level), and the error at constant speed shrank in every
    run. By the fallback it is claimed; the same plain and level ratios with a constant-speed error that does
    not shrink (held-out run 18's null 37013007) are not; neither is a candidate whose plain mean is negative,
    nor one without the fallback."""

    def errors(plain, level, cruise):
        return {f"r{i}": {"force": 10.0 * math.exp(-a), "force_level": 6.0 * math.exp(-b),
                          "force_constant_speed": 4.0 * math.exp(-c)}
                for i, (a, b, c) in enumerate(zip(plain, level, cruise))}

    reference = errors([0.0] * 5, [0.0] * 5, [0.0] * 5)
    bar, null = 2.13, (0.177, 0.184)
    plain, level = [0.089, 0.015, 0.818, 0.837, 0.711], [-0.126, -0.386, 0.755, 0.791, 0.657]
    real = errors(plain, level, [0.534, 0.667, 0.813, 0.627, 0.624])
    assert not D._passes(reference, real, bar, null=null).passes  # the rule alone misses it
    t = D._passes(reference, real, bar, null=null, fallback_regime="constant_speed")
    assert t.passes and t.fallback and t.regime == "constant_speed" and t.regime_log_ratio > 0.6
    assert "constant speed fallback" in D._verdict(t)
    flat = errors(plain, level, [-0.04, 0.04, 0.04, 0.0, 0.0])  # the null's constant-speed ratios
    t = D._passes(reference, flat, bar, null=null, fallback_regime="constant_speed")
    assert not t.passes and not t.fallback and t.regime == "constant_speed"
    worse = errors(plain, [-0.5] * 5, [0.534, 0.667, 0.813, 0.627, 0.624])  # the level mean negative: no either
    assert not D._passes(reference, worse, bar, null=null, fallback_regime="constant_speed").passes
    # a candidate that passes its rule is not marked as passing by the fallback
    strong = errors([0.8] * 4 + [0.9], [0.7] * 4 + [0.75], [0.6] * 5)
    t = D._passes(reference, strong, bar, null=null, fallback_regime="constant_speed")
    assert t.passes and not t.fallback
    assert D._fallback("asymmetric_friction") == "constant_speed"
    assert not any(e.fallback_regime for n, e in D.DRAKE_EFFECTS.items() if n != "asymmetric_friction")


def test_a_friction_along_the_travel_passes_with_either_test():
    """Each of the two held-out tests is blind to a friction along the travel in its own way (docs/gap_benchmark.md,
    3q and 3w). Held-out run 14's seed 29002001: every run's plain error shrank (log ratios 0.58-1.63) while, with
    each run's own friction level, the short runs (6 and 11 mm, where the map is a level) swung negative. Held-out
    run 13's seed 27002001: the level test passed (every run positive) and the plain one did not (two runs whose
    drifted level cancels the map). The candidate's rule is ``either``, and both pass under it, each still above
    its training-run null; every other candidate keeps :data:`CLAIM_RULE`, under which both fail. Useless on both
    tests fails, and so does held-out run 10's null 21013001: the map passed the level test and made the plain
    error worse on average."""

    def errors(plain, level):
        return {f"r{i}": {"force": 10.0 * np.exp(-a), "force_level": 6.0 * np.exp(-b)}
                for i, (a, b) in enumerate(zip(plain, level))}

    reference = errors([0.0] * 5, [0.0] * 5)
    short_runs = errors([0.64, 1.63, 1.00, 0.58, 0.87], [-0.41, 0.82, -0.09, 0.74, -0.27])
    drifted = errors([0.84, 1.36, 0.26, -0.17, -0.31], [0.89, 1.15, 0.35, 0.26, 0.63])
    useless = errors([0.05, -0.04, 0.02, -0.01, 0.0], [0.03, -0.02, 0.01, 0.0, -0.01])
    worse = errors([0.05, -0.2, 0.03, -0.06, -0.07], [0.10, 0.18, 0.09, 0.14, 0.12])
    bar, rule = 2.13, D._rule("position_friction")
    assert rule == "either"
    for along, null in ((short_runs, (0.20, 0.43)), (drifted, (0.035, 0.098))):
        t = D._passes(reference, along, bar, rule=rule, null=null)
        assert t.passes and t.rule == "either" and "(either test suffices)" in D._verdict(t)
        assert not D._passes(reference, along, bar, rule="both", null=null).passes
    # the other candidates' rule takes the level test alone only with the plain mean above its null (drifted);
    # the plain test alone (short runs) is not enough for them
    assert not D._passes(reference, short_runs, bar, rule=D.CLAIM_RULE, null=(0.20, 0.43)).passes
    assert D._passes(reference, drifted, bar, rule=D.CLAIM_RULE, null=(0.035, 0.098)).passes
    assert not D._passes(reference, short_runs, bar, rule=rule, null=(1.7, 0.43)).passes
    assert not D._passes(reference, useless, bar, rule=rule).passes
    assert D._passes(reference, worse, bar, rule="level").passes
    assert not D._passes(reference, worse, bar, rule=rule).passes
    assert [n for n in D.DRAKE_EFFECTS if D._rule(n) != D.CLAIM_RULE] == ["position_friction"]
    assert D._rule("control_delay") == D.CLAIM_RULE


def test_an_axial_mode_is_claimed_when_it_shrinks_the_error_at_its_own_frequency():
    """A 40 Hz mode of the two-mass axis, withheld from the rigid nominal: the fit finds it, shrinks the held-out
    error in the band around its frequency by more than over the whole runs (an oscillation is its signature),
    and is claimed. A fit whose whole-run gain is real but whose band error grows (a compliance fitted to a lost
    motion: the backlash answered ``axial_mode`` in held-out runs 14-19) is not."""
    import math

    from drakecreep.gap.drake_effects import axial_mode_frequency
    from drakecreep.gap.drake_replay import mode_band

    truth = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3, motor_mass_fraction=0.2)
    reduced = truth["motor_mass_fraction"] * (1 - truth["motor_mass_fraction"]) * truth["mass"]
    k = (2 * math.pi * 40.0) ** 2 * reduced
    truth.update(stiffness=k, damping=2 * 0.03 * math.sqrt(k * reduced))
    full = load_emps("estimation").runs[0]
    runs = []
    for seed, a in enumerate((0, 3000, 6000, 9000, 12000)):
        run = full.slice(a, a + 1000)
        res = DrakeReplay(run, flexible=True).simulate(truth)
        noise = np.random.default_rng(seed).normal(0.0, 0.5, res.u.size)
        runs.append(dataclasses.replace(run, x_motor=res.x_motor, u=res.u + noise / run.u_gain, label=f"m{a}"))
    diag = diagnose_drake(runs[:2], runs[2:], effects=("axial_mode",), max_nfev=12)
    mode = diag.ranking[0]
    f, zeta = axial_mode_frequency(mode.fit.parameters)
    assert diag.claimed == ("axial_mode",) and 36.0 < f < 44.0 and zeta < 0.2
    assert mode.regime == mode_band(40.0) and mode.regime_log_ratio > mode.log_ratio > 0.5
    line = next(x for x in diag.summary() if x.strip().startswith("axial_mode"))
    assert f"at band {mode.regime[5:-3]} Hz" in line and f"(mode {f:.3g} Hz, damping ratio {zeta:.2g})" in line

    def errors(whole, band):
        return {f"r{i}": {"force": 10.0 * w, "force_level": 6.0 * w, f"force_{mode.regime}": 3.0 * b}
                for i, (w, b) in enumerate(zip(whole, band))}

    gain = np.exp(-np.array([0.057, 0.028, 0.026, 0.051, 0.019]))  # development seed 60003 (a backlash)
    reference = errors([1.0] * 5, [1.0] * 5)
    compliance = errors(gain, np.exp(np.array([0.116, 0.28, 0.078, 0.168, 0.147])))
    assert D._passes(reference, compliance, 2.13).passes
    assert not D._passes(reference, compliance, 2.13, regime=mode.regime).passes


def test_a_lead_error_carried_by_two_fast_runs_passes_by_the_held_out_runs_pieces():
    """Spent held-out dataset 35003007 (a lead error at SNR 7.0, rerun as development; docs/gap_benchmark.md, 3ai):
    two fast held-out runs of five carry it, so neither Student's t nor the sign-flip test over the runs passes,
    while both means are far above their training-run nulls and its 20 pieces give a sign-flip p of 0.001. It is
    claimed by its pieces. The same pieces are not enough without the piece test, with a mean under the null, with
    no training-run null (one training run), or without the pieces' errors; spent null 35013001's load friction,
    whose pieces' p is 0.013, stays under its null. A candidate that passes its rule is not marked as passing by
    its pieces."""
    keys = [f"force_piece_{i}" for i in range(4)]

    def errors(plain, level, pieces):
        return {f"r{i}": {"force": 10.0 * math.exp(-a), "force_level": 6.0 * math.exp(-b),
                          **{k: 10.0 * math.exp(-c) for k, c in zip(keys, cs)}}
                for i, (a, b, cs) in enumerate(zip(plain, level, pieces))}

    reference = errors([0.0] * 5, [0.0] * 5, [[0.0] * 4] * 5)
    bar, null = 2.13, (0.062, 0.012)
    pieces = [[1.216, 1.635, 1.121, 1.704], [0.258, 0.218, 0.087, 0.172], [0.006, -0.028, 0.007, 0.002],
              [-0.02, 0.067, -0.023, -0.065], [0.11, 0.052, 0.018, -0.017]]
    lead = errors([1.413, 0.163, -0.001, -0.014, 0.04], [1.597, 0.157, 0.009, -0.003, 0.022], pieces)
    assert not D._passes(reference, lead, bar, null=null).passes  # the rule over whole runs misses it
    t = D._passes(reference, lead, bar, null=null, pieces=True)
    assert t.passes and t.pieces and t.piece_p_sign_flip <= 0.01 and t.piece_log_ratio > 0.3
    assert "passes by its pieces" in D._verdict(t)
    assert not D._passes(reference, lead, bar, null=(0.4, 0.012), pieces=True).passes  # plain mean 0.32 under it
    assert not D._passes(reference, lead, bar, null=(0.062, 0.4), pieces=True).passes  # level mean 0.36 under it
    assert not D._passes(reference, lead, bar, null=(0.0, 0.0), pieces=True).passes  # no training-run null
    bare = {k: {n: v for n, v in e.items() if n not in keys} for k, e in lead.items()}
    t = D._passes(reference, bare, bar, null=null, pieces=True)
    assert not t.passes and math.isnan(t.piece_log_ratio)
    # pieces of mixed sign: the mean over whole runs is the same, the pieces' p is not small
    mixed = errors([1.413, 0.163, -0.001, -0.014, 0.04], [1.597, 0.157, 0.009, -0.003, 0.022],
                   [[2.5, -1.0, 2.0, 2.152], [0.8, -0.5, 0.6, -0.248], [0.3, -0.3, 0.2, -0.2],
                    [-0.3, 0.3, -0.2, 0.2], [0.3, -0.3, 0.2, -0.2]])
    t = D._passes(reference, mixed, bar, null=null, pieces=True)
    assert not t.passes and t.piece_p_sign_flip > 0.05
    # spent null 35013001's load friction: pieces p 0.013, mean log ratio 0.002 against a null of 0.073
    load = errors([0.0042, 0.0012, 0.002, -0.0003, 0.0016], [0.002, 0.001, 0.002, 0.0, 0.001],
                  [[-0.0009, 0.0052, 0.0089, 0.0061], [-0.0025, 0.0027, -0.0015, 0.0042],
                   [-0.0009, 0.0031, -0.0001, 0.0047], [-0.002, -0.0001, -0.0005, 0.001],
                   [-0.0006, 0.002, 0.0016, 0.0025]])
    t = D._passes(reference, load, bar, null=(0.073, 0.032), pieces=True)
    assert not t.passes and t.piece_p_sign_flip < 0.05
    strong = errors([0.8] * 4 + [0.9], [0.7] * 4 + [0.75], [[0.8] * 4] * 5)
    t = D._passes(reference, strong, bar, null=null, pieces=True)
    assert t.passes and not t.pieces
    assert D._piece_test("lead_error") and not D._piece_test("control_delay")
    assert not any(e.piece_test for n, e in D.DRAKE_EFFECTS.items() if n != "lead_error")


def test_a_passing_candidate_below_a_fitted_one_that_fails_is_not_claimed():
    """``_outranked``: a passing candidate whose held-out log ratio is below that of a fitted candidate that does
    not pass is marked (and the greedy step skips it); one above every failing candidate, a screened-out
    candidate and a ranking without failing fitted candidates are left alone."""
    from types import SimpleNamespace

    from drakecreep.gap.drake_diagnosis import RankedEffect, _outranked

    def ranked(name, passes, log_ratio, fitted=True):
        fit = SimpleNamespace(name=name, test_force_error=1.0) if fitted else None
        return RankedEffect(fit=fit, gain=1.0, standard_error=0.1, passes=passes, effect=name, log_ratio=log_ratio)

    ranking = [ranked("axial_mode", False, 0.161), ranked("position_friction", True, 0.082),
               ranked("stribeck", True, 0.30), ranked("lead_error", False, float("nan"), fitted=False)]
    out = {r.name: r.outranked_by for r in _outranked(ranking)}
    assert out == {"axial_mode": "", "position_friction": "axial_mode", "stribeck": "", "lead_error": ""}
    assert [r.outranked_by for r in _outranked(ranking[1:3])] == ["", ""]


@pytest.mark.parametrize("effects, allowed", [("stribeck", "a list of names (one name goes in a list: ['stribeck'])"),
                                              (["axial_mode", "axial_mode"], "each name once (axial_mode given twice)")])
def test_one_string_or_an_effect_twice_is_refused_before_any_fit(effects, allowed):
    """'stribeck' was read as its letters ('effects: got 's''), an effect twice was fitted and ranked twice (found by
    the fuzzing pass)."""
    from drakecreep.data import example_path
    from drakecreep.gap.runs import load_runs

    runs = load_runs(example_path("emps_segment.csv"), split="half")
    with pytest.raises(InputError) as err:
        diagnose_drake(runs[:1], runs[1:3], effects)
    assert err.value.field == "effects" and err.value.allowed == allowed


def test_a_run_both_fitted_and_held_out_or_held_out_twice_is_refused_before_any_fit():
    """A script's diagnose_drake(runs[:2], runs[1:]) scored the fit on a run it was fitted on, exit-free (the CLI's
    --train/--test refuse it; found by the fuzzing pass)."""
    from drakecreep.data import example_path
    from drakecreep.gap.runs import load_runs

    runs = load_runs(example_path("emps_segment.csv"), split="half")
    for train, test, said in ((runs[:2], runs[1:], "a training run too"), (runs[:1], [runs[1], runs[1]], "twice")):
        with pytest.raises(InputError) as err:
            diagnose_drake(train, test, ("stribeck",))
        assert err.value.field == "test" and said in str(err.value.value)


def test_a_candidate_whose_held_out_replay_diverged_says_so_instead_of_nan():
    """A Stribeck fitted to 1.4e8 N on an 8 ms EMPS log (session 86) diverged on a held-out run: its line read
    'held-out nan %, gain +nan points of %, error xnan'."""
    from types import SimpleNamespace

    from drakecreep.gap.drake_diagnosis import DrakeDiagnosis, RankedEffect

    fit = SimpleNamespace(name="stribeck", test_force_error=float("nan"), train_force_error=7.0, delay=0.0,
                          parameters={"stribeck_extra": 1.4e8, "stribeck_velocity": 1.65e-3},
                          test_errors={"r0": {"force": float("nan")}}, seconds=1.0)
    ranked = RankedEffect(fit=fit, gain=float("nan"), standard_error=float("nan"), passes=False, effect="stribeck",
                          log_ratio=float("nan"))
    diag = DrakeDiagnosis(nominal=None, nominal_test_errors={"r0": {"force": 9.0}}, ranking=(ranked,), claimed=(),
                          model={"parameters": {"mass": 90.0}, "flexible": False, "delay": 0.0},
                          test_errors={"r0": {"force": 9.0}}, seconds=0.0, k_se=2.0)
    (line,) = [x for x in diag.summary() if "stribeck" in x]
    assert line.split() == ["stribeck", "held-out", "replay", "diverged", "at", "its", "fitted", "values", "(not",
                            "claimed)"]
    assert "nan" not in " ".join(diag.summary()).lower()
