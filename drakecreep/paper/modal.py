"""Experimental modal analysis of joints: FRF estimation and SDOF identification (paper Sec. 3.2.2).

The paper identified the moving joints (Tables 4-6) from hammer tests with the half-power bandwidth
method. This module provides:

* :func:`frf_h1` -- the H1 estimator ``H1 = S_fx / S_ff`` from force/response records
  (:func:`scipy.signal.csd`, :func:`scipy.signal.welch`), averaged over several hits, with coherence;
* :func:`force_window`, :func:`exponential_window` and :func:`exponential_window_damping` -- the usual
  impact-test windows and the correction of the damping the exponential window adds;
* :func:`to_receptance`, :func:`to_mobility` -- convert accelerance/mobility/receptance;
* :func:`pick_peaks` and :func:`half_power` -- peak picking (on the FRF as measured) and the half-power
  bandwidth, evaluated on the *mobility*, for which an SDOF's half-power bandwidth is exactly ``2 ζ ωn`` and the peak exactly
  at ``ωn`` (on receptance or accelerance both are biased by O(ζ²));
* :func:`fit_sdof` -- least-squares SDOF fit of the complex receptance ``1/(k - m ω² + j c ω)``: Levy's
  linearised rational-fraction fit as the start, refined by :func:`scipy.optimize.least_squares`;
* :func:`modal_stiffness_damping` -- ``k = m ωn²`` and ``c = 2 ζ m ωn`` from a modal mass;
* :func:`synthetic_hammer_test` -- hammer tests on an N-DOF ``(M, C, K)`` model (half-sine impulse,
  noise on both channels, finite record), exact for the piecewise-linear sampled force;
* :func:`half_power_error_study` -- how half-power degrades with noise and frequency resolution.

SI units: Hz for frequencies in arrays named ``f``, rad/s for ``w``; receptance in m/N.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal
from scipy.optimize import least_squares

from drakecreep.errors import InputError

__all__ = [
    "FRF",
    "frf_h1",
    "force_window",
    "exponential_window",
    "exponential_window_damping",
    "to_receptance",
    "to_mobility",
    "pick_peaks",
    "HalfPowerResult",
    "half_power",
    "SDOFFit",
    "fit_sdof",
    "modal_stiffness_damping",
    "HammerTest",
    "synthetic_hammer_test",
    "Identification",
    "identify_frf",
    "identify_hammer_test",
    "half_power_error_study",
    "FRF_COLUMNS",
    "TIME_COLUMNS",
    "read_hammer_csv",
]

#: the columns of a measured FRF file and of a file of time records (``drakecreep modal``)
FRF_COLUMNS = ("f_Hz", "re", "im")
#: Range of the largest magnitude of a hammer-test file's signal columns (SI units): outside it the SDOF fit's
#: stiffness, mass and damping under- or overflow
MIN_MAGNITUDE, MAX_MAGNITUDE = 1e-20, 1e20
#: Range of the highest frequency of a hammer-test file (an FRF's last f_Hz, a time record's Nyquist frequency) [Hz]:
#: hammer tests reach a few kHz; far outside it the fit's w^2 terms overflow (f_Hz up to 5e302 Hz, or a time step of
#: 1e-304 s, ended in 'internal error: LinAlgError: SVD did not converge')
MIN_FREQUENCY, MAX_FREQUENCY = 1e-3, 1e6
TIME_COLUMNS = ("t", "force", "response")
#: Largest damping ratio half-power reads an exponentially windowed mode at [-]: the half-power points of a mode
#: damped beyond about 1 / (2 sqrt 2) = 0.35 are no longer where 2 zeta = (w2 - w1) / wn puts them. A window that
#: lifts a mode beyond it (a 1 ms window on a 300 Hz mode of zeta 0.02: 0.02 + 1 / (tau wn) = 0.55) read the mode at
#: 206 Hz and zeta 0.40 after its correction, exit 0
MAX_WINDOWED_ZETA = 0.3

_FRF_POWERS = {"receptance": 0, "displacement": 0, "mobility": 1, "velocity": 1,
               "accelerance": 2, "acceleration": 2}


@dataclass(frozen=True)
class FRF:
    """A frequency response function.

    Attributes
    ----------
    f : ndarray
        Frequencies, Hz.
    H : ndarray
        Complex FRF (response / force) at ``f``.
    coherence : ndarray or None
        Ordinary coherence (None for a single record, where it is identically 1).
    force_autospectrum : ndarray or None
        Averaged force autospectrum (N²/Hz), to judge where the impulse excites the structure.
    """

    f: np.ndarray
    H: np.ndarray
    coherence: np.ndarray | None = None
    force_autospectrum: np.ndarray | None = None

    def excited_band(self, drop_dB: float = 20.0):
        """Frequency band where the force autospectrum is within ``drop_dB`` of its maximum.

        Outside it the hammer puts little energy in and the FRF is mostly noise (the usual rule for
        choosing a hammer tip). Returns ``(fmin, fmax)`` in Hz, ``fmin`` the first nonzero bin.
        """
        if self.force_autospectrum is None:
            return float(self.f[1]), float(self.f[-1])
        s = self.force_autospectrum
        ok = s >= s.max() * 10.0 ** (-drop_dB / 10.0)
        # the band runs from the first bin up to the first bin where the spectrum drops too far
        drop = np.flatnonzero(~ok[1:])
        hi = self.f[drop[0]] if drop.size else self.f[-1]
        return float(self.f[1]), float(hi)


def frf_h1(force, response, fs, nfft=None, window="boxcar") -> FRF:
    """H1 estimate ``S_fx / S_ff`` of the FRF from impact-test records.

    Parameters
    ----------
    force, response : array_like
        Records, shape ``(n,)`` for one hit or ``(hits, n)`` for several; spectra are averaged over
        hits. Each hit is one transient record (one segment, no overlap).
    fs : float
        Sampling rate, Hz.
    nfft : int, optional
        FFT length (>= n; zero padding interpolates the spectrum, it does not add resolution).
    window : str or array_like
        Window passed to scipy; ``"boxcar"`` for transients already windowed with
        :func:`force_window` / :func:`exponential_window`.

    Returns
    -------
    FRF
        One-sided, ``f`` from 0 to ``fs/2``; ``coherence`` when more than one hit is given.
    """
    x = np.atleast_2d(np.asarray(force, dtype=float))
    y = np.atleast_2d(np.asarray(response, dtype=float))
    if x.shape != y.shape:
        raise InputError("response", y.shape, f"same shape as force {x.shape}")
    if x.shape[-1] < 8:
        raise InputError("force", x.shape[-1], "at least 8 samples")
    if not (np.isfinite(fs) and fs > 0.0):
        raise InputError("fs", fs, "> 0 Hz")
    n = x.shape[-1]
    kw = dict(fs=fs, window=window, nperseg=n, noverlap=0, nfft=nfft, detrend=False, axis=-1)
    f, sxy = signal.csd(x, y, **kw)
    _, sxx = signal.welch(x, **kw)
    sxy, sxx = sxy.mean(axis=0), sxx.mean(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        H = sxy / sxx
        coh = None
        if x.shape[0] > 1:
            _, syy = signal.welch(y, **kw)
            coh = np.abs(sxy) ** 2 / (sxx * syy.mean(axis=0))
    return FRF(f, H, coh, sxx)


def force_window(force, fs, width, pre=0.0):
    """Rectangular force window: keep the impulse, zero the noise elsewhere.

    Parameters
    ----------
    force : array_like
        Force record(s), ``(n,)`` or ``(hits, n)``.
    fs : float
        Sampling rate, Hz.
    width : float
        Window length after the peak of each record, s.
    pre : float
        Window length kept before the peak, s.

    Returns
    -------
    ndarray
        Windowed copy.
    """
    x = np.array(force, dtype=float, ndmin=2)
    t = np.arange(x.shape[-1]) / fs
    out = np.zeros_like(x)
    for i, row in enumerate(x):
        t_peak = t[np.argmax(np.abs(row))]
        keep = (t >= t_peak - pre) & (t <= t_peak + width)
        out[i, keep] = row[keep]
    return out.reshape(np.shape(force))


def exponential_window(n, fs, tau):
    """Exponential window ``w(t) = exp(-t/tau)`` for ``n`` samples at ``fs``.

    It forces a lightly damped response to decay inside the record (less leakage) at the cost of
    added apparent damping; remove it with :func:`exponential_window_damping` or
    :meth:`SDOFFit.unwindowed`. Apply the same window to force and response.
    """
    if not (np.isfinite(tau) and tau > 0.0):
        raise InputError("tau", tau, "> 0 s")
    return np.exp(-np.arange(n) / fs / tau)


def exponential_window_damping(fn, zeta, tau):
    """Natural frequency and damping ratio corrected for an exponential window ``exp(-t/tau)``.

    Applied to force *and* response, the window turns the impulse response ``h(t)`` into
    ``h(t) exp(-t/tau)``, i.e. the FRF into ``H(s + 1/tau)``: every pole moves left by ``1/tau``
    with its damped frequency unchanged. Undoing the shift exactly:
    ``σ = ζ' ωn' - 1/τ``, ``ωd = ωn' sqrt(1 - ζ'²)``, ``ωn = sqrt(σ² + ωd²)``, ``ζ = σ/ωn``
    (to first order the familiar ``ζ = ζ' - 1/(τ ωn)``).

    Parameters
    ----------
    fn : array_like
        Natural frequency identified from the windowed data, Hz.
    zeta : array_like
        Damping ratio identified from the windowed data.
    tau : float
        Window time constant, s.

    Returns
    -------
    (ndarray, ndarray)
        Corrected natural frequency (Hz) and damping ratio.
    """
    wn = 2.0 * np.pi * np.asarray(fn, dtype=float)
    zeta = np.asarray(zeta, dtype=float)
    sigma = zeta * wn - 1.0 / tau
    wd = wn * np.sqrt(1.0 - zeta**2)
    wn_true = np.hypot(sigma, wd)
    return wn_true / (2.0 * np.pi), sigma / wn_true


def _convert(f, H, from_type, to_power):
    if from_type not in _FRF_POWERS:
        raise InputError("frf_type", from_type, "one of " + ", ".join(_FRF_POWERS))
    jw = 2j * np.pi * np.asarray(f, dtype=float)
    power = _FRF_POWERS[from_type] - to_power
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(H) / jw**power


def to_receptance(f, H, frf_type="receptance"):
    """Convert an FRF (``receptance``, ``mobility`` or ``accelerance``) to receptance, m/N."""
    return _convert(f, H, frf_type, 0)


def to_mobility(f, H, frf_type="receptance"):
    """Convert an FRF (``receptance``, ``mobility`` or ``accelerance``) to mobility, m/(N s)."""
    return _convert(f, H, frf_type, 1)


def pick_peaks(f, H, count=1, fmin=None, fmax=None):
    """Indices of the ``count`` most prominent peaks of ``|H|`` in ``[fmin, fmax]``, by frequency.

    Uses :func:`scipy.signal.find_peaks` with prominence ranking.
    """
    f = np.asarray(f, dtype=float)
    mag = np.abs(np.asarray(H))
    band = np.isfinite(mag) & (f > 0.0)
    if fmin is not None:
        band &= f >= fmin
    if fmax is not None:
        band &= f <= fmax
    idx = np.flatnonzero(band)
    if idx.size < 3:
        raise InputError("frequency band", (fmin, fmax), "a band with at least 3 FRF points")
    peaks, props = signal.find_peaks(mag[idx], prominence=0.0)
    if peaks.size == 0:
        raise InputError("FRF", "no peak", "an FRF with a resonance peak inside the band")
    order = np.argsort(props["prominences"])[::-1][:count]
    return np.sort(idx[peaks[order]])


@dataclass(frozen=True)
class HalfPowerResult:
    """Half-power bandwidth result.

    Attributes
    ----------
    fn : float
        Natural frequency (peak of the mobility, refined by a parabola through 3 points), Hz.
    zeta : float
        ``(f2 - f1) / (2 fn)``.
    f1, f2 : float
        Half-power frequencies (linear interpolation of ``|Y|`` between bins), Hz.
    peak_mobility : float
        ``|Y(fn)|``, m/(N s); for an SDOF it equals ``1/c``.
    """

    fn: float
    zeta: float
    f1: float
    f2: float
    peak_mobility: float


def half_power(f, H, frf_type="receptance", fmin=None, fmax=None) -> HalfPowerResult:
    """Half-power bandwidth method on the mobility of one well-separated mode.

    Parameters
    ----------
    f : array_like
        Frequencies, Hz.
    H : array_like
        FRF of type ``frf_type``.
    frf_type : {"receptance", "mobility", "accelerance"}
    fmin, fmax : float, optional
        Band holding the mode.

    Returns
    -------
    HalfPowerResult

    Raises
    ------
    InputError
        If the half-power points are not inside the data (record too short or band too narrow).
    """
    f = np.asarray(f, dtype=float)
    Y = np.abs(to_mobility(f, H, frf_type))
    Y = np.where(np.isfinite(Y), Y, 0.0)
    # Locate the mode on the FRF as measured (converting first divides noise by ω near f = 0 and
    # can create spurious low-frequency peaks), then climb to the local maximum of the mobility.
    i = int(pick_peaks(f, H, 1, fmin, fmax)[0])
    while 0 < i < f.size - 1 and max(Y[i - 1], Y[i + 1]) > Y[i]:
        i = i - 1 if Y[i - 1] > Y[i + 1] else i + 1
    # parabolic refinement of the peak through (i-1, i, i+1)
    if 0 < i < f.size - 1:
        y0, y1, y2 = Y[i - 1], Y[i], Y[i + 1]
        denom = y0 - 2.0 * y1 + y2
        shift = 0.5 * (y0 - y2) / denom if denom != 0.0 else 0.0
        shift = float(np.clip(shift, -0.5, 0.5))
        df = f[i + 1] - f[i]
        fn = f[i] + shift * df
        peak = y1 - 0.25 * (y0 - y2) * shift
    else:
        fn, peak = f[i], Y[i]
    level = peak / np.sqrt(2.0)
    lo = i
    while lo > 0 and Y[lo] > level:
        lo -= 1
    hi = i
    while hi < f.size - 1 and Y[hi] > level:
        hi += 1
    if Y[lo] > level or Y[hi] > level:
        raise InputError("FRF", "half-power points outside the data",
                         "a record/band that contains both half-power points")
    f1 = np.interp(level, [Y[lo], Y[lo + 1]], [f[lo], f[lo + 1]])
    f2 = np.interp(level, [Y[hi], Y[hi - 1]], [f[hi], f[hi - 1]])
    return HalfPowerResult(float(fn), float((f2 - f1) / (2.0 * fn)), float(f1), float(f2),
                           float(peak))


@dataclass(frozen=True)
class SDOFFit:
    """Least-squares SDOF fit ``H = 1/(k - m ω² + j c ω) + residual`` of a receptance.

    Attributes
    ----------
    k, m, c : float
        Stiffness (N/m), mass (kg), damping (N s/m) seen from the driving point.
    fn : float
        ``sqrt(k/m) / (2π)``, Hz.
    zeta : float
        ``c / (2 sqrt(k m))``.
    residual : complex
        Constant residual compliance of out-of-band modes (0 when not fitted), m/N.
    band : tuple of float
        Frequency band used, Hz.
    """

    k: float
    m: float
    c: float
    fn: float
    zeta: float
    residual: complex
    band: tuple

    def unwindowed(self, tau: float) -> "SDOFFit":
        """Undo an exponential window ``exp(-t/tau)`` applied to force and response.

        The windowed FRF is ``H(s + a)``, ``a = 1/tau``, i.e. an SDOF with ``m' = m``,
        ``c' = c + 2 m a`` and ``k' = k + c a + m a²``; this inverts that exactly.
        """
        a = 1.0 / tau
        c = self.c - 2.0 * self.m * a
        k = self.k - c * a - self.m * a**2
        return SDOFFit(k, self.m, c, float(np.sqrt(k / self.m) / (2 * np.pi)),
                       float(c / (2.0 * np.sqrt(k * self.m))), self.residual, self.band)


def _levy_sdof(w, H):
    """Levy's linearised fit: minimise Σ |H (k - m ω² + j c ω) - 1|² (linear in k, m, c)."""
    A = np.vstack([
        np.column_stack([H.real, -w**2 * H.real, -w * H.imag]),
        np.column_stack([H.imag, -w**2 * H.imag, w * H.real]),
    ])
    b = np.concatenate([np.ones_like(w), np.zeros_like(w)])
    return np.linalg.lstsq(A, b, rcond=None)[0]


def fit_sdof(f, H, frf_type="receptance", band=None, fit_residual=False, fmin=None,
             fmax=None) -> SDOFFit:
    """Fit an SDOF model to the complex FRF around one mode.

    Parameters
    ----------
    f : array_like
        Frequencies, Hz.
    H : array_like
        Complex FRF of type ``frf_type``.
    frf_type : {"receptance", "mobility", "accelerance"}
    band : (float, float), optional
        Band to fit, Hz. Default: the half-power estimate ``fn ± max(3 (f2 - f1), 5 df)``.
    fit_residual : bool
        Also fit a constant complex residual compliance (neighbouring modes).
    fmin, fmax : float, optional
        Band in which to look for the mode when ``band`` is not given, Hz.

    Returns
    -------
    SDOFFit

    Notes
    -----
    Levy's linear least squares gives the start; :func:`scipy.optimize.least_squares` then minimises
    the complex error ``H_model - H`` (not the linearised one, which over-weights the skirts). Unlike
    half-power, the fit uses every bin of the band, so it tolerates coarse resolution and noise.
    """
    f = np.asarray(f, dtype=float)
    R = to_receptance(f, H, frf_type)
    if band is None:
        hp = half_power(f, H, frf_type, fmin, fmax)
        half = max(3.0 * (hp.f2 - hp.f1), 5.0 * (f[1] - f[0]))
        band = (max(hp.fn - half, f[1]), hp.fn + half)
    sel = (f >= band[0]) & (f <= band[1]) & np.isfinite(R) & (f > 0.0)
    if np.count_nonzero(sel) < 4:
        raise InputError("band", band, "a band with at least 4 FRF points")
    w, Hs = 2.0 * np.pi * f[sel], R[sel]
    k0, m0, c0 = _levy_sdof(w, Hs)
    if not (k0 > 0.0 and m0 > 0.0 and c0 > 0.0):
        raise InputError("FRF", "no SDOF mode in band", "a band around one resonance")
    scale = np.max(np.abs(Hs))
    p0 = np.log([k0, m0, c0])

    def model(p):
        k, m, c = np.exp(p[:3])
        out = 1.0 / (k - m * w**2 + 1j * c * w)
        if fit_residual:
            out = out + (p[3] + 1j * p[4]) * scale
        return out

    def err(p):
        e = (model(p) - Hs) / scale
        return np.concatenate([e.real, e.imag])

    if fit_residual:
        p0 = np.concatenate([p0, [0.0, 0.0]])
    sol = least_squares(err, p0, method="lm", x_scale="jac")
    k, m, c = np.exp(sol.x[:3])
    res = complex(sol.x[3] + 1j * sol.x[4]) * scale if fit_residual else 0j
    return SDOFFit(float(k), float(m), float(c), float(np.sqrt(k / m) / (2 * np.pi)),
                   float(c / (2.0 * np.sqrt(k * m))), res, (float(band[0]), float(band[1])))


def modal_stiffness_damping(fn, zeta, modal_mass):
    """``k = m ωn²`` and ``c = 2 ζ m ωn`` from natural frequency (Hz), damping ratio and modal mass.

    Returns
    -------
    (ndarray, ndarray)
        Stiffness N/m, damping N s/m.
    """
    wn = 2.0 * np.pi * np.asarray(fn, dtype=float)
    m = np.asarray(modal_mass, dtype=float)
    return m * wn**2, 2.0 * np.asarray(zeta, dtype=float) * m * wn


@dataclass(frozen=True)
class HammerTest:
    """Records of a (synthetic) hammer test.

    Attributes
    ----------
    t : ndarray
        Time, s, shape ``(n,)``.
    force : ndarray
        Measured force, N, shape ``(hits, n)``.
    response : ndarray
        Measured response (displacement m, velocity m/s or acceleration m/s²), ``(hits, n)``.
    fs : float
        Sampling rate, Hz.
    response_type : str
        ``"displacement"``, ``"velocity"`` or ``"acceleration"``.
    """

    t: np.ndarray
    force: np.ndarray
    response: np.ndarray
    fs: float
    response_type: str


def synthetic_hammer_test(M, C, K, fs, duration, pulse_width, peak_force=100.0, hits=1,
                          noise=0.0, response_type="acceleration", drive=0, measure=0,
                          delay=0.01, seed=0, oversample=8) -> HammerTest:
    """Simulate hammer tests on ``M q'' + C q' + K q = b F(t)``.

    Parameters
    ----------
    M, C, K : array_like
        Mass (kg), damping (N s/m) and stiffness (N/m): scalars (SDOF) or ``(n, n)`` matrices.
    fs : float
        Sampling rate, Hz.
    duration : float
        Record length, s (frequency resolution ``1/duration``).
    pulse_width : float
        Half-sine impulse duration, s (its spectrum is flat to about ``1/pulse_width``).
    peak_force : float
        Impulse amplitude, N.
    hits : int
        Number of independent hits (different noise).
    noise : float
        Gaussian noise standard deviation on each channel, as a fraction of that channel's peak.
    response_type : {"displacement", "velocity", "acceleration"}
    drive, measure : int
        Excited and measured DOF (driving point when equal).
    delay : float
        Time of the impulse start, s.
    seed : int
        Random seed.
    oversample : int
        The response is computed at ``oversample * fs`` and then sampled at ``fs``.

    Returns
    -------
    HammerTest

    Notes
    -----
    The state-space model is discretised with a first-order hold (:func:`scipy.signal.cont2discrete`,
    ``method="foh"``) at the fine rate, exact for the linearly interpolated fine force, and run with
    :func:`scipy.signal.lfilter`. Both channels then go through the same anti-aliasing FIR filter
    and are decimated to ``fs`` (:func:`scipy.signal.decimate`), as a real acquisition system does;
    the FRF is accurate up to about 0.8 times the Nyquist frequency. Without this, a pulse of a few
    samples aliases and the sampled FRF is off by a few percent.
    """
    if response_type not in ("displacement", "velocity", "acceleration"):
        raise InputError("response_type", response_type, "displacement, velocity or acceleration")
    M, C, K = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (M, C, K))
    n = M.shape[0]
    if not (M.shape == C.shape == K.shape == (n, n)):
        raise InputError("M, C, K", (M.shape, C.shape, K.shape), "scalars or equal square matrices")
    if pulse_width * fs < 4:
        raise InputError("pulse_width", pulse_width, f">= 4 samples ({4 / fs:.3g} s)")
    oversample = int(oversample)
    if oversample < 1:
        raise InputError("oversample", oversample, ">= 1")
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    b = np.zeros((n, 1))
    b[drive, 0] = 1.0
    B = np.vstack([np.zeros((n, 1)), Minv @ b])
    row = np.zeros((1, 2 * n))
    D = np.zeros((1, 1))
    if response_type == "displacement":
        row[0, measure] = 1.0
    elif response_type == "velocity":
        row[0, n + measure] = 1.0
    else:
        row = A[n + measure:n + measure + 1, :]
        D = B[n + measure:n + measure + 1, :]
    fine = fs * oversample
    Ad, Bd, Cd, Dd, _ = signal.cont2discrete((A, B, row, D), 1.0 / fine, method="foh")
    num, den = signal.ss2tf(Ad, Bd, Cd, Dd)
    t_fine = np.arange(int(round(duration * fs)) * oversample) / fine
    tau = t_fine - delay
    F_fine = np.where((tau >= 0) & (tau <= pulse_width),
                      peak_force * np.sin(np.pi * tau / pulse_width), 0.0)
    y_fine = signal.lfilter(num[0], den, F_fine)
    if oversample > 1:  # the same anti-aliasing filter on both channels, as in a real DAQ
        F = signal.decimate(F_fine, oversample, ftype="fir", zero_phase=True)
        y = signal.decimate(y_fine, oversample, ftype="fir", zero_phase=True)
    else:
        F, y = F_fine, y_fine
    t = t_fine[::oversample]
    rng = np.random.default_rng(seed)
    force = F + noise * np.max(np.abs(F)) * rng.standard_normal((hits, t.size))
    resp = y + noise * np.max(np.abs(y)) * rng.standard_normal((hits, t.size))
    return HammerTest(t, force, resp, float(fs), response_type)


