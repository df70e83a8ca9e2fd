"""Units at the edge of the Drake diagnosis report (drakecreep.report.gap_report)."""

import pytest

from drakecreep.report.gap_report import _edge


def test_parameters_are_shown_in_the_units_feed_drive_engineers_read():
    assert _edge("lead_error_cos", 2.5e-6) == (pytest.approx(2.5), "um")
    assert _edge("lead", 5e-3) == (pytest.approx(5.0), "mm")
    assert _edge("stiffness", 2e8) == (pytest.approx(200.0), "N/um")
    assert _edge("coulomb", 20.0) == (20.0, "N")


def test_the_ranking_json_carries_a_candidate_s_regime_test():
    """A candidate with a regime (the time ripple: constant speed) has its log ratio there in ``ranking.json``;
    one without has no such entry."""
    import math
    from types import SimpleNamespace

    from drakecreep.gap.drake_diagnosis import RankedEffect
    from drakecreep.report.gap_report import ranking_json

    values = {"time_ripple_cos": 0.1, "time_ripple_sin": 0.3, "ripple_frequency": 5.6, "coulomb_asym": 0.0,
              "viscous_asym": 0.0}

    def fit(name):
        return SimpleNamespace(name=name, test_force_error=8.0, train_force_error=7.0, parameters=values, delay=0.0,
                               test_errors={"r0": {"force": 8.0}},
                               seconds=1.0)

    ripple = RankedEffect(fit=fit("time_ripple"), gain=0.4, standard_error=0.1, passes=False, effect="time_ripple", log_ratio=0.06,
                          log_ratio_se=0.02, regime="constant_speed", regime_log_ratio=-0.004,
                          regime_log_ratio_se=0.018, regime_p_sign_flip=0.62)
    asym = RankedEffect(fit=fit("asymmetric_friction"), gain=0.4, standard_error=0.1, passes=False, effect="asymmetric_friction")
    nominal = SimpleNamespace(parameters={"mass": 95.0}, fitted=("mass",), ci95={}, jackknife_std={}, warnings=())
    rows = {r["effect"]: r for r in ranking_json(nominal, {"r0": {"force": 9.0}}, (ripple, asym))["ranking"]}
    assert rows["time_ripple"]["closed_loop"]["regime"] == {
        "name": "constant_speed", "log_error_ratio": -0.004, "log_error_ratio_standard_error": 0.018,
        "sign_flip_p": 0.62}
    assert "regime" not in rows["asymmetric_friction"]["closed_loop"]
    assert math.isnan(asym.regime_log_ratio)


def _ranking(*candidates):
    """``ranking.json``'s rows, by effect, of passing candidates ``(name, RankedEffect fields)`` on a stub nominal."""
    from types import SimpleNamespace

    from drakecreep.gap.drake_diagnosis import RankedEffect
    from drakecreep.gap.drake_effects import DRAKE_EFFECTS
    from drakecreep.report.gap_report import ranking_json

    values = dict.fromkeys([p for name, _ in candidates for p in DRAKE_EFFECTS[name].parameters], 0.1)

    def ranked(name, **kw):
        fit = SimpleNamespace(name=name, test_force_error=8.0, train_force_error=7.0, parameters=values, delay=0.0,
                               test_errors={"r0": {"force": 8.0}},
                              seconds=1.0)
        return RankedEffect(fit=fit, gain=0.4, standard_error=0.1, passes=True, effect=name, **kw)

    nominal = SimpleNamespace(parameters={"mass": 95.0}, fitted=("mass",), ci95={}, jackknife_std={}, warnings=())
    out = ranking_json(nominal, {"r0": {"force": 9.0}}, tuple(ranked(name, **kw) for name, kw in candidates))
    return {r["effect"]: r["closed_loop"] for r in out["ranking"]}


def test_the_ranking_json_carries_the_rule_a_candidate_was_decided_on():
    """``claim_rule`` in ``ranking.json``: ``either`` for a candidate that passes with either held-out test (a
    friction along the travel), the diagnosis's ``CLAIM_RULE`` for the others; ``level_test_alone``: whether the
    level test alone carried the claim."""
    from drakecreep.gap.drake_diagnosis import CLAIM_RULE

    rows = _ranking(("position_friction", {"rule": "either"}), ("stribeck", {"level_alone": True}))
    assert {n: r["claim_rule"] for n, r in rows.items()} == {"position_friction": "either", "stribeck": CLAIM_RULE}
    # whether the level test alone carried it (drift_robust)
    assert {n: r["level_test_alone"] for n, r in rows.items()} == {"position_friction": False, "stribeck": True}


def test_the_ranking_json_says_when_a_candidate_passed_by_its_fallback_regime():
    """``by_fallback_regime``: an asymmetric friction claimed through its constant-speed fallback says so, with
    the regime's numbers; a candidate decided by its rule does not."""
    rows = _ranking(("asymmetric_friction", {"fallback": True, "regime": "constant_speed", "regime_log_ratio": 0.26,
                                             "regime_log_ratio_se": 0.08, "regime_p_sign_flip": 1 / 32}),
                    ("stribeck", {}))
    assert rows["asymmetric_friction"]["by_fallback_regime"] is True
    assert rows["asymmetric_friction"]["regime"]["name"] == "constant_speed"
    assert rows["stribeck"]["by_fallback_regime"] is False and "regime" not in rows["stribeck"]


