import ast
import math
import pathlib

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.gap import truth as T
from drakecreep.gap.benchmark import (DECLARED_AT, DECLARED_SPREAD, DEV_SEEDS, EXPECTED, EXPECTED_DRIVE, HELDOUT_SEEDS,
                                      benchmark_specs, category_of, declared_params, design, evaluate, expected_of,
                                      generate_dataset, out_and_back, run_benchmark, score_rows,
                                      true_drive_values)


def test_specs_cover_every_effect_and_axis_and_keep_seed_sets_apart():
    specs = benchmark_specs(HELDOUT_SEEDS, n_per_effect=4, tries=2, n_null=3, n_ool=2)
    seeds = [s[0] for s in specs]
    assert len(set(seeds)) == len(seeds)
    dev = {s[0] for s in benchmark_specs(DEV_SEEDS, n_per_effect=10, tries=3, n_null=10, n_ool=10)}
    assert not dev & set(seeds)
    assert {s[2] for s in specs} == {"p_p_cascade"}
    for e in T.LIBRARY_EFFECTS:
        mine = [s for s in specs if s[1] == (e,)]
        assert len(mine) == 8 and {s[3] for s in mine} == set(T.AXES)
    assert sum(1 for s in specs if s[1] == ()) == 3
    for e in T.OUT_OF_LIBRARY + T.NO_CANDIDATE:
        assert sum(1 for s in specs if s[1] == (e,)) == 2


def test_a_run_of_some_library_effects_holds_the_same_datasets_as_the_whole_benchmark():
    kw = dict(n_per_effect=2, tries=2, n_null=3, n_ool=2)
    whole = benchmark_specs(HELDOUT_SEEDS, **kw)
    some = benchmark_specs(HELDOUT_SEEDS, library=("asymmetric_friction",), **kw)
    assert set(some) <= set(whole)
    assert {s for s in whole if s[1] in ((), ("asymmetric_friction",)) or category_of(s[2], s[1]) != "library"} \
        == set(some)
    assert sum(1 for s in some if s[1] == ("asymmetric_friction",)) == 4
    for bad in (("coulomb",), ("cable_carrier",), ()):  # not a library effect (the cable carrier is outside it)
        with pytest.raises(InputError, match="library"):
            benchmark_specs(HELDOUT_SEEDS, library=bad, **kw)


def test_every_library_effect_has_an_expected_drake_candidate():
    from drakecreep.gap.drake_effects import DRAKE_EFFECTS, NOT_RANKED

    assert set(EXPECTED) == set(T.LIBRARY_EFFECTS)
    assert set(EXPECTED.values()) <= set(DRAKE_EFFECTS) | {"control_delay"}
    # the effects the benchmark expects "no claim" for are really outside the ranked candidates
    assert "backlash" in NOT_RANKED and {"load_friction", "drive_saturation", "lead_error"} <= set(DRAKE_EFFECTS)
    assert not (set(T.OUT_OF_LIBRARY) | set(T.NO_CANDIDATE)) & set(DRAKE_EFFECTS)
    assert "backlash" in T.OUT_OF_LIBRARY and EXPECTED["lead_error"] == "lead_error"


def test_the_benchmark_does_not_use_the_former_rigid_diagnosis():
    src = pathlib.Path(__file__).parents[2] / "drakecreep" / "gap" / "benchmark.py"
    names = set()
    for node in ast.walk(ast.parse(src.read_text())):
        if isinstance(node, ast.ImportFrom):
            names.add(node.module)
        elif isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
    assert not names & {"drakecreep.gap.diagnosis", "drakecreep.gap.effects", "drakecreep.gap.replay",
                        "drakecreep.gap.claims"}
    assert "drakecreep.gap.drake_diagnosis" in names


def test_an_unknown_kind_is_refused_before_any_work():
    with pytest.raises(InputError, match="kind"):
        run_benchmark(seed=DEV_SEEDS, kinds=("pid",), n_per_effect=0, n_null=1, n_ool=0)


