"""Identification (drakecreep.gap.identify) on runs whose truth is known: the Drake replay's own output."""

import dataclasses

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.gap.drake_replay import DrakeReplay, axis_from_idim
from drakecreep.gap.identify import identify, idim_start
from drakecreep.gap.idim import PUBLISHED_IDIM
from drakecreep.gap.measured import load_emps

TRUTH = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3, coulomb=24.0, viscous=180.0, offset=-2.0)


def _synthetic(run, truth, seed):
    """The run with x_motor and u replaced by the replay of ``truth`` (plus force noise of 0.5 N rms)."""
    res = DrakeReplay(run).simulate(truth)
    rng = np.random.default_rng(seed)
    u = res.u + rng.normal(0.0, 0.5 / run.u_gain, res.u.size)
    return dataclasses.replace(run, x_motor=res.x_motor, u=u)


@pytest.fixture(scope="module")
def runs():
    full = load_emps("estimation").runs[0]
    # 1.5 s windows with both directions of motion
    return [_synthetic(full.slice(a, a + 1500), TRUTH, seed) for seed, a in enumerate((0, 5000))]


def test_output_error_recovers_the_friction_of_a_known_axis(runs):
    idf = identify(runs, uncertain=("viscous", "coulomb", "offset"), max_nfev=6,
                   fixed={"mass": PUBLISHED_IDIM["M"], "regularization_velocity": 1e-3})
    for name in ("viscous", "coulomb", "offset"):
        assert abs(idf.parameters[name] - TRUTH[name]) < max(3 * idf.ci95[name], 0.02 * abs(TRUTH[name])), name
        assert idf.ci95[name] > 0
    assert idf.cost <= idf.cost_start
    assert idf.n_evaluations >= 4 and idf.evaluations_per_s > 0


def test_one_way_runs_warn_that_coulomb_and_offset_are_not_separable():
    full = load_emps("estimation").runs[0]
    v = np.diff(full.x_ref)
    start = int(np.argmax(v > 1e-6 * full.dt))
    stop = start + int(np.argmax(v[start:] <= 0))
    one_way = full.slice(max(start - 100, 0), stop)
    st = idim_start([one_way])
    assert any("not separable" in w for w in st.warnings)
    assert st.parameters["offset"] == 0.0


def test_identify_refuses_unknown_names(runs):
    with pytest.raises(InputError, match="uncertain"):
        identify(runs, uncertain=("friction",))
    with pytest.raises(InputError, match="bounds.coulomb"):
        identify(runs[:1], uncertain=("coulomb",), bounds={"coulomb": (30.0, 10.0)})


def test_leave_one_run_out_values_match_refits_and_see_a_run_that_differs():
    """Three runs, the third with a Coulomb level 25 % higher (friction drifts between runs). The linearized
    leave-one-run-out values (one Gauss-Newton step on the other runs' rows, no replays) are those of a real refit
    on the other two runs, and the jackknife spread of the Coulomb level is that of a mean of levels 24, 24 and
    30 N (standard error 2 N), within a factor of 2."""
    full = load_emps("estimation").runs[0]
    odd = dict(TRUTH, coulomb=1.25 * TRUTH["coulomb"])
    runs = [_synthetic(full.slice(a, a + 1500), t, seed)
            for seed, (a, t) in enumerate(((0, TRUTH), (5000, TRUTH), (10000, odd)))]
    names = ("viscous", "coulomb", "offset")
    fixed = {"mass": PUBLISHED_IDIM["M"], "regularization_velocity": 1e-3}
    idf = identify(runs, uncertain=names, max_nfev=8, fixed=fixed)
    assert len(idf.jackknife) == 3 and set(idf.jackknife_std) == set(names)
    without_odd = identify(runs[:2], uncertain=names, max_nfev=8, fixed=dict(idf.parameters))
    assert idf.jackknife[2]["coulomb"] == pytest.approx(without_odd.parameters["coulomb"], abs=0.3)
    assert abs(without_odd.parameters["coulomb"] - TRUTH["coulomb"]) < 0.5  # the refit found the two runs' level
    assert 1.0 < idf.jackknife_std["coulomb"] < 4.0
    assert any("leave one run out" in line for line in idf.summary())
    assert identify(runs[:1], uncertain=names, max_nfev=2, fixed=fixed).jackknife == ()


