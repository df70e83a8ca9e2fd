"""When may the diagnosis claim an effect? Thresholds from the data's own run-to-run variation.

An effect is **claimed** only when all of these hold (:func:`decide`):

1. **Identifiable**: it adds a regressor (or changes the target) of the inverse-dynamics model. An effect
   with nothing to fit (quantisation today) is reported as not identifiable and never ranked.
2. **Inverse dynamics beats a permutation null**: the held-out gain ``1 - SSE_eff / SSE_nom`` exceeds the
   ``1 - alpha`` quantile of the same gain when the effect's regressor columns are circularly shifted
   within each run (the shift keeps the columns' autocorrelation, their run structure and the
   nonlinear-parameter search, and breaks their alignment with the force). The threshold therefore
   grows with the noise, the drift between runs and the freedom of the effect (:func:`permutation_null`).
3. **Consistent across runs**: a majority of the held-out runs gets better (:func:`run_gains`, which also
   reports the leave-one-training-run-out gains; those are not used, as a position- or speed-dependent
   effect left out of a run's range cannot extrapolate to it).
4. **The held-out closed-loop replay improves** by more than run-to-run variation explains: the pooled
   normalised replay residual energy (:func:`replay_energy`: force and speed) of the held-out runs shrinks
   by more than it changes when the nominal is refitted with one training run left out (the largest such
   change, :func:`replay_null`), and a majority of the held-out runs get better (:func:`replay_test`).

When the replay is not available for a run's controller (today: ``kind: drakecreep``, until the Drake
replay lands), no effect is claimed; candidates that pass 1-3 are reported as ``provisional``.

The replay goes through the function registered with :func:`use` only (today
:func:`drakecreep.gap.diagnosis.replay_gap`), so the Drake replay can be swapped in at one place.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

from drakecreep.errors import InputError

__all__ = [
    "ALPHA",
    "HOOKS",
    "use",
    "N_PERMUTATIONS",
    "identifiable",
    "permutation_null",
    "run_gains",
    "replay_energy",
    "replay_null",
    "replay_test",
    "decide",
]

#: One-sided level of every test of a claim.
ALPHA = 0.05
#: Circular-shift permutations of the null (the null quantile is the ``1 - ALPHA`` one).
N_PERMUTATIONS = 39


#: The model functions the claims call, registered by :func:`use` (``drakecreep.gap.diagnosis`` does it on
#: import, so that this module does not import the diagnosis that imports it):
#: ``design(effects, hypers, sig, ctx, nominal) -> (X, y, names)``, ``fit_effect`` as
#: :func:`drakecreep.gap.diagnosis.fit_effect`, ``replay(fit, runs, ctx)`` as
#: :func:`drakecreep.gap.diagnosis.replay_gap` (the Drake replay replaces this one).
HOOKS = {}


def use(design, fit_effect, replay):
    """Register the design-matrix, fitting and closed-loop replay functions the claim tests call."""
    HOOKS.update(design=design, fit_effect=fit_effect, replay=replay)


def _hook(name):
    if name not in HOOKS:
        raise RuntimeError("drakecreep.gap.claims needs its model functions: import drakecreep.gap.diagnosis "
                           "(it calls claims.use on import)")
    return HOOKS[name]


def identifiable(name, sig, ctx, nominal):
    """Whether effect ``name`` adds anything to fit (a regressor column or a changed target)."""
    from drakecreep.gap.effects import get_effect

    eff = get_effect(name)
    h = eff.grid(ctx)[0]
    cols = eff.columns(sig, ctx, h, nominal)
    return bool(np.asarray(cols).ndim == 2 and np.asarray(cols).shape[1] > 0) or eff.target(sig, h) is not sig.tau


def _design_all(name, sig, ctx, nominal):
    """``{hyper: (X, y)}`` of the nominal + effect design on ``sig`` for every grid value."""
    from drakecreep.gap.effects import get_effect

    _design = _hook("design")
    out = {}
    for h in get_effect(name).grid(ctx):
        X, y, _ = _design((name,), (h,), sig, ctx, nominal)
        out[h] = (X, y)
    return out


def _shift(cols, run_index, shifts):
    out = np.empty_like(cols)
    for r, s in shifts.items():
        m = run_index == r
        out[m] = np.roll(cols[m], s, axis=0)
    return out


def _fit_score(designs, n_nom):
    """Best grid value on the training part; held-out SSE with those parameters."""
    best = None
    for h, (Xtr, ytr, Xte, yte) in designs.items():
        theta, *_ = np.linalg.lstsq(Xtr, ytr, rcond=None)
        r = ytr - Xtr @ theta
        sse = float(r @ r)
        if best is None or sse < best[0]:
            rt = yte - Xte @ theta
            best = (sse, float(rt @ rt))
    return best


def permutation_null(name, train, test, ctx, nominal, sse_nom_test, n=N_PERMUTATIONS, seed=0):
    """Held-out inverse-dynamics gains of effect ``name`` with its columns circularly shifted per run.

    Parameters
    ----------
    name : str
        Effect.
    train, test : drakecreep.gap.effects.IdimData
    ctx, nominal
        As for :func:`drakecreep.gap.diagnosis.fit_effect`.
    sse_nom_test : float
        Held-out SSE of the nominal model.
    n : int
        Permutations.
    seed : int
        Seed of the shifts.

    Returns
    -------
    numpy.ndarray
        ``n`` null gains (empty when the effect has no columns: its null is ``gain <= 0``).
    """
    dtr, dte = _design_all(name, train, ctx, nominal), _design_all(name, test, ctx, nominal)
    if next(iter(dtr.values()))[0].shape[1] <= 4:
        return np.zeros(0)
    rng = np.random.default_rng(seed)
    gains = []
    for _ in range(n):
        sh_tr = {r: int(rng.uniform(0.25, 0.75) * np.sum(train.run_index == r)) for r in np.unique(train.run_index)}
        sh_te = {r: int(rng.uniform(0.25, 0.75) * np.sum(test.run_index == r)) for r in np.unique(test.run_index)}
        designs = {}
        for h in dtr:
            Xtr, ytr = dtr[h]
            Xte, yte = dte[h]
            Xtr = np.column_stack([Xtr[:, :4], _shift(Xtr[:, 4:], train.run_index, sh_tr)])
            Xte = np.column_stack([Xte[:, :4], _shift(Xte[:, 4:], test.run_index, sh_te)])
            designs[h] = (Xtr, ytr, Xte, yte)
        _, sse_te = _fit_score(designs, 4)
        gains.append(1.0 - sse_te / sse_nom_test)
    return np.array(gains)


def run_gains(name, train, test, ctx, nominal):
    """Per-run out-of-sample inverse-dynamics gains of effect ``name`` over the nominal.

    Each training run is left out in turn (nominal and effect refitted on the other training runs, the
    grid value chosen there), then each held-out run is scored with the fit on all training runs.

    Returns
    -------
    numpy.ndarray
        One gain ``1 - SSE_eff / SSE_nom`` per run (training runs first).
    """
    from drakecreep.gap.idim import regressor

    dtr, dte = _design_all(name, train, ctx, nominal), _design_all(name, test, ctx, nominal)
    out = []
    runs_tr = np.unique(train.run_index)

    for r in (runs_tr if runs_tr.size > 1 else []):
        fit_m, ev_m = train.run_index != r, train.run_index == r
        W = regressor(train.dq, train.ddq)
        th0, *_ = np.linalg.lstsq(W[fit_m], train.tau[fit_m], rcond=None)
        r0 = train.tau[ev_m] - W[ev_m] @ th0
        designs = {h: (X[fit_m], y[fit_m], X[ev_m], y[ev_m]) for h, (X, y) in dtr.items()}
        _, sse1 = _fit_score(designs, 4)
        out.append(1.0 - sse1 / float(r0 @ r0))
    W = regressor(train.dq, train.ddq)
    th0, *_ = np.linalg.lstsq(W, train.tau, rcond=None)
    Wt = regressor(test.dq, test.ddq)
    best = None
    for h, (X, y) in dtr.items():
        theta, *_ = np.linalg.lstsq(X, y, rcond=None)
        rr = y - X @ theta
        if best is None or float(rr @ rr) < best[0]:
            best = (float(rr @ rr), h, theta)
    _, h, theta = best
    Xt, yt = dte[h]
    for r in np.unique(test.run_index):
        m = test.run_index == r
        r0 = test.tau[m] - Wt[m] @ th0
        r1 = yt[m] - Xt[m] @ theta
        out.append(1.0 - float(r1 @ r1) / float(r0 @ r0))
    return np.array(out)


def replay_energy(fit, runs, ctx):
    """Normalised closed-loop replay residual energy per run (mean of the force and the speed part).

    ``E = (||F - F_sim||^2 / ||F - mean F||^2 + ||v - v_sim||^2 / ||v||^2) / 2`` on each run, with ``F``
    the drive force and ``v`` the filtered motor speed.

    Raises
    ------
    drakecreep.errors.InputError
        When the replay cannot run these runs (e.g. their controller kind).
    """
    gap = _hook("replay")(fit, runs, ctx)
    out = []
    for p in gap["per_run"]:
        f = p["force"] - np.mean(p["force"])
        ef = float(p["e_force"] @ p["e_force"]) / max(float(f @ f), 1e-30)
        ev = float(p["e_speed"] @ p["e_speed"]) / max(float(p["v"] @ p["v"]), 1e-30)
        out.append(0.5 * (ef + ev))
    return np.array(out)


def _t_bound(x, upper):
    """One-sided ``1 - ALPHA`` t bound of the mean of ``x`` (upper or lower)."""
    x = np.asarray(x, dtype=float)
    if x.size < 2:
        return float(x.mean()) if x.size else math.nan
    half = stats.t.ppf(1 - ALPHA, x.size - 1) * float(np.std(x, ddof=1)) / math.sqrt(x.size)
    return float(x.mean() + half if upper else x.mean() - half)


def replay_null(train, test, test_runs, ctx, e_nom):
    """How much the held-out replay changes when only the training runs change (no effect added).

    The nominal is refitted with each training run left out in turn and replayed on the held-out runs;
    the threshold is the largest relative change of the pooled replay energy. An effect must shrink the
    held-out replay by more than this run-to-run variation.

    Returns
    -------
    dict
        ``ratios`` (pooled energy of each refit / of the full nominal) and ``threshold``.
    """
    fit_effect = _hook("fit_effect")
    ratios = []
    for r in np.unique(train.run_index):
        sub = train.select(train.run_index != r)
        if sub.n < 20:
            continue
        f = fit_effect((), sub, test, ctx, {})
        try:
            e = replay_energy(f, test_runs, ctx)
        except InputError:
            continue
        ratios.append(float(np.sum(e) / np.sum(e_nom)))
    thr = float(max(abs(1.0 - x) for x in ratios)) if ratios else 0.0
    return {"ratios": ratios, "threshold": thr}


def replay_test(e_nom, e_eff, threshold=0.0):
    """Held-out replay: pooled shrink above ``threshold`` and a majority of the runs better."""
    e_nom, e_eff = np.asarray(e_nom, dtype=float), np.asarray(e_eff, dtype=float)
    lr = np.log(np.maximum(e_eff, 1e-300) / np.maximum(e_nom, 1e-300))
    shrink = float(1.0 - np.sum(e_eff) / np.sum(e_nom))
    better = int(np.sum(lr < 0))
    return {"log_ratios": lr.tolist(), "shrink": shrink, "threshold": float(threshold),
            "runs_better": better, "passes": bool(shrink > threshold and 2 * better > lr.size)}


def decide(fit, base, train, test, test_runs, ctx, replay_nominal=None, replay_threshold=0.0, seed=0):
    """Decide whether the fitted single effect ``fit`` may be claimed.

    Parameters
    ----------
    fit, base : drakecreep.gap.diagnosis.EffectFit
        The effect's fit and the nominal.
    train, test : drakecreep.gap.effects.IdimData
    test_runs : sequence of MeasuredRun
        The held-out runs (closed-loop replay).
    ctx : drakecreep.gap.effects.EffectContext
    replay_nominal : numpy.ndarray or None or Exception
        Per-run replay energies of the nominal on ``test_runs`` (computed once by the caller); an
        :class:`~drakecreep.errors.InputError` when the replay is unavailable.
    replay_threshold : float
        From :func:`replay_null`.
    seed : int
        Seed of the permutation null.

    Returns
    -------
    dict
        ``claim`` (bool), ``provisional`` (passes the inverse-dynamics tests, replay unavailable),
        ``idim`` (gain, null threshold, run gains, lower bound), ``replay`` (see :func:`replay_test`),
        ``reason``.
    """
    name = fit.effects[0]
    nominal = base.nominal
    null = permutation_null(name, train, test, ctx, nominal, base.sse_test, seed=seed)
    thr = float(np.quantile(null, 1 - ALPHA)) if null.size else 0.0
    thr = max(thr, 0.0)
    gains = run_gains(name, train, test, ctx, nominal)
    n_tr = np.unique(train.run_index).size if np.unique(train.run_index).size > 1 else 0
    held = gains[n_tr:]
    better = int(np.sum(held > 0))
    idim = {"gain": float(fit.gain), "null_threshold": thr, "null_median": float(np.median(null)) if null.size else None,
            "run_gains": gains.tolist(), "held_out_runs_better": better,
            "passes": bool(fit.physical and fit.gain > thr and 2 * better > held.size)}
    out = {"effect": name, "idim": idim, "replay": None, "claim": False, "provisional": False}
    if not idim["passes"]:
        why = "not physical" if not fit.physical else (
            f"held-out gain {100 * fit.gain:.1f} % <= null {100 * thr:.1f} %" if fit.gain <= thr else
            f"only {better} of {held.size} held-out runs better")
        out["reason"] = "inverse dynamics: " + why
        return out
    if isinstance(replay_nominal, Exception) or replay_nominal is None:
        out["provisional"] = True
        out["reason"] = f"closed-loop replay unavailable ({replay_nominal})"
        return out
    try:
        e_eff = replay_energy(fit, test_runs, ctx)
    except InputError as err:
        out["reason"] = f"replay with the effect failed: {err}"
        return out
    rt = replay_test(replay_nominal, e_eff, replay_threshold)
    out["replay"] = rt
    out["claim"] = rt["passes"]
    out["reason"] = ("claimed" if rt["passes"] else
                     f"held-out replay: shrink {100 * rt['shrink']:.1f} % (threshold {100 * replay_threshold:.1f} %), "
                     f"{rt['runs_better']}/{len(rt['log_ratios'])} runs better")
    return out