def test_the_drakecreep_kind_has_its_own_library():
    """Only Stribeck, lead error, the time ripple and the control delay have a default DriveParams candidate; every
    other library effect of the truth is out of that kind's library (asymmetric friction and cogging too: their
    candidates run only when named), and the specs draw it like one (no SNR selection)."""
    from drakecreep.gap.drive_fit import EFFECTS, NOT_IN_MODEL, ON_REQUEST

    assert set(EXPECTED_DRIVE.values()) <= set(EFFECTS)
    for e in T.LIBRARY_EFFECTS:
        lib = category_of("drakecreep", (e,))
        assert lib == ("library" if e in EXPECTED_DRIVE else "out_of_library"), e
        assert category_of("p_p_cascade", (e,)) == "library" and expected_of("p_p_cascade", (e,)) == EXPECTED[e]
        if e not in EXPECTED_DRIVE:
            assert expected_of("drakecreep", (e,)) is None
    assert {"position_friction", "structural_mode", "backlash"} <= set(NOT_IN_MODEL)
    assert {"asymmetric_friction", "cogging"} <= set(ON_REQUEST) and not set(ON_REQUEST) & set(EXPECTED_DRIVE.values())
    assert category_of("drakecreep", ("cogging",)) == "out_of_library"
    assert category_of("drakecreep", ("asymmetric_friction",)) == "out_of_library"
    assert "control_delay" not in NOT_IN_MODEL and expected_of("drakecreep", ("control_delay",)) == "control_delay"
    assert category_of("drakecreep", ()) == "null" and category_of("drakecreep", ("load_friction",)) == "out_of_library"
    specs = benchmark_specs(HELDOUT_SEEDS, kinds=("p_p_cascade", "drakecreep"), n_per_effect=2, tries=2, n_null=1,
                            n_ool=1)
    mine = [s for s in specs if s[2] == "drakecreep"]
    assert sum(1 for s in mine if s[1] == ("stribeck",)) == 4 and sum(1 for s in mine if s[1] == ("cogging",)) == 1
    assert sum(1 for s in specs if s[2] == "p_p_cascade" and s[1] == ("cogging",)) == 4
    assert len({s[0] for s in specs}) == len(specs)
    assert {s[2] for s in benchmark_specs(HELDOUT_SEEDS, n_per_effect=1, n_null=1, n_ool=1)} == {"p_p_cascade"}


def test_declared_params_carry_the_truths_effect_free_physics():
    import math

    from drakecreep.model.nut_friction import nut_friction_levels
    from drakecreep.model.nut_table import table_friction_levels
    from drakecreep.model.screw import axial_damping, axial_stiffness, screw_inertia

    for seed, axis in ((1, "flexible"), (2, "rigid")):
        tr = T.draw_truth(np.random.default_rng(seed), "drakecreep", axis)
        p = declared_params(tr)
        ratio = tr.lead / (2 * math.pi)
        inertia = p.motor.rotor_inertia + p.motor.coupling_inertia + screw_inertia(p.screw)
        assert inertia / ratio ** 2 == pytest.approx(tr.m1, rel=1e-9)
        assert p.table.mass + p.nut.mass == pytest.approx(tr.m2, rel=1e-12)
        assert axial_stiffness(p.screw, p.nut, DECLARED_AT) == pytest.approx(tr.k_axial, rel=1e-9)
        assert axial_damping(p.screw, p.nut, DECLARED_AT) == pytest.approx(tr.c_axial, rel=1e-9)
        for x in (0.0, 0.036, 0.13):  # the runs' travel: the truth's chain is the params file's everywhere
            k, c = tr.chain(x)
            assert axial_stiffness(p.screw, p.nut, x) == pytest.approx(k, rel=1e-9)
            assert axial_damping(p.screw, p.nut, x) == pytest.approx(c, rel=1e-9)
        assert tr.chain(0.0)[0] > 1.1 * tr.k_axial > 1.1 * tr.chain(0.13)[0]  # it softens along the screw
        load = p.load_case(0)
        share = tr.motor_friction_share
        assert table_friction_levels(p, load)[0] == pytest.approx((1 - share) * tr.Fc, rel=1e-9)
        assert nut_friction_levels(p, load)[0] == pytest.approx(share * tr.Fc, rel=1e-9)
        assert p.friction.viscous + p.motor.viscous_damping / ratio ** 2 == pytest.approx(tr.Fv, rel=1e-9)
        assert (p.friction.law, p.friction.bristle_stiffness, p.controller.velocity_gain) == (
            "lugre", tr.sigma0, T._controller_gains(tr)["kv"])
        off = declared_params(tr, np.random.default_rng(0))
        factors = [off.table.seal_force / p.table.seal_force, off.nut.preload_torque / p.nut.preload_torque,
                   off.friction.viscous / p.friction.viscous]
        assert all(f != 1.0 and abs(math.log(f)) < 5 * DECLARED_SPREAD for f in factors), factors
        assert off.table.mass == p.table.mass and off.screw == p.screw


