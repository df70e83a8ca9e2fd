"""What to run: feed speed, load case and duration (the parameters say what the machine is)."""

import math
from dataclasses import dataclass

from drakecreep.errors import InputError

__all__ = ["Scenario", "MAX_FEED"]

#: largest feed accepted (m/s); feed drives of this class reach 0.5-1 m/s rapid traverse
MAX_FEED = 1.0


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
        if isinstance(self.feed, bool) or not isinstance(self.feed, (int, float)) or not math.isfinite(self.feed) \
                or self.feed == 0 or abs(self.feed) > MAX_FEED:
            raise InputError("feed", self.feed, f"a non-zero speed within +-{MAX_FEED} m/s")
        if isinstance(self.load_case, bool) or not isinstance(self.load_case, int) or self.load_case < 0:
            raise InputError("load_case", self.load_case, "an integer >= 0 (0 = unloaded)")
        if isinstance(self.duration, bool) or not isinstance(self.duration, (int, float)) \
                or not math.isfinite(self.duration) or not 0 < self.duration <= 3600:
            raise InputError("duration", self.duration, "a time in (0, 3600] s")
