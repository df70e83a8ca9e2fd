"""Conclusions that survive the unknowns: creep over every plausible rig, not one guessed one.

The paper gives the stiffness chain, the loads and the screw geometry; the other values of a preset are
assumptions (``[assumed]`` in ``presets/<name>.yaml``). The *uncertainty spec*
(``presets/<name>_uncertainty.yaml``) gives each sampled assumption a distribution over its plausible
range with the source of that range, and names every assumption held fixed and why.
:func:`run_uncertainty` draws ``n`` rigs from it (a seeded Latin hypercube, :class:`scipy.stats.qmc.LatinHypercube`,
mapped to uniform or log-uniform marginals), runs every rig at every feed and load case through the sweep
engine (:func:`drakecreep.sim.sweep.run_sweep`: batched, local processes or a Dask cluster) and reports

* per feed and load case (:func:`summarize`): the share of plausible rigs that creep (stick-slip in the
  steady window, :attr:`drakecreep.sim.metrics.FeedMetrics.creep`) with a 95 % Wilson interval, and
  percentiles of the maximum speed fluctuation;
* per sampled parameter (:func:`sensitivity`): Spearman's rank correlation with the creep verdict and
  with the fluctuation, and the creep share of the rigs in the lower and the upper half of the
  parameter's range (log-scale halves for log-uniform ones): which unknown decides the answer.

Every rig runs at every feed and load (common random numbers), so differences between feeds are not
sampling noise of different rigs.
"""

import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from drakecreep.errors import InputError, renaming, short_repr
from drakecreep.params import PRESETS, get_value, load_yaml_file, preset, with_value

__all__ = [
    "DISTRIBUTIONS",
    "Distribution",
    "UncertaintySpec",
    "UncertaintyResult",
    "load_uncertainty",
    "uncertainty_spec",
    "sample_rigs",
    "check_rigs",
    "run_uncertainty",
    "summarize",
    "sensitivity",
]

DISTRIBUTIONS = ("uniform", "log-uniform")


@dataclass(frozen=True)
class Distribution:
    """Distribution of one assumed parameter over its plausible range (SI).

    Parameters
    ----------
    path : str
        Dotted parameter path (``"friction.bristle_stiffness"``).
    dist : {"uniform", "log-uniform"}
    low, high : float
        The plausible range, ``low < high`` (``low > 0`` for log-uniform).
    source : str
        Where the range comes from.
    """

    path: str
    dist: str
    low: float
    high: float
    source: str

    def __post_init__(self):
        where = f"sample.{self.path}"
        if self.dist not in DISTRIBUTIONS:
            raise InputError(f"{where}.dist", self.dist, "one of " + ", ".join(DISTRIBUTIONS))
        for name in ("low", "high"):
            value = getattr(self, name)
            try:  # an integer of hundreds of digits: math.isfinite raised 'internal error: OverflowError'
                number = float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None
            except OverflowError:
                number = None
            if number is None or not math.isfinite(number):
                raise InputError(f"{where}.{name}", value, "a finite number")
            object.__setattr__(self, name, number)
        if not self.low < self.high:
            raise InputError(f"{where}.high", self.high, f"> low ({self.low})")
        if self.dist == "log-uniform" and self.low <= 0:
            raise InputError(f"{where}.low", self.low, "> 0 for a log-uniform distribution")
        if not isinstance(self.source, str) or not self.source.strip():
            raise InputError(f"{where}.source", self.source, "a non-empty text naming the source of the range")

    def ppf(self, u):
        """Values at quantiles ``u`` in [0, 1] (inverse CDF)."""
        u = np.asarray(u, dtype=float)
        if self.dist == "log-uniform":
            return np.exp(math.log(self.low) + u * (math.log(self.high) - math.log(self.low)))
        return self.low + u * (self.high - self.low)

    def unit(self, value):
        """Position of ``value`` in the range, 0-1 (on a log scale for log-uniform)."""
        value = np.asarray(value, dtype=float)
        if self.dist == "log-uniform":
            return (np.log(value) - math.log(self.low)) / (math.log(self.high) - math.log(self.low))
        return (value - self.low) / (self.high - self.low)


@dataclass(frozen=True)
class UncertaintySpec:
    """The distributions of a preset's sampled assumptions and the assumptions held fixed.

    ``preset`` is the preset the spec was read for (a spec file may name several presets that share
    their assumptions, e.g. ``paper`` and ``paper_catalogue``).
    """

    preset: str
    distributions: tuple
    fixed: dict = field(default_factory=dict)
    source: str = ""

    @property
    def paths(self):
        """Sampled parameter paths, in the spec's order."""
        return [d.path for d in self.distributions]