def test_the_truths_effect_goes_into_the_params_file_field_by_field():
    """Three drakecreep-kind library effects onto the fields their candidates fit, with the truth's values; none for
    Stribeck (its drop needs the levels refitted), a null, an effect without a DriveParams candidate or two."""
    rng = np.random.default_rng
    assert set(EXPECTED_DRIVE) == {"lead_error", "stribeck", "time_ripple", "control_delay"}
    for seed, effect in enumerate(EXPECTED_DRIVE):
        tr = T.draw_truth(rng(DEV_SEEDS + seed), "drakecreep", "flexible", (effect,))
        e, v = tr.effects[effect], true_drive_values(tr)
        if effect == "lead_error":
            assert v["disturbance.lead_error_period"] == tr.lead
            assert v["disturbance.lead_error_2_amplitude"] == pytest.approx(e["h2"] * e["amplitude_m"], rel=1e-15)
            assert (v["disturbance.lead_error_amplitude"], v["disturbance.lead_error_phase"],
                    v["disturbance.lead_error_2_phase"]) == (e["amplitude_m"], e["phase"], e["phase2"])
        elif effect == "stribeck":
            assert v is None
        elif effect == "time_ripple":
            assert v == {"disturbance.force_ripple": e["amplitude_N"], "disturbance.ripple_frequency": e["freq_Hz"],
                         "disturbance.ripple_phase": e["phase"]}
        else:
            assert v == {"controller.computation_delay": 4.0 * e["delay_samples"]} and T.VEL_DIV == 4
    for withheld in ((), ("cogging",), ("backlash",), ("lead_error", "time_ripple")):
        assert true_drive_values(T.draw_truth(rng(DEV_SEEDS), "drakecreep", "rigid", withheld)) is None


@pytest.mark.parametrize("effect, error", [("lead_error", "transmission"), ("time_ripple", "force")])
def test_the_truths_own_values_shrink_its_audit_replay(effect, error):
    """The truth's values in its exact params file (no friction factor) make the audit replay closer: the lead
    error's phases and the ripple's sign are the truth's. A sign or a phase off would make the error grow."""
    from drakecreep.gap.drake_replay import drake_replay_errors, replay_drakecreep
    from drakecreep.gap.drive_fit import _with

    ds = generate_dataset(DEV_SEEDS + 7, withheld=(effect,), kind="drakecreep", axis="rigid", n_samples=1500)
    exact = declared_params(ds.truth)
    true = _with(exact, true_drive_values(ds.truth))

    def energy(params):
        return np.mean([drake_replay_errors(replay_drakecreep(r, params))[error] ** 2 for r in ds.audit])

    without, with_truth = energy(exact), energy(true)
    assert with_truth < 0.5 * without, (without, with_truth)


def test_a_drakecreep_rows_true_shrink_is_the_truths_values_in_the_nominal_params_file(monkeypatch):
    """The audit of a library dataset replays the nominal params file with the truth's values of its effect (a
    stand-in diagnosis that claims nothing, so the row's own audit shrink is 0); not where the runs oscillate."""
    from types import SimpleNamespace

    from drakecreep.gap import benchmark, drive_fit

    ds = generate_dataset(DEV_SEEDS + 7, withheld=("time_ripple",), kind="drakecreep", axis="rigid", n_samples=600)
    nominal = ds.train[0].meta.params

    def diagnosis(train, test, progress=False, **kw):
        return SimpleNamespace(claimed=(), nominal_test_errors={r.label: {"force": 10.0, "force_lowpass": 5.0}
                                                                for r in test}, candidates=(),
                               params=nominal, nominal=nominal, replay_null=0.01, transmission_null=None,
                               null_test_force=[], null_test_force_lowpass=[], train_sse=1.0, train_variance=1.0,
                               test_errors={}, seconds=0.0, warnings=(), oscillation=oscillation, where={}, fitted=())

    monkeypatch.setattr(drive_fit, "diagnose_drive", diagnosis)
    oscillation = None
    row = benchmark._evaluate_drive(ds)
    assert row["expected"] == "force_ripple" and row["audit_shrink"] == 0.0
    assert row["audit"]["true"]["energy"] < row["audit"]["nominal"]["energy"] and 0 < row["true_shrink"] < 1
    oscillation = {"freq_Hz": 60.0}
    row = benchmark._evaluate_drive(ds)
    assert "true" not in row["audit"] and row["true_shrink"] is None


