"""A truth simulator richer than the diagnosis model: independent "measured" data for the gap benchmark.

Why a second implementation of the equations
--------------------------------------------
The gap diagnosis is scored on data whose answer is known. If those data came from the model under test
(the former rigid replay of :mod:`drakecreep.gap.replay`, or the Drake diagram
the diagnosis will replay through), every modelling shortcut of that model would be invisible: the truth
would share its integrator, its friction law and its sensor model, and a benchmark could not tell a good
diagnosis from one that only recognises its own equations. This module is therefore written separately
(vectorised NumPy, no import of the diagnosis model) and is *richer* than any model the diagnosis fits:

* **two bodies with an axial mode**: a motor-side mass ``m1`` (rotor, coupling and screw reflected to the
  table) and the table ``m2`` on an axial spring ``k, c`` (screw + nut + bearing in series). ``flexible``
  axes have the mode at 150-300 Hz (the paper rig: about 180 Hz), ``rigid`` axes at 500-700 Hz, at table
  position :data:`CHAIN_AT`; the fixed-free shaft, a quarter of the chain's compliance there, softens as the
  nut moves away from the thrust bearing (:meth:`Truth.chain`; a constant spring until session 75, which the
  replay's chain did not match away from 0.1 m: docs/gap_benchmark.md, 3cb);
* **LuGre friction on the table** (bristle state ``z``, ``sigma0``, ``sigma1``, viscous ``Fv``), with a
  small Stribeck rise (``Fs/Fc`` <= 1.05) always present; bearing friction (smooth Coulomb + viscous) on
  the motor side;
* **run-to-run drift**: the friction levels of each run follow a random walk over the runs (1-4 % per
  run); the runs are interleaved between training, held-out and audit sets;
* **sensor realism**: motor encoder and linear scale quantisation, a current loop (first-order lag
  50-150 us), white and low-pass (5 Hz) unknown force noise;
* the **controller kinds** of the metadata schema: ``p_p_cascade`` (the EMPS law at 1 kHz, ``u`` in V
  through ``u_gain``) and ``drakecreep`` (the project's cascade: position P with speed feed-forward at
  1 kHz, speed PI at 4 kHz on the encoder's backward difference, conditional integration, force output).

Integration: semi-implicit (symplectic) Euler at ``h = 42 us`` (24 substeps per 1 ms sample), every force of a
kick, the current loop's output included, taken at the substep's start; the LuGre
bristle state is advanced with the exact solution of ``dz/dt = v - |v| z sigma0 / g(v)`` for ``v`` held
over the substep, so the stiff bristle dynamics stay stable at any ``sigma0``. Near a loop's stability limit
the oscillation's amplitude is within 17 % of a step four times finer (``tests/gap/test_truth.py``). Until
session 76 each kick took the force of its substep's end (the lag advanced first), a substep early, at 12
substeps: 4-5 times the converged amplitude there. Nothing here is the diagnosis model's exact per-sample rigid
step or its ``sign`` friction.

Withheld effects
----------------
The right answer of each withheld effect is decided by the benchmark (:mod:`drakecreep.gap.benchmark`, which
maps them onto the candidates of the diagnosis); this module only simulates them.

* with a candidate in the Drake diagnosis's library (:data:`LIBRARY_EFFECTS`): a strong Stribeck drop,
  asymmetric friction, position-dependent friction (a smooth ``tanh`` ramp, not the library's periodic
  level), a lead error with harmonics (kinematic: the nut follows the screw angle with a periodic error, so
  it acts through the table's inertia and the spring, whose force reaches the motor through the error's
  gearing, ``F (1 + e')``; it shows on the scale), cogging with harmonics (motor
  side), an extra structural mode (a payload on a spring, 10-120 Hz), a control delay of 1-3 samples, a
  bearing defect (a force periodic in screw angle at a *non-integer* order 2.3-3.7: periodic in position,
  with a period that is not a divisor of the lead), a force ripple at a fixed time frequency (6-25 Hz,
  e.g. a pump), a load-dependent nut friction (``mu |F_axial|``, ``mu`` 0.2-0.4, with ``F_axial`` the
  screw's spring force: the table's LuGre force is scaled by ``1 + mu |F_axial| / F_c``, so in steady
  sliding the Coulomb level is ``F_c + mu |F_axial|``) and a **drive-gain saturation**, the drive force
  ``F_k tanh(F_cmd / F_k)`` instead of the commanded ``F_cmd`` (the recorded ``u`` is the command; the
  candidate's saturation has another shape, ``F / sqrt(1 + (F / F_k)^2)``);
* outside the library (:data:`OUT_OF_LIBRARY`; the right answer is "unexplained"): a **cable carrier**, a
  conservative force of the table position (linear and quadratic about a neutral position, the same in
  both directions of motion: not friction, not periodic), and **backlash**, a lost motion of 4-20 um in the
  screw-nut chain (a dead zone of the axial spring: no force until the balls bear; the diagnosis ranks no
  backlash, ``drake_effects.NOT_RANKED``).

Cross-tests (``tests/gap/test_truth.py``, with the measured differences and the tolerances):

* **against the Drake diagram**: the PI cascade on the project's default drive (parameters mapped onto
  the two bodies; no motor drag or nut friction, which the truth does not have; no noise, drift or
  effect), unloaded, 10 mm/s: motor positions 0.07 um RMS apart (session 75) against a 1.9 um RMS tracking error,
  force commands 0.21 N RMS apart against 7.3 N RMS;
* **against the exact rigid replay** (:func:`drakecreep.gap.replay.replay`, the P-P cascade): one stiff
  body, ``Fs = Fc``, stiff bristles: positions 0.2-1.1 um RMS apart against 39-786 um of tracking error.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
from scipy import signal

from drakecreep.errors import InputError
from drakecreep.gap.measured import ControllerMeta, EMPS_CONTROLLER, MeasuredMeta, MeasuredRun, SensorMeta
from drakecreep.params import ControllerParams, DriveParams, ScrewParams

__all__ = [
    "LIBRARY_EFFECTS",
    "NO_CANDIDATE",
    "OUT_OF_LIBRARY",
    "WITHHELD",
    "CONTROLLER_KINDS",
    "AXES",
    "DT",
    "SUBSTEPS",
    "GTAU",
    "Truth",
    "draw_truth",
    "out_and_back",
    "draw_profiles",
    "noise_draws",
    "simulate_batch",
    "simulate_truth",
    "make_runs",
]

#: Withheld effects the Drake diagnosis has a candidate for (the benchmark maps each onto its candidate).
LIBRARY_EFFECTS = ("stribeck", "asymmetric_friction", "position_friction", "lead_error", "cogging",
                   "structural_mode", "control_delay", "bearing_defect", "time_ripple", "load_friction",
                   "drive_saturation")
#: Withheld effects whose kind the diagnosis knows but never ranks (no candidate in its replay axis): none since
#: the load-dependent friction got its candidate (it and the drive saturation, out of the library before, are
#: last in :data:`LIBRARY_EFFECTS`, so the benchmark's seeds still draw the same datasets).
NO_CANDIDATE = ()
#: Withheld effects outside the diagnosis's library (the answer must be "unexplained").
OUT_OF_LIBRARY = ("cable_carrier", "backlash")
WITHHELD = LIBRARY_EFFECTS + NO_CANDIDATE + OUT_OF_LIBRARY
CONTROLLER_KINDS = ("p_p_cascade", "drakecreep")
AXES = ("flexible", "rigid")

#: the table position [m] at which a drawn truth's axial chain has its drawn stiffness and damping (``k_axial``,
#: ``c_axial``; the benchmark's params file matches the chain there, :func:`drakecreep.gap.benchmark.declared_params`)
CHAIN_AT = 0.1
#: the shaft's share of a drawn truth's chain compliance at :data:`CHAIN_AT` (thrust bearing and nut the rest)
SHAFT_SHARE = 0.25
#: thrust bearing to nut [m] at table position 0: the params files' default screw's
NUT_START = ScrewParams().nut_start_distance

DT = 1e-3          # recording and position-loop sample time [s]
SUBSTEPS = 24      # integration substeps per sample (h = 42 us; a multiple of VEL_DIV)
GTAU = 35.15       # N/V of the P-P cascade drive (EMPS)
VEL_DIV = 4        # PI cascade: speed-loop ticks per sample (4 kHz)


@dataclass
class Truth:
    """Every parameter of one truth (SI). Hidden from the diagnosis; the benchmark scores against it."""

    kind: str
    axis: str
    M: float
    table_share: float
    f_axial: float
    zeta_axial: float
    lead: float
    Fc: float
    Fv: float
    motor_friction_share: float
    offset: float
    Fs_ratio: float
    vs: float
    sigma0: float
    sigma1: float
    current_lag: float
    noise_N: float
    lowpass_noise_N: float
    encoder: float
    scale: float
    drift_sd: float
    effects: dict = field(default_factory=dict)
    gains: dict | None = None  # PI cascade gains {kp, kv, ki, ff, sat}; default from the mass (40 Hz speed loop)
    shaft_share: float = SHAFT_SHARE  # the shaft's share of the chain's compliance at chain_at (0: a constant spring)
    chain_at: float = CHAIN_AT  # table position [m] where the chain is k_axial, c_axial
    nut_start: float = NUT_START  # thrust bearing to nut [m] at table position 0

    @property
    def m1(self):
        return (1.0 - self.table_share) * self.M

    @property
    def m2(self):
        return self.table_share * self.M

    @property
    def k_axial(self):
        mu = self.m1 * self.m2 / self.M
        return mu * (2 * math.pi * self.f_axial) ** 2

    @property
    def c_axial(self):
        mu = self.m1 * self.m2 / self.M
        return 2 * self.zeta_axial * math.sqrt(self.k_axial * mu)

    def chain(self, x):
        """``(stiffness [N/m], damping [N s/m])`` of the axial chain with the table at ``x`` [m] (floats or arrays).

        Thrust bearing and nut in series with a fixed-free shaft, ``E A / a``, which softens as the nut's distance
        ``a = nut_start + x`` from the bearing grows; the shaft's share of the compliance is ``shaft_share`` at
        ``chain_at``, where the chain is ``k_axial``, ``c_axial``. The shaft is undamped, so the damping of the
        bearing and nut reaches the table as ``c_axial (k / k_axial)^2`` (a chain of elements in series).
        """
        return _chain(self.k_axial, self.c_axial, self.shaft_share, self.nut_start, self.nut_start + self.chain_at, x)

    def to_dict(self):
        return dataclasses.asdict(self)


def _chain(k, c, share, a0, a_ref, x):
    """:meth:`Truth.chain` from its columns (arrays in :func:`simulate_batch`)."""
    stiffness = k / ((1.0 - share) + share * np.maximum(a0 + x, 0.0) / a_ref)
    return stiffness, c * (stiffness / k) ** 2


def draw_truth(rng, kind, axis, withheld=()):
    """Draw a truth for a controller ``kind`` and an ``axis`` (flexible / rigid) with ``withheld`` effects.

    Parameters
    ----------
    rng : numpy.random.Generator
    kind : str
        One of :data:`CONTROLLER_KINDS`.
    axis : str
        One of :data:`AXES`.
    withheld : sequence of str
        Effects of :data:`WITHHELD`.

    Returns
    -------
    Truth
    """
    if kind not in CONTROLLER_KINDS:
        raise InputError("kind", kind, "one of " + ", ".join(CONTROLLER_KINDS))
    if axis not in AXES:
        raise InputError("axis", axis, "one of " + ", ".join(AXES))
    for w in withheld:
        if w not in WITHHELD:
            raise InputError("withheld", w, "one of " + ", ".join(WITHHELD))
    lead = float(rng.choice([2.5e-3, 5e-3, 1e-2]))
    f_ax = rng.uniform(150.0, 300.0) if axis == "flexible" else rng.uniform(500.0, 700.0)
    Fc = rng.uniform(10.0, 30.0)
    tr = Truth(kind=kind, axis=axis, M=rng.uniform(60.0, 120.0), table_share=rng.uniform(0.35, 0.6),
               f_axial=f_ax, zeta_axial=rng.uniform(0.05, 0.1), lead=lead, Fc=Fc, Fv=rng.uniform(100.0, 300.0),
               motor_friction_share=rng.uniform(0.2, 0.4), offset=rng.uniform(-4.0, 4.0),
               Fs_ratio=rng.uniform(1.0, 1.05), vs=rng.uniform(5e-4, 2e-3), sigma0=rng.uniform(2e6, 2e7),
               sigma1=0.0, current_lag=rng.uniform(5e-5, 1.5e-4), noise_N=rng.uniform(0.3, 1.5),
               lowpass_noise_N=rng.uniform(0.1, 0.6), encoder=float(rng.choice([2e-8, 5e-8, 1e-7])),
               scale=float(rng.choice([5e-8, 1e-7])), drift_sd=rng.uniform(0.01, 0.04))
    tr.sigma1 = 2 * 0.5 * math.sqrt(tr.sigma0 * tr.m2)  # bristles critically damped on the table mass
    p = {}
    sgn = lambda: float(rng.choice([-1.0, 1.0]))  # noqa: E731
    for h in withheld:
        if h == "stribeck":
            p[h] = {"Fs_ratio": rng.uniform(1.6, 2.5), "vs_m_s": rng.uniform(0.003, 0.012)}
        elif h == "asymmetric_friction":
            p[h] = {"beta": rng.uniform(0.25, 0.5) * sgn(), "coulomb_asym": rng.uniform(-0.05, 0.05)}
        elif h == "position_friction":
            p[h] = {"gamma": rng.uniform(0.25, 0.5) * sgn(), "width_m": rng.uniform(0.02, 0.06)}
        elif h == "lead_error":
            p[h] = {"amplitude_m": rng.uniform(4e-6, 12e-6), "phase": rng.uniform(0, 2 * np.pi),
                    "h2": rng.uniform(0.1, 0.4), "phase2": rng.uniform(0, 2 * np.pi)}
        elif h == "cogging":
            p[h] = {"amplitude_N": rng.uniform(2.0, 6.0), "order": int(rng.integers(1, 7)),
                    "phase": rng.uniform(0, 2 * np.pi), "h2": rng.uniform(0.1, 0.4)}
        elif h == "structural_mode":
            p[h] = {"mass_share": rng.uniform(0.2, 0.4), "fn_Hz": rng.uniform(10.0, 120.0),
                    "zeta": rng.uniform(0.01, 0.05)}
        elif h == "control_delay":
            p[h] = {"delay_samples": int(rng.integers(1, 4))}
        elif h == "load_friction":
            p[h] = {"mu": rng.uniform(0.2, 0.4)}
        elif h == "bearing_defect":
            o = int(rng.integers(2, 4)) + rng.uniform(0.3, 0.7)
            p[h] = {"amplitude_N": rng.uniform(2.0, 6.0), "order": o, "phase": rng.uniform(0, 2 * np.pi)}
        elif h == "time_ripple":
            p[h] = {"amplitude_N": rng.uniform(2.0, 6.0), "freq_Hz": rng.uniform(6.0, 25.0),
                    "phase": rng.uniform(0, 2 * np.pi)}
        elif h == "cable_carrier":
            # assumption (no rig data): a 0.1-0.3 m travel carrier pulls 8-25 N at 0.1 m from its neutral point
            p[h] = {"stiffness_N_m": rng.uniform(80.0, 250.0) * sgn(), "quadratic_N": rng.uniform(2.0, 6.0) * sgn(),
                    "neutral_m": rng.uniform(0.0, 0.15)}
        elif h == "backlash":
            # assumption: the lost motion of a ball screw without preload (or with a worn one), 4-20 um in all
            p[h] = {"lost_motion_m": rng.uniform(4e-6, 20e-6)}
        elif h == "drive_saturation":
            # assumption: the drive's force constant falls off above F_k (tanh), F_k 60-160 N (a few times the
            # friction level of these axes, so the larger accelerations and speeds reach it)
            p[h] = {"knee_N": rng.uniform(60.0, 160.0)}
    tr.effects = p
    return tr


def out_and_back(speed, x0, n=3000, dt=DT, leg=1.3, starts=(0.2, 1.7)):
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


def draw_profiles(rng, n_runs, n=3000):
    """References (out-and-back, speeds log-uniform 5-150 mm/s, shuffled) and known force pulses [N] (10-50 ms)."""
    speeds = np.exp(rng.uniform(np.log(0.005), np.log(0.15), n_runs))
    refs, pulses = [], []
    r = n / 3000.0  # shorter runs: the same out-and-back, faster
    for v in speeds:
        refs.append(out_and_back(v, rng.uniform(0.0, 0.12), n=n, leg=1.3 * r, starts=(0.2 * r, 1.7 * r)))
        p = np.zeros(n)
        for _ in range(3):
            k = int(rng.integers(100, n - 100))
            p[k: k + int(rng.integers(10, 51))] = rng.choice([-1, 1]) * rng.uniform(7.0, 20.0)
        pulses.append(p)
    return np.array(refs), np.array(pulses), speeds


def _controller_gains(tr):
    if tr.kind == "p_p_cascade":
        return {"kp": EMPS_CONTROLLER.kp, "kv": EMPS_CONTROLLER.kv, "sat": EMPS_CONTROLLER.saturation}
    if tr.gains is not None:
        return dict(tr.gains)
    wv = 2 * math.pi * 40.0  # speed-loop bandwidth [rad/s]
    return {"kp": wv / 5.0, "kv": tr.M * wv, "ki": tr.M * wv * wv / 5.0, "ff": 1.0, "sat": 2000.0}


def noise_draws(tr, n_runs, n, rng_noise):
    """Drift multipliers ``(runs,)`` and unknown force noise ``(runs, n)`` [N] of one truth's runs."""
    drift = 1.0 + np.cumsum(rng_noise.normal(0.0, tr.drift_sd, n_runs))
    white = rng_noise.normal(0.0, tr.noise_N, (n_runs, n))
    lp = rng_noise.normal(0.0, 1.0, (n_runs, n))
    b, a = signal.butter(2, 5.0 / (0.5 / DT))
    lp = signal.lfilter(b, a, lp, axis=1)
    lp = tr.lowpass_noise_N * lp / max(float(np.std(lp)), 1e-12)
    return drift, white + lp