def test_the_ranking_json_says_when_a_lead_error_passed_by_the_held_out_runs_pieces():
    """``by_pieces`` with the pieces' mean log ratio and sign-flip p: a lead error claimed through its pieces says
    so; a candidate without a piece test has none (NaN, written as null) and ``by_pieces`` false."""
    rows = _ranking(("lead_error", {"pieces": True, "piece_log_ratio": 0.33, "piece_p_sign_flip": 0.001}),
                    ("stribeck", {}))
    assert rows["lead_error"]["by_pieces"] is True
    assert (rows["lead_error"]["piece_log_error_ratio"], rows["lead_error"]["piece_sign_flip_p"]) == (0.33, 0.001)
    assert rows["stribeck"]["by_pieces"] is False and rows["stribeck"]["piece_sign_flip_p"] is None


def test_the_ranking_json_says_where_a_closed_loop_fit_with_two_starts_began():
    """A drive saturation whose screen offered two closed-loop starts: ``ranking.json`` carries the second one
    beside the first, and ``started_from`` says which one its fit came from (``inverse_dynamics`` or
    ``shifted_nominal``; ``nominal`` for a Stribeck, whose first start does not shift the nominal's friction); a
    candidate with one start has neither."""
    from types import SimpleNamespace

    from drakecreep.gap.drake_diagnosis import RankedEffect
    from drakecreep.gap.screen import ScreenResult
    from drakecreep.report.gap_report import ranking_json

    start = {"inverse_drive_limit": 0.016, "viscous": -417.0, "mass": 74.0}
    offered = ScreenResult("drive_saturation", start, 1.0, 1.0, 2.0, 1.0, 0.1, True,
                           alternative_start=dict(start, viscous=122.0))
    rows = _ranking(("drive_saturation", {"screen": offered}), ("stribeck", {}))
    assert rows["drive_saturation"]["started_from"] == "shifted_nominal"  # the stub fit has no start_index: the first
    assert rows["stribeck"]["started_from"] is None
    own = ScreenResult("stribeck", {"stribeck_extra": 20.0}, 1.0, 1.0, 2.0, 1.0, 0.1, True,
                       alternative_start={"stribeck_extra": 20.0, "viscous": 296.0})
    assert _ranking(("stribeck", {"screen": own}))["stribeck"]["started_from"] == "nominal"
    fit = SimpleNamespace(name="drive_saturation", test_force_error=8.0, train_force_error=7.0, start_index=1,
                          test_errors={"r0": {"force": 8.0}},
                          parameters={"inverse_drive_limit": 0.016}, delay=0.0, seconds=1.0)
    ranked = RankedEffect(fit=fit, gain=0.4, standard_error=0.1, passes=True, screen=offered)
    assert ranked.closed_loop_start == "inverse_dynamics"
    nominal = SimpleNamespace(parameters={"mass": 95.0}, fitted=("mass",), ci95={}, jackknife_std={}, warnings=())
    row = ranking_json(nominal, {"r0": {"force": 9.0}}, (ranked,))["ranking"][0]
    assert row["inverse_dynamics"]["alternative_start"]["viscous"] == 122.0
    assert row["closed_loop"]["started_from"] == "inverse_dynamics"


def test_the_ranking_json_shows_which_held_out_runs_carry_a_candidate():
    """Each fitted candidate's force error per held-out run, against the reference it is measured against (its
    equal-effort refit when it has one, else the nominal), with the per-run log ratio, in ``ranking.json`` (the
    page's table: tests/cli/test_diagnose.py). A run the candidate replays better has a positive log ratio."""
    import math
    from types import SimpleNamespace

    from drakecreep.gap.drake_diagnosis import RankedEffect
    from drakecreep.report.gap_report import ranking_json

    def ranked(name, errors, reference=None):
        fit = SimpleNamespace(name=name, test_force_error=8.0, train_force_error=7.0, delay=0.0, seconds=1.0,
                              parameters={"inverse_drive_limit": 0.01, "stribeck_extra": 1.0,
                                          "stribeck_velocity": 0.001},
                              test_errors={k: {"force": v} for k, v in errors.items()})
        return RankedEffect(fit=fit, gain=0.4, standard_error=0.1, passes=False, effect=name,
                            reference_errors=reference)

    nominal_errors = {"run4": {"force": 8.55}, "run7": {"force": 71.1}}
    drive = ranked("drive_saturation", {"run4": 9.35, "run7": 51.8},
                   reference={"run4": {"force": 8.6}, "run7": {"force": 70.0}})
    stribeck = ranked("stribeck", {"run4": 8.0, "run7": 71.1})
    nominal = SimpleNamespace(parameters={"mass": 95.0}, fitted=("mass",), ci95={}, jackknife_std={}, warnings=())
    rows = {r["effect"]: r["closed_loop"]["held_out_force_error_percent_by_run"]
            for r in ranking_json(nominal, nominal_errors, (drive, stribeck))["ranking"]}
    assert rows["drive_saturation"]["run7"] == {"reference": 70.0, "candidate": 51.8,
                                                "log_error_ratio": math.log(70.0 / 51.8)}
    assert rows["drive_saturation"]["run4"]["log_error_ratio"] < 0
    assert rows["stribeck"]["run4"]["reference"] == 8.55  # no refit of its own: the nominal's
    assert rows["stribeck"]["run7"]["log_error_ratio"] == 0.0


def test_the_ranking_json_says_which_failing_candidate_outranked_a_passing_one():
    rows = _ranking(("position_friction", {"outranked_by": "axial_mode"}), ("stribeck", {}))
    assert rows["position_friction"]["outranked_by"] == "axial_mode" and rows["stribeck"]["outranked_by"] is None