@dataclass(frozen=True)
class Identification:
    """Joint stiffness and damping identified from one FRF by half-power and by the SDOF fit.

    Attributes
    ----------
    half_power : HalfPowerResult
        Raw half-power result (on the possibly windowed FRF).
    fn_half_power, zeta_half_power : float
        Half-power natural frequency (Hz) and damping ratio, window-corrected.
    k_half_power, c_half_power : float
        ``m ωn²`` and ``2 ζ m ωn`` with the given modal mass (nan without one).
    fit : SDOFFit or None
        Window-corrected least-squares SDOF fit (None if it failed).
    modal_mass : float
        Mass used for the half-power ``k`` and ``c`` (nan if none was given).
    band : (float, float)
        Frequency band searched, Hz.
    fit_failure : str
        Why ``fit`` is None, in a few words ("" when it is not).
    """

    half_power: HalfPowerResult
    fn_half_power: float
    zeta_half_power: float
    k_half_power: float
    c_half_power: float
    fit: SDOFFit | None
    modal_mass: float
    band: tuple
    fit_failure: str = ""


def identify_frf(f, H, frf_type="receptance", modal_mass=None, band=None, exp_tau=None
                 ) -> Identification:
    """Half-power and SDOF-fit identification of one mode of an FRF.

    Parameters
    ----------
    f, H : array_like
        Frequencies (Hz) and complex FRF.
    frf_type : {"receptance", "mobility", "accelerance"}
    modal_mass : float, optional
        Modal mass for ``k = m ωn²`` and ``c = 2 ζ m ωn`` from the half-power result, kg.
    band : (float, float), optional
        Band holding the mode, Hz.
    exp_tau : float, optional
        Time constant of an exponential window applied to the records, s (corrected for).

    Returns
    -------
    Identification
    """
    fmin, fmax = band if band is not None else (None, None)
    f = np.asarray(f, dtype=float)
    hp = half_power(f, H, frf_type, fmin, fmax)
    fn, zeta = hp.fn, hp.zeta
    if exp_tau is not None:
        decay = 2.0 * np.pi * fn * zeta  # of the windowed record; the window's own share is 1/tau
        if not 1.0 / exp_tau < decay:  # no damping of its own left: zeta -0.82 (exit 0), or an OverflowError
            raise InputError("exp_tau", exp_tau, f"a longer window time constant: 1/tau = {1.0 / exp_tau:.3g} 1/s is "
                             f"not below the decay rate zeta wn = {decay:.3g} 1/s of the windowed data, so the mode "
                             "keeps no damping of its own (were the records windowed with it?)")
        share = 1.0 / (exp_tau * decay)  # the window's share of the windowed decay
        if zeta > MAX_WINDOWED_ZETA and zeta * (1.0 - share) <= MAX_WINDOWED_ZETA:
            raise InputError("exp_tau", exp_tau, f"a longer window time constant: the window's 1/tau = "
                             f"{1.0 / exp_tau:.3g} 1/s damps the windowed mode to zeta = {zeta:.3g} (half-power at "
                             f"{fn:.4g} Hz), beyond the {MAX_WINDOWED_ZETA:g} half-power reads")
        fn, zeta = (float(v) for v in exponential_window_damping(fn, zeta, exp_tau))
    mass = float("nan") if modal_mass is None else float(modal_mass)
    k, c = (float(v) for v in modal_stiffness_damping(fn, zeta, mass))
    failure = ""
    try:
        fit = fit_sdof(f, H, frf_type, fmin=fmin, fmax=fmax)
        if exp_tau is not None:
            fit = fit.unwindowed(exp_tau)
            if not (fit.zeta > 0.0 and fit.k > 0.0):
                # the window's share 1/tau exceeds the fitted decay: an undamped or unstable 'mode' (zeta -0.0045,
                # k 1.48e6 against 1.14e6 N/m for a 10 ms window on a 1 s record, printed without a word)
                failure = (f"the window's correction leaves zeta = {fit.zeta:.3g} and k = {fit.k:.3g} N/m; "
                           "a longer window time constant")
                fit = None
    except InputError:
        fit, failure = None, "no single mode in the band"
    band = (float(fmin) if fmin is not None else float(f[f > 0][0]),
            float(fmax) if fmax is not None else float(f[-1]))
    return Identification(hp, fn, zeta, k, c, fit, mass, band, failure)