def _columns(jobs):
    """Per-column parameter arrays of a batch (see :func:`simulate_batch`)."""
    cols = {}

    def put(name, values):
        cols.setdefault(name, []).extend(values)

    for tr, refs, pulses, drift, noise, with_effects in jobs:
        S = refs.shape[0]
        eff = tr.effects if with_effects else {}
        g = _controller_gains(tr)
        one = lambda v: [float(v)] * S  # noqa: E731
        put("pp", one(tr.kind == "p_p_cascade"))
        put("gain", one(GTAU if tr.kind == "p_p_cascade" else 1.0))
        for k_ in ("kp", "kv", "sat"):
            put(k_, one(g[k_]))
        put("ki", one(g.get("ki", 0.0)))
        put("ff", one(g.get("ff", 0.0)))
        sm = eff.get("structural_mode")
        mp = sm["mass_share"] * tr.m2 if sm else 0.0
        put("mp", one(mp))
        put("kpl", one(mp * (2 * math.pi * sm["fn_Hz"]) ** 2 if sm else 0.0))
        put("cpl", one(2 * sm["zeta"] * math.sqrt(mp * (2 * math.pi * sm["fn_Hz"]) ** 2 * mp) if sm else 0.0))
        put("m1", one(tr.m1))
        put("m2", one(tr.m2 - mp))
        put("k", one(tr.k_axial))
        put("c", one(tr.c_axial))
        put("shaft_share", one(tr.shaft_share))
        put("a0", one(tr.nut_start))
        put("a_ref", one(tr.nut_start + tr.chain_at))
        sh = tr.motor_friction_share
        put("Fc_m", list(sh * tr.Fc * drift))
        put("Fv_m", list(sh * tr.Fv * drift))
        put("Fc_t", list((1 - sh) * tr.Fc * drift))
        put("Fv_t", list((1 - sh) * tr.Fv * drift))
        put("offset", one(tr.offset))
        st = eff.get("stribeck")
        put("Fs_ratio", one(st["Fs_ratio"] if st else tr.Fs_ratio))
        put("vs", one(st["vs_m_s"] if st else tr.vs))
        put("sigma0", one(tr.sigma0))
        put("sigma1", one(tr.sigma1))
        put("lag", one(tr.current_lag))
        put("enc", one(tr.encoder))
        put("scale", one(tr.scale))
        put("lead", one(tr.lead))
        put("xc", one(float(np.mean(refs))))
        e = eff.get("asymmetric_friction", {})
        put("beta", one(e.get("beta", 0.0)))
        put("casym", one(e.get("coulomb_asym", 0.0)))
        e = eff.get("position_friction", {})
        put("gamma", one(e.get("gamma", 0.0)))
        put("width", one(e.get("width_m", 1.0)))
        put("mu", one(eff.get("load_friction", {}).get("mu", 0.0)))
        e = eff.get("lead_error", {})
        for k_ in ("amplitude_m", "phase", "h2", "phase2"):
            put("le_" + k_, one(e.get(k_, 0.0)))
        e = eff.get("cogging", {})
        for k_ in ("amplitude_N", "order", "phase", "h2"):
            put("cg_" + k_, one(e.get(k_, 0.0)))
        e = eff.get("bearing_defect", {})
        for k_ in ("amplitude_N", "order", "phase"):
            put("bd_" + k_, one(e.get(k_, 0.0)))
        e = eff.get("time_ripple", {})
        for k_ in ("amplitude_N", "freq_Hz", "phase"):
            put("tr_" + k_, one(e.get(k_, 0.0)))
        put("delay", one(eff.get("control_delay", {}).get("delay_samples", 0)))
        e = eff.get("cable_carrier", {})
        put("cc_k", one(e.get("stiffness_N_m", 0.0)))
        put("cc_q", one(e.get("quadratic_N", 0.0)))
        put("cc_x0", one(e.get("neutral_m", 0.0)))
        put("knee", one(eff.get("drive_saturation", {}).get("knee_N", 0.0)))
        put("bl", one(0.5 * eff.get("backlash", {}).get("lost_motion_m", 0.0)))
    return {k: np.array(v) for k, v in cols.items()}