def test_a_mass_spread_puts_the_declared_table_mass_off_and_nothing_else():
    """``mass_spread``: the drakecreep kind's params file declares the table mass off by a factor drawn from the
    seed on its own stream, so the runs and the friction levels declared are those of the exact file; the row says
    the factor; the p_p_cascade kind, which has no params file, is left as it is; bad spreads are refused."""
    from drakecreep.gap import benchmark

    exact = generate_dataset(DEV_SEEDS + 5, withheld=(), kind="drakecreep", axis="rigid", n_samples=600)
    off = generate_dataset(DEV_SEEDS + 5, withheld=(), kind="drakecreep", axis="rigid", n_samples=600,
                           mass_spread=0.15)
    assert exact.mass_factor == 1.0 and off.mass_factor != 1.0 and abs(math.log(off.mass_factor)) < 5 * 0.15
    p0, p1 = exact.train[0].meta.params, off.train[0].meta.params
    assert p1.table.mass == pytest.approx(off.mass_factor * p0.table.mass, rel=1e-12)
    assert p1.table.seal_force == p0.table.seal_force and p1.friction.viscous == p0.friction.viscous
    assert p1.nut.preload_torque == p0.nut.preload_torque and p1.motor.rotor_inertia == p0.motor.rotor_inertia
    for a, b in zip(exact.train + exact.test + exact.audit, off.train + off.test + off.audit):
        assert np.array_equal(a.force, b.force) and b.meta.params is p1
    assert benchmark._row(off, [], [])["mass_factor"] == off.mass_factor
    again = generate_dataset(DEV_SEEDS + 5, withheld=(), kind="drakecreep", axis="rigid", n_samples=600,
                             mass_spread=0.15)
    assert again.mass_factor == off.mass_factor  # drawn from the seed
    pp = generate_dataset(DEV_SEEDS + 5, withheld=(), kind="p_p_cascade", axis="rigid", n_samples=600,
                          mass_spread=0.15)
    assert pp.mass_factor == 1.0 and "mass_factor" not in benchmark._row(pp, [], [])
    for bad in (-0.1, 0.6, math.nan, "x", True):
        with pytest.raises(InputError, match="^mass_spread: got .*; allowed: a number in"):
            benchmark.check_mass_spread(bad)
    with pytest.raises(InputError, match="allowed: 0 unless kinds include drakecreep"):
        run_benchmark(kinds=("p_p_cascade",), mass_spread=0.15, n_per_effect=0, n_null=1, n_ool=0)


def test_a_drakecreep_dataset_is_diagnosed_by_diagnose_drive_and_audited():
    """One short null of the drakecreep kind (two cheap candidates and one uncertain field, to stay fast: 42 s
    against 100-114 s with the three default fields, session 65): the runs carry the declared params file, the row
    has the drive diagnosis's ranking and the audit replays of the fitted params file."""
    ds = generate_dataset(DEV_SEEDS + 5, withheld=(), kind="drakecreep", axis="rigid", n_samples=600)
    assert all(r.meta.params is not None and r.meta.params.table.mass > 0 for r in ds.train + ds.test + ds.audit)
    row = evaluate(ds, effects=("force_ripple", "nut_friction_side"), uncertain=("table.seal_force",))
    assert row["kind"] == "drakecreep" and row["category"] == "null" and row["expected"] is None
    ranked = {r["effect"]: r for r in row["ranking"]}
    assert set(ranked) == {"force_ripple", "nut_friction_side"}
    # the held-out runs' force errors, nominal and candidate, from which the ranking's gain is recounted (the
    # switch is always replayed; the ripple of a null has no line to fit)
    nominal, switched = row["test_force_nominal_runs"], ranked["nut_friction_side"]["test_force_runs"]
    assert len(switched) == len(nominal) == len(ds.test)
    assert np.mean(np.subtract(nominal, switched)) == pytest.approx(ranked["nut_friction_side"]["gain"], abs=1e-9)
    ripple = ranked["force_ripple"]["test_force_runs"]
    assert ripple is None or len(ripple) == len(ds.test)
    assert ranked["nut_friction_side"]["values"] == {"friction.nut_friction_on": "table"}  # the params file's: screw
    # the run-to-run null run by run: each leave-one-out refit's held-out errors, whose largest pooled change is
    # the null; and the training fit's SSE and variance, a candidate's chi-square statistic
    null_runs = row["null_test_force_runs"]
    assert len(null_runs) == len(ds.train) and all(len(r) == len(ds.test) for r in null_runs)
    e_nom = np.sum(np.square(nominal))
    assert max(abs(1 - np.sum(np.square(r)) / e_nom) for r in null_runs) == pytest.approx(row["replay_null"], rel=1e-9)
    assert row["train_sse"] > 0 and row["train_variance"] > 0
    # the same below 100 Hz (docs 3ce), for a recount there: the nominal's, each candidate's and each refit's
    low = row["test_force_lowpass_nominal_runs"]
    assert len(low) == len(nominal) and all(0 < a <= b for a, b in zip(low, nominal))
    assert len(ranked["nut_friction_side"]["test_force_lowpass_runs"]) == len(ds.test)
    assert [len(r) for r in row["null_test_force_lowpass_runs"]] == [len(r) for r in null_runs]
    assert row["uncertain"] == ["table.seal_force"] and set(row["claimed_model"]["fitted"]) == {"table.seal_force"}
    assert row["audit"]["nominal"]["force_rms"] > 0 and row["true_shrink"] is None
    # beside the scored figure, its part below 100 Hz (docs 3ce), which an encoder-count ripple hardly reaches
    assert 0 < row["audit"]["nominal"]["force_lowpass_rms"] <= row["audit"]["nominal"]["force_rms"]
    assert row["oscillation"] is None and "audit_oscillation_nepers" not in row  # a stable null: no spectral audit
    # where the diagnosis located what it left unexplained on the held-out runs
    assert row["where"]["force_rms_N"] > 0 and sum(row["where"]["bands"].values()) == pytest.approx(1.0)
    assert row["worse"] is (bool(row["claimed"]) and row["audit"]["claimed"]["energy"] > row["audit"]["nominal"]["energy"])