def test_a_drive_limit_started_at_zero_is_still_found():
    """The screen's drive limit on data that barely shows it can be ~0 (1e-10 1/N). The applied force
    ``F / sqrt(1 + (c F)^2)`` is quadratic in ``c`` at 0: no gradient there, and from that start the least
    squares never moved. The candidate starts at least at 1/1000 1/N (``start_floor``; the least-squares scale
    is 1/400 1/N, not the start's size) and finds the limit of an axis that saturates at 150 N within 10 %."""
    from drakecreep.gap.drake_effects import fit_effect

    full = load_emps("estimation").runs[0]
    truth = dict(TRUTH, inverse_drive_limit=1.0 / 150.0)
    runs = [_synthetic(full.slice(a, a + 1500), truth, seed) for seed, a in enumerate((0, 5000, 10000))]
    fixed = {"mass": PUBLISHED_IDIM["M"], "regularization_velocity": 1e-3, "inverse_drive_limit": 1e-10}
    stuck = identify(runs[:2], uncertain=("inverse_drive_limit",), max_nfev=6, fixed=dict(TRUTH, **fixed))
    assert stuck.parameters["inverse_drive_limit"] < 1e-6  # (why the floor: the start at ~0 does not move)
    nominal = identify(runs[:2], uncertain=(), fixed=dict(TRUTH, **fixed))
    fit = fit_effect("drive_saturation", runs[:2], runs[2:], nominal, max_nfev=6, refit=(),
                     starts=({"inverse_drive_limit": 1e-10},))
    assert 1.0 / fit.parameters["inverse_drive_limit"] == pytest.approx(150.0, rel=0.1)


def test_a_viscous_started_at_zero_is_refined_from_its_floor(runs, monkeypatch):
    """IDIM sets a negative viscous coefficient to 0 (a Stribeck friction falling with speed over slow runs). On
    its log scale a start of 0 sits at log(1e-300) and never moves; from the floor (10 % of the runs' RMS force at
    their RMS speed) the fit finds the known axis's 180 N s/m again. A positive start, however small, is kept."""
    import drakecreep.gap.identify as identify_module

    fixed = {"mass": PUBLISHED_IDIM["M"], "regularization_velocity": 1e-3, "viscous": 0.0}
    floors = identify_module.start_floors(runs)
    force = np.concatenate([r.force for r in runs])
    assert floors["coulomb"] == pytest.approx(0.1 * np.sqrt(np.mean(force ** 2)))
    assert 0.0 < floors["viscous"] < 0.5 * TRUTH["viscous"]
    idf = identify(runs, uncertain=("viscous", "coulomb", "offset"), max_nfev=8, fixed=fixed)
    assert idf.parameters["viscous"] == pytest.approx(TRUTH["viscous"], rel=0.1)
    assert any(w.startswith("viscous starts at") for w in idf.warnings)
    small = identify(runs, uncertain=("viscous",), max_nfev=1, fixed=dict(fixed, viscous=1e-3 * floors["viscous"]))
    assert not any("starts at" in w for w in small.warnings)
    monkeypatch.setattr(identify_module, "START_FLOOR_SHARE", 0.0)
    stuck = identify(runs, uncertain=("viscous", "coulomb", "offset"), max_nfev=8, fixed=fixed)
    assert stuck.parameters["viscous"] < 1e-100  # (why the floor)


def test_a_diverged_replay_is_a_poor_fit_not_a_crash():
    """A replay whose samples went non-finite (a candidate's closed loop diverged) gives a large finite residual
    the least squares steps back from; before, the trust-region SVD raised and the dataset was lost."""
    from types import SimpleNamespace

    from drakecreep.gap.identify import NONFINITE_RESIDUAL, _Problem

    n = 50
    run = SimpleNamespace(n=n, force=np.linspace(1.0, 2.0, n), x_motor=np.linspace(0.0, 1e-2, n))
    force = run.force.copy()
    force[10:] = np.nan
    x = run.x_motor.copy()
    x[-1] = np.inf
    r = _Problem.residual_of([SimpleNamespace(run=run, force=force, x_motor=x)])
    assert r.size == 2 * n and np.all(np.isfinite(r))
    assert np.count_nonzero(r == NONFINITE_RESIDUAL) == (n - 10) + 1
    # finite but on its way out (held-out dataset 29010000): clipped, so that the cost r @ r stays finite
    huge = run.x_motor.copy()
    huge[5:] = -1e200
    r = _Problem.residual_of([SimpleNamespace(run=run, force=run.force, x_motor=huge)])
    assert np.count_nonzero(r == -NONFINITE_RESIDUAL) == n - 5 and np.isfinite(r @ r)
    good = _Problem.residual_of([SimpleNamespace(run=run, force=run.force, x_motor=run.x_motor)])
    assert np.all(good == 0.0)


