"""What to run: feed speed, load case and duration (the parameters say what the machine is)."""

import math
import numbers
from dataclasses import dataclass

from drakecreep.errors import InputError

__all__ = ["Scenario", "check_scenario", "MIN_FEED", "MAX_FEED", "MAX_DURATION"]

#: largest feed accepted (m/s); feed drives of this class reach 0.5-1 m/s rapid traverse
MAX_FEED = 1.0
#: smallest feed magnitude accepted (m/s), the CLI's 1e-4 mm/s: a run of seconds moves a few scale counts, nothing
#: left to measure, and the analyses' 1/v terms overflow (a sweep at 1e-300 m/s reported a fluctuation of 60130 %
#: and creep, exit 0)
MIN_FEED = 1e-7
#: longest simulated time of one run (s)
MAX_DURATION = 3600.0


@dataclass(frozen=True)
class Scenario:
    """A feed at constant speed under one load case.

    Parameters
    ----------
    feed : float
        Commanded table speed (m/s), non-zero; negative feeds move towards the motor.
    load_case : int
        Number of the load case in ``params.loads.cases`` (1-based); 0 for no external load.
    duration : float
        Simulated time (s).
    """

    feed: float = 1e-3
    load_case: int = 3
    duration: float = 5.0

    def __post_init__(self):
        feed, duration = _finite_real(self.feed), _finite_real(self.duration)
        if feed is None or not MIN_FEED <= abs(feed) <= MAX_FEED:
            raise InputError("feed", self.feed, f"a non-zero speed within +-{MAX_FEED} m/s, of magnitude at least "
                             f"{MIN_FEED:g} m/s")
        if isinstance(self.load_case, bool) or not isinstance(self.load_case, numbers.Integral) or self.load_case < 0:
            raise InputError("load_case", self.load_case, "an integer >= 0 (0 = unloaded)")
        if duration is None or not 0 < duration <= MAX_DURATION:
            raise InputError("duration", self.duration, f"a time in (0, {MAX_DURATION:g}] s")
        # NumPy's scalars (np.float32, np.int64) are numbers too: stored as Python's
        object.__setattr__(self, "load_case", int(self.load_case))
        for name, value in (("feed", feed), ("duration", duration)):
            if not isinstance(getattr(self, name), (int, float)):
                object.__setattr__(self, name, value)


def _finite_real(value):
    """``float(value)`` of a finite real number (NumPy's scalars too), else None (bool, text, NaN, inf, an integer
    of hundreds of digits: float() overflowed, an 'internal error')."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return None
    try:
        x = float(value)
    except OverflowError:
        return None
    return x if math.isfinite(x) else None


def check_scenario(scenario, field="scenario"):
    """Refuse what is no :class:`Scenario` (a feed, None) by ``field``, before an attribute of it is read."""
    if not isinstance(scenario, Scenario):
        raise InputError(field, scenario, "a Scenario (drakecreep.Scenario(feed=m/s, load_case=n, duration=s))")
    return scenario