def identify_hammer_test(test: HammerTest, pulse_width, modal_mass=None, exp_tau=None,
                         drop_dB=10.0, band=None) -> Identification:
    """Process hammer-test records: force window, optional exponential window, H1, identification.

    Parameters
    ----------
    test : HammerTest
        Records (``force`` and ``response`` of shape ``(hits, n)``).
    pulse_width : float
        Impulse duration, s; the force window keeps ``[peak - pulse_width, peak + 2 pulse_width]``.
    modal_mass : float, optional
        For half-power ``k`` and ``c``, kg.
    exp_tau : float, optional
        Exponential-window time constant, s (applied to both channels from the record start).
    drop_dB : float
        The mode is searched where the force autospectrum is within ``drop_dB`` of its maximum.
    band : (float or None, float or None), optional
        Band holding the mode, Hz; a ``None`` end falls back to the excited band.

    Returns
    -------
    Identification
    """
    fs = test.fs
    force = force_window(test.force, fs, width=2.0 * pulse_width, pre=pulse_width)
    response = np.asarray(test.response, dtype=float)
    if exp_tau is not None:
        w = exponential_window(response.shape[-1], fs, exp_tau)
        force, response = force * w, response * w
    frf = frf_h1(force, response, fs)
    kind = {"displacement": "receptance", "velocity": "mobility",
            "acceleration": "accelerance"}[test.response_type]
    lo, hi = frf.excited_band(drop_dB)
    excited = np.count_nonzero((frf.f >= lo) & (frf.f <= hi) & (frf.f > 0.0))
    if band is None and excited < 3:  # (identify_frf then said 'frequency band: got (20.0, 0.0)')
        raise InputError("force", f"no band excited within {drop_dB:g} dB of the autospectrum's maximum "
                                  f"({lo:g}-{hi:g} Hz)", "a recorded impulse, its autospectrum flat over the mode "
                                                         "(or give the band with --fmin/--fmax)")
    if band is not None:
        lo = lo if band[0] is None else band[0]
        hi = hi if band[1] is None else band[1]
    return identify_frf(frf.f, frf.H, kind, modal_mass, (lo, hi), exp_tau)