def test_the_iv_start_keeps_the_mass_that_a_lead_error_ripple_takes_from_least_squares():
    """A lead error of 8 um (2.5 mm lead) on the truth: at 0.12 m/s its force ``m_t e''(x) v^2`` is a 50 Hz ripple
    of about 50 N that the loop cannot reject, so the motor shakes with it and the measured acceleration is
    correlated with the equation error of a model without it. IDIM-LS then puts the mass 35 % low; IDIM-IV
    (the replay of the IDIM-LS model as instruments) finds it within 5 %, and the output-error friction from
    that start is within 5 % (offset 0.5 N) of the truth, where from the least-squares start it is not."""
    full = load_emps("estimation").runs[0]
    truth = dict(TRUTH, lead=2.5e-3, lead_error_cos=8e-6, lead_error_2_sin=3e-6)
    runs = [_synthetic(full.slice(a, a + 1500), truth, seed) for seed, a in enumerate((0, 5000))]
    names = ("viscous", "coulomb", "offset")
    fixed = {"regularization_velocity": 1e-3}
    ls = identify(runs, uncertain=names, max_nfev=6, fixed=fixed, instruments=False)
    iv = identify(runs, uncertain=names, max_nfev=6, fixed=fixed)
    assert ls.start.method == "LS" and iv.start.method == "IV"
    assert ls.parameters["mass"] < 0.8 * truth["mass"]
    assert iv.parameters["mass"] == pytest.approx(truth["mass"], rel=0.05)
    assert iv.parameters["viscous"] == pytest.approx(truth["viscous"], rel=0.05)
    assert iv.parameters["coulomb"] == pytest.approx(truth["coulomb"], rel=0.05)
    assert iv.parameters["offset"] == pytest.approx(truth["offset"], abs=0.5)
    assert abs(ls.parameters["offset"] - truth["offset"]) > 1.0
    assert iv.cost < ls.cost
    assert any(line.split()[:2] == ["mass", f"{iv.parameters['mass']:.5g}"] and "IDIM-IV start, not refined" in line
               for line in iv.summary())
    # a value the caller fixes is kept (the closed-loop fits of the candidates start from the nominal's)
    assert identify(runs, uncertain=(), fixed=dict(fixed, mass=80.0)).parameters["mass"] == 80.0
    with pytest.raises(InputError, match="instruments"):
        idim_start(runs, instruments=[runs[0].x_motor])


def test_a_failed_instruments_replay_keeps_the_least_squares_start(runs):
    """When the replay of the IDIM-LS model (the instruments) does not stay finite, the least-squares start is
    kept and a warning says so; the fit goes on."""
    from drakecreep.gap.drake_replay import make_replay

    class FirstDiverges:
        def __init__(self, rep):
            self.rep, self.calls = rep, 0

        def __getattr__(self, name):
            return getattr(self.rep, name)

        def simulate(self, parameters):
            res = self.rep.simulate(parameters)
            self.calls += 1
            return dataclasses.replace(res, x_motor=np.full_like(res.x_motor, np.nan)) if self.calls == 1 else res

    replays = [FirstDiverges(make_replay(r, free=())) for r in runs]
    idf = identify(runs, uncertain=(), fixed={"regularization_velocity": 1e-3}, replays=replays)
    assert idf.start.method == "LS"
    assert any("IDIM-IV" in w and "did not stay finite" in w and "least-squares start kept" in w for w in idf.warnings)
    assert idf.parameters["mass"] == pytest.approx(idim_start(runs).parameters["mass"])


def test_a_non_positive_instrumental_mass_keeps_the_least_squares_start(runs, monkeypatch):
    """An IDIM-IV solution whose mass is not positive is not used: the least-squares start is kept, and the
    warning names the mass (not a failed replay)."""
    import drakecreep.gap.identify as identify_module

    real = identify_module.idim_start

    def negative_mass(rs, instruments=None, **kw):
        start = real(rs, instruments=instruments, **kw)
        if instruments is None:
            return start
        return dataclasses.replace(start, parameters=dict(start.parameters, mass=-3.0))

    monkeypatch.setattr(identify_module, "idim_start", negative_mass)
    idf = identify(runs, uncertain=(), fixed={"regularization_velocity": 1e-3})
    assert idf.start.method == "LS"
    assert idf.parameters["mass"] == pytest.approx(real(runs).parameters["mass"])
    assert any("instrumental-variable mass is -3 kg, not positive" in w for w in idf.warnings)
    assert not any("did not stay finite" in w for w in idf.warnings)