def test_design_cycles_through_slots():
    n = len(T.LIBRARY_EFFECTS) + len(T.NO_CANDIDATE) + len(T.OUT_OF_LIBRARY)
    got = [design(i)[0] for i in range(n + 2)]
    assert got[: len(T.LIBRARY_EFFECTS)] == [(e,) for e in T.LIBRARY_EFFECTS] and got[n:] == [(), ()]


def test_out_and_back_returns_home():
    x = out_and_back(0.05, 0.01)
    assert x[0] == pytest.approx(0.01) and x[-1] == pytest.approx(0.01, abs=1e-12)
    assert np.max(np.gradient(x, 1e-3)) == pytest.approx(0.05, rel=1e-3)


def _row(w, snr, claimed, shrink=None, true=None, worse=False, axis="rigid"):
    w = list(w)
    if not w:
        cat = "null"
    elif w[0] in T.LIBRARY_EFFECTS:
        cat = "library"
    else:
        cat = "no_candidate" if w[0] in T.NO_CANDIDATE else "out_of_library"
    return {"withheld": w, "expected": EXPECTED.get(w[0]) if w else None, "category": cat, "kind": "p_p_cascade",
            "axis": axis, "snr": snr, "claimed": claimed, "audit_shrink": shrink, "true_shrink": true, "worse": worse}


def test_score_rows():
    rows = [_row(["cogging"], 5.0, ["position_ripple"], shrink=0.8, true=0.9),
            _row(["stribeck"], 4.0, ["thermal_drift"], shrink=-0.1, true=0.5, worse=True, axis="flexible"),
            _row(["stribeck"], 1.0, []),
            _row([], 0.0, []), _row([], 0.0, ["stribeck"]),
            _row(["cable_carrier"], 4.0, []), _row(["cable_carrier"], 2.0, ["position_friction"]),
            dict(_row(["cable_carrier"], 6.0, []), category="no_candidate")]
    s = score_rows(rows)
    assert s["top1_snr3"] == {"rate": 0.5, "n": 2}
    assert s["top1_all"] == {"rate": pytest.approx(1 / 3), "n": 3}
    assert s["claims_on_nulls"] == {"rate": 0.5, "n": 2}
    assert s["out_of_library_unexplained"] == {"rate": 0.5, "n": 2}
    assert s["no_candidate_unclaimed"] == {"rate": 1.0, "n": 1}
    assert s["median_relative_shrink_snr3"] == pytest.approx(0.5 * (0.8 / 0.9 - 0.2))
    assert s["claims_making_audit_worse"] == 1 and s["n_claims"] == 4
    assert s["wrong_claims"] == 3  # thermal_drift for stribeck, a null's claim, an out-of-library claim
    assert s["per_effect"]["stribeck"]["n"] == 2 and s["per_effect"]["stribeck"]["n_scored"] == 1
    assert s["per_effect"]["cogging"]["expected"] == "position_ripple"
    assert s["per_axis"]["flexible"]["top1_snr3"] == {"rate": 0.0, "n": 1}