def half_power_error_study(mass, stiffness, damping, noise_levels, durations, fs=None,
                           pulse_width=None, hits=4, exp_tau=None, seed=0):
    """Errors of half-power and of the SDOF fit vs noise level and record length (resolution).

    Every combination runs a synthetic driving-point hammer test (accelerance, force window,
    ``hits`` averages) and identifies ``fn`` and ``ζ`` both ways with :func:`identify_hammer_test`.

    Parameters
    ----------
    mass, stiffness, damping : float
        SDOF under test (kg, N/m, N s/m).
    noise_levels : sequence of float
        Noise std as a fraction of each channel's peak.
    durations : sequence of float
        Record lengths, s (resolution ``1/duration``).
    fs : float, optional
        Sampling rate, Hz; default ``40 fn`` rounded up to 100 Hz (the sampled accelerance of an
        un-filtered record deviates from the continuous FRF by about ``(2π fn/fs)²/12``).
    pulse_width : float, optional
        Impulse width, s; default ``0.2 / fn`` (at least 4 samples).
    hits : int
        Averages per test.
    exp_tau : float, optional
        Exponential window time constant, s.
    seed : int

    Returns
    -------
    list of dict
        Per combination: ``noise``, ``duration_s``, ``df_Hz``, ``bandwidth_bins`` (half-power band in
        bins), signed relative errors ``fn_err_half_power``, ``zeta_err_half_power``,
        ``fn_err_fit``, ``zeta_err_fit``, ``k_err_fit`` (0.02 = +2 %), nan where a method failed.
    """
    fn = np.sqrt(stiffness / mass) / (2.0 * np.pi)
    zeta = damping / (2.0 * np.sqrt(stiffness * mass))
    fs = float(fs if fs is not None else np.ceil(40.0 * fn / 100.0) * 100.0)
    pulse_width = float(pulse_width if pulse_width is not None else max(0.2 / fn, 4.0 / fs))
    nan = float("nan")
    rows = []
    for T in durations:
        for noise in noise_levels:
            test = synthetic_hammer_test(mass, damping, stiffness, fs, T, pulse_width, hits=hits,
                                         noise=noise, seed=seed, delay=2.0 * pulse_width)
            row = {"noise": float(noise), "duration_s": float(T), "df_Hz": 1.0 / T,
                   "bandwidth_bins": 2.0 * zeta * fn * T}
            try:
                ident = identify_hammer_test(test, pulse_width, mass, exp_tau)
            except InputError:
                ident = None
            if ident is None:
                row.update(fn_err_half_power=nan, zeta_err_half_power=nan)
            else:
                row["fn_err_half_power"] = ident.fn_half_power / fn - 1.0
                row["zeta_err_half_power"] = ident.zeta_half_power / zeta - 1.0
            if ident is None or ident.fit is None:
                row.update(fn_err_fit=nan, zeta_err_fit=nan, k_err_fit=nan)
            else:
                row["fn_err_fit"] = ident.fit.fn / fn - 1.0
                row["zeta_err_fit"] = ident.fit.zeta / zeta - 1.0
                row["k_err_fit"] = ident.fit.k / stiffness - 1.0
            rows.append(row)
    return rows


