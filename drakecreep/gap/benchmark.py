"""Withheld-effect benchmark of the gap diagnosis: synthetic "measured" datasets with hidden effects.

:func:`generate_dataset` draws (seeded) a truth model **richer than the library** and simulates it in
closed loop under the EMPS-like sampled cascade, with a different integrator and time step than the
diagnosis (RK4 at ``dt/8`` on smooth ``tanh`` friction, where the diagnosis uses exact per-sample rigid
steps and a sign law), effect shapes that are not the library's parametrization (Stribeck exponent 1.5,
lead error and cogging with a second harmonic, position friction as a ``tanh`` ramp, backlash as a real
dead zone between two bodies, the structural mode as a real second body, the delay with an extra
sub-sample lag, load friction driven by the drive force), white and low-pass force noise, encoder
quantization, and small nominal parameter errors between the runs' truth and any prior. Each dataset
holds one hidden effect, two, or none, and six runs at different speeds and positions (with known
disturbance pulses), three for training and three held out.

:func:`run_benchmark` diagnoses every dataset without access to the truth (only the runs and their
metadata) and scores top-1/top-3 attribution, false claims on null datasets, held-out gap shrink and
parameter recovery. The signal-to-noise ratio of a dataset is computed from a twin simulated without the
hidden effects (same noise): ``SNR = sqrt(E_with / E_without - 1)`` with ``E`` the training energy of the
nominal inverse-dynamics residual.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field

import numpy as np

from drakecreep.gap.diagnosis import DiagnosisConfig, diagnose, fit_effect
from drakecreep.gap.effects import idim_data
from drakecreep.gap.measured import EMPS_CONTROLLER, MeasuredMeta, MeasuredRun, SensorMeta

__all__ = ["HIDDEN_EFFECTS", "Dataset", "out_and_back", "score_rows", "draw_hidden", "draw_truth", "generate_dataset", "diagnose_dataset", "run_benchmark"]

#: Effects the generator may hide (quantization is always present and declared in the metadata).
HIDDEN_EFFECTS = ("stribeck", "asymmetric_friction", "position_friction", "lead_error", "cogging", "backlash",
                  "structural_mode", "control_delay", "load_friction", "disturbance_scale")

N_RUNS = 6
N_SAMPLES = 3000
DT = 1e-3
SUBSTEPS = 8
GTAU = 35.15


@dataclass
class Dataset:
    """Generated runs (train / held-out), the truth (hidden from the diagnosis) and the SNR."""

    seed: int
    hidden: tuple
    truth: dict
    train: list
    test: list
    snr: float = 0.0
    floor: dict = field(default_factory=dict)


def draw_truth(rng, hidden):
    """Draw the truth parameters for the hidden effects (and the nominal) from ``rng``."""
    M = rng.uniform(60.0, 120.0)
    tr = {"M": M, "Fv": rng.uniform(100.0, 300.0), "Fc": rng.uniform(10.0, 30.0), "offset": rng.uniform(-4, 4),
          "lead": float(rng.choice([2.5e-3, 5e-3, 1e-2])), "noise_N": rng.uniform(0.3, 1.5),
          "lowpass_noise_N": rng.uniform(0.1, 0.6), "encoder": float(rng.choice([5e-8, 1e-7])),
          "v_eps": 2e-4, "hidden": tuple(hidden)}
    p = {}
    for h in hidden:
        if h == "stribeck":
            p[h] = {"dFs_N": rng.uniform(0.4, 1.0) * tr["Fc"], "vs_m_s": rng.uniform(0.002, 0.01)}
        elif h == "asymmetric_friction":
            beta = rng.uniform(0.15, 0.4) * rng.choice([-1, 1])
            p[h] = {"beta": beta, "dFv_pos_N_s_m": 2 * beta * tr["Fv"], "coulomb_asym": rng.uniform(-0.1, 0.1)}
        elif h == "position_friction":
            p[h] = {"gamma": rng.uniform(0.2, 0.5) * rng.choice([-1, 1]), "width_m": rng.uniform(0.03, 0.08)}
        elif h == "lead_error":
            p[h] = {"amplitude_m": rng.uniform(0.5e-6, 4e-6), "phase": rng.uniform(0, 2 * np.pi),
                    "h2": rng.uniform(0.1, 0.4), "phase2": rng.uniform(0, 2 * np.pi), "h3": rng.uniform(0.03, 0.1)}
        elif h == "cogging":
            p[h] = {"amplitude_N": rng.uniform(1.5, 6.0), "order": int(rng.integers(1, 7)),
                    "phase": rng.uniform(0, 2 * np.pi), "h2": rng.uniform(0.1, 0.4), "h3": rng.uniform(0.03, 0.1)}
        elif h == "backlash":
            p[h] = {"lost_motion_m": rng.uniform(1e-5, 8e-5), "mass_share": rng.uniform(0.3, 0.6), "fn_Hz": 150.0}
        elif h == "structural_mode":
            p[h] = {"mass_share": rng.uniform(0.08, 0.25), "fn_Hz": rng.uniform(8.0, 40.0),
                    "zeta": rng.uniform(0.02, 0.08)}
        elif h == "control_delay":
            p[h] = {"delay_samples": int(rng.integers(1, 3)), "lag_s": rng.uniform(1e-4, 4e-4)}
        elif h == "load_friction":
            p[h] = {"mu": rng.uniform(0.03, 0.1)}
        elif h == "disturbance_scale":
            p[h] = {"scale_error": rng.uniform(0.1, 0.3) * rng.choice([-1, 1])}
    tr["effects"] = p
    return tr


def out_and_back(speed, x0, n=N_SAMPLES, dt=DT, leg=1.3, starts=(0.2, 1.7)):
    """Out-and-back reference [m]: two legs of ``leg`` seconds at ``speed`` (cosine ramps, 20 % each).

    Parameters
    ----------
    speed : float
        Cruise speed [m/s].
    x0 : float
        Start position [m].
    n, dt : int, float
        Samples and sample time.
    leg : float
        Duration of each leg [s].
    starts : tuple of float
        Start times of the out and the back leg [s].
    """
    t = np.arange(n) * dt
    s = np.zeros_like(t)
    ramp = 0.2
    for start, sign in zip(starts, (1.0, -1.0)):
        tau = np.clip((t - start) / leg, 0, 1)
        vshape = np.where(tau < ramp, 0.5 * (1 - np.cos(np.pi * tau / ramp)),
                          np.where(tau > 1 - ramp, 0.5 * (1 - np.cos(np.pi * (1 - tau) / ramp)), 1.0))
        vshape = vshape * ((t >= start) & (t <= start + leg))
        s = s + sign * np.cumsum(vshape) * dt
    return x0 + speed * s


def _profile(rng, n_runs):
    """Out-and-back references, speeds log-uniform and interleaved over train/held-out."""
    speeds = np.sort(np.exp(rng.uniform(np.log(0.005), np.log(0.15), n_runs)))
    order = np.concatenate([np.arange(0, n_runs, 2), np.arange(1, n_runs, 2)])  # train: even ranks
    speeds = speeds[order]
    refs, pulses = [], []
    for v in speeds:
        refs.append(out_and_back(v, rng.uniform(0.0, 0.12)))
        p = np.zeros(N_SAMPLES)
        for _ in range(3):
            k = int(rng.integers(100, N_SAMPLES - 100))
            p[k: k + 50] = rng.choice([-1, 1]) * rng.uniform(0.2, 0.6)  # volts added to the command
        pulses.append(p)
    return np.array(refs), np.array(pulses), speeds


def _simulate(truth, refs, pulses, noise, with_effects=True):
    """Vectorized closed-loop truth simulation of all runs (RK4 at DT/SUBSTEPS)."""
    S = refs.shape[0]
    eff = truth["effects"] if with_effects else {}
    M, Fv, Fc, off, veps = truth["M"], truth["Fv"], truth["Fc"], truth["offset"], truth["v_eps"]
    ctrl = EMPS_CONTROLLER
    kp, kv, sat = ctrl.kp, ctrl.kv, ctrl.saturation
    lead = truth["lead"]
    q_enc = truth["encoder"]
    two = "backlash" in eff or "structural_mode" in eff
    if "backlash" in eff:
        b = eff["backlash"]
        m2 = b["mass_share"] * M
        k_c = m2 * (2 * np.pi * b["fn_Hz"]) ** 2
        c_c = 2 * 0.1 * math.sqrt(k_c * m2)
        gap = b["lost_motion_m"] / 2
        fric_share = b["mass_share"]
    elif "structural_mode" in eff:
        b = eff["structural_mode"]
        m2 = b["mass_share"] * M
        k_c = m2 * (2 * np.pi * b["fn_Hz"]) ** 2
        c_c = 2 * b["zeta"] * math.sqrt(k_c * m2)
        gap, fric_share = 0.0, 0.0
    else:
        m2, k_c, c_c, gap, fric_share = 0.0, 0.0, 0.0, 0.0, 0.0
    M1 = M - m2
    xc = float(np.mean(refs))

    def friction(x, v, fdrive, share):
        sg = np.tanh(v / veps)
        fc = Fc * np.ones_like(v)
        fv = Fv * np.ones_like(v)
        if "asymmetric_friction" in eff:
            a = eff["asymmetric_friction"]
            fv = np.where(v > 0, Fv * (1 + a["beta"]), Fv * (1 - a["beta"]))
            fc = np.where(v > 0, Fc * (1 + a["coulomb_asym"]), Fc * (1 - a["coulomb_asym"]))
        if "position_friction" in eff:
            a = eff["position_friction"]
            fc = fc * (1 + a["gamma"] * np.tanh((x - xc) / a["width_m"]))
        if "load_friction" in eff:
            fc = fc + eff["load_friction"]["mu"] * np.abs(fdrive)
        f = fc * sg + fv * v + off
        if "stribeck" in eff:
            a = eff["stribeck"]
            f = f + a["dFs_N"] * np.exp(-np.abs(v / a["vs_m_s"]) ** 1.5) * sg
        if "cogging" in eff:
            a = eff["cogging"]
            th = 2 * np.pi * a["order"] * x / lead
            f = f + a["amplitude_N"] * (np.sin(th + a["phase"]) + a["h2"] * np.sin(2 * th) + a["h3"] * np.cos(3 * th))
        return share * f

    def deriv(y, fdrive):
        x1, v1, x2, v2 = y
        if two:
            d = x1 - x2
            if gap > 0:
                dz = np.where(d > gap, d - gap, np.where(d < -gap, d + gap, 0.0))
                fcpl = k_c * dz + c_c * (v1 - v2) * (dz != 0)
            else:
                fcpl = k_c * d + c_c * (v1 - v2)
            a1 = (fdrive - friction(x1, v1, fdrive, 1.0 - fric_share) - fcpl) / M1
            a2 = (fcpl - (friction(x2, v2, fdrive, fric_share) if fric_share > 0 else 0.0)) / m2
        else:
            a1 = (fdrive - friction(x1, v1, fdrive, 1.0)) / M
            a2 = a1
            v2 = v1
        return np.array([v1, a1, v2, a2])

    def measure(x):
        y = x
        if "lead_error" in eff:
            a = eff["lead_error"]
            th = 2 * np.pi * x / lead
            y = y + a["amplitude_m"] * (np.sin(th + a["phase"]) + a["h2"] * np.sin(2 * th + a["phase2"])
                                        + a["h3"] * np.sin(3 * th))
        return np.round(y / q_enc) * q_enc

    y = np.zeros((4, S))
    y[0] = refs[:, 0]
    y[2] = refs[:, 0]
    delay = eff.get("control_delay", {}).get("delay_samples", 0)
    lag = eff.get("control_delay", {}).get("lag_s", 0.0)
    scale = 1.0 + eff.get("disturbance_scale", {}).get("scale_error", 0.0)
    xm = np.zeros((S, N_SAMPLES))
    u_rec = np.zeros((S, N_SAMPLES))
    q_prev = measure(y[0])
    qf_prev = q_prev
    queue = [np.zeros(S) for _ in range(delay)]
    f_applied = np.zeros(S)
    h = DT / SUBSTEPS
    white, lowp = noise
    for k in range(N_SAMPLES):
        q = measure(y[0])
        qf = 0.5 * q + 0.5 * q_prev
        dq = (qf - qf_prev) / DT
        u = np.clip(kp * kv * (refs[:, k] - q) - kv * dq, -sat, sat)
        xm[:, k] = q
        u_rec[:, k] = u
        queue.append(u + pulses[:, k] * scale)
        cmd = GTAU * queue.pop(0) + white[:, k] + lowp[:, k]
        for _ in range(SUBSTEPS):
            if lag > 0:  # first-order current-loop lag, integrated with the substep
                f_applied = f_applied + (cmd - f_applied) * (1 - math.exp(-h / lag))
            else:
                f_applied = cmd
            k1 = deriv(y, f_applied)
            k2 = deriv(y + 0.5 * h * k1, f_applied)
            k3 = deriv(y + 0.5 * h * k2, f_applied)
            k4 = deriv(y + h * k3, f_applied)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        q_prev, qf_prev = q, qf
    return xm, u_rec


def _draw_hidden(rng):
    n_hidden = int(rng.choice([0, 1, 2], p=[0.3, 0.45, 0.25]))
    return tuple(sorted(rng.choice(HIDDEN_EFFECTS, size=n_hidden, replace=False).tolist()))


def draw_hidden(seed):
    """The hidden effects :func:`generate_dataset` draws for ``seed`` (none 30 %, one 45 %, two 25 %)."""
    return _draw_hidden(np.random.default_rng(seed))


def generate_dataset(seed, hidden=None, n_runs=N_RUNS):
    """Generate one dataset (training and held-out runs) with hidden effects.

    Parameters
    ----------
    seed : int
        Seeds everything (the draw of the hidden effects when ``hidden`` is None, truth, profiles, noise).
    hidden : sequence of str, optional
        Force the hidden effects; default: none (30 %), one (45 %) or two (25 %) drawn from
        :data:`HIDDEN_EFFECTS`.
    n_runs : int
        Runs (even count; half for training).

    Returns
    -------
    Dataset
    """
    rng = np.random.default_rng(seed)
    drawn = _draw_hidden(rng)
    hidden = drawn if hidden is None else hidden
    truth = draw_truth(rng, tuple(hidden))
    refs, pulses, speeds = _profile(rng, n_runs)
    white = rng.normal(0.0, truth["noise_N"], (n_runs, N_SAMPLES))
    lp = rng.normal(0.0, 1.0, (n_runs, N_SAMPLES))
    from scipy import signal

    b, a = signal.butter(2, 5.0 / 500.0)
    lp = signal.lfilter(b, a, lp, axis=1)
    lp = truth["lowpass_noise_N"] * lp / max(float(np.std(lp)), 1e-12)
    meta = MeasuredMeta(u_units="V", u_gain=GTAU, controller=EMPS_CONTROLLER,
                        sensors=SensorMeta(encoder_resolution=truth["encoder"]),
                        source=f"drakecreep gap benchmark, seed {seed}")
    t = np.arange(N_SAMPLES) * DT
    out = {}
    for tag, with_eff in (("with", True), ("without", False)):
        xm, u = _simulate(truth, refs, pulses, (white, lp), with_effects=with_eff)
        runs = [MeasuredRun(t=t, x_ref=refs[i], x_motor=xm[i], u=u[i], f_ext=GTAU * pulses[i], meta=meta,
                            label=f"run{i}") for i in range(n_runs)]
        out[tag] = runs
    half = n_runs // 2
    ds = Dataset(seed=seed, hidden=tuple(hidden), truth=truth, train=out["with"][:half], test=out["with"][half:])
    ds.truth["speeds_m_s"] = speeds.tolist()
    # SNR and noise floor from the effect-free twin (scoring only; never given to the diagnosis)
    cfg = DiagnosisConfig(screw_lead=truth["lead"])
    ctx = cfg.context(ds.train)
    vm = cfg.v_min_frac * ctx.v_max
    tw_train, tw_test = idim_data(out["without"][:half], v_min=vm), idim_data(out["without"][half:], v_min=vm)
    w_train, w_test = idim_data(ds.train, v_min=vm), idim_data(ds.test, v_min=vm)
    f_tw = fit_effect((), tw_train, tw_test, ctx, {})
    f_w = fit_effect((), w_train, w_test, ctx, {})
    ds.snr = float(math.sqrt(max(f_w.sse_train / f_tw.sse_train - 1.0, 0.0)))
    ds.floor = {"idim_test_sse": f_tw.sse_test, "idim_test_n": tw_test.n}
    return ds


def diagnose_dataset(ds, replay=True):
    """Diagnose a dataset with only what a user would have: the runs, their metadata and the screw lead."""
    return diagnose(ds.train, ds.test, DiagnosisConfig(screw_lead=ds.truth["lead"]), replay=replay)


_RECOVERY = {  # effect -> (truth key, fitted key, transform of fitted params)
    "stribeck": ("dFs_N", lambda p: p["stribeck.dFs_N"]["value"]),
    "asymmetric_friction": ("dFv_pos_N_s_m", lambda p: p["asymmetric_friction.dFv_pos_N_s_m"]["value"]),
    "lead_error": ("amplitude_m", lambda p: math.hypot(p["lead_error.e_sin_m"]["value"], p["lead_error.e_cos_m"]["value"])),
    "cogging": ("amplitude_N", lambda p: math.hypot(p["cogging.a_sin_N"]["value"], p["cogging.a_cos_N"]["value"])),
    "backlash": ("lost_motion_m", lambda p: p["backlash.lost_motion_m"]["value"]),
    "structural_mode": ("fn_Hz", lambda p: p["structural_mode.fn_Hz"]["value"]),
    "control_delay": ("delay_samples", lambda p: p["control_delay.delay_samples"]["value"]),
    "load_friction": ("mu", lambda p: p["load_friction.mu"]["value"]),
    "disturbance_scale": ("scale_error", lambda p: p["disturbance_scale.scale_error"]["value"]),
}


def run_benchmark(n=20, seed=0, replay=True, progress=False):
    """Generate ``n`` datasets (seeds ``seed .. seed+n-1``), diagnose each blind, score.

    Returns
    -------
    dict
        ``scores`` (top1, top3 over datasets with hidden effects, also restricted to SNR >= 3;
        false-claim rate on null datasets; median shrink; parameter recovery) and ``datasets`` rows.
    """
    rows = []
    for i in range(n):
        ds = generate_dataset(seed + i)
        res = diagnose_dataset(ds, replay=replay)
        ranked = [r["effect"] for r in res["ranking"]]
        claimed = res["claimed"]
        floor_rms = math.sqrt(ds.floor["idim_test_sse"] / ds.floor["idim_test_n"])
        b, a = res["idim_rms_N"]["before"], res["idim_rms_N"]["after"]
        ex_b = math.sqrt(max(b * b - floor_rms ** 2, 0.0))
        ex_a = math.sqrt(max(a * a - floor_rms ** 2, 0.0))
        row = {"seed": seed + i, "hidden": list(ds.hidden), "snr": ds.snr, "claimed": claimed,
               "top3": ranked[:3], "idim_rms_N": {"before": b, "after": a, "noise_floor": floor_rms},
               "excess_shrink": (1 - ex_a / ex_b) if ex_b > 0 else None}
        if replay and "shrink" in res:
            sb, sa = res["shrink"]["before"], res["shrink"]["after"]
            row["replay_rms"] = {"before": sb, "after": sa}
        rec = {}
        if len(ds.hidden) == 1 and claimed and claimed[0] == ds.hidden[0] and ds.hidden[0] in _RECOVERY:
            key, get = _RECOVERY[ds.hidden[0]]
            top = res["ranking"][0]
            truth = ds.truth["effects"][ds.hidden[0]][key]
            try:
                fitted = get(top["params"])
                rec = {"truth": truth, "fitted": fitted, "rel_error": abs(fitted - truth) / abs(truth)}
            except KeyError:
                rec = {}
        row["recovery"] = rec
        rows.append(row)
        if progress:
            print(f"[gap-benchmark] {i + 1}/{n} seed {seed + i}: hidden {list(ds.hidden) or 'none'} "
                  f"(SNR {ds.snr:.1f}) -> claimed {claimed or 'nothing'}", file=sys.stderr, flush=True)
    return {"scores": score_rows(rows), "datasets": rows}


def score_rows(rows):
    """Aggregate scores of benchmark rows (see :func:`run_benchmark`)."""

    def rate(sel, ok):
        sel = list(sel)
        return {"rate": (sum(ok(r) for r in sel) / len(sel)) if sel else None, "n": len(sel)}

    eff = [r for r in rows if r["hidden"]]
    strong = [r for r in eff if r["snr"] >= 3]
    null = [r for r in rows if not r["hidden"]]
    top1 = lambda r: bool(r["claimed"]) and r["claimed"][0] in r["hidden"]  # noqa: E731
    top3 = lambda r: any(h in r["top3"] for h in r["hidden"])  # noqa: E731
    shrinks = [r["excess_shrink"] for r in eff if r["excess_shrink"] is not None and r["snr"] >= 3]
    raw = [1 - r["idim_rms_N"]["after"] / r["idim_rms_N"]["before"] for r in eff if r["snr"] >= 3]
    rec = {}
    for r in eff:
        if r["recovery"]:
            rec.setdefault(r["hidden"][0], []).append(r["recovery"]["rel_error"])
    wrong = [r for r in eff if any(c not in r["hidden"] for c in r["claimed"])]
    return {
        "n_datasets": len(rows),
        "top1_all": rate(eff, top1), "top1_snr3": rate(strong, top1),
        "top3_all": rate(eff, top3), "top3_snr3": rate(strong, top3),
        "false_claims_null": rate(null, lambda r: bool(r["claimed"])),
        "wrong_claims_with_effects": {"rate": len(wrong) / len(eff) if eff else None, "n": len(eff)},
        "median_excess_shrink_snr3": float(np.median(shrinks)) if shrinks else None,
        "median_raw_idim_shrink_snr3": float(np.median(raw)) if raw else None,
        "parameter_recovery_median_rel_error": {k: float(np.median(v)) for k, v in rec.items()},
    }
