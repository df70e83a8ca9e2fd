"""Effects switched into the Drake replay model (drakecreep.gap.drake_effects) on runs with a known truth."""

import dataclasses

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.gap.drake_effects import DRAKE_EFFECTS, NOT_RANKED, fit_effect, residual_peak_frequency
from drakecreep.gap.drake_replay import DrakeReplay, axis_from_idim
from drakecreep.gap.identify import identify
from drakecreep.gap.idim import PUBLISHED_IDIM
from drakecreep.gap.measured import load_emps

NOMINAL = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3)


def _runs(truth, starts=(0, 5000, 10000, 15000), n=1200):
    full = load_emps("estimation").runs[0]
    out = []
    for seed, a in enumerate(starts):
        run = full.slice(a, a + n)
        res = DrakeReplay(run).simulate(truth)
        u = res.u + np.random.default_rng(seed).normal(0.0, 0.5 / run.u_gain, res.u.size)
        out.append(dataclasses.replace(run, x_motor=res.x_motor, u=u, label=f"w{a}"))
    return out


def test_a_time_ripple_is_found_at_its_frequency_and_shrinks_the_held_out_replay():
    truth = dict(NOMINAL, time_ripple_cos=6.0, time_ripple_sin=-3.0, ripple_frequency=37.0)
    runs = _runs(truth)
    train, test = runs[0::2], runs[1::2]
    nominal = identify(train, (), fixed={"regularization_velocity": 1e-3})
    assert abs(residual_peak_frequency(train, nominal.parameters) - 37.0) < 1.0
    fit = fit_effect("time_ripple", train, test, nominal, max_nfev=12, refit=())
    assert abs(fit.parameters["ripple_frequency"] - 37.0) < 0.2
    assert abs(fit.parameters["time_ripple_cos"] - 6.0) < 1.0
    assert abs(fit.parameters["time_ripple_sin"] + 3.0) < 1.0
    from drakecreep.gap.drake_effects import score_parameters

    _, nominal_test = score_parameters(test, nominal.parameters)
    assert fit.test_force_error < 0.8 * nominal_test


def test_a_fit_that_chooses_its_start_fits_from_the_one_with_the_lower_training_error():
    """``best_start_index`` picks the parameters whose fixed replay of the runs has the lower force error (the axis's own
    against a viscous friction 3 times too large; a start whose replay fails counts as worst), and
    ``fit_effect(choose=True)`` fits from only that start: the same fit as from the good start alone, not the one
    from the bad start alone."""
    from drakecreep.gap.drake_effects import best_start_index

    truth = dict(NOMINAL, inverse_drive_limit=1.0 / 60.0)
    runs = _runs(truth, starts=(0, 5000, 10000), n=800)
    train, test = runs[:2], runs[2:]
    bad = dict(truth, viscous=3.0 * truth["viscous"])
    assert best_start_index(train, [bad, truth]) == 1
    assert best_start_index(train, [dict(truth, mass=-1.0), bad]) == 1
    nominal = identify(train, (), fixed=dict(NOMINAL, regularization_velocity=1e-3))
    good_start = {"inverse_drive_limit": 1.0 / 60.0, "viscous": truth["viscous"]}
    bad_start = {"inverse_drive_limit": 1.0 / 60.0, "viscous": 3.0 * truth["viscous"]}
    kw = dict(max_nfev=2, refit=("viscous",))
    chosen = fit_effect("drive_saturation", train, test, nominal, starts=(bad_start, good_start), choose=True, **kw)
    good = fit_effect("drive_saturation", train, test, nominal, starts=(good_start,), **kw)
    worse = fit_effect("drive_saturation", train, test, nominal, starts=(bad_start,), **kw)
    assert chosen.parameters == good.parameters and chosen.start_index == 1
    assert chosen.parameters != worse.parameters


