"""Where the sim-to-real gap lies: residuals decomposed by time regime, order, operating map; whiteness.

Inputs are plain arrays on a uniform time grid: the measured run and the closed-loop replay of a model
(:func:`drakecreep.gap.where.where_gap` replays the Drake model), or an inverse-dynamics residual. Functions:

* :func:`classify_regimes`: every sample is ``dwell``, ``stick``, ``reversal``, ``acceleration`` or
  ``constant_speed`` (from the reference motion and the measured speed);
* :func:`regime_shares`: share of the residual energy and of the time in each regime;
* :func:`order_spectrum`: residual resampled against position and its spectrum in orders (cycles per
  period: screw revolution, motor revolution, millimetre of table travel), so a periodic effect shows
  as a sharp order; :func:`time_spectrum` the same against time;
* :func:`operating_map`: residual RMS binned by speed, position and load;
* :func:`whiteness`: Ljung-Box test (SciPy chi-square) and the largest cross-correlation with the input;
* :func:`independence`: the residual-input independence test of system identification (cross-correlation
  of the residual with each input over lags, with its confidence band);
* :func:`frequency_bands`: share of the residual energy in frequency bands (Welch PSD);
* :func:`fixed_to`: is a periodic residual fixed to the travel or to time (its peak frequency run by run against
  the speed)?
* :func:`motor_table_split`: for runs with a linear scale, is the gap before or after the screw?
* :func:`dominant_oscillation` and :func:`sustained_oscillation`: does the measured force carry an oscillation
  (an unstable loop's limit cycle) that the replay does not? A replay sample by sample cannot follow an
  oscillation whose phase is free, so such a gap is reported by its frequency, not closed by a fit.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal, stats

from drakecreep.errors import InputError

__all__ = [
    "REGIMES",
    "limit_cycle",
    "classify_regimes",
    "regime_shares",
    "order_spectrum",
    "time_spectrum",
    "operating_map",
    "transmission_position",
    "whiteness",
    "BANDS_HZ",
    "frequency_bands",
    "fixed_to",
    "independence",
    "motor_table_split",
    "OSCILLATION_MIN_HZ",
    "OSCILLATION_SHARE",
    "OSCILLATION_RATIO",
    "dominant_oscillation",
    "sustained_oscillation",
    "oscillates_at",
    "oscillation_log_errors",
    "oscillation_band_errors",
]

#: Frequency bands [Hz] of :func:`frequency_bands` (the last one ends at the Nyquist frequency).
BANDS_HZ = ((0.0, 2.0), (2.0, 10.0), (10.0, 50.0), (50.0, 150.0), (150.0, math.inf))

#: Lowest frequency [Hz] of :func:`dominant_oscillation`: above the motion profiles' own content (a few Hz).
OSCILLATION_MIN_HZ = 20.0
#: Share of a record's variance its dominant oscillation must hold to be called sustained: a quarter. An unstable
#: loop's saturated limit cycle holds 0.95-0.98 of the motor force on development seeds (1000-1039, drakecreep
#: kind, delays of 2-3 samples), one still growing in a short run 0.38-0.79 (the quick rig at 24 samples); a force
#: ripple or a mode excited by the motion at most 0.13 (seeds 1100-1111, both kinds, every withheld effect).
OSCILLATION_SHARE = 0.25
#: How much larger (RMS in the oscillation's band) the measured oscillation must be than the replay's (20 dB).
OSCILLATION_RATIO = 10.0
#: Half-width of an oscillation's band, relative to its frequency.
_OSC_WIDTH = 0.15
#: Samples per Welch segment of the oscillation measures: their frequency resolution is ``1 / (256 dt)`` (3.9 Hz
#: at 1 kHz).
_OSC_SEGMENT = 256

#: Time regimes, in order of precedence.
REGIMES = ("dwell", "stick", "reversal", "acceleration", "constant_speed")


def classify_regimes(t, x_ref, v_meas, v_frac=0.01, a_frac=0.02, reversal_window=0.03):
    """Label every sample with a time regime.

    Parameters
    ----------
    t : array_like
        Time [s], uniform.
    x_ref : array_like
        Reference position [m].
    v_meas : array_like
        Measured (filtered) speed [m/s].
    v_frac, a_frac : float
        Speed and acceleration thresholds as fractions of the largest reference speed / acceleration.
    reversal_window : float
        Half-width [s] around a change of direction of the measured motion labelled ``reversal``.

    Returns
    -------
    numpy.ndarray
        Array of regime names (dtype object).
    """
    t = np.asarray(t, dtype=float)
    dt = float(t[1] - t[0])
    v_ref = np.gradient(np.asarray(x_ref, dtype=float), dt)
    a_ref = np.gradient(v_ref, dt)
    v_meas = np.asarray(v_meas, dtype=float)
    v_eps = v_frac * max(np.max(np.abs(v_ref)), 1e-12)
    a_eps = a_frac * max(np.max(np.abs(a_ref)), 1e-12)
    labels = np.full(t.size, "constant_speed", dtype=object)
    labels[np.abs(a_ref) >= a_eps] = "acceleration"
    moving = np.abs(v_meas) > v_eps
    s = np.sign(v_meas) * moving
    nz = np.flatnonzero(s)
    rev = np.zeros(t.size, bool)
    if nz.size > 1:
        flips = nz[1:][np.diff(s[nz]) != 0]
        prev = nz[:-1][np.diff(s[nz]) != 0]
        w = int(round(reversal_window / dt))
        for a, b in zip(prev, flips):
            rev[max(a - w, 0): b + w + 1] = True
    labels[rev] = "reversal"
    labels[(np.abs(v_ref) >= v_eps) & ~moving & ~rev] = "stick"
    labels[(np.abs(v_ref) < v_eps) & (np.abs(a_ref) < a_eps)] = "dwell"
    return labels


def regime_shares(residual, labels):
    """Share of residual energy and of time per regime.

    Returns
    -------
    dict
        ``{regime: {"energy_share": ..., "time_share": ..., "rms": ...}}`` (shares in 0..1).
    """
    r = np.asarray(residual, dtype=float)
    total = float(np.sum(r * r))
    out = {}
    for name in REGIMES:
        m = labels == name
        e = float(np.sum(r[m] ** 2))
        out[name] = {"energy_share": e / total if total > 0 else 0.0, "time_share": float(np.mean(m)),
                     "rms": float(np.sqrt(np.mean(r[m] ** 2))) if m.any() else 0.0}
    return out


def _stretches(mask):
    d = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def order_spectrum(x, v, residual, period, points_per_period=32, periods_per_segment=8, min_speed=None,
                   segment=None):
    """Spectrum of a residual resampled against position, in orders (cycles per ``period`` of travel).

    Monotone stretches of motion (``|v| > min_speed``) are resampled on a uniform position grid of
    ``period / points_per_period`` and passed through Welch's method; the spectra are averaged, weighted by
    their length. Several runs (lists of arrays) are pooled that way, each with its own stretches, so runs at
    other speeds add up in orders where their time frequencies differ.

    Parameters
    ----------
    x, v, residual : array_like, or sequences of them (one per run)
        Measured position [m], speed [m/s] and the residual, same length.
    period : float
        Travel of one cycle [m] (screw lead, motor revolution at the table, or 1e-3 for per-mm).
    points_per_period, periods_per_segment : int
        Resampling density and Welch segment length (``periods_per_segment`` periods).
    min_speed : float, optional
        Default: 20 % of each run's largest speed.
    segment : float or "auto", optional
        Travel of a Welch segment [m] instead of ``periods_per_segment`` periods. ``"auto"``: the shorter of
        ``periods_per_segment`` periods and the travel of the shortest stretch of at least half the longest's,
        so every such stretch is used whole (short runs, e.g. a few mm at creep speeds, cover less than one
        lead: the resolution is then ``period / segment`` orders).

    Returns
    -------
    dict
        ``orders``, ``psd`` (arrays), ``peak_order``, ``peak_share`` (energy within +-1 bin of the peak /
        total), ``peak_ratio`` (peak / median PSD of the 8 bins on either side, the peak's 3 bins left
        out: a local prominence, insensitive to the low-pass filter's roll-off), ``n_segments``,
        ``resolution`` (orders per bin), ``flat_share`` (the ``peak_share`` of a flat spectrum, the share of the
        bins at orders >= 0.75 within +-1 bin of the peak: coarse bins make any peak hold most of the energy).
    """
    if period <= 0:
        raise InputError("period", period, "a travel > 0 m")
    many = isinstance(x, (list, tuple)) and len(x) > 0 and np.ndim(x[0]) == 1  # one array per run
    records = list(zip(x, v, residual)) if many else [(x, v, residual)]
    step = period / points_per_period
    stretches = []
    for xr, vr, rr in records:
        xr, vr, rr = (np.asarray(a, dtype=float) for a in (xr, vr, rr))
        floor = 0.2 * float(np.max(np.abs(vr))) if min_speed is None else min_speed
        for sign in (1.0, -1.0):
            for a, b in _stretches(sign * vr > floor):
                xs, rs = xr[a:b], rr[a:b]
                if sign < 0:
                    xs, rs = xs[::-1], rs[::-1]
                keep = np.concatenate([[True], np.diff(xs) > 0])
                xs, rs = xs[keep], rs[keep]
                if xs.size >= 4:
                    stretches.append((xs, rs))
    nper = points_per_period * periods_per_segment
    if isinstance(segment, str):
        if segment != "auto":
            raise InputError("segment", segment, "a travel > 0 m or 'auto'")
        travels = np.array([xs[-1] - xs[0] for xs, _ in stretches])
        if travels.size:  # every stretch of at least half the longest's travel is used, whole
            nper = min(nper, int(np.min(travels[travels >= 0.5 * travels.max()]) / step))
    elif segment is not None:
        nper = int(segment / step)
    psds, weights = [], []
    if nper >= 8:
        for xs, rs in stretches:
            if xs[-1] - xs[0] < nper * step:
                continue
            grid = np.arange(xs[0], xs[-1], step)
            rr = np.interp(grid, xs, rs)
            f, p = signal.welch(rr, fs=1.0 / step, nperseg=nper, detrend="linear")
            psds.append(p)
            weights.append(grid.size)
    if not psds:
        return {"orders": [], "psd": [], "peak_order": None, "peak_share": 0.0, "peak_ratio": 0.0, "n_segments": 0,
                "resolution": None, "flat_share": None}
    psd = np.average(np.array(psds), axis=0, weights=weights)
    orders = f * period
    band = orders >= 0.75
    idx = np.flatnonzero(band)
    k = idx[np.argmax(psd[band])]
    total = float(np.sum(psd[band]))
    share = float(np.sum(psd[max(k - 1, idx[0]): k + 2]) / total) if total > 0 else 0.0
    around = np.r_[psd[max(k - 8, idx[0]): max(k - 1, idx[0])], psd[k + 2: k + 9]]
    med = float(np.median(around)) if around.size else 0.0
    return {"orders": orders, "psd": psd, "peak_order": float(orders[k]), "peak_share": share,
            "peak_ratio": float(psd[k] / med) if med > 0 else 0.0, "n_segments": len(psds),
            "resolution": float(orders[1] - orders[0]),
            "flat_share": float((min(k + 2, idx[-1] + 1) - max(k - 1, idx[0])) / idx.size)}


def time_spectrum(residual, dt, nperseg=1024):
    """Welch spectrum of a residual against time: ``freq`` [Hz], ``psd``, ``peak_hz``."""
    r = np.asarray(residual, dtype=float)
    f, p = signal.welch(r, fs=1.0 / dt, nperseg=min(nperseg, r.size), detrend="linear")
    k = 1 + int(np.argmax(p[1:]))
    return {"freq": f, "psd": p, "peak_hz": float(f[k])}


def operating_map(residual, speed, position, load, bins=5):
    """Residual RMS binned by |speed|, position and |load| (quantile bins for speed and load).

    Returns
    -------
    dict
        ``{"speed": [{"lo", "hi", "rms", "energy_share", "time_share"}, ...], "position": [...], "load": [...]}``
        (``time_share``: the bin's share of the samples).
    """
    r = np.asarray(residual, dtype=float)
    total = float(np.sum(r * r)) or 1.0
    out = {}
    for name, val, quantile in (("speed", np.abs(speed), True), ("position", np.asarray(position), False),
                                ("load", np.abs(load), True)):
        val = np.asarray(val, dtype=float)
        if quantile:
            edges = np.unique(np.quantile(val, np.linspace(0, 1, bins + 1)))
        else:
            edges = np.linspace(val.min(), val.max(), bins + 1)
        if edges.size < 2:
            edges = np.array([val.min(), val.max() + 1e-12])
        which = np.clip(np.searchsorted(edges, val, side="right") - 1, 0, edges.size - 2)
        rows = []
        for i in range(edges.size - 1):
            m = which == i
            rows.append({"lo": float(edges[i]), "hi": float(edges[i + 1]),
                         "rms": float(np.sqrt(np.mean(r[m] ** 2))) if m.any() else 0.0,
                         "energy_share": float(np.sum(r[m] ** 2) / total), "time_share": float(np.mean(m))})
        out[name] = rows
    return out


def whiteness(residual, inputs=None, lags=10):
    """Is the residual white noise, uncorrelated with the input?

    Parameters
    ----------
    residual : array_like
        Residual samples (decimated, so that noise is not coloured by the pre-processing).
    inputs : array_like, optional
        The input (controller output) on the same samples.
    lags : int
        Lags of the Ljung-Box test and of the cross-correlation.

    Returns
    -------
    dict
        ``ljung_box_q``, ``ljung_box_p``, ``acf`` (lags 1..``lags``), ``max_abs_xcorr``, ``xcorr_bound``
        (95 % family-wise band for the largest of the ``2 lags + 1`` values, ``z/sqrt(n)`` with Bonferroni), ``white`` (p >= 0.05 and the cross-correlation inside the band).
    """
    r = np.asarray(residual, dtype=float)
    r = r - r.mean()
    n = r.size
    denom = float(r @ r)
    acf = np.array([float(r[:-k] @ r[k:]) / denom for k in range(1, lags + 1)]) if denom > 0 else np.zeros(lags)
    q = float(n * (n + 2) * np.sum(acf ** 2 / (n - np.arange(1, lags + 1))))
    p = float(stats.chi2.sf(q, lags))
    # 95 % band for the largest of the 2 lags + 1 cross-correlations (Bonferroni)
    bound = float(stats.norm.ppf(1 - 0.05 / (2 * (2 * lags + 1)))) / np.sqrt(n)
    xmax = 0.0
    if inputs is not None:
        u = np.asarray(inputs, dtype=float)
        u = u - u.mean()
        nu = float(np.sqrt((u @ u) * denom))
        if nu > 0:
            xc = [float(r[max(0, -k): n - max(0, k)] @ u[max(0, k): n - max(0, -k)]) / nu
                  for k in range(-lags, lags + 1)]
            xmax = float(np.max(np.abs(xc)))
    return {"ljung_box_q": q, "ljung_box_p": p, "acf": acf.tolist(), "max_abs_xcorr": xmax,
            "xcorr_bound": float(bound), "white": bool(p >= 0.05 and xmax <= bound)}


def frequency_bands(residual, dt, bands=BANDS_HZ, nperseg=1024):
    """Share of a residual's energy per frequency band (Welch PSD, :func:`scipy.signal.welch`).

    Parameters
    ----------
    residual : array_like or sequence of array_like
        One record or several (separate runs: their spectra are averaged, weighted by length).
    dt : float
        Sample time [s].
    bands : sequence of (float, float)
        Band edges [Hz]; ``inf`` means the Nyquist frequency. A band that starts at or above the Nyquist frequency
        is left out, and one that holds it ends there.
    nperseg : int
        Welch segment length (shortened for short records).

    Returns
    -------
    dict
        ``bands`` (list of ``{"lo_Hz", "hi_Hz", "share", "rms"}``), ``peak_hz`` and ``top`` (the band
        with the largest share).
    """
    recs = [np.asarray(residual, dtype=float)] if np.ndim(residual[0]) == 0 else \
        [np.asarray(r, dtype=float) for r in residual]
    if dt <= 0:
        raise InputError("dt", dt, "a sample time > 0 s")
    seg = int(min(nperseg, min(r.size for r in recs)))
    if seg < 8:
        raise InputError("residual", f"{seg} samples", "records of at least 8 samples")
    psds, w = [], []
    for r in recs:
        f, p = signal.welch(r, fs=1.0 / dt, nperseg=seg, detrend="constant")
        psds.append(p)
        w.append(r.size)
    psd = np.average(np.array(psds), axis=0, weights=w)
    df = float(f[1] - f[0])
    total = float(np.sum(psd) * df)
    rows = []
    for lo, hi in bands:
        if lo >= f[-1] and rows:  # a band beyond the Nyquist frequency (a log every 4 ms ends at 125 Hz): none
            continue
        m = (f >= lo) & (f < (hi if math.isfinite(hi) else np.inf))
        e = float(np.sum(psd[m]) * df)
        rows.append({"lo_Hz": float(lo), "hi_Hz": float(min(hi, f[-1])), "share": e / total if total > 0 else 0.0,
                     "rms": math.sqrt(max(e, 0.0))})
    k = 1 + int(np.argmax(psd[1:]))
    top = max(rows, key=lambda r: r["share"])
    return {"bands": rows, "peak_hz": float(f[k]), "top": top}


def fixed_to(residuals, speeds, labels, dt, nperseg=256):
    """Is a periodic residual fixed to the travel or to time? Its peak frequency at constant speed, run by run.

    In each run the residual's constant-speed stretches (``labels`` of :func:`classify_regimes`) give a Welch
    spectrum (segments of ``nperseg`` samples, or the longest stretch's length when shorter) and its peak frequency
    ``f``, beside the run's mean speed ``v`` there. A force fixed to the travel (period ``P``) has ``f = v / P``;
    one fixed in time the same ``f`` at every speed. Each peak is known to within half the spectrum's bin, so a
    model fits the runs when every peak lies within a bin of it: ``f = c v`` (``c`` by least squares) and
    ``f = const``; the verdict is the one model that fits, else "cannot tell" (both fit: runs at like speeds or
    bins too coarse; neither: the peaks are not one effect's).

    Parameters
    ----------
    residuals, speeds, labels : sequences of array_like
        Per run: the residual, the measured speed [m/s] and the regime labels, same length.
    dt : float
        Sample time [s].
    nperseg : int
        Welch segment length [samples].

    Returns
    -------
    dict
        ``verdict`` (``"travel"``, ``"time"`` or ``"cannot tell"``), ``runs`` (per run with a constant-speed
        stretch: ``speed`` [m/s], ``peak_Hz``), ``resolution_Hz`` (the coarsest bin), ``period_m`` (``1 / c`` when
        the verdict is the travel, else None).
    """
    runs = []
    for r, v, lab in zip(residuals, speeds, labels):
        r, v = np.asarray(r, dtype=float), np.asarray(v, dtype=float)
        stretches = [(a, b) for a, b in _stretches(np.asarray(lab) == "constant_speed") if b - a >= 16]
        if not stretches:
            continue
        seg = int(min(nperseg, max(b - a for a, b in stretches)))
        psds, w = [], []
        for a, b in stretches:
            if b - a < seg:
                continue
            f, p = signal.welch(r[a:b], fs=1.0 / dt, nperseg=seg, detrend="linear")
            psds.append(p)
            w.append(b - a)
        psd = np.average(np.array(psds), axis=0, weights=w)
        k = 1 + int(np.argmax(psd[1:]))
        m = np.concatenate([np.arange(a, b) for a, b in stretches])
        runs.append({"speed": float(np.mean(np.abs(v[m]))), "peak_Hz": float(f[k]), "bin_Hz": float(f[1] - f[0])})
    if len(runs) < 2:
        return {"verdict": "cannot tell", "runs": runs, "resolution_Hz": None, "period_m": None}
    f = np.array([x["peak_Hz"] for x in runs])
    v = np.array([x["speed"] for x in runs])
    tol = max(x["bin_Hz"] for x in runs)
    c = float(v @ f / (v @ v)) if v @ v > 0 else 0.0
    travel = bool(c > 0 and np.all(np.abs(f - c * v) <= tol))
    time = bool(np.all(np.abs(f - np.mean(f)) <= tol))
    verdict = "travel" if travel and not time else ("time" if time and not travel else "cannot tell")
    return {"verdict": verdict, "runs": [{"speed": x["speed"], "peak_Hz": x["peak_Hz"]} for x in runs],
            "resolution_Hz": tol, "period_m": 1.0 / c if verdict == "travel" else None}


def _acf(x, lags):
    x = x - x.mean()
    d = float(x @ x)
    return np.array([1.0] + [float(x[:-k] @ x[k:]) / d if d > 0 else 0.0 for k in range(1, lags + 1)])


def independence(residual, inputs, lags=25, level=0.99):
    """Cross-correlation of a residual with each input, with its confidence band (residual analysis).

    As system-identification tools do (e.g. ``resid``), the normalised cross-correlation
    ``r_eu(k) = corr(e[t], u[t - k])`` for ``k = -lags .. lags`` (positive lags: the residual follows the
    input) is compared with a band that holds with probability ``level``
    if residual and input are independent. The band uses Bartlett's variance of a cross-correlation of
    two independent autocorrelated series, ``var r_eu(k) = (1/N) sum_j rho_e(j) rho_u(j)``, so slowly
    varying residuals and inputs (filtered or closed-loop data) do not give false alarms.

    Parameters
    ----------
    residual : array_like
    inputs : dict
        ``{name: array}`` on the same samples (e.g. the reference speed and the drive force).
    lags : int
        Largest lag (samples).
    level : float
        Family-wise coverage of the band over all lags (0.99; ``resid`` uses 0.99 pointwise).

    Returns
    -------
    dict
        Per input: ``xcorr`` (list), ``lags``, ``band``, ``max_abs``, ``lag_of_max``, ``independent``
        (every lag inside the band).
    """
    e = np.asarray(residual, dtype=float)
    e = e - e.mean()
    n = e.size
    if n < 4 * lags:
        raise InputError("residual", f"{n} samples", f"at least {4 * lags} samples for {lags} lags")
    # family-wise over the 2 lags + 1 values tested (Bonferroni): a pointwise band would flag about
    # (2 lags + 1) (1 - level) lags of an independent pair by chance
    z = float(stats.norm.ppf(1 - (1 - level) / (2 * (2 * lags + 1))))
    rho_e = _acf(e, n // 4)
    out = {}
    for name, u in inputs.items():
        u = np.asarray(u, dtype=float)
        if u.size != n:
            raise InputError(f"inputs.{name}", f"length {u.size}", f"length {n} like the residual")
        u = u - u.mean()
        den = math.sqrt(float(e @ e) * float(u @ u))
        ks = np.arange(-lags, lags + 1)
        if den == 0:
            xc = np.zeros(ks.size)
        else:
            # xc[k] = corr(e[t], u[t - k]): a residual that follows the input by d samples peaks at k = +d
            xc = np.array([float(e[max(0, k): n - max(0, -k)] @ u[max(0, -k): n - max(0, k)]) / den for k in ks])
        rho_u = _acf(u, n // 4) if den > 0 else np.zeros(rho_e.size)
        var = (1.0 + 2.0 * float(np.sum(rho_e[1:] * rho_u[1:]))) / n
        band = z * math.sqrt(max(var, 1.0 / n))
        i = int(np.argmax(np.abs(xc)))
        out[name] = {"lags": ks.tolist(), "xcorr": xc.tolist(), "band": band, "max_abs": float(abs(xc[i])),
                     "lag_of_max": int(ks[i]), "independent": bool(np.all(np.abs(xc) <= band))}
    return out


def transmission_position(x_motor, x_table):
    """What the screw adds between the motor and the table [m]: ``x_table - x_motor``, less its mean (a constant is
    the scale's mounting datum, not the transmission's): the windup of the axial chain plus any kinematic error
    of the screw (a lead error), which a motor encoder cannot see and a linear scale can."""
    d = np.asarray(x_table, dtype=float) - np.asarray(x_motor, dtype=float)
    return d - d.mean()


def motor_table_split(x_motor, x_table, x_motor_sim, x_table_sim=None):
    """Is the position gap before or after the screw? (runs with a linear scale)

    The motor-side gap is ``x_motor - x_motor_sim``; the part the transmission adds is the measured
    deflection ``x_table - x_motor`` minus the simulated one (0 for a rigid model, when
    ``x_table_sim`` is None).

    Returns
    -------
    dict
        ``motor_rms_m``, ``transmission_rms_m``, ``table_rms_m`` and ``after_screw_share``
        (transmission energy / (motor + transmission energy)); ``where``: ``"before the screw"``,
        ``"after the screw"`` or ``"both"``.
    """
    xm, xt, xs = (np.asarray(a, dtype=float) for a in (x_motor, x_table, x_motor_sim))
    xts = xs if x_table_sim is None else np.asarray(x_table_sim, dtype=float)
    em = xm - xs
    et = transmission_position(xm, xt) - transmission_position(xs, xts)
    e_m, e_t = float(em @ em), float(et @ et)
    share = e_t / (e_m + e_t) if e_m + e_t > 0 else 0.0
    where = "after the screw" if share > 0.67 else ("before the screw" if share < 0.33 else "both")
    return {"motor_rms_m": math.sqrt(e_m / em.size), "transmission_rms_m": math.sqrt(e_t / et.size),
            "table_rms_m": float(np.sqrt(np.mean((xt - xts - np.mean(xt - xts)) ** 2))),
            "after_screw_share": share, "where": where}


def _welch(record, dt, nperseg=_OSC_SEGMENT):
    r = np.asarray(record, dtype=float)
    f, p = signal.welch(r, fs=1.0 / dt, nperseg=int(min(nperseg, r.size)), detrend="constant")
    return f, p, float(f[1] - f[0])


def _band_rms(f, p, df, freq):
    m = np.abs(f - freq) <= max(_OSC_WIDTH * freq, 1.5 * df)
    return math.sqrt(max(float(np.sum(p[m]) * df), 0.0))


def dominant_oscillation(record, dt, f_min=OSCILLATION_MIN_HZ):
    """The strongest oscillation of a record above ``f_min``: its frequency, RMS and share of the variance.

    Parameters
    ----------
    record : array_like
        A signal on a uniform grid (e.g. the measured or replayed motor force [N]).
    dt : float
        Sample time [s].
    f_min : float
        Lowest frequency searched [Hz].

    Returns
    -------
    dict
        ``freq_Hz`` (the Welch PSD's peak above ``f_min``), ``rms`` (in the band of +-15 % around it, the
        record's unit) and ``share`` (of the record's variance about its mean).
    """
    if dt <= 0:
        raise InputError("dt", dt, "a sample time > 0 s")
    r = np.asarray(record, dtype=float)
    if r.size < 16:
        raise InputError("record", f"{r.size} samples", "at least 16 samples")
    f, p, df = _welch(r, dt)
    above = f >= f_min
    if not np.any(above):
        raise InputError("f_min", f_min, f"a frequency below the Nyquist frequency {f[-1]:g} Hz")
    k = int(np.flatnonzero(above)[np.argmax(p[above])])
    rms = _band_rms(f, p, df, float(f[k]))
    var = float(np.var(r))
    return {"freq_Hz": float(f[k]), "rms": rms, "share": rms * rms / var if var > 0 else 0.0}


def limit_cycle(record, dt, f_min=OSCILLATION_MIN_HZ):
    """A record's :func:`dominant_oscillation` when it holds at least :data:`OSCILLATION_SHARE` of the variance (a
    sustained oscillation: the limit cycle of an unstable loop), else None; None too for a record too short to
    search, or sampled too coarsely for ``f_min``."""
    try:
        o = dominant_oscillation(record, dt, f_min)
    except InputError:
        return None
    return o if o["share"] >= OSCILLATION_SHARE else None


def _paired_bands(measured, simulated, dt, f_min, freq=None):
    """Per run: the measured record's :func:`dominant_oscillation` and the replay's RMS in its band; with ``freq``,
    a measured record whose dominant oscillation holds less than :data:`OSCILLATION_SHARE` of its variance is
    taken in the band of ``freq`` instead (its ``rms`` there)."""
    if len(measured) != len(simulated):
        raise InputError("simulated", f"{len(simulated)} records", f"one per measured record ({len(measured)})")
    for m, s in zip(measured, simulated):
        o = dominant_oscillation(m, dt, f_min)
        if freq is not None and o["share"] < OSCILLATION_SHARE:
            o = dict(o, freq_Hz=float(freq), rms=_band_rms(*_welch(np.asarray(m, dtype=float), dt), float(freq)))
        f, p, df = _welch(s, dt)
        yield o, _band_rms(f, p, df, o["freq_Hz"])


def _log_band_errors(pairs):
    """``|ln(model / measured)|`` per ``(dominant oscillation, replay's band RMS)`` of :func:`_paired_bands`."""
    out = []
    for o, model in pairs:
        tiny = 1e-12 * max(o["rms"], 1.0)  # a replay with nothing in the band: finite, large
        out.append(abs(math.log(max(model, tiny) / max(o["rms"], tiny))))
    return np.array(out)


def sustained_oscillation(measured, simulated, dt, f_min=OSCILLATION_MIN_HZ):
    """Do the measured records carry a sustained oscillation that the replayed ones do not?

    A record oscillates when its dominant oscillation (:func:`dominant_oscillation`) holds at least
    :data:`OSCILLATION_SHARE` of its variance and its RMS in that band is at least :data:`OSCILLATION_RATIO`
    times the replay's in the same band: an unstable (or nearly unstable) real loop whose model is stable.

    Parameters
    ----------
    measured, simulated : sequence of array_like
        Paired records of each run (e.g. measured and replayed motor force [N]).
    dt, f_min : float
        As :func:`dominant_oscillation`.

    Returns
    -------
    dict or None
        None when no record oscillates; otherwise ``freq_Hz`` (median over the oscillating runs), ``rms`` and
        ``model_rms`` (their median RMS in the band, measured and replayed), ``share`` (median), ``runs`` (how
        many oscillate), ``of`` (how many were checked), ``oscillating`` (a bool per run, in order), ``freqs_Hz``
        (each oscillating run's frequency, in order) and ``resolution_Hz`` (the frequency resolution of the
        spectra they are read from, that of the shortest record).
    """
    hits, flags = [], []
    for o, model in _paired_bands(measured, simulated, dt, f_min):
        flags.append(bool(o["share"] >= OSCILLATION_SHARE and o["rms"] >= OSCILLATION_RATIO * model))
        if flags[-1]:
            hits.append((o["freq_Hz"], o["rms"], model, o["share"]))
    if not hits:
        return None
    med = np.median(np.array(hits), axis=0)
    shortest = min(np.asarray(m).size for m in measured)
    return {"freq_Hz": float(med[0]), "rms": float(med[1]), "model_rms": float(med[2]), "share": float(med[3]),
            "runs": len(hits), "of": len(measured), "oscillating": flags,
            "freqs_Hz": [float(h[0]) for h in hits], "resolution_Hz": 1.0 / (dt * min(_OSC_SEGMENT, shortest))}


def oscillates_at(record, dt, freq, f_min=OSCILLATION_MIN_HZ):
    """Whether a (replayed) record's dominant oscillation is sustained and within +-15 % of ``freq`` [Hz]:
    ``(bool, its dominant_oscillation)``."""
    o = dominant_oscillation(record, dt, f_min)
    return bool(o["share"] >= OSCILLATION_SHARE and abs(o["freq_Hz"] - freq) <= _OSC_WIDTH * freq), o


def oscillation_band_errors(measured, simulated, dt, freq, f_min=OSCILLATION_MIN_HZ):
    """Run by run, how far each replay is from the measurement in the band of a known oscillation, whether or not
    the run oscillates: ``|ln(model / measured)|`` of the RMS in the band of +-15 % around the measured record's
    dominant oscillation where it holds :data:`OSCILLATION_SHARE` of the record's variance, else around ``freq``
    [Hz] (the oscillation found on other runs). A replay that oscillates on a run that does not, or is quiet on one
    that oscillates, scores high; one that oscillates where and as strongly as the measurement, about 0.

    Parameters
    ----------
    measured, simulated, dt, f_min
        As :func:`sustained_oscillation`.
    freq : float
        The oscillation's frequency [Hz] (e.g. :func:`sustained_oscillation`'s ``freq_Hz``).

    Returns
    -------
    numpy.ndarray
        One error per run [nepers].
    """
    return _log_band_errors(_paired_bands(measured, simulated, dt, f_min, freq))


def oscillation_log_errors(measured, simulated, dt, f_min=OSCILLATION_MIN_HZ):
    """How far each replay's oscillation is from the measured one's, in the measured one's band.

    A spectral error for records whose phase is free (a limit cycle): ``|ln(model / measured)|`` of the RMS in
    the band of +-15 % around each measured record's dominant oscillation (:func:`dominant_oscillation`). A replay
    that oscillates there as strongly scores about 0; a stable replay of an oscillating record at least
    ``ln(OSCILLATION_RATIO)`` = 2.3.

    Parameters
    ----------
    measured, simulated, dt, f_min
        As :func:`sustained_oscillation`.

    Returns
    -------
    numpy.ndarray
        One error per run [nepers].
    """
    return _log_band_errors(_paired_bands(measured, simulated, dt, f_min))
