"""Creep metrics of a simulated or measured feed, as the seed paper defines them (Tables 8-9).

All inputs and outputs are SI; :meth:`FeedMetrics.report` converts to mm/s, um and percent.
"""

from dataclasses import asdict, dataclass

import numpy as np

from drakecreep.errors import InputError

__all__ = ["FeedMetrics", "feed_metrics", "speed_fluctuation", "stick_slip", "following_error"]


def _window(t, t_start, t_end=None):
    t = np.asarray(t, dtype=float)
    mask = t >= t_start if t_end is None else (t >= t_start) & (t <= t_end)
    if mask.sum() < 2:
        raise InputError("steady_start", t_start, f"a time leaving at least two samples before the end ({t[-1]:.4g} s)")
    return mask


def speed_fluctuation(speed):
    """Mean speed, maximum fluctuation and fluctuation rate of a speed record (the paper's metric).

    The maximum fluctuation is the largest deviation of the speed from its mean over the record
    (the paper's Tables 8-9); the rate is that over the mean speed.

    Returns
    -------
    mean : float
        m/s.
    max_fluctuation : float
        ``max |v - mean|`` in m/s.
    rate : float
        ``max_fluctuation / |mean|`` (fraction; ``inf`` for a zero mean).
    """
    v = np.asarray(speed, dtype=float)
    mean = float(v.mean())
    dev = float(np.max(np.abs(v - mean)))
    rate = dev / abs(mean) if mean != 0 else float("inf")
    return mean, dev, rate


def stick_slip(speed, feed, threshold):
    """Stick fraction and number of stick-slip cycles of a speed record.

    Speeds are taken in the feed direction. The table is stuck while it moves slower than
    ``threshold * |feed|`` (including a presliding rebound backwards). The threshold is a share of the
    feed, not an absolute speed, and must stand above the speed a stuck table still creeps at in the
    model: the regularized ``coulomb``/``stribeck`` laws (``tanh(v / v_reg)``) hold the breakaway force only
    while creeping at ``v_reg atanh(F / Fs)``, 1-3 um/s for ``v_reg`` = 1 um/s, and LuGre creeps at the
    bristles' presliding rate. With the default 0.2 that creep reads as stuck down to feeds of about
    0.01 mm/s (0.2 x 10 um/s = 2 um/s); the former 0.05 counted it as sliding below about 0.05 mm/s.
    It must exceed the feed itself
    to count as slipping again. A slip that makes up for a stick overshoots the feed, while noise at the
    threshold and the ringing after a slip do not, so they are not counted as cycles.
    A cycle is one entry into sticking from slipping.

    Returns
    -------
    fraction : float
        Share of samples stuck (0-1).
    cycles : int
    """
    v = np.asarray(speed, dtype=float) * np.sign(feed)
    low = threshold * abs(feed)
    stuck_samples = v < low
    cycles = 0
    stuck = bool(stuck_samples[0])
    for value in v[1:]:
        if stuck and value > abs(feed):
            stuck = False
        elif not stuck and value < low:
            stuck = True
            cycles += 1
    return float(stuck_samples.mean()), cycles


def following_error(x_ref, x):
    """Largest and RMS following error ``x_ref - x`` (m)."""
    err = np.asarray(x_ref, dtype=float) - np.asarray(x, dtype=float)
    return float(np.max(np.abs(err))), float(np.sqrt(np.mean(err**2)))


@dataclass(frozen=True)
class FeedMetrics:
    """Metrics of a feed over its steady window (SI units)."""

    window_start: float  # s
    window_end: float  # s
    feed: float  # m/s commanded
    mean_speed: float  # m/s
    max_fluctuation: float  # m/s
    fluctuation_rate: float  # fraction
    stick_fraction: float  # fraction of the window
    stick_slip_cycles: int
    stick_slip_frequency: float  # cycles per second
    following_error_max: float  # m
    following_error_rms: float  # m
    min_speed: float  # m/s
    max_speed: float  # m/s
    converged: object = None  # True/False: the run's convergence check agreed; None: not checked

    @property
    def creep(self):
        """True when the table stops during the steady window (stick-slip)."""
        return self.stick_slip_cycles > 0 or self.stick_fraction > 0

    def report(self):
        """Metrics in report units, with the unit in each key."""
        return {
            "window_start_s": self.window_start,
            "window_end_s": self.window_end,
            "feed_mm_s": self.feed * 1e3,
            "mean_speed_mm_s": self.mean_speed * 1e3,
            "max_fluctuation_mm_s": self.max_fluctuation * 1e3,
            "fluctuation_rate_percent": self.fluctuation_rate * 100.0,
            "stick_fraction": self.stick_fraction,
            "stick_slip_cycles": self.stick_slip_cycles,
            "stick_slip_frequency_Hz": self.stick_slip_frequency,
            "creep": self.creep,
            "following_error_max_um": self.following_error_max * 1e6,
            "following_error_rms_um": self.following_error_rms * 1e6,
            "min_speed_mm_s": self.min_speed * 1e3,
            "max_speed_mm_s": self.max_speed * 1e3,
            "converged": self.converged,
        }

    def as_dict(self):
        """SI values by field name."""
        return asdict(self)


def feed_metrics(t, table_speed, x_ref, table_position, feed, steady_start, stick_threshold):
    """All :class:`FeedMetrics` of a record over ``t >= steady_start``.

    Parameters
    ----------
    t, table_speed, x_ref, table_position : array_like
        Time (s), table speed (m/s), reference and table position (m), uniformly sampled.
    feed : float
        Commanded speed (m/s).
    steady_start : float
        Start of the steady window (s).
    stick_threshold : float
        Stuck when ``|v| < stick_threshold * |feed|``.
    """
    t = np.asarray(t, dtype=float)
    mask = _window(t, steady_start)
    v = np.asarray(table_speed, dtype=float)[mask]
    mean, dev, rate = speed_fluctuation(v)
    fraction, cycles = stick_slip(v, feed, stick_threshold)
    fe_max, fe_rms = following_error(np.asarray(x_ref)[mask], np.asarray(table_position)[mask])
    span = float(t[mask][-1] - t[mask][0])
    return FeedMetrics(
        window_start=float(t[mask][0]), window_end=float(t[mask][-1]), feed=float(feed),
        mean_speed=mean, max_fluctuation=dev, fluctuation_rate=rate, stick_fraction=fraction,
        stick_slip_cycles=cycles, stick_slip_frequency=cycles / span if span > 0 else 0.0,
        following_error_max=fe_max, following_error_rms=fe_rms,
        min_speed=float(v.min()), max_speed=float(v.max()),
    )
