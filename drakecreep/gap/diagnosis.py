"""Sim-to-real gap diagnosis: where the gap lies, which unmodelled effect explains it, how far it shrinks.

Pipeline (:func:`diagnose`):

1. **Nominal**: the rigid IDIM model (:mod:`drakecreep.gap.idim`) fitted by least squares on the training
   runs only.
2. **Where**: closed-loop replay of the nominal on the held-out runs
   (:func:`drakecreep.gap.effects.replay_with_effects`); speed, position and force residuals decomposed by
   time regime, by order against screw / motor angle and table position, by operating map
   (:mod:`drakecreep.gap.residuals`); whiteness of the inverse-dynamics residual.
3. **Which**: every identifiable effect of :data:`drakecreep.gap.effects.EFFECTS` (one that adds a
   regressor; quantization does not and is never ranked) is refitted with the nominal friction (linear
   least squares on the inverse-dynamics residual, the nonlinear parameter on a grid) on the training
   runs, then scored on the held-out runs with the parameters fixed and ranked by the penalized held-out
   log-likelihood ``n_eff ln(SSE_eff / SSE_nom) + k ln(n_train)``. The best-ranked candidates are put to
   the claim tests of :mod:`drakecreep.gap.claims` (held-out inverse-dynamics gain above a circular-shift
   permutation null and better on most held-out runs, then a held-out closed-loop replay shrink above the
   run-to-run variation of the nominal); the first that passes is claimed. Without a replay for the
   runs' controller nothing is claimed and the candidates that pass the inverse-dynamics tests are
   listed as provisional. What stays is located by :func:`locate` ("unexplained" and where).
4. **Shrink**: RMS of the speed, position and force residuals of the closed-loop replay on the held-out
   runs, before and after adding the claimed effect(s), and of the inverse-dynamics force residual.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from drakecreep.gap.effects import (
    EFFECTS,
    EffectContext,
    get_effect,
    idim_data,
    replay_with_effects,
)
from drakecreep.errors import InputError
from drakecreep.gap.idim import filtered_derivatives, regressor
from drakecreep.gap.replay import RigidModel
from drakecreep.gap.runs import split_cycles  # noqa: F401 (moved to gap.runs; kept importable here)
from drakecreep.gap import claims as claims_mod
from drakecreep.gap.claims import identifiable
from drakecreep.gap.residuals import (
    classify_regimes,
    frequency_bands,
    independence,
    motor_table_split,
    operating_map,
    order_spectrum,
    regime_shares,
    time_spectrum,
    whiteness,
)

__all__ = [
    "DiagnosisConfig",
    "EffectFit",
    "split_cycles",
    "fit_nominal",
    "fit_effect",
    "replay_gap",
    "where",
    "diagnose",
    "score_fixed",
    "locate",
]

NOMINAL = ("M", "Fv", "Fc", "offset")


@dataclass(frozen=True)
class DiagnosisConfig:
    """Options of the diagnosis.

    Parameters
    ----------
    screw_lead, motor_period : float
        Travel per screw / motor revolution [m]; ``motor_period`` defaults to the lead (direct drive).
    claim_score : float
        An effect is claimed when its penalized held-out score is below ``-claim_score``.
    pair_claim_score : float
        The same for the second effect of a pair (its score relative to the first one).
    min_gain : float
        ... and it removes at least this share of the held-out inverse-dynamics residual energy.
    max_effects : int
        Unused since claims go through :mod:`drakecreep.gap.claims` (single effects only).
    max_candidates : int
        Best-ranked effects put to the claim tests (:func:`drakecreep.gap.claims.decide`), in ranking order;
        the first that passes is claimed.
    effects : tuple of str or None
        Subset of the library to try (default: all).
    v_min_frac : float
        Inverse-dynamics samples slower than this fraction of the largest reference speed are dropped
        (a standing axis has no defined Coulomb force).
    progress : bool
        Print progress on stderr.
    """

    screw_lead: float = 2.5e-3
    motor_period: float | None = None
    claim_score: float = 10.0
    pair_claim_score: float = 10.0
    min_gain: float = 0.05
    max_effects: int = 2
    effects: tuple | None = None
    max_candidates: int = 3
    v_min_frac: float = 0.01
    progress: bool = False

    def context(self, runs):
        x = np.concatenate([r.x_motor for r in runs])
        v = np.concatenate([np.gradient(r.x_ref, r.dt) for r in runs])
        lo, hi = float(x.min()), float(x.max())
        res = runs[0].meta.sensors.encoder_resolution
        return EffectContext(screw_lead=self.screw_lead, motor_period=self.motor_period or self.screw_lead,
                             x_center=0.5 * (lo + hi), x_half=max(0.5 * (hi - lo), 1e-6),
                             v_max=float(np.max(np.abs(v))) or 1e-3, dt=runs[0].dt,
                             encoder_resolution=res)


def _log(cfg, msg):
    if cfg.progress:
        print(f"[diagnose] {msg}", file=sys.stderr, flush=True)


@dataclass
class EffectFit:
    """One effect (or a combination) fitted on the training runs and scored on the held-out runs."""

    effects: tuple
    hyper: tuple
    theta: np.ndarray
    std: np.ndarray
    names: tuple
    sse_train: float
    sse_test: float
    n_train: int
    n_test: int
    k: int
    score: float = 0.0
    gain: float = 0.0
    bic_delta: float = 0.0
    physical: bool = True

    @property
    def label(self):
        return "+".join(self.effects) if self.effects else "nominal"

    @property
    def nominal(self):
        return dict(zip(NOMINAL, (float(x) for x in self.theta[:4])))

    def params(self):
        """``{name: {"value", "std"}}`` of the effect parameters (without the nominal ones)."""
        out = {}
        for n_, th, sd in zip(self.names[4:], self.theta[4:], self.std[4:]):
            out[n_] = {"value": float(th), "std": float(sd)}
        for e, h in zip(self.effects, self.hyper):
            hn = get_effect(e).hyper_name()
            if hn is not None and h is not None:
                out[f"{e}.{hn}"] = {"value": float(h), "std": None}
            if e == "quantization":
                out["quantization.step_m"] = {"value": float(h or 0.0), "std": None}
        return out


def _design(effects, hypers, sig, ctx, nominal):
    cols = [regressor(sig.dq, sig.ddq)]
    names = list(NOMINAL)
    y = sig.tau
    for e, h in zip(effects, hypers):
        eff = get_effect(e)
        c = eff.columns(sig, ctx, h, nominal)
        cols.append(c)
        names += [f"{e}.{p}" for p in eff.params]
        if eff.target(sig, h) is not sig.tau:
            y = eff.target(sig, h)
    return np.column_stack(cols), y, names


def _lstsq(X, y):
    theta, *_ = np.linalg.lstsq(X, y, rcond=None)
    r = y - X @ theta
    n, p = X.shape
    sigma2 = float(r @ r) / max(n - p, 1)
    try:
        cov = sigma2 * np.linalg.pinv(X.T @ X)
        std = np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:
        std = np.full(p, np.nan)
    return theta, std, float(r @ r)


def fit_nominal(train):
    """Rigid-model least squares on :class:`~drakecreep.gap.effects.IdimData`: ``(theta, std, sse)``."""
    return _lstsq(regressor(train.dq, train.ddq), train.tau)


def fit_effect(effects, train, test, ctx, nominal, base=None, n_eff_ratio=None):
    """Fit effects (names) with the nominal friction on ``train``; score on ``test`` with fixed parameters.

    Parameters
    ----------
    effects : sequence of str
    train, test : drakecreep.gap.effects.IdimData
    ctx : drakecreep.gap.effects.EffectContext
    nominal : dict
        Nominal parameters (used inside some columns: lead error, load friction).
    base : EffectFit, optional
        The model the score is relative to (default: the nominal fit).
    n_eff_ratio : float, optional
        Effective-sample ratio ``(1 - rho) / (1 + rho)`` of the held-out residual; default: from the
        lag-1 autocorrelation ``rho`` of the training residual this model leaves.

    Returns
    -------
    EffectFit
    """
    effects = tuple(effects)
    grids = [get_effect(e).grid(ctx) for e in effects]
    best = None
    for combo in _product(grids):
        combo = list(combo)
        for i, e in enumerate(effects):
            if e == "quantization":
                combo[i] = ctx.encoder_resolution or None
        X, y, names = _design(effects, combo, train, ctx, nominal)
        theta, std, sse = _lstsq(X, y)
        if best is None or sse < best[2]:
            best = (theta, std, sse, tuple(combo), names, y - X @ theta)
    theta, std, sse, hyper, names, r_train = best
    if n_eff_ratio is None:  # from the lag-1 autocorrelation of what this model leaves
        rho = max(_lag1(r_train), 0.0)
        n_eff_ratio = (1 - rho) / (1 + rho)
    Xt, yt, _ = _design(effects, hyper, test, ctx, nominal)
    rt = yt - Xt @ theta
    k = len(theta) + sum(1 for e in effects if get_effect(e).hyper_name() is not None)
    fit = EffectFit(effects=effects, hyper=hyper, theta=theta, std=std, names=tuple(names), sse_train=sse,
                    sse_test=float(rt @ rt), n_train=train.n, n_test=test.n, k=k)
    i = 4
    for e, h in zip(effects, hyper):
        eff = get_effect(e)
        fit.physical = fit.physical and eff.physical(theta[i: i + len(eff.params)], h, ctx, nominal)
        i += len(eff.params)
    if base is not None:
        n_eff = max(n_eff_ratio * test.n, 1.0)
        fit.score = float(n_eff * math.log(fit.sse_test / base.sse_test) + (fit.k - base.k) * math.log(train.n))
        fit.gain = float(1.0 - fit.sse_test / base.sse_test)
        fit.bic_delta = float(train.n * math.log(fit.sse_train / base.sse_train)
                              + (fit.k - base.k) * math.log(train.n))
    return fit


def _product(grids):
    if not grids:
        yield ()
        return
    for h in grids[0]:
        for rest in _product(grids[1:]):
            yield (h,) + rest


def _model(fit):
    p = fit.nominal
    return RigidModel(M=max(p["M"], 1e-6), Fv=max(p["Fv"], 0.0), Fc=max(p["Fc"], 0.0), offset=p["offset"])


def _terms(fit, ctx):
    terms = []
    nominal = fit.nominal
    i = 4
    for e, h in zip(fit.effects, fit.hyper):
        eff = get_effect(e)
        th = fit.theta[i: i + len(eff.params)]
        i += len(eff.params)
        terms.append(eff.replay_term(th, h, ctx, nominal))
    return terms


def replay_gap(fit, runs, ctx):
    """Closed-loop replay of a fitted model on runs: residual arrays and RMS of speed, position, force.

    Returns
    -------
    dict
        ``rms`` (``speed_mm_s``, ``position_um``, ``force_N``) over all runs, and ``per_run`` residual
        arrays (``t``, ``x``, ``v``, ``force``, ``e_speed``, ``e_position``, ``e_force``, ``x_ref``, ``u``).
    """
    model = _model(fit)
    per = []
    for run in runs:
        sim = replay_with_effects(run, model, _terms(fit, ctx))
        _, v_meas, _ = filtered_derivatives(run.x_motor, run.dt)
        _, v_sim, _ = filtered_derivatives(sim["x"], run.dt)
        per.append({"t": run.t, "x": run.x_motor, "x_ref": run.x_ref, "v": v_meas, "force": run.force,
                    "x_sim": sim["x"], "x_table": run.x_table,
                    "u": run.u, "e_speed": v_meas - v_sim, "e_position": run.x_motor - sim["x"],
                    "e_force": run.force - sim["force"]})
    cat = {k: np.concatenate([p[k] for p in per]) for k in ("e_speed", "e_position", "e_force")}
    rms = {"speed_mm_s": 1e3 * float(np.sqrt(np.mean(cat["e_speed"] ** 2))),
           "position_um": 1e6 * float(np.sqrt(np.mean(cat["e_position"] ** 2))),
           "force_N": float(np.sqrt(np.mean(cat["e_force"] ** 2)))}
    return {"rms": rms, "per_run": per}


claims_mod.use(design=_design, fit_effect=fit_effect, replay=replay_gap)


def where(gap, ctx, idim_residual=None, idim_input=None):
    """Decompose replay residuals (from :func:`replay_gap`) by regime, order and operating map.

    Returns
    -------
    dict
        ``regimes`` (per signal), ``orders`` (per signal and axis: screw, motor, table_mm), ``time`` (peak
        frequency per signal), ``map`` (per signal), ``whiteness`` (of the IDIM residual), ``sentences``.
    """
    per = gap["per_run"]
    cat = {k: np.concatenate([p[k] for p in per]) for k in per[0] if k not in ("t", "x_table")}
    labels = np.concatenate([classify_regimes(p["t"], p["x_ref"], p["v"]) for p in per])
    dt = float(per[0]["t"][1] - per[0]["t"][0])
    signals = {"speed": "e_speed", "position": "e_position", "force": "e_force"}
    axes = {"screw": ctx.screw_lead, "motor": ctx.motor_period, "table_mm": 1e-3}
    out = {"regimes": {}, "orders": {}, "time": {}, "map": {}, "spectra": {}}
    for name, key in signals.items():
        out["regimes"][name] = regime_shares(cat[key], labels)
        out["orders"][name] = {}
        out["spectra"][name] = {}
        for axis, period in axes.items():
            # spectra per run, averaged (the runs are separate records)
            specs = [order_spectrum(p["x"], p["v"], p[key], period) for p in per]
            specs = [s for s in specs if s["n_segments"]]
            if not specs:
                out["orders"][name][axis] = {"peak_order": None, "peak_share": 0.0, "peak_ratio": 0.0}
                continue
            psd = np.mean([s["psd"] for s in specs], axis=0)
            orders = specs[0]["orders"]
            band = orders >= 0.75  # below: drift over a few revolutions, not an order
            idx = np.flatnonzero(band)
            k = idx[np.argmax(psd[band])]
            total = float(np.sum(psd[band]))
            lo = max(k - 1, idx[0])
            out["orders"][name][axis] = {
                "peak_order": float(orders[k]),
                "peak_share": float(np.sum(psd[lo: k + 2]) / total) if total > 0 else 0.0,
                "peak_ratio": _prominence(psd, k, idx[0]),
                "at_band_edge": bool(k == idx[0])}
            out["spectra"][name][axis] = (orders, psd)
        ts = time_spectrum(cat[key], dt)
        out["time"][name] = {"peak_hz": ts["peak_hz"]}
        out["spectra"][name]["time"] = (ts["freq"], ts["psd"])
        out["map"][name] = operating_map(cat[key], cat["v"], cat["x"], cat["force"])
    out["bands"] = {name: frequency_bands([p[key] for p in per], dt) for name, key in signals.items()}
    v_ref = np.concatenate([np.gradient(p["x_ref"], dt) for p in per])
    try:
        out["independence"] = independence(cat["e_force"], {"reference_speed": v_ref, "force": cat["force"]})
    except InputError:
        out["independence"] = {}
    if all(p["x_table"] is not None for p in per):
        out["motor_table"] = motor_table_split(cat["x"], np.concatenate([p["x_table"] for p in per]), cat["x_sim"])
    if idim_residual is not None:
        out["whiteness"] = whiteness(idim_residual, idim_input)
    out["sentences"] = _sentences(out)
    return out


def _prominence(psd, k, lo, half=8):
    """Peak over the median of its neighbourhood (``+-half`` bins, the peak's own 3 bins left out)."""
    around = np.r_[psd[max(k - half, lo): max(k - 1, lo)], psd[k + 2: k + half + 1]]
    med = float(np.median(around)) if around.size else 0.0
    return float(psd[k] / med) if med > 0 else 0.0


def _sentences(w):
    lines = []
    for name in ("speed", "position", "force"):
        reg = w["regimes"][name]
        top = max(reg, key=lambda r: reg[r]["energy_share"])
        o = w["orders"][name]["screw"]
        order_txt = ""
        if o.get("peak_order") is not None and o["peak_ratio"] >= 10 and not o.get("at_band_edge"):
            order_txt = (f", with a sharp peak at {o['peak_order']:.2f}x screw order "
                         f"({100 * o['peak_share']:.0f} % of the position-resampled energy)")
        else:
            order_txt = ", no sharp order against screw angle"
        lines.append(f"{100 * reg[top]['energy_share']:.0f} % of the {name} residual energy lies in "
                     f"{top.replace('_', '-')} phases ({100 * reg[top]['time_share']:.0f} % of the time){order_txt}.")
    if "bands" in w:
        b = w["bands"]["force"]["top"]
        lines.append(f"{100 * b['share']:.0f} % of the force residual energy lies between {b['lo_Hz']:g} and "
                     f"{b['hi_Hz']:g} Hz (peak at {w['bands']['force']['peak_hz']:.3g} Hz).")
    if "motor_table" in w:
        m = w["motor_table"]
        lines.append(f"Position gap: {1e6 * m['motor_rms_m']:.3g} um RMS at the motor, {1e6 * m['transmission_rms_m']:.3g} "
                     f"um RMS added by the transmission: {m['where']} ({100 * m['after_screw_share']:.0f} % after).")
    if w.get("independence"):
        dep = [f"{k} (max |r| {v['max_abs']:.2f} at lag {v['lag_of_max']} > band {v['band']:.2f})"
               for k, v in w["independence"].items() if not v["independent"]]
        lines.append("The replay force residual is " + ("correlated with " + "; ".join(dep) if dep else
                     "independent of the reference speed and the force (99 % band)") + ".")
    if "whiteness" in w:
        wh = w["whiteness"]
        lines.append("The inverse-dynamics residual is " + ("white (noise)" if wh["white"] else
                     f"not white (Ljung-Box p = {wh['ljung_box_p']:.2g}, max |xcorr with u| = "
                     f"{wh['max_abs_xcorr']:.2f} vs {wh['xcorr_bound']:.2f})") + ".")
    return lines


def _rel(sse, data):
    """Relative force error ``100 ||r|| / ||tau||`` [%] (the EMPS papers' fit error)."""
    return float(100.0 * math.sqrt(sse) / np.linalg.norm(data.tau))


def _lag1(r):
    r = r - r.mean()
    d = float(r @ r)
    return float(r[:-1] @ r[1:]) / d if d > 0 else 0.0


def diagnose(train_runs, test_runs, config=None, replay=True):
    """Diagnose the sim-to-real gap of the rigid model on measured runs.

    Parameters
    ----------
    train_runs, test_runs : sequence of drakecreep.gap.measured.MeasuredRun
        Fitting happens on ``train_runs`` only; ``test_runs`` are held out and only scored.
    config : DiagnosisConfig, optional
    replay : bool
        Compute the closed-loop "where" and shrink (else inverse-dynamics only, faster).

    Returns
    -------
    dict
        ``nominal``, ``where`` (when ``replay``), ``ranking`` (list, best first), ``claimed`` (effect
        names), ``shrink``, ``unexplained_share``, ``summary`` (sentences).
    """
    cfg = config or DiagnosisConfig()
    train_runs, test_runs = list(train_runs), list(test_runs)
    if not train_runs or not test_runs:
        raise InputError("runs", f"{len(train_runs)} training, {len(test_runs)} held-out", "at least one of each")
    ctx = cfg.context(train_runs)
    _log(cfg, f"{len(train_runs)} training runs, {len(test_runs)} held-out runs")
    v_min = cfg.v_min_frac * ctx.v_max
    geo = {"screw_lead": ctx.screw_lead, "motor_period": ctx.motor_period}
    train, test = idim_data(train_runs, v_min=v_min, **geo), idim_data(test_runs, v_min=v_min, **geo)
    base = fit_effect((), train, test, ctx, {})
    nominal = base.nominal
    ratio = None
    _log(cfg, "nominal: " + ", ".join(f"{k}={v:.4g}" for k, v in nominal.items()))
    names = cfg.effects or tuple(e.name for e in EFFECTS)
    ranking = []
    not_identifiable = []
    for name in names:
        eff = get_effect(name)
        if not eff.applicable(train):
            continue
        if not identifiable(name, train, ctx, nominal):
            not_identifiable.append(name)  # nothing to fit: never ranked (no 0.0 score in a top-3)
            continue
        fit = fit_effect((name,), train, test, ctx, nominal, base=base, n_eff_ratio=ratio)
        _log(cfg, f"effect {name}: held-out score {fit.score:+.1f}, gain {100 * fit.gain:.1f} %")
        ranking.append(fit)
    ranking.sort(key=lambda f: (not f.physical, f.score))

    # claims (drakecreep.gap.claims): permutation null, run-to-run spread, held-out closed-loop replay
    replay_nominal = None
    if replay:
        try:
            replay_nominal = claims_mod.replay_energy(base, test_runs, ctx)
        except InputError as err:
            replay_nominal = err
    rnull = {"ratios": [], "threshold": 0.0}
    if replay and not isinstance(replay_nominal, Exception):
        rnull = claims_mod.replay_null(train, test, test_runs, ctx, replay_nominal)
        _log(cfg, f"replay threshold from run-to-run variation: {100 * rnull['threshold']:.1f} %")
    decisions = {}
    claimed = []
    for f in ranking[: cfg.max_candidates]:
        if not f.physical or f.gain <= 0:
            continue
        d = claims_mod.decide(f, base, train, test, test_runs, ctx, replay_nominal=replay_nominal,
                              replay_threshold=rnull["threshold"])
        decisions[f.label] = d
        _log(cfg, f"claim test {f.label}: {d['reason']}")
        if d["claim"]:
            claimed = [f]
            break
    final = claimed[-1] if claimed else base
    idim_test_nom = math.sqrt(base.sse_test / test.n)
    idim_test_fin = math.sqrt(final.sse_test / test.n)
    result = {
        "n_train_runs": len(train_runs), "n_test_runs": len(test_runs),
        "nominal": {"params": nominal, "std": dict(zip(NOMINAL, map(float, base.std[:4])))},
        "context": ctx.__dict__,
        "claimed": list(final.effects),
        "ranking": [],
        "unexplained_share": float(final.sse_test / base.sse_test),
        "idim_rms_N": {"before": idim_test_nom, "after": idim_test_fin},
        "idim_error_percent": {"before": _rel(base.sse_test, test), "after": _rel(final.sse_test, test)},
    }
    result["claims"] = {
        "rule": "permutation null + run-to-run spread on inverse dynamics, then the held-out closed-loop replay "
                "(drakecreep.gap.claims)",
        "replay_available": replay and not isinstance(replay_nominal, Exception),
        "replay_error": str(replay_nominal) if isinstance(replay_nominal, Exception) else None,
        "replay_null": rnull,
        "decisions": _jsonable(decisions),
        "provisional": [k for k, d in decisions.items() if d["provisional"]],
        "not_identifiable": not_identifiable,
    }
    replay = replay and not isinstance(replay_nominal, Exception)
    if replay:
        _log(cfg, "closed-loop replay of the nominal on the held-out runs")
        gap0 = replay_gap(base, test_runs, ctx)
        r_test = test.tau - regressor(test.dq, test.ddq) @ base.theta
        result["where"] = where(gap0, ctx, r_test, test.u)
        result["_gap_before"] = gap0
        gaps = {"nominal": gap0["rms"]}
        for f in ranking[:3] + claimed:
            if f.label not in gaps:
                _log(cfg, f"closed-loop replay with {f.label}")
                try:
                    gaps[f.label] = replay_gap(f, test_runs, ctx)["rms"]
                except InputError as err:  # e.g. a fitted mass <= 0
                    gaps[f.label] = {"error": str(err)}
        if claimed:
            result["_gap_after"] = replay_gap(final, test_runs, ctx)
        result["shrink"] = {"before": gap0["rms"], "after": gaps.get(final.label, gap0["rms"]),
                            "model": final.label, "replays": gaps}
        w_after = where(result["_gap_after"], ctx) if claimed else result["where"]
        result["unexplained"] = locate(w_after, claimed=list(final.effects),
                                       remaining_share=result["unexplained_share"])
    else:
        result["unexplained"] = {"verdict": "explained" if claimed else "unexplained", "where": None,
                                 "sentence": "Where the gap lies needs the closed-loop replay "
                                             f"({result['claims']['replay_error'] or 'not run'})."}
    for f in ranking:
        row = {"effect": f.label, "score": f.score, "gain": f.gain, "bic_delta": f.bic_delta,
               "physical": f.physical,
               "params": f.params(), "nominal": f.nominal, "signature": get_effect(f.effects[0]).signature,
               "idim_rms_N": {"before": idim_test_nom, "after": math.sqrt(f.sse_test / test.n)},
               "claimed": bool(claimed and f is claimed[0])}
        if replay and f.label in result["shrink"]["replays"]:
            row["replay_rms"] = {"before": result["shrink"]["before"], "after": result["shrink"]["replays"][f.label]}
        result["ranking"].append(row)
    result["_fits"] = {"base": base, "ranking": ranking, "final": final, "ctx": ctx, "config": cfg}
    if len(claimed) > 1:
        result["pair"] = {"effect": claimed[1].label, "score": claimed[1].score, "gain": claimed[1].gain,
                          "params": claimed[1].params()}
    result["summary"] = _summary(result)
    return result


def locate(w, claimed=(), remaining_share=1.0):
    """Where the gap no claimed effect explains lies, from a :func:`where` decomposition.

    Parameters
    ----------
    w : dict
        :func:`where` of the replay residual left by the claimed model (or the nominal).
    claimed : sequence of str
        Claimed effects (empty: the whole gap is unexplained).
    remaining_share : float
        Held-out inverse-dynamics residual energy left, relative to the nominal's.

    Returns
    -------
    dict
        ``verdict`` ("unexplained" or "partly explained by ..."), ``regime``, ``band``, ``order``,
        ``operating_point``, ``dependent_on`` (inputs the force residual correlates with), ``sentence``.
    """
    reg = w["regimes"]["force"]
    top_reg = max(reg, key=lambda r: reg[r]["energy_share"])
    band = w["bands"]["force"]["top"] if "bands" in w else None
    order = None
    for axis in ("screw", "motor"):
        o = w["orders"]["force"].get(axis, {})
        if o.get("peak_order") is not None and o.get("peak_ratio", 0) >= 10 and not o.get("at_band_edge"):
            order = {"axis": axis, "order": o["peak_order"], "share": o["peak_share"]}
            break
    op = None
    for dim in ("speed", "position", "load"):
        rows = w["map"]["force"][dim]
        k = max(range(len(rows)), key=lambda i: rows[i]["energy_share"])
        if op is None or rows[k]["energy_share"] > op["energy_share"]:
            op = dict(rows[k], dimension=dim)
    dep = [k for k, v in w.get("independence", {}).items() if not v["independent"]]
    verdict = "unexplained" if not claimed else "partly explained by " + " + ".join(claimed)
    unit = {"speed": (1e3, "mm/s"), "position": (1e3, "mm"), "load": (1.0, "N")}[op["dimension"]]
    parts = [f"{100 * reg[top_reg]['energy_share']:.0f} % in {top_reg.replace('_', '-')} phases"]
    if band is not None:
        parts.append(f"{100 * band['share']:.0f} % between {band['lo_Hz']:g} and {band['hi_Hz']:.0f} Hz")
    parts.append(f"{100 * op['energy_share']:.0f} % at {op['dimension']} {unit[0] * op['lo']:.3g}-"
                 f"{unit[0] * op['hi']:.3g} {unit[1]}")
    parts.append(f"a sharp {order['axis']} order {order['order']:.2f}" if order else "no sharp order")
    if dep:
        parts.append("correlated with " + " and ".join(d.replace("_", " ") for d in dep))
    head = ("Unexplained gap, in the replay force residual" if not claimed else
            f"Gap left after {' + '.join(claimed)} ({100 * remaining_share:.0f} % of the inverse-dynamics "
            "residual remains), in the replay force residual")
    return {"verdict": verdict, "regime": top_reg, "band": band, "order": order, "operating_point": op,
            "dependent_on": dep, "sentence": f"{head}: " + "; ".join(parts) + "."}


def _jsonable(x):
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    return x


def _summary(res):
    lines = list(res.get("where", {}).get("sentences", []))
    if res["claimed"]:
        top = next(r for r in res["ranking"] if r["effect"] == "+".join(res["claimed"]))
        lines.append(f"Best explanation: {' + '.join(res['claimed'])} (held-out score {top['score']:+.1f}); "
                     f"it removes {100 * (1 - res['unexplained_share']):.0f} % of the held-out inverse-dynamics "
                     f"residual energy, {100 * res['unexplained_share']:.0f} % stays unexplained.")
    else:
        lines.append("Unexplained: no effect of the library passes the claim tests (held-out inverse dynamics "
                     "against a permutation null, and the held-out closed-loop replay against run-to-run variation).")
        prov = res.get("claims", {}).get("provisional", [])
        if prov:
            lines.append("Provisional (inverse dynamics only, the replay is unavailable): " + ", ".join(prov) + ".")
    if res.get("unexplained", {}).get("sentence"):
        lines.append(res["unexplained"]["sentence"])
    if "shrink" in res:
        b, a = res["shrink"]["before"], res["shrink"]["after"]
        if "speed_mm_s" in a:
            lines.append(f"Held-out replay RMS before -> after: speed {b['speed_mm_s']:.3g} -> {a['speed_mm_s']:.3g} "
                         f"mm/s, position {b['position_um']:.3g} -> {a['position_um']:.3g} um, force "
                         f"{b['force_N']:.3g} -> {a['force_N']:.3g} N.")
    return lines


def score_fixed(result, runs, replay=True):
    """Score a finished diagnosis on other runs with every parameter FIXED (no fitting: a held-out test).

    Parameters
    ----------
    result : dict
        From :func:`diagnose` (holds the fitted models).
    runs : sequence of drakecreep.gap.measured.MeasuredRun
        The runs to score on (e.g. the EMPS validation set).
    replay : bool
        Also the closed-loop replay gap and the "where" decomposition on these runs.

    Returns
    -------
    dict
        ``idim_rms_N`` (nominal and per ranked effect), ``unexplained_share`` of the claimed model,
        ``shrink`` (replay RMS before / after), ``where`` and ``summary``.
    """
    fits = result["_fits"]
    base, final, ctx, cfg = fits["base"], fits["final"], fits["ctx"], fits["config"]
    runs = list(runs)
    v_min = cfg.v_min_frac * ctx.v_max
    data = idim_data(runs, v_min=v_min, screw_lead=ctx.screw_lead, motor_period=ctx.motor_period)

    def sse(fit):
        X, y, _ = _design(fit.effects, fit.hyper, data, ctx, base.nominal)
        r = y - X @ fit.theta
        return float(r @ r)

    s0 = sse(base)
    rows = []
    for f in fits["ranking"]:
        s1 = sse(f)
        rows.append({"effect": f.label, "idim_rms_N": math.sqrt(s1 / data.n), "gain": 1.0 - s1 / s0})
    sf = sse(final)
    out = {"n_runs": len(runs), "model": final.label, "idim_rms_N": {"before": math.sqrt(s0 / data.n),
                                                                   "after": math.sqrt(sf / data.n)},
           "unexplained_share": sf / s0, "ranking": rows,
           "idim_error_percent": {"before": _rel(s0, data), "after": _rel(sf, data)}}
    if replay:
        g0 = replay_gap(base, runs, ctx)
        g1 = replay_gap(final, runs, ctx) if final is not base else g0
        r0 = data.tau - regressor(data.dq, data.ddq) @ base.theta
        out["where"] = where(g0, ctx, r0, data.u)
        out["shrink"] = {"before": g0["rms"], "after": g1["rms"], "model": final.label}
        out["_gap_before"], out["_gap_after"] = g0, g1
    lines = list(out.get("where", {}).get("sentences", []))
    lines.append(f"With the parameters fixed on the estimation data, {final.label} removes "
                 f"{100 * (1 - out['unexplained_share']):.0f} % of the inverse-dynamics residual energy here.")
    if replay:
        b, a = out["shrink"]["before"], out["shrink"]["after"]
        lines.append(f"Replay RMS before -> after: speed {b['speed_mm_s']:.3g} -> {a['speed_mm_s']:.3g} mm/s, "
                     f"position {b['position_um']:.3g} -> {a['position_um']:.3g} um, force {b['force_N']:.3g} -> "
                     f"{a['force_N']:.3g} N.")
    out["summary"] = lines
    return out