def simulate_batch(jobs, skip_zero_terms=True):
    """Closed-loop simulation of many runs of many truths at once (one column per run).

    Parameters
    ----------
    jobs : sequence of tuple
        ``(truth, refs, pulses, drift, noise, with_effects)``: a :class:`Truth`, ``(runs, n)`` references [m],
        known external forces [N], the drift multipliers and unknown force noise of :func:`noise_draws`,
        and whether the truth's withheld effects are on (False: the effect-free twin). All jobs have the
        same ``n``.
    skip_zero_terms : bool
        Leave out the terms that are zero in every column (the same numbers, bit for bit; False evaluates
        every term, the reference ``tests/gap/test_truth.py`` and ``analysis/bench_truth.py`` hold it to).

    Returns
    -------
    list of dict
        Per job: ``x_motor``, ``x_table`` (quantised), ``u`` (controller output: V for the P-P cascade,
        N for the PI cascade), ``(runs, n)`` each.
    """
    p = _columns(jobs)
    refs = np.concatenate([j[1] for j in jobs])
    pulses = np.concatenate([j[2] for j in jobs])
    noise = np.concatenate([j[4] for j in jobs])
    S, n = refs.shape
    v_ref = np.gradient(refs, DT, axis=1)
    h = DT / SUBSTEPS
    sub = SUBSTEPS // VEL_DIV
    tv = DT / VEL_DIV
    lagc = 1.0 - np.exp(-h / p["lag"])
    pp = p["pp"] > 0.5
    mp_safe = np.where(p["mp"] > 0, p["mp"], 1.0)
    # terms that are zero in every column are skipped: the same numbers (a zero term adds +-0), fewer numpy calls
    every = not skip_zero_terms
    has_le = every or bool(np.any(p["le_amplitude_m"] != 0))
    has_knee = every or bool(np.any(p["knee"] > 0))
    knee_safe = np.where(p["knee"] > 0, p["knee"], 1.0)
    has_cc = every or bool(np.any(p["cc_k"] != 0) or np.any(p["cc_q"] != 0))
    has_bl = every or bool(np.any(p["bl"] > 0))
    has_cg = every or bool(np.any(p["cg_amplitude_N"] != 0))
    has_bd = every or bool(np.any(p["bd_amplitude_N"] != 0))
    has_tr = every or bool(np.any(p["tr_amplitude_N"] != 0))
    has_casym = every or bool(np.any(p["casym"] != 0))
    has_gamma = every or bool(np.any(p["gamma"] != 0))
    has_mu = every or bool(np.any(p["mu"] != 0))
    has_beta = every or bool(np.any(p["beta"] != 0))
    has_pl = every or bool(np.any(p["kpl"] != 0) or np.any(p["cpl"] != 0))
    w_lead = 2 * np.pi / p["lead"]
    v_eps = 1e-4

    def lead_err(x):
        th = w_lead * x
        return p["le_amplitude_m"] * (np.sin(th + p["le_phase"]) + p["le_h2"] * np.sin(2 * th + p["le_phase2"]))

    def lead_err_slope(x):
        th = w_lead * x
        return p["le_amplitude_m"] * w_lead * (np.cos(th + p["le_phase"])
                                               + 2 * p["le_h2"] * np.cos(2 * th + p["le_phase2"]))

    x1 = refs[:, 0].copy()
    v1 = np.zeros(S)
    x2 = x1 + (lead_err(x1) if has_le else 0.0)
    v2 = np.zeros(S)
    xp, vp = x2.copy(), np.zeros(S)
    z = np.zeros(S)
    f_app = np.zeros(S)
    enc = lambda x: np.round(x / p["enc"]) * p["enc"]  # noqa: E731
    xm, xt, u_rec = np.empty((S, n)), np.empty((S, n)), np.empty((S, n))
    q_prev = enc(x1)
    q_prev_sample = q_prev.copy()
    qf_prev = q_prev.copy()
    integ = np.zeros(S)
    v_cmd = np.zeros(S)
    out = np.zeros(S)
    dmax = int(p["delay"].max()) * VEL_DIV
    ring = np.zeros((dmax + 1, S))
    dticks = (p["delay"] * VEL_DIV).astype(int)
    cols = np.arange(S)
    tick = 0
    for kk in range(n):
        for j in range(VEL_DIV):
            q = enc(x1)
            if j == 0:
                # P-P cascade (1 kHz): u = kp kv (r - q) - kv d/dt(0.5 q + 0.5 q_prev)
                qf = 0.5 * q + 0.5 * q_prev_sample
                out_pp = np.clip(p["kp"] * p["kv"] * (refs[:, kk] - q) - p["kv"] * (qf - qf_prev) / DT,
                                 -p["sat"], p["sat"])
                qf_prev, q_prev_sample = qf, q
                v_cmd = p["kp"] * (refs[:, kk] - q) + p["ff"] * v_ref[:, kk]
            # PI cascade speed loop (4 kHz), conditional integration
            err = v_cmd - (q - q_prev) / tv
            raw = p["kv"] * err + integ + p["ki"] * err * tv
            integ = np.where(np.abs(raw) >= p["sat"], integ, integ + p["ki"] * err * tv)
            out_pi = np.clip(p["kv"] * err + integ, -p["sat"], p["sat"])
            out = np.where(pp, out_pp if j == 0 else out, out_pi) if j == 0 else np.where(pp, out, out_pi)
            q_prev = q
            if j == 0:
                xm[:, kk] = q
                xt[:, kk] = np.round(x2 / p["scale"]) * p["scale"]
                u_rec[:, kk] = out
            ring[tick % (dmax + 1)] = out
            applied = ring[(tick - dticks) % (dmax + 1), cols] if dmax else out
            tick += 1
            drive = p["gain"] * applied
            if has_knee:
                drive = np.where(p["knee"] > 0, p["knee"] * np.tanh(drive / knee_safe), drive)
            cmd = drive + pulses[:, kk] + noise[:, kk]
            for i in range(sub):
                t = (kk + (j * sub + i) / SUBSTEPS) * DT
                # the nut's travel is x1 + e(x1): its gearing 1 + e'(x1) moves the chain's motor end and, by virtual
                # work, carries the chain's force back to the motor
                gearing = 1.0 + lead_err_slope(x1) if has_le else 1.0
                if has_le:
                    stretch = x1 + lead_err(x1) - x2
                    dstretch = v1 * gearing - v2
                else:
                    stretch, dstretch = x1 - x2, v1 - v2
                k, c = _chain(p["k"], p["c"], p["shaft_share"], p["a0"], p["a_ref"], x2)
                if has_bl:  # a dead zone of +-bl in the chain: no force (and no damping) until the balls bear
                    bearing = np.abs(stretch) >= p["bl"]
                    fk = np.where(bearing, k * (stretch - np.clip(stretch, -p["bl"], p["bl"])) + c * dstretch, 0.0)
                else:
                    fk = k * stretch + c * dstretch
                fm = p["Fc_m"] * np.tanh(v1 / v_eps) + p["Fv_m"] * v1 + p["offset"]
                if has_cg or has_bd:
                    th = w_lead * x1
                extra = 0.0
                if has_cg:
                    extra = p["cg_amplitude_N"] * (np.sin(p["cg_order"] * th + p["cg_phase"])
                                                   + p["cg_h2"] * np.sin(2 * p["cg_order"] * th))
                if has_bd:
                    extra = extra + p["bd_amplitude_N"] * np.sin(p["bd_order"] * th + p["bd_phase"])
                if has_tr:
                    extra = extra + p["tr_amplitude_N"] * np.sin(2 * np.pi * p["tr_freq_Hz"] * t + p["tr_phase"])
                push = f_app - fm - (fk * gearing if has_le else fk)
                if has_cg or has_bd or has_tr:
                    push = push - extra
                a1 = push / p["m1"]
                if has_casym or has_beta:
                    sg = np.sign(v2)
                fc = p["Fc_t"]
                if has_casym:
                    fc = fc * (1 + sg * p["casym"])
                if has_gamma:
                    fc = fc * (1 + p["gamma"] * np.tanh((x2 - p["xc"]) / p["width"]))
                gz = fc * (1 + (p["Fs_ratio"] - 1) * np.exp(-(v2 / p["vs"]) ** 2))
                # the nut's load scales the bristle force (normal-load-scaled LuGre), not the bristles' target
                # g(v): putting mu |fk| into g made sigma1 dz/dt follow every swing of the axial spring force, a
                # damping force of order sigma1 mu dfk/dt / sigma0, 15 times the screw's own damper, which
                # tripled the friction at 80 mm/s (docs/gap_benchmark.md, 3l). Steady sliding is the same.
                lam = 1.0 + p["mu"] * np.abs(fk) / np.maximum(fc, 1e-9) if has_mu else 1.0
                # exact bristle update for v2 held over the substep
                rate = p["sigma0"] * np.abs(v2) / np.maximum(gz, 1e-9)
                moving = rate > 0
                zss = np.where(moving, v2 / np.where(moving, rate, 1.0), 0.0)
                z_new = np.where(moving, zss + (z - zss) * np.exp(-rate * h), z)
                dz = (z_new - z) / h
                z = z_new
                fv = p["Fv_t"] * (1 + sg * p["beta"]) if has_beta else p["Fv_t"]
                bristles = p["sigma0"] * z + p["sigma1"] * dz
                ft = (lam * bristles if has_mu else bristles) + fv * v2
                if has_pl:
                    fp = p["kpl"] * (x2 - xp) + p["cpl"] * (v2 - vp)
                if has_cc:  # conservative: the same force of position in both directions of motion
                    d = x2 - p["cc_x0"]
                    fcc = p["cc_k"] * d + p["cc_q"] * (d / 0.1) ** 2
                pull = fk - ft
                if has_pl:
                    pull = pull - fp
                if has_cc:
                    pull = pull - fcc
                a2 = pull / p["m2"]
                v1 = v1 + h * a1
                v2 = v2 + h * a2
                x1 = x1 + h * v1
                x2 = x2 + h * v2
                if has_pl:
                    vp = vp + h * fp / mp_safe
                    xp = xp + h * vp
                # the current loop's lag advances after the kick: the kick takes the applied force at the substep's
                # start, as it takes every other force (a semi-implicit Euler step is the leapfrog's kick-drift, its
                # force at the step's start). Advanced before the kick, the force led by one substep, which near a
                # loop's stability limit drew oscillations that the converged truth does not have (docs 3ci)
                f_app = f_app + (cmd - f_app) * lagc
    res, i0 = [], 0
    for j in jobs:
        m = j[1].shape[0]
        res.append({"x_motor": xm[i0: i0 + m], "x_table": xt[i0: i0 + m], "u": u_rec[i0: i0 + m]})
        i0 += m
    return res