def test_a_drive_force_of_the_wrong_sign_is_named_in_the_measured_signals_terms(runs):
    """u recorded with the opposite sign gives a negative least-squares mass: the error names u and the likely
    cause, not the replay axis's field (it said 'axis.mass: got -94.56'; found by fuzzing)."""
    flipped = [dataclasses.replace(r, u=-r.u) for r in runs]
    with pytest.raises(InputError, match=r"^u: got 'a drive force whose inverse-dynamics mass is -"):
        idim_start(flipped)


def test_a_parameter_the_error_does_not_depend_on_alone_has_no_finite_interval():
    """Two parameters the replay error only sees as a sum get an infinite half-width and the warning (the
    pseudo-inverse gave them a finite, minimum-norm one); a third, identifiable one keeps its finite interval.
    With three independent columns every interval is finite and there is no warning."""
    from types import SimpleNamespace

    from drakecreep.gap.identify import _confidence

    rng = np.random.default_rng(0)
    a, b = rng.normal(size=200), rng.normal(size=200)
    values = {"viscous": 200.0, "coulomb": 20.0, "bristle_stiffness": 1e7}
    prob = SimpleNamespace(names=tuple(values), log=np.array([False, False, True]), scale=np.array([100.0, 10.0, 1.0]))
    sol = SimpleNamespace(jac=np.column_stack([a, a, b]), fun=0.1 * rng.normal(size=200), cost=1.0)
    std, ci, _, warnings = _confidence(sol, prob, values)
    assert std["viscous"] == np.inf and std["coulomb"] == np.inf and np.isfinite(std["bristle_stiffness"])
    assert any("does not depend on 1 combination" in w for w in warnings)
    sol = SimpleNamespace(jac=np.column_stack([a, rng.normal(size=200), b]), fun=sol.fun, cost=1.0)
    std, _, _, warnings = _confidence(sol, prob, values)
    assert all(np.isfinite(s) for s in std.values()) and not any("does not depend" in w for w in warnings)


def test_a_stiff_parameter_beside_a_viscous_one_keeps_its_interval():
    """The covariance is taken in the fit's scaled variables: in SI the normal matrix of a stiffness of 1e12 N/m
    (fitted on a log scale) beside a viscous coefficient is beyond a pseudo-inverse's tolerance, which cut the
    stiffness's direction and gave it a half-width of ~0 (a LuGre nominal showed 7e-6 N/m beside a
    leave-one-run-out spread of 1.6e6 N/m)."""
    from types import SimpleNamespace

    from drakecreep.gap.identify import _confidence

    rng = np.random.default_rng(1)
    values = {"viscous": 200.0, "bristle_stiffness": 1e12}
    prob = SimpleNamespace(names=tuple(values), log=np.array([False, True]), scale=np.array([100.0, 1.0]))
    sol = SimpleNamespace(jac=rng.normal(size=(300, 2)), fun=0.1 * rng.normal(size=300), cost=1.5)
    std, _, _, warnings = _confidence(sol, prob, values)
    # one scaled unit is the value itself on the log scale and the scale (100) on the linear one: two independent
    # columns of the same size give the two the same std in scaled units
    assert 0.5 < (std["bristle_stiffness"] / 1e12) / (std["viscous"] / 100.0) < 2.0
    assert not warnings


def test_a_limit_cycle_in_the_drive_force_is_named_when_it_leaves_no_mass(runs):
    """An unstable loop's limit cycle can leave no positive inverse-dynamics mass (a benchmark truth with a delay:
    -162 kg): the refusal names the oscillation, its frequency and share, instead of asking about u's sign;
    the same runs without it are asked about the sign."""
    flipped = [dataclasses.replace(r, u=-r.u) for r in runs]
    cycle = [dataclasses.replace(r, u=r.u + 20 * np.std(r.u) * np.sin(2 * np.pi * 157.0 * r.t)) for r in flipped]
    with pytest.raises(InputError, match=r"^u: got 'a drive force whose inverse-dynamics mass is -") as err:
        idim_start(cycle)
    assert "oscillates at 15" in str(err.value) and f"on {len(runs)} of {len(runs)} runs" in str(err.value)
    assert "is the real loop unstable?" in str(err.value) and "sign of u" not in str(err.value)
    with pytest.raises(InputError, match="is the sign of u or u_gain"):
        idim_start(flipped)