def _dataset(seed, withheld, effects, n=1000):
    """A short development dataset whose withheld effect has the given parameters (not drawn)."""
    from drakecreep.gap.benchmark import N_AUDIT, N_TEST, N_TRAIN, Dataset, snr

    rng = np.random.default_rng(seed)
    tr = T.draw_truth(rng, "p_p_cascade", "rigid", withheld)
    tr.effects.update(effects)
    n_runs = N_TRAIN + N_TEST + N_AUDIT
    refs, pulses, _ = T.draw_profiles(rng, n_runs, n=n)
    drift, noise = T.noise_draws(tr, n_runs, n, rng)
    sim, twin = T.simulate_batch([(tr, refs, pulses, drift, noise, True), (tr, refs, pulses, drift, noise, False)])
    runs = T.make_runs(tr, refs, pulses, sim)
    i, j = N_TRAIN, N_TRAIN + N_TEST
    ds = Dataset(seed=seed, withheld=withheld, truth=tr, train=runs[:i], test=runs[i:j], audit=runs[j:])
    if withheld:
        ds.twin_train = T.make_runs(tr, refs[:i], pulses[:i], {k: v[:i] for k, v in twin.items()})
        ds.snr = snr(ds.train, ds.twin_train)
    return ds


def test_diagnose_drake_end_to_end_on_a_strong_effect():
    """Through the product diagnosis with one candidate (position_ripple) on 0.7 s runs: a 10 N cogging force
    (motor order 1) is claimed as position_ripple and shrinks the audit replay (runs the diagnosis never saw) as
    much as the true effect's fit (it is that fit). The rates over all candidates are the benchmark's business
    (docs/gap_benchmark.md); this checks the mechanism, with at most 3 evaluations per least-squares fit (the
    benchmark's 6 gave audit force RMS 16.2 -> 3.1 N in 57-63 s on an idle core, most of it the nominal
    identification's replays; 3 give 16.1 -> 3.4 N in 33 s, session 67; SNR 3.8). The null, which claims nothing
    and leaves the audit as the nominal's, is tests/cli/test_gap_benchmark.py's, through the command."""
    from drakecreep.gap.benchmark import evaluate

    ds = _dataset(DEV_SEEDS + 2200, ("cogging",), {"cogging": {"amplitude_N": 10.0, "order": 1, "phase": 0.5, "h2": 0.0}},
                  n=700)
    assert ds.snr >= 3
    row = evaluate(ds, effects=("position_ripple",), max_nfev=3)
    assert row["expected"] == "position_ripple" and row["claimed"] == ["position_ripple"]
    assert row["audit_shrink"] > 0.3 and not row["worse"]
    assert row["true_shrink"] == pytest.approx(row["audit_shrink"])
    assert row["where"]["force_rms_N"] > 0 and row["where"]["order"]["cycle_m"] == pytest.approx(1e-2)
    # the per-run log ratios the rows carry are the ones the claim's statistic is made of
    ranked = row["ranking"][0]
    for key, runs in (("log_error_ratio", "run_log_error_ratios"), ("level_log_error_ratio", "run_level_log_error_ratios")):
        assert len(ranked[runs]) == len(ds.test) and np.mean(ranked[runs]) == pytest.approx(ranked[key])
        assert np.std(ranked[runs], ddof=1) / np.sqrt(len(ds.test)) == pytest.approx(ranked[key + "_standard_error"])
    # and so are the training-run null's signed moves, one per training run, the null their largest size
    assert len(row["training_run_moves"]) == len(ds.train)
    assert row["training_run_null"] == pytest.approx([max(abs(m[i]) for m in row["training_run_moves"]) for i in (0, 1)])
    # and the candidate's own model's moves (its fit's jackknife), for a null of its own counted on the rows
    assert len(ranked["own_training_run_moves"]) == len(ds.train)
    assert all(len(m) == 2 and all(np.isfinite(m)) for m in ranked["own_training_run_moves"])


def test_a_resumed_run_keeps_the_earlier_rows_and_diagnoses_only_the_rest(monkeypatch):
    from drakecreep.gap import benchmark

    seen = []

    def fake_evaluate(ds, **kwargs):
        seen.append(ds.seed)
        return {"seed": ds.seed, "withheld": list(ds.withheld), "claimed": [], "seconds": 0.0}

    monkeypatch.setattr(benchmark, "evaluate", fake_evaluate)
    monkeypatch.setattr(benchmark, "score_rows", lambda rows: {"n_datasets": len(rows)})
    first = run_benchmark(seed=DEV_SEEDS, n_per_effect=0, n_null=3, n_ool=0, n_no_candidate=0, audit=False,
                          n_samples=300)
    assert len(first["datasets"]) == 3 and len(seen) == 3
    earlier = [dict(first["datasets"][0], marker="earlier")]
    seen.clear()
    again = run_benchmark(seed=DEV_SEEDS, n_per_effect=0, n_null=3, n_ool=0, n_no_candidate=0, audit=False,
                          n_samples=300, done=earlier)
    assert earlier[0]["seed"] not in seen and len(seen) == 2
    assert [r["seed"] for r in again["datasets"]] == [r["seed"] for r in first["datasets"]]
    assert again["datasets"][0]["marker"] == "earlier"