def simulate_truth(tr, refs, pulses, rng_noise, with_effects=True):
    """Closed-loop simulation of all runs of one truth (columns = runs); see :func:`simulate_batch`.

    Parameters
    ----------
    tr : Truth
    refs, pulses : numpy.ndarray
        ``(runs, samples)`` reference [m] and known external force [N].
    rng_noise : numpy.random.Generator
        Draws the drift and the noise (:func:`noise_draws`).
    with_effects : bool
        Include ``tr.effects`` (False: the effect-free twin).

    Returns
    -------
    dict
        ``x_motor``, ``x_table``, ``u`` and ``drift``.
    """
    drift, noise = noise_draws(tr, refs.shape[0], refs.shape[1], rng_noise)
    out = simulate_batch([(tr, refs, pulses, drift, noise, with_effects)])[0]
    out["drift"] = drift
    return out


def controller_meta(tr):
    """The metadata a user of the rig would write (controller, units, sensors, drive parameters)."""
    sensors = SensorMeta(encoder_resolution=tr.encoder, scale_resolution=tr.scale)
    if tr.kind == "p_p_cascade":
        return MeasuredMeta(u_units="V", u_gain=GTAU, controller=EMPS_CONTROLLER, sensors=sensors,
                            source="drakecreep.gap.truth (P-P cascade)")
    g = _controller_gains(tr)
    ctrl = ControllerParams(position_gain=g["kp"], velocity_feedforward=g["ff"], velocity_gain=g["kv"],
                            velocity_integral_gain=g["ki"], velocity_period=DT / VEL_DIV, position_period=DT)
    params = DriveParams(controller=ctrl, screw=ScrewParams(lead=tr.lead))
    return MeasuredMeta(u_units="N", u_gain=1.0, params=params,
                        controller=ControllerMeta(kind="drakecreep", sample_time=DT), sensors=sensors,
                        source="drakecreep.gap.truth (PI cascade)")


def make_runs(tr, refs, pulses, sim, label="run"):
    """:class:`~drakecreep.gap.measured.MeasuredRun` objects of a simulation (with the linear scale)."""
    meta = controller_meta(tr)
    n = refs.shape[1]
    t = np.arange(n) * DT
    return [MeasuredRun(t=t, x_ref=refs[i], x_motor=sim["x_motor"][i], x_table=sim["x_table"][i], u=sim["u"][i],
                        f_ext=pulses[i], meta=meta, label=f"{label}{i}") for i in range(refs.shape[0])]