def load_uncertainty(path, preset_name=None):
    """Read an uncertainty spec (YAML; see ``presets/paper_uncertainty.yaml``).

    ``preset_name``: the preset it is to be used with, which its ``preset`` must name (default: its first).

    Raises
    ------
    InputError
        For bad YAML, an unknown key, a bad distribution, an unknown parameter path, or a spec of other presets.
    """
    path = Path(path)
    return _spec_from_data(load_yaml_file(path, str(path), "a YAML uncertainty spec"), str(path), preset_name)


def uncertainty_spec(name="paper"):
    """The packaged uncertainty spec of preset ``name``: the ``presets/*_uncertainty.yaml`` whose ``preset`` names it."""
    folder = resources.files("drakecreep").joinpath("presets")
    files = sorted((f for f in folder.iterdir() if f.name.endswith("_uncertainty.yaml")), key=lambda f: f.name)
    have = []
    for file in files:
        data = load_yaml_file(Path(str(file)), f"presets/{file.name}", "a YAML uncertainty spec")
        names = data.get("preset", "paper")
        names = [names] if isinstance(names, str) else list(names)
        if name in PRESETS and name in names:
            return _spec_from_data(data, f"presets/{file.name}", name)
        have += names
    raise InputError("preset", name, "a preset with an uncertainty spec: " + ", ".join(have))


def _spec_from_data(data, where, name=None):
    if not isinstance(data, dict) or set(data) - {"preset", "sample", "fixed"} or "sample" not in data:
        raise InputError(where, f"a YAML {type(data).__name__}" if not isinstance(data, dict) else sorted(data),
                         "a mapping with preset, sample and (optional) fixed")
    names = data.get("preset", "paper")
    names = [names] if isinstance(names, str) else names
    if not isinstance(names, list) or not names or any(n not in PRESETS for n in names):
        raise InputError("preset", names, "a preset name or a list of them: " + ", ".join(PRESETS))
    if name is not None and name not in names:  # its ranges and fixed values are another preset's assumptions
        raise InputError(f"{where}: preset", names, f"a spec of the preset it is used with, {name} (or choose --preset)")
    name = name or names[0]
    sample = data["sample"]
    if not isinstance(sample, dict) or not sample:
        raise InputError("sample", sample, "a mapping path -> {dist, low, high, source}")
    base = preset(name)
    dists = []
    for path, spec in sample.items():
        keys = ("dist", "low", "high", "source")
        if isinstance(spec, dict):  # the key at fault by name (the mapping was shown cut off after four items)
            for key in spec:
                if key not in keys:
                    raise InputError(f"sample.{path}.{key}", "an unknown key", "one of dist, low, high, source")
            for key in keys:
                if key not in spec:
                    raise InputError(f"sample.{path}.{key}", "nothing", "a value (each of dist, low, high, source)")
        else:
            raise InputError(f"sample.{path}", spec, "a mapping with dist, low, high, source")
        dist = Distribution(path=str(path), **spec)
        # raises for an unknown path, naming the spec's key (it said '1: got '1'', no 'sample')
        current = renaming(lambda f: f"sample.{path}", get_value, base, dist.path)
        if isinstance(current, (bool, str)):
            raise InputError(f"sample.{path}", current, "a numeric parameter")
        if isinstance(current, int):  # its draws were refused one by one: 'got 1363.0383126785457; allowed: an integer'
            raise InputError(f"sample.{path}", current, "a real-valued parameter (an integer one cannot take the "
                             "distribution's values)")
        for key, bound in (("low", dist.low), ("high", dist.high)):
            try:
                with_value(base, dist.path, bound)  # each bound is a valid value of the field
            except InputError as err:  # the spec's key ('motor.peak_torque: got 1e+300' named the params field)
                raise InputError(f"sample.{path}.{key}", bound, f"a value of {dist.path}: {err.allowed}") from None
        dists.append(dist)
    fixed = data.get("fixed") or {}
    if not isinstance(fixed, dict):
        raise InputError("fixed", fixed, "a mapping path -> reason")
    for path in fixed:  # 'fixed: {1: x}' said 'path: got 1', no 'fixed'
        renaming(lambda f: f"fixed.{path}", get_value, base, path)
    both = sorted(set(fixed) & set(sample))
    if both:
        raise InputError(f"fixed.{both[0]}", fixed[both[0]], "a path not also sampled")
    return UncertaintySpec(preset=name, distributions=tuple(dists), fixed=dict(fixed), source=where)