def test_each_drakecreep_diagnosis_keeps_its_steps_in_the_checkpoint_folder_until_its_row_is_written(
        monkeypatch, tmp_path):
    """``checkpoints``: each dataset's diagnosis gets ``<folder>/<seed>.pkl`` (``diagnose_drive``'s checkpoint,
    tests/gap/test_checkpoint.py), removed once ``on_row`` has the row; a file in the folder's place is refused
    before any dataset is generated."""
    from types import SimpleNamespace

    from drakecreep.gap import benchmark, drive_fit

    folder, given, present = tmp_path / "ckpt", [], []

    def fake_evaluate(ds, **kw):
        given.append(kw["checkpoint"])
        kw["checkpoint"].write_bytes(b"steps")
        return {"seed": ds.seed, "withheld": [], "claimed": [], "seconds": 0.0}

    monkeypatch.setattr(benchmark, "evaluate", fake_evaluate)
    monkeypatch.setattr(benchmark, "score_rows", lambda rows: {"n_datasets": len(rows)})
    kw = dict(seed=DEV_SEEDS, kinds=("drakecreep",), n_per_effect=0, n_null=2, n_ool=0, n_no_candidate=0,
              audit=False, n_samples=300)
    rows = run_benchmark(checkpoints=folder, on_row=lambda row, rows: present.append(
        (folder / f"{row['seed']}.pkl").exists()), **kw)["datasets"]
    assert given == [folder / f"{r['seed']}.pkl" for r in rows] and present == [True, True]
    assert list(folder.iterdir()) == []
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="checkpoints"):
        run_benchmark(checkpoints=tmp_path / "file", **kw)
    monkeypatch.undo()

    class Stop(Exception):
        pass

    def fake(train, test, **kwargs):
        given.append(kwargs["checkpoint"])
        raise Stop

    monkeypatch.setattr(drive_fit, "diagnose_drive", fake)
    with pytest.raises(Stop):
        benchmark.evaluate(SimpleNamespace(kind="drakecreep", train=[], test=[]), checkpoint=folder / "1.pkl")
    assert given[-1] == folder / "1.pkl"


def test_skipped_seeds_are_neither_generated_nor_diagnosed(monkeypatch):
    """A development study's fresh datasets: the seeds an earlier study looked at are left out, a library
    effect's next dataset with SNR >= 3 takes a skipped one's place, and the next null a skipped null's."""
    from drakecreep.gap import benchmark

    monkeypatch.setattr(benchmark, "evaluate", lambda ds, **kw: {"seed": ds.seed, "withheld": list(ds.withheld),
                                                                 "claimed": [], "seconds": 0.0})
    monkeypatch.setattr(benchmark, "score_rows", lambda rows: {"n_datasets": len(rows)})
    kw = dict(seed=DEV_SEEDS, kinds=("p_p_cascade",), n_per_effect=2, n_null=3, n_ool=0, n_no_candidate=0,
              audit=False, tries=6, library=["time_ripple"], n_samples=1500)  # 1.5 s runs: 9 s, not 26
    whole = run_benchmark(**kw)["datasets"]
    nulls = [r["seed"] for r in whole if not r["withheld"]]
    ripples = [r["seed"] for r in whole if r["withheld"]]
    assert len(nulls) == 3 and len(ripples) == 2
    fresh = run_benchmark(skip=[nulls[0], ripples[0]], **kw)["datasets"]
    fresh_nulls = sorted(r["seed"] for r in fresh if not r["withheld"])
    assert len(fresh_nulls) == 3 and fresh_nulls[:2] == sorted(nulls[1:]) and fresh_nulls[2] == max(nulls) + 1
    # every null skipped (session 61's run drew none of --n-null 4 this way): the next three in their place
    after = run_benchmark(skip=nulls, **dict(kw, library=None, n_per_effect=0))["datasets"]
    assert sorted(r["seed"] for r in after) == [max(nulls) + k for k in (1, 2, 3)]
    again = [r["seed"] for r in fresh if r["withheld"]]
    assert len(again) == 2 and ripples[0] not in again and ripples[1] in again  # the next one took its place