def test_a_position_ripple_with_a_second_harmonic_is_fitted_in_closed_loop():
    """A cogging-like ripple (3 N at 3.7 mm, 1.2 N at its second harmonic): from the screen's start the
    closed-loop fit gets both harmonics, and the held-out replay is better in every run than with the first
    harmonic alone (the candidate before docs/gap_benchmark.md 3as)."""
    from drakecreep.gap.screen import screen_effect

    truth = dict(NOMINAL, position_ripple_sin=3.0, position_ripple_2_cos=1.2, position_period=3.7e-3)
    runs = _runs(truth)
    train, test = runs[0::2], runs[1::2]
    nominal = identify(train, (), fixed={"regularization_velocity": 1e-3})
    effect = DRAKE_EFFECTS["position_ripple"]
    start = screen_effect(effect, train, test, nominal.parameters).start
    both = fit_effect(effect, train, test, nominal, starts=(start,), max_nfev=12, refit=())
    p = both.parameters
    assert p["position_period"] == pytest.approx(3.7e-3, rel=1e-3)
    assert abs(complex(p["position_ripple_cos"], p["position_ripple_sin"]) - 3.0j) < 0.1 * 3.0
    assert abs(complex(p["position_ripple_2_cos"], p["position_ripple_2_sin"]) - 1.2) < 0.1 * 1.2
    def first_harmonic(names):
        return [n for n in names if not n.startswith("position_ripple_2_")]

    first = dataclasses.replace(effect, parameters=tuple(first_harmonic(effect.parameters)))
    one = fit_effect(first, train, test, nominal, starts=({k: start[k] for k in first_harmonic(start)},),
                     max_nfev=12, refit=())
    for run in both.test_errors:
        assert both.test_errors[run]["force"] < one.test_errors[run]["force"], run


def test_effects_outside_the_replay_axis_are_refused_not_ranked():
    assert not set(NOT_RANKED) & set(DRAKE_EFFECTS)
    with pytest.raises(InputError, match="backlash"):
        fit_effect("backlash", [], [], None)
    with pytest.raises(InputError, match="effect"):
        fit_effect("nonsense", [], [], None)


def test_compiled_axis_carries_every_effect_term():
    run = load_emps("estimation").runs[0].slice(0, 400)
    p = dict(NOMINAL, stribeck_extra=3.0, stribeck_velocity=5e-3, coulomb_asym=1.5, viscous_asym=-20.0,
             friction_ripple_cos=0.1, friction_period=0.05, friction_map_1=0.1, friction_map_2=-0.05,
             friction_map_start=run.x_motor.min(), friction_map_end=run.x_motor.max() + 0.01, position_ripple_sin=2.0,
             position_ripple_2_cos=0.7, time_ripple_cos=3.0, ripple_frequency=40.0, friction_drift=0.01)
    for flexible in (False, True):
        p2 = dict(p, stiffness=3e6, damping=300.0) if flexible else p
        a = DrakeReplay(run, flexible=flexible).simulate(p2)
        b = DrakeReplay(run, flexible=flexible, compiled=False).simulate(p2)
        c = DrakeReplay(run, flexible=flexible).simulate(dict(NOMINAL, stiffness=3e6, damping=300.0))
        assert np.max(np.abs(a.x_motor - b.x_motor)) < 1e-9
        assert np.max(np.abs(a.u - c.u)) > 1e-3  # the terms act


def test_a_fitted_axial_mode_resolves_to_the_band_around_its_own_frequency():
    """``axial_mode_frequency`` inverts the start's ``k = w^2 s (1 - s) m``; ``effect_regime`` gives an axial mode
    the band around that frequency, the time ripple its constant speed, the others none."""
    import math

    from drakecreep.gap.drake_effects import axial_mode_frequency, effect_regime

    m, s = 90.0, 0.3
    k = (2 * math.pi * 75.0) ** 2 * s * (1 - s) * m
    p = {"mass": m, "motor_mass_fraction": s, "stiffness": k, "damping": 2 * 0.04 * math.sqrt(k * s * (1 - s) * m)}
    assert axial_mode_frequency(p) == pytest.approx((75.0, 0.04))
    assert DRAKE_EFFECTS["axial_mode"].regime == "mode_band"
    assert effect_regime("axial_mode", p) == "band_56.6-113_Hz"
    assert effect_regime("axial_mode", dict(p, stiffness=k / 4)) == "band_28.3-56.6_Hz"  # half the frequency
    assert effect_regime("time_ripple", p) == "constant_speed"
    assert effect_regime("stribeck", p) == effect_regime("control_delay", p) == ""