def sample_rigs(spec, n, seed=0):
    """``n`` plausible rigs: a Latin hypercube over the spec's distributions.

    Parameters
    ----------
    spec : UncertaintySpec
    n : int
        Number of rigs (>= 1).
    seed : int
        Seed of :class:`scipy.stats.qmc.LatinHypercube`; the same seed gives the same rigs.

    Returns
    -------
    list of dict
        One ``{path: value}`` per rig (SI), ready as sweep points.
    """
    from scipy.stats import qmc

    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InputError("samples", n, "an integer >= 1")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError("seed", seed, "an integer >= 0")
    u = qmc.LatinHypercube(d=len(spec.distributions), seed=seed).random(n)
    columns = [d.ppf(u[:, j]) for j, d in enumerate(spec.distributions)]
    return [{d.path: float(columns[j][i]) for j, d in enumerate(spec.distributions)} for i in range(n)]


@dataclass
class UncertaintyResult:
    """What :func:`run_uncertainty` produced.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per rig, feed and load case: ``rig``, the sampled paths (SI), ``feed`` (m/s),
        ``load_case`` and the sweep's metric columns (``creep``, ``max_fluctuation_mm_s``, ...).
    summary : pandas.DataFrame
        :func:`summarize` of the table.
    sensitivity : pandas.DataFrame
        :func:`sensitivity` of the table.
    spec : UncertaintySpec
    samples, seed : int
    wall_time : float
        Seconds for the simulations (the sweep).
    failed : int
        Cases that failed in the sweep (excluded from the shares).
    """

    table: object
    summary: object
    sensitivity: object
    spec: UncertaintySpec
    samples: int
    seed: int
    wall_time: float
    failed: int


def check_rigs(base, rigs):
    """Refuse a sample with a rig that is no valid parameter set, naming the spec's key (``sample.PATH``) whose draw
    made it invalid, before anything runs (the sweep named the field a cross-check refused: a velocity period drawn
    between 0.2 and 0.25 ms said 'controller.position_period: got 0.001', a key the spec does not have).

    ``rigs`` are :func:`sample_rigs`' draws, applied to ``base`` in the spec's order as the sweep applies them
    (:func:`run_uncertainty` calls it when the sweep refuses a case: 1.6 ms a rig of the paper's spec, no cost when
    every rig is valid)."""
    for i, rig in enumerate(rigs):
        params = base
        for path, value in rig.items():
            try:
                params = with_value(params, path, value)
            except InputError as err:
                why = (err.allowed if err.field == path else
                       f"then {err.field} = {short_repr(err.value)} is refused, allowed: {err.allowed}")
                raise InputError(f"sample.{path}", value, f"a range whose every draw makes a valid rig (rig {i} drew "
                                 f"this value; {why})") from None