def test_shards_split_one_run_without_overlap(monkeypatch):
    from drakecreep.gap import benchmark

    monkeypatch.setattr(benchmark, "evaluate", lambda ds, **kw: {"seed": ds.seed, "withheld": [], "claimed": [], "seconds": 0.0})
    monkeypatch.setattr(benchmark, "score_rows", lambda rows: {"n_datasets": len(rows)})
    kw = dict(seed=DEV_SEEDS, n_per_effect=0, n_null=5, n_ool=0, n_no_candidate=0, audit=False, n_samples=300)
    whole = [r["seed"] for r in run_benchmark(**kw)["datasets"]]
    parts = [[r["seed"] for r in run_benchmark(shard=(i, 2), **kw)["datasets"]] for i in (0, 1)]
    assert len(whole) == 5 and parts[0] == whole[0::2] and parts[1] == whole[1::2]
    with pytest.raises(InputError, match="shard"):
        run_benchmark(shard=(2, 2), **kw)


def test_the_drakecreep_kinds_nominal_may_fit_other_fields_for_a_development_study(monkeypatch):
    """``uncertain`` reaches ``diagnose_drive`` on every dataset of the run (a study of another nominal, such as one
    with ``loads.constant_force``), and is refused before any dataset with a ``p_p_cascade`` kind or a field the
    fit cannot take."""
    from types import SimpleNamespace

    from drakecreep.gap import benchmark, drive_fit

    seen = []
    monkeypatch.setattr(benchmark, "evaluate", lambda ds, **kw: seen.append(kw["uncertain"]) or
                        {"seed": ds.seed, "withheld": [], "claimed": [], "seconds": 0.0})
    monkeypatch.setattr(benchmark, "score_rows", lambda rows: {"n_datasets": len(rows)})
    kw = dict(seed=DEV_SEEDS, kinds=("drakecreep",), n_per_effect=0, n_null=2, n_ool=0, n_no_candidate=0,
              audit=False, n_samples=300)
    paths = ("table.seal_force", "loads.constant_force")
    run_benchmark(uncertain=list(paths), **kw)
    assert seen == [paths, paths]
    for kinds, bad, fragment in ((("p_p_cascade",), paths, "drakecreep alone"), (("drakecreep",), ("table.colour",), "fields among"),
                                 (("drakecreep",), paths[:1] * 2, "distinct")):
        with pytest.raises(InputError, match=fragment):
            run_benchmark(**dict(kw, kinds=kinds), uncertain=bad)
    monkeypatch.undo()

    class Stop(Exception):
        pass

    def fake(train, test, **kwargs):
        seen.append(kwargs.get("uncertain"))
        raise Stop

    monkeypatch.setattr(drive_fit, "diagnose_drive", fake)
    ds = SimpleNamespace(kind="drakecreep", train=[], test=[])
    for given in (paths, None):
        with pytest.raises(Stop):
            benchmark.evaluate(ds, uncertain=given)
    assert seen[-2:] == [paths, None]  # None: diagnose_drive's own default


def test_a_study_names_a_dataset_by_seed_withheld_effect_and_axis():
    """``SEED:WITHHELD:AXIS`` (the development studies' datasets): ``null`` for none; a bad part is named."""
    from drakecreep.gap.benchmark import dataset_spec

    assert dataset_spec("29003009:lead_error:rigid") == (29003009, ("lead_error",), "rigid")
    assert dataset_spec("45013000:null:flexible") == (45013000, (), "flexible")
    for bad, field in (("29003009:lead_error", "dataset"), ("x1:null:rigid", "dataset"), ("1:nope:rigid", "withheld"),
                       ("1:null:wobbly", "axis"), ("-1:null:rigid", "dataset")):
        with pytest.raises(InputError, match=field):
            dataset_spec(bad)


def test_snr_survives_runs_without_a_positive_inverse_dynamics_mass():
    """A withheld effect that leaves the runs no positive IDIM mass (an unstable delay's limit cycle; here the
    drive force reversed) gets the twin's mass instead of ending the benchmark: a large SNR, the same as with the
    twin's mass given by hand, while a dataset whose runs have a mass keeps its own."""
    import dataclasses

    from drakecreep.gap.benchmark import _idim_energy, snr
    from drakecreep.gap.identify import idim_start

    ds = _dataset(DEV_SEEDS + 7, ("time_ripple",), {})
    flipped = [dataclasses.replace(r, u=-r.u) for r in ds.train]
    with pytest.raises(InputError, match="inverse-dynamics mass"):
        idim_start(flipped)
    m_twin = idim_start(ds.twin_train).parameters["mass"]
    value = snr(flipped, ds.twin_train)
    assert value == pytest.approx(math.sqrt(_idim_energy(flipped, m_twin) / _idim_energy(ds.twin_train, m_twin) - 1))
    assert value > 10 * max(ds.snr, 1.0)
    m_own = idim_start(ds.train).parameters["mass"]
    assert ds.snr == pytest.approx(math.sqrt(max(_idim_energy(ds.train, m_own)
                                                 / _idim_energy(ds.twin_train, m_twin) - 1, 0)))