def read_hammer_csv(path):
    """Read a hammer test: an FRF (columns ``f_Hz,re,im``) or time records (``t,force,response``).

    Fields may be separated by ``,``, ``;`` or a tab, with a decimal point or comma
    (:func:`drakecreep.files.csv_dialect`); ``#`` lines are comments.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    header : tuple of str
        :data:`FRF_COLUMNS` or :data:`TIME_COLUMNS`.
    data : numpy.ndarray
        ``(n, 3)`` finite values, ``n >= 8``.

    Raises
    ------
    InputError
        Not a bounded UTF-8 text file, another header, a cell that is not a number, NaN or inf, too few rows.
    """
    import io

    from drakecreep.files import MAX_DATA_BYTES, csv_dialect, first_non_number, read_csv_frame, read_input_text

    text = read_input_text(path, str(path), MAX_DATA_BYTES)  # regular UTF-8 file, bounded
    allowed = "f_Hz,re,im  or  t,force,response (separated by ',', ';' or a tab)"
    if not any(ln.strip() and not ln.lstrip().startswith("#") for ln in text.splitlines()):
        raise InputError(str(path), "empty", "a CSV with header " + allowed)
    separator, decimal = csv_dialect(text.splitlines())
    frame = read_csv_frame(io.StringIO(text), str(path), "a CSV with header " + allowed, separator, decimal)
    header = tuple(str(c).strip() for c in frame.columns)
    if header not in (FRF_COLUMNS, TIME_COLUMNS):
        raise InputError(f"{path}: header", separator.join(header), allowed)
    from pandas.api.types import is_numeric_dtype

    text_columns = [c for c in frame.columns if not is_numeric_dtype(frame[c])]
    bad = first_non_number(frame[text_columns].to_numpy().ravel()) if text_columns else None
    if bad is not None:  # '1_5', which float() reads as 15, included
        raise InputError(f"{path}: data", str(bad)[:40], "numbers")
    try:
        data = frame.to_numpy(dtype=float)
    except (TypeError, ValueError):
        bad = str(first_non_number(frame.to_numpy().ravel()))
        raise InputError(f"{path}: data", bad[:40], "numbers") from None
    if data.shape[0] < 8:
        raise InputError(f"{path}: rows", data.shape[0], "at least 8 rows of 3 numbers")
    if not np.all(np.isfinite(data)):
        row = int(np.flatnonzero(~np.all(np.isfinite(data), axis=1))[0])
        raise InputError(f"{path}: data", f"NaN, inf or an empty cell at data row {row + 1}", "finite numbers")
    axis = data[:, 0]
    name, unit = ("f_Hz", "Hz") if header == FRF_COLUMNS else ("t", "s")
    if header == FRF_COLUMNS and np.any(axis < 0):  # (the band search then said 'frequency band: got (None, None)')
        row = int(np.flatnonzero(axis < 0)[0])
        raise InputError(f"{path}: {name}", f"{axis[row]:g} {unit} at data row {row + 1}", "frequencies >= 0 Hz")
    if np.any(np.diff(axis) <= 0):
        row = int(np.flatnonzero(np.diff(axis) <= 0)[0]) + 1
        raise InputError(f"{path}: {name}", f"{axis[row]:g} {unit} at data row {row + 1} after {axis[row - 1]:g}",
                         "values increasing row by row")
    top = float(axis[-1]) if header == FRF_COLUMNS else 0.5 / float(np.min(np.diff(axis)))
    if not MIN_FREQUENCY <= top <= MAX_FREQUENCY:
        got = (f"a highest frequency of {top:.3g} Hz" if header == FRF_COLUMNS
               else f"a sample interval of {0.5 / top:.3g} s (Nyquist frequency {top:.3g} Hz)")
        allowed = (f"a highest frequency in [{MIN_FREQUENCY:g}, {MAX_FREQUENCY:g}] Hz" if header == FRF_COLUMNS
                   else f"a sample interval in [{0.5 / MAX_FREQUENCY:g}, {0.5 / MIN_FREQUENCY:g}] s")
        raise InputError(f"{path}: {name}", got, allowed + " (a hammer test's band in SI units; is a unit wrong?)")
    # magnitudes no hammer test gives in SI units (a receptance of 1e-9 m/N, an accelerance of 1e2 m/s^2/N, forces of
    # 1e3 N): beyond these the fit's k, m and c under- or overflow (an FRF scaled by 1e300 gave zeta = inf)
    values = np.abs(data[:, 1:])
    top = float(np.max(values))
    if not MIN_MAGNITUDE <= top <= MAX_MAGNITUDE:
        raise InputError(f"{path}: data", f"largest magnitude {top:.3g}", f"values whose largest magnitude is in "
                         f"[{MIN_MAGNITUDE:g}, {MAX_MAGNITUDE:g}] (SI units; is a unit wrong?)")
    return header, data