def run_uncertainty(base, spec, samples, feeds, load_cases=(3,), *, seed=0, duration=3.0, executor="processes",
                    workers=None, scheduler=None, batch_size=200, out_dir=None, progress=True):
    """Run every plausible rig at every feed and load case; summarize creep and fluctuation.

    Parameters
    ----------
    base : drakecreep.params.DriveParams
        The preset the spec belongs to (its non-sampled values are used as they are).
    spec : UncertaintySpec
    samples : int
        Number of rigs.
    feeds : sequence of float
        Feeds (m/s).
    load_cases : sequence of int
        Load cases of ``base``.
    seed : int
        Seed of the rig sample.
    duration : float
        Simulated time per case (s); the metrics window is ``simulation.steady_start`` to the end.
    executor, workers, scheduler, batch_size, out_dir, progress
        As :func:`drakecreep.sim.sweep.run_sweep` (``out_dir`` caches finished cases).

    Returns
    -------
    UncertaintyResult
    """
    from drakecreep.sim.sweep import run_sweep

    feeds = [float(f) for f in feeds]
    if not feeds:
        raise InputError("feeds", feeds, "at least one feed")
    load_cases = [int(c) for c in load_cases]
    if not load_cases:
        raise InputError("load_cases", load_cases, "at least one load case")
    for case in load_cases:
        base.load_case(case)
    rigs = sample_rigs(spec, samples, seed)
    points = [dict(rig, feed=f, load_case=c) for rig in rigs for c in load_cases for f in feeds]
    try:
        result = run_sweep(base, points, scenario=dict(duration=duration), executor=executor, workers=workers,
                           scheduler=scheduler, out_dir=out_dir, progress=progress, batch_size=batch_size)
    except InputError:  # the sweep checks every case before it runs one; a rig it refused is named by its key
        check_rigs(base, rigs)
        raise
    table = result.table
    per_rig = len(load_cases) * len(feeds)
    table.insert(1, "rig", table["case"] // per_rig)
    return UncertaintyResult(table=table, summary=summarize(table), sensitivity=sensitivity(table, spec),
                             spec=spec, samples=samples, seed=seed, wall_time=result.wall_time, failed=result.failed)


def _wilson(k, n, z=1.96):
    if n == 0:
        return float("nan"), float("nan")
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def _ok(table):
    if "status" not in table:
        return table.iloc[0:0]
    return table[table["status"] == "ok"]


def summarize(table, percentiles=(5, 50, 95)):
    """Per feed and load case: the share of rigs that creep and the spread of the fluctuation.

    Parameters
    ----------
    table : pandas.DataFrame
        :attr:`UncertaintyResult.table` (columns ``feed``, ``load_case``, ``status``, ``creep``,
        ``max_fluctuation_mm_s``, ``fluctuation_rate_percent``).
    percentiles : sequence of float
        Percentiles of the fluctuation to report.

    Returns
    -------
    pandas.DataFrame
        ``feed_mm_s``, ``load_case``, ``rigs`` (ok cases), ``failed``, ``creep_percent`` and its 95 %
        Wilson interval ``creep_low_percent``/``creep_high_percent``, ``fluctuation_p<q>_mm_s``,
        ``rate_p<q>_percent``.
    """
    import pandas as pd

    rows = []
    for (feed, case), group in table.groupby(["feed", "load_case"], sort=True):
        ok = _ok(group)
        n = len(ok)
        k = int(ok["creep"].astype(bool).sum()) if n else 0
        low, high = _wilson(k, n)
        row = dict(feed_mm_s=feed * 1e3, load_case=int(case), rigs=n, failed=len(group) - n,
                   creep_percent=100.0 * k / n if n else float("nan"),
                   creep_low_percent=100.0 * low, creep_high_percent=100.0 * high)
        for q in percentiles:
            row[f"fluctuation_p{q:g}_mm_s"] = float(np.percentile(ok["max_fluctuation_mm_s"], q)) if n else float("nan")
        for q in percentiles:
            row[f"rate_p{q:g}_percent"] = float(np.percentile(ok["fluctuation_rate_percent"], q)) if n else float("nan")
        rows.append(row)
    return pd.DataFrame(rows)


def sensitivity(table, spec):
    """Which sampled assumption decides creep: rank correlations and half-range creep shares.

    Over all ok cases of ``table`` (every feed and load case pooled; run it on a sub-table for one
    feed), per sampled parameter:

    * ``rho_creep``: Spearman's rank correlation of the parameter with the creep verdict (0/1);
    * ``rho_fluctuation``: with ``max_fluctuation_mm_s``;
    * ``creep_low_half_percent`` / ``creep_high_half_percent``: creep share of the rigs whose value lies
      in the lower / upper half of the range (log scale for log-uniform).

    Rows are sorted by ``|rho_creep|``, largest first. A correlation is ``nan`` when the verdict
    does not vary (every rig creeps, or none).

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd
    from scipy.stats import spearmanr

    ok = _ok(table)
    creep = ok["creep"].astype(bool).to_numpy() if len(ok) else np.zeros(0, dtype=bool)
    fluct = ok["max_fluctuation_mm_s"].to_numpy(dtype=float) if len(ok) else np.zeros(0)
    rows = []
    for d in spec.distributions:
        x = ok[d.path].to_numpy(dtype=float) if len(ok) else np.zeros(0)
        varies = len(x) > 2 and np.ptp(x) > 0
        rho_c = float(spearmanr(x, creep).statistic) if varies and 0 < creep.sum() < len(creep) else float("nan")
        rho_f = float(spearmanr(x, fluct).statistic) if varies and np.ptp(fluct) > 0 else float("nan")
        lower = d.unit(x) < 0.5
        rows.append(dict(
            parameter=d.path, dist=d.dist, low=d.low, high=d.high, rho_creep=rho_c, rho_fluctuation=rho_f,
            creep_low_half_percent=100.0 * creep[lower].mean() if lower.any() else float("nan"),
            creep_high_half_percent=100.0 * creep[~lower].mean() if (~lower).any() else float("nan"),
        ))
    frame = pd.DataFrame(rows)
    order = np.argsort(-np.nan_to_num(np.abs(frame["rho_creep"].to_numpy()), nan=-1.0), kind="stable")
    return frame.iloc[order].reset_index(drop=True)
