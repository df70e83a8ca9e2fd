"""Parameter sweeps at scale: grid or random cases -> simulations on an executor -> one tidy table.

A *point* is a mapping of dotted parameter paths (``"nut.axial_stiffness"``, see
:func:`drakecreep.params.with_value`) and scenario fields (``feed``, ``load_case``, ``duration``) to
values. :func:`grid` and :func:`random_sample` expand axes into points; :func:`make_cases` turns
points into validated :class:`Case` objects (full parameters + scenario + a hash of both);
:func:`run_sweep` runs a function of each simulation result on

* ``"serial"``: in this process;
* ``"processes"`` (default): a local process pool, all usable CPUs unless ``workers`` says fewer (never more);
* ``"dask"``: a ``dask.distributed`` cluster given its scheduler address (or a ``Client``).

The same code runs on all three. With ``out_dir`` every finished case is cached as
``cache/<key>.json`` (written to a temporary file, then ``os.replace``: a case is either fully there or
not at all), so an interrupted sweep resumes without recomputing, and the table is written the same
way as ``results.parquet`` and ``results.csv``. A case whose worker dies is resubmitted (process pool:
the pool is rebuilt; Dask: the scheduler reschedules it, and a case that still fails is resubmitted
by the sweep) up to ``retries`` times; one that fails every time becomes a row whose ``status`` says
why, and is not cached.

Parameter columns carry the path as name and SI values; metric columns are in report units with the
unit in the name (``fluctuation_rate_percent``), as :meth:`drakecreep.sim.metrics.FeedMetrics.report`.
"""

import concurrent.futures as cf
import dataclasses
import hashlib
import importlib.util
import itertools
import json
import math
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drakecreep.model.drive_source import scenario_with_drive
from drakecreep.errors import InputError, renaming, short_repr
from drakecreep.files import write_json
from drakecreep.params import check_params, params_to_dict, with_value
from drakecreep.processes import new_pool, pool_size, stop_pool, usable_cpus
from drakecreep.scenario import Scenario

__all__ = [
    "SCENARIO_FIELDS",
    "EXECUTORS",
    "MAX_RETRIES",
    "CACHE_VERSION",
    "Case",
    "SweepResult",
    "grid",
    "random_sample",
    "make_cases",
    "case_key",
    "feed_report",
    "run_case",
    "run_sweep",
    "SweepSpec",
    "load_spec",
    "metric_columns",
    "connect_dask",
    "MAX_CASES",
    "DEFAULT_MAP_COLOR",
]

#: point keys that set the :class:`~drakecreep.scenario.Scenario` rather than a parameter (``drive``:
#: ``"cascade"`` or ``"constant_speed"``, see :class:`drakecreep.model.drive_source.DriveScenario`)
SCENARIO_FIELDS = ("feed", "load_case", "duration", "drive")
EXECUTORS = ("serial", "processes", "dask")
#: The most extra attempts of a failed case: a deterministic failure (a bad value) fails every attempt, so a
#: large count only repeats it (99999999999 ran for ever)
MAX_RETRIES = 10
#: bump when the meaning of a cached row changes (simulation semantics, report keys)
CACHE_VERSION = 1
#: default largest number of cases of one sweep (``max_cases`` / ``--max-cases`` raise it): 100 000 cases
#: of a few seconds each are days of computing, and the case list alone must fit in memory
MAX_CASES = 100_000
#: the metric a spec's stability map (``plot``) is coloured by when it names no ``color``
DEFAULT_MAP_COLOR = "fluctuation_rate_percent"


def _check_size(n, max_cases, what="the sweep"):
    if n > max_cases:
        digits = len(str(int(n))) if n < 10**4000 else 4000
        raise InputError("axes", f"about 10^{digits - 1} cases" if n >= 10**6 else f"{n} cases",
                         f"at most {max_cases} {'case' if max_cases == 1 else 'cases'} in {what} (raise the cap "
                         "with --max-cases / max_cases)")


# --------------------------------------------------------------------------- points

def _axis_values(path, values):
    if not isinstance(path, str):
        raise InputError("axes", path, "a parameter path (text such as nut.axial_stiffness) or a scenario field")
    if isinstance(values, dict) or isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        raise InputError(f"axes.{path}", values, "a list of values")
    values = list(values)
    if not values:
        raise InputError(f"axes.{path}", values, "a non-empty list of values")
    return [v.item() if isinstance(v, np.generic) else v for v in values]


def _check_distinct(path, values):
    """A grid axis with a value twice would run its cases twice (1 and 1.0 are the same value)."""
    hashed, unhashable = set(), []
    for v in values:
        try:
            again = v in hashed
            hashed.add(v)
        except TypeError:  # an unhashable value (a list): compared one by one
            again = any(v == w for w in unhashable)
            unhashable.append(v)
        if again:
            raise InputError(f"axes.{path}", values, f"distinct values ({short_repr(v, 40)} is there twice)")


def grid(axes, max_cases=MAX_CASES):
    """Every combination of the axes' values (the first axis varies slowest).

    Parameters
    ----------
    axes : mapping
        ``path -> list of values``; paths are parameter paths or scenario fields. The values of an axis are
        distinct (a value twice, ``1`` and ``1.0`` alike, is refused: its cases would run twice).

    max_cases : int
        Refuse grids of more points (an :class:`InputError` before any is made).

    Returns
    -------
    list of dict
        One ``{path: value}`` per point.
    """
    if not axes:
        return [{}]
    names = list(axes)
    lists = [_axis_values(n, axes[n]) for n in names]
    for name, values in zip(names, lists):
        _check_distinct(name, values)
    _check_size(math.prod(len(v) for v in lists), max_cases, "the grid")
    return [dict(zip(names, combo)) for combo in itertools.product(*lists)]


def random_sample(axes, n, seed=0, max_cases=MAX_CASES):
    """``n`` random points.

    Parameters
    ----------
    axes : mapping
        ``path -> spec``; a list (uniform choice among its items) or a mapping
        ``{"low": a, "high": b, "scale": "linear"|"log"}`` (uniform, or log-uniform for ``"log"``;
        integers when both bounds are integers and the scale is linear).
    n : int
        Number of points (>= 1).
    seed : int
        Seed of :func:`numpy.random.default_rng`; the same seed gives the same points.

    Returns
    -------
    list of dict
    """
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InputError("n", n, "an integer >= 1")
    _check_size(n, max_cases, "the sample")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise InputError("seed", seed, "an integer in [0, 2^63)")
    rng = np.random.default_rng(seed)
    columns = {}
    for path, spec in axes.items():
        if not isinstance(path, str):
            raise InputError("axes", path, "a parameter path (text such as nut.axial_stiffness) or a scenario field")
        if isinstance(spec, dict):
            low, high = spec.get("low"), spec.get("high")
            scale = spec.get("scale", "linear")
            if set(spec) - {"low", "high", "scale"}:
                raise InputError(f"axes.{path}", spec, "a mapping with keys low, high, scale")
            if not all(isinstance(b, (int, float)) and not isinstance(b, bool) and abs(b) < 1e300 and math.isfinite(b)
                       for b in (low, high)) or not low <= high:
                raise InputError(f"axes.{path}", spec, "low <= high, both finite numbers")
            if scale == "log":
                if low <= 0:
                    raise InputError(f"axes.{path}.low", low, "> 0 for a log scale")
                columns[path] = [float(v) for v in np.exp(rng.uniform(math.log(low), math.log(high), n))]
            elif scale == "linear":
                if isinstance(low, int) and isinstance(high, int):
                    if not -2**63 <= low <= high < 2**63:  # 'internal error: ValueError: high is out of bounds for int64'
                        raise InputError(f"axes.{path}", spec, "integer bounds low <= high in [-2^63, 2^63) (drawn as "
                                         "64-bit integers; write a bound with a decimal point for real values)")
                    columns[path] = [int(v) for v in rng.integers(low, high + 1, n)]
                else:
                    columns[path] = [float(v) for v in rng.uniform(low, high, n)]
            else:
                raise InputError(f"axes.{path}.scale", scale, "linear or log")
        else:
            values = _axis_values(path, spec)
            columns[path] = [values[i] for i in rng.integers(0, len(values), n)]
    return [{p: columns[p][i] for p in columns} for i in range(n)]


# --------------------------------------------------------------------------- cases

@dataclass(frozen=True)
class Case:
    """One simulation of a sweep: where it sits in the sweep, and everything that defines it."""

    index: int
    point: dict
    params: object
    scenario: Scenario
    key: str


def case_key(params, scenario, metric_name):
    """Hash of the full parameters, the scenario and the metric function: the cache key of a case."""
    payload = dict(
        version=CACHE_VERSION, params=params_to_dict(params), scenario=dataclasses.asdict(scenario),
        metric=metric_name,
    )
    text = json.dumps(payload, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def _metric_name(func):
    return f"{getattr(func, '__module__', '?')}.{getattr(func, '__qualname__', repr(func))}"


def make_cases(base, points, scenario=None, metric=None):
    """Validated cases from points.

    Parameters
    ----------
    base : drakecreep.params.DriveParams
    points : list of dict
        ``{path: value}``; scenario fields override ``scenario``.
    scenario : Scenario or mapping, optional
        Defaults of the scenario fields (default ``Scenario()``); ``drive`` picks the drive.
    metric : callable, optional
        The function of the result (part of the cache key); default :func:`feed_report`.

    Raises
    ------
    InputError
        Naming the path and value of the first invalid point.
    """
    from drakecreep.sim.simulation import check_log_period, check_step_budget, check_window  # pydrake, as simulate: not at import

    check_params(base, "base")
    if isinstance(points, (str, bytes, Mapping)) or not hasattr(points, "__iter__"):  # 'str' has no attribute 'items'
        raise InputError("points", points, "a list of {path: value} mappings, one a case")
    points = list(points)
    for index, point in enumerate(points):
        if not isinstance(point, Mapping):
            raise InputError(f"points[{index}]", point, "a {path: value} mapping")
    if scenario is not None and not isinstance(scenario, (Scenario, Mapping)):
        raise InputError("scenario", scenario, "a Scenario or a mapping of its fields")
    metric = metric or feed_report
    defaults = dataclasses.asdict(scenario) if isinstance(scenario, Scenario) else dict(scenario or {})
    unknown = set(defaults) - set(SCENARIO_FIELDS)
    if unknown:
        name = sorted(unknown)[0]
        raise InputError(f"scenario.{name}", defaults[name], "one of " + ", ".join(SCENARIO_FIELDS))
    name = _metric_name(metric)
    cases = []
    for index, point in enumerate(points):
        params = base
        fields = dict(defaults)
        for path, value in point.items():
            if path in SCENARIO_FIELDS:
                fields[path] = value
            else:
                params = with_value(params, path, value)
        try:
            scen = scenario_with_drive(**fields)
        except InputError as err:  # the load cases this params file has ('1.0': 'an integer >= 0'; '7': '0..3')
            if err.field != "load_case":
                raise
            raise InputError("load_case", fields["load_case"], params.load_cases_allowed) from None
        check_window(params, scen.duration)
        check_log_period(params.simulation.log_period, scen.duration, params.simulation.steady_start)
        check_step_budget(params, scen.duration)
        params.load_case(scen.load_case)  # validates the load case number
        cases.append(Case(index=index, point=dict(point), params=params, scenario=scen,
                          key=case_key(params, scen, name)))
    return cases


# --------------------------------------------------------------------------- one case

def feed_report(result):
    """Default metric: the :class:`~drakecreep.sim.metrics.FeedMetrics` report plus run information."""
    row = dict(status=result.status, sim_time_s=float(result.time[-1]) if len(result.time) else 0.0,
               wall_time_s=result.wall_time, steps=result.stats.get("steps"))
    if result.metrics is not None:
        row.update(result.metrics.report())
    return row


def run_case(case, metric=None):
    """Simulate one case and apply ``metric`` (default :func:`feed_report`) to the result.

    Returns
    -------
    dict
        The metric's flat ``{column: value}``.
    """
    from drakecreep.sim.simulation import simulate

    metric = metric or feed_report
    result = simulate(case.params, case.scenario)
    row = metric(result)
    if not isinstance(row, dict):
        raise TypeError(f"the sweep metric must return a dict, got {type(row).__name__}")
    return {k: _plain(v) for k, v in row.items()}


@dataclass(frozen=True)
class _Batch:
    """Cases simulated together in one system (:mod:`drakecreep.sim.batch`): a unit of work of the executors."""

    cases: tuple

    @property
    def key(self):
        return hashlib.sha1("".join(c.key for c in self.cases).encode()).hexdigest()[:20]


def run_batch(batch):
    """Simulate a :class:`_Batch` in one system; one :func:`feed_report`-shaped row per case."""
    from drakecreep.sim.batch import simulate_batch

    metrics, info = simulate_batch([(c.params, c.scenario) for c in batch.cases])
    share = info["wall_time"] / len(batch.cases)
    return [
        {k: _plain(v) for k, v in dict(status="ok", sim_time_s=float(c.scenario.duration), wall_time_s=share,
                                       steps=info["steps"], **m.report()).items()}
        for c, m in zip(batch.cases, metrics)
    ]


def _work(unit, metric):
    return run_batch(unit) if isinstance(unit, _Batch) else run_case(unit, metric)


def _batches(todo, batch_size, metric):
    """Group compatible cases into batches of at most ``batch_size``; the rest stay single cases."""
    from drakecreep.sim.baseline import unsupported
    from drakecreep.sim.batch import batch_key

    if not batch_size or batch_size < 2 or metric is not feed_report:
        return list(todo)
    groups, units = {}, []
    for case in todo:
        if (getattr(case.scenario, "drive", "cascade") != "cascade" or not case.params.controller.sampled
                or unsupported(case.params) is not None):
            units.append(case)
        else:
            groups.setdefault(batch_key(case.params, case.scenario), []).append(case)
    for members in groups.values():
        # a batch steps as finely as its most demanding case: slow feeds (which creep, and need ~3x the
        # steps of a smooth feed) go together, so that they do not slow the batches of smooth feeds
        members.sort(key=lambda c: (abs(c.scenario.feed), c.key))
        for i in range(0, len(members), batch_size):
            chunk = tuple(members[i:i + batch_size])
            units.append(_Batch(chunk) if len(chunk) > 1 else chunk[0])
    return units


def _plain(value):
    if isinstance(value, np.generic):
        return value.item()
    return value


# --------------------------------------------------------------------------- files

def _read_cache(path, key, batch=None):
    """The cached row of case ``key``, or None when absent, unreadable, not a well-formed row of that case, or
    computed in another batch than ``batch`` (a batched row depends on its batch: it steps as finely as the
    batch's most demanding member)."""
    try:
        if not path.is_file() or path.stat().st_size > 1_000_000:
            return None
        entry = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(entry, dict) or entry.get("key") != key or entry.get("batch") != batch:
        return None
    row = entry.get("row")
    if not isinstance(row, dict) or not isinstance(row.get("status"), str):
        return None
    if not all(isinstance(k, str) and (v is None or isinstance(v, (bool, int, float, str))) for k, v in row.items()):
        return None
    return row


# --------------------------------------------------------------------------- running

@dataclass
class SweepResult:
    """What a sweep produced.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per case: ``case``, ``key``, the swept paths, ``feed``/``load_case``/``duration``,
        then the metric columns (``status`` says ``"ok"`` or why a case failed).
    computed, cached, failed : int
        Cases simulated in this run, taken from the cache, failed after every retry.
    paths : dict
        ``results_parquet``, ``results_csv`` when written.
    wall_time : float
        Seconds for the whole sweep.
    """

    table: object
    computed: int
    cached: int
    failed: int
    retried: int
    paths: dict
    wall_time: float


class _Progress:
    def __init__(self, total, enabled, desc):
        self.bar = None
        if enabled:
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc=desc, unit="case", file=sys.stderr, dynamic_ncols=True)

    def update(self, n=1):
        if self.bar is not None:
            self.bar.update(n)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _run_serial(todo, metric, retries, done):
    for case in todo:
        error = None
        for _attempt in range(retries + 1):
            try:
                done(case, _work(case, metric), None)
                break
            except Exception as err:  # noqa: BLE001 - reported in the row
                error = err
        else:
            done(case, None, error)


def _run_processes(todo, metric, retries, done, workers):
    attempts = {_unit_key(c): 0 for c in todo}
    pending = list(todo)
    retried = 0
    while pending:
        broken = []
        pool = new_pool(workers)  # workers ignore SIGINT and exit with the sweep's process
        try:
            futures = {pool.submit(_work, case, metric): case for case in pending}
            for future in cf.as_completed(futures):
                case = futures[future]
                try:
                    row = future.result()
                except Exception as err:  # noqa: BLE001 - BrokenProcessPool (a worker died) or the case raised
                    attempts[_unit_key(case)] += 1
                    if attempts[_unit_key(case)] <= retries:
                        broken.append(case)
                    else:
                        done(case, None, err)
                    continue
                done(case, row, None)
        except BaseException:
            stop_pool(pool)
            raise
        pool.shutdown(wait=True)
        retried += len(broken)
        pending = broken
    return retried


def _unit_key(unit):
    return unit.key


def _members(unit):
    return unit.cases if isinstance(unit, _Batch) else (unit,)


#: seconds to wait for a Dask scheduler to answer, and for its first worker
DASK_TIMEOUT = 10.0


def connect_dask(scheduler, timeout=None):
    """A ``distributed.Client`` of ``scheduler`` that has at least one worker, within ``timeout`` seconds each.

    ``timeout`` defaults to :data:`DASK_TIMEOUT`.

    Raises
    ------
    InputError
        Naming ``--scheduler``: a malformed address, no scheduler answering, or no worker joining in time.
    """
    from distributed import Client

    timeout = DASK_TIMEOUT if timeout is None else timeout
    if not isinstance(scheduler, str) or not scheduler.strip():
        raise InputError("--scheduler", scheduler, "a Dask scheduler address such as tcp://host:8786")
    try:
        client = Client(scheduler, timeout=f"{timeout}s")
    except Exception as err:  # noqa: BLE001 - OSError, TimeoutError, a bad address, a non-Dask server's reply
        reason = "malformed address" if isinstance(err, (ValueError, TypeError)) else type(err).__name__
        raise InputError("--scheduler", scheduler,
                         f"a reachable Dask scheduler address such as tcp://host:8786 (none answered within "
                         f"{timeout:g} s: {reason})") from None
    try:
        client.wait_for_workers(1, timeout=timeout)
    except Exception:  # noqa: BLE001 - TimeoutError (no worker), a lost connection
        client.close()
        raise InputError("--scheduler", scheduler,
                         f"a scheduler with at least one worker (none joined within {timeout:g} s)") from None
    return client


def _run_dask(todo, metric, retries, done, scheduler):
    from distributed import as_completed

    own = not hasattr(scheduler, "submit")
    client = connect_dask(scheduler) if own else scheduler
    retried = 0
    try:
        attempts = {c.key: 0 for c in todo}
        cases = {}
        futures = []
        for case in todo:
            f = client.submit(_work, case, metric, key=f"drakecreep-case-{case.key}-0", pure=False)
            cases[f.key] = case
            futures.append(f)
        queue = as_completed(futures)
        for future in queue:
            case = cases.pop(future.key)
            try:
                row = future.result()
            except Exception as err:  # noqa: BLE001 - KilledWorker, a worker's exception
                attempts[case.key] += 1
                if attempts[case.key] <= retries:
                    retried += 1
                    f = client.submit(_work, case, metric, pure=False,
                                      key=f"drakecreep-case-{case.key}-{attempts[case.key]}")
                    cases[f.key] = case
                    queue.add(f)
                else:
                    done(case, None, err)
                continue
            finally:
                future.release()
            done(case, row, None)
    finally:
        if own:
            client.close()
    return retried


def run_sweep(base, points, *, scenario=None, metric=None, executor="processes", workers=None, scheduler=None,
              out_dir=None, progress=True, retries=2, columns=None, batch_size=None, extra_outputs=None):
    """Run a sweep and collect one row per case.

    Parameters
    ----------
    base : drakecreep.params.DriveParams
        Parameters every case starts from.
    points : list of dict
        From :func:`grid`, :func:`random_sample` or by hand.
    scenario : Scenario or mapping, optional
        Defaults of ``feed``, ``load_case``, ``duration``, ``drive``.
    metric : callable, optional
        ``metric(SimulationResult) -> dict``; a module-level function (it is pickled to the workers).
        Default :func:`feed_report`.
    executor : {"serial", "processes", "dask"}
        ``"dask"`` needs ``scheduler``.
    workers : int, optional
        Processes of the local pool (default, and the most started: the CPUs this process may use).
    scheduler : str or distributed.Client, optional
        Dask scheduler address (``"tcp://host:8786"``) or a connected client.
    out_dir : path, optional
        Cache (``cache/``) and tables (``results.parquet``, ``results.csv``); without it nothing is
        cached or written.
    progress : bool
        tqdm progress bar on stderr.
    retries : int
        Extra attempts for a case whose worker died or that raised.
    columns : list of str, optional
        Metric columns to keep (default: all the metric returns).
    extra_outputs : dict, optional
        ``file name -> write(table, path)`` of further files of the output set (e.g. a map).
    batch_size : int, optional
        Simulate up to this many compatible cases together in one Drake system
        (:mod:`drakecreep.sim.batch`; several times the throughput for large sweeps). Only with the
        default metric; cases the batch path cannot run (constant-speed drive, continuous
        controller, disturbances, compensation, nut friction on the screw: see
        :func:`drakecreep.sim.baseline.unsupported`) run one by one. The batches are the executors' units of
        work; they are made no larger than needed to give every worker one (a kill or Ctrl-C loses at most
        the batches under way: every finished batch is cached at once).

    Returns
    -------
    SweepResult

    Notes
    -----
    The tables (and ``extra_outputs``) are one :class:`drakecreep.files.OutputSet` whose ``manifest.json``
    is written last. On Ctrl-C the queued cases are cancelled, the running workers stopped, the tables
    written with the finished cases (the others ``status: "not run (interrupted)"``) and
    ``KeyboardInterrupt`` raised again. Pool workers exit by themselves when the sweep's process dies.
    """
    if executor not in EXECUTORS:
        raise InputError("executor", executor, "one of " + ", ".join(EXECUTORS))
    if executor == "dask" and scheduler is None:
        raise InputError("scheduler", scheduler, "a Dask scheduler address for the dask executor")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise InputError("workers", workers, "an integer >= 1")
    if batch_size is not None and (isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1):
        raise InputError("batch_size", batch_size, "an integer >= 1")
    if isinstance(retries, bool) or not isinstance(retries, int) or not 0 <= retries <= MAX_RETRIES:
        raise InputError("retries", retries, f"an integer in [0, {MAX_RETRIES}]")
    start = time.perf_counter()
    metric = metric or feed_report
    cases = make_cases(base, points, scenario, metric)
    cache_dir = Path(out_dir) / "cache" if out_dir is not None else None
    n_workers = 1 if executor == "serial" else pool_size(workers or usable_cpus())
    if executor == "dask" and hasattr(scheduler, "scheduler_info"):
        n_workers = max(1, len(scheduler.scheduler_info().get("workers", {})))
    if batch_size and cases:
        # no larger than needed to give every worker a batch: a kill loses at most the batches under way
        batch_size = max(1, min(batch_size, math.ceil(len(cases) / n_workers)))
    # batches are formed from the whole sweep, so a case always shares its batch with the same cases; the
    # batch is part of what a cached row is valid for, and a batch is run (and cached) whole or not at all
    all_units = _batches(cases, batch_size, metric)
    batch_of = {}
    for unit in all_units:
        for case in _members(unit):
            batch_of[case.key] = unit.key if isinstance(unit, _Batch) else None
    rows = {}
    units = []
    for unit in all_units:
        got = {}
        if cache_dir is not None:
            got = {c.key: _read_cache(cache_dir / f"{c.key}.json", c.key, batch_of[c.key]) for c in _members(unit)}
        if got and all(row is not None for row in got.values()):
            rows.update(got)
        else:
            units.append(unit)
    todo = [case for unit in units for case in _members(unit)]
    n_cached = len(cases) - len(todo)
    failed = computed = 0
    bar = _Progress(len(cases), progress, "sweep")
    bar.update(n_cached)

    def done(unit, result, error):
        if isinstance(unit, _Batch):
            for i, case in enumerate(unit.cases):
                done_case(case, None if result is None else result[i], error)
        else:
            done_case(unit, result, error)

    def done_case(case, row, error):
        nonlocal failed, computed
        if row is None:
            failed += 1
            rows[case.key] = dict(
                status=f"failed: {type(error).__name__}: {str(error).splitlines()[0] if str(error) else ''}")
        else:
            computed += 1
            rows[case.key] = row
            if cache_dir is not None:  # held until written: the Ctrl-C handler writes it if the write is cut short
                unwritten[case.key] = dict(key=case.key, batch=batch_of.get(case.key), point=case.point, row=row)
                write_json(cache_dir / f"{case.key}.json", unwritten[case.key])
                del unwritten[case.key]
        bar.update()

    unwritten = {}  # finished cases whose cache file is being written (a Ctrl-C may cut the write short)
    retried = 0
    interrupted = False
    try:
        if units:
            if executor == "serial":
                _run_serial(units, metric, retries, done)
            elif executor == "processes":
                retried = _run_processes(units, metric, retries, done, n_workers)
            else:
                retried = _run_dask(units, metric, retries, done, scheduler)
    except KeyboardInterrupt as err:
        interrupted, stop = True, err  # raised again once the table is written: a SIGTERM stays one (exit 143)
        for key, entry in unwritten.items():  # the finished case whose cache write the Ctrl-C cut short
            write_json(cache_dir / f"{key}.json", entry)
    finally:
        bar.close()

    for case in cases:
        if interrupted and case.key not in rows:
            rows[case.key] = dict(status="not run (interrupted)")
    table = _table(cases, rows, columns)
    paths = {}
    if out_dir is not None:
        from drakecreep.files import OutputSet

        with OutputSet(out_dir, "manifest.json") as out:
            paths["results_csv"] = out.write("results.csv", lambda tmp: table.to_csv(tmp, index=False))
            if importlib.util.find_spec("pyarrow") is not None:  # a dependency; without it the CSV is still written
                paths["results_parquet"] = out.write("results.parquet", lambda tmp: table.to_parquet(tmp, index=False))
            if not interrupted:
                for name, write in (extra_outputs or {}).items():
                    paths[Path(name).stem] = out.write(name, lambda tmp, w=write: w(table, tmp))
            paths["manifest"] = out.commit(dict(cases=len(cases), interrupted=interrupted,
                                                computed=computed, cached=n_cached, failed=failed))
    if interrupted:
        raise stop
    return SweepResult(table=table, computed=computed, cached=n_cached, failed=failed, retried=retried,
                       paths=paths, wall_time=time.perf_counter() - start)


def _table(cases, rows, columns):
    import pandas as pd

    records = []
    for case in cases:
        rec = dict(case=case.index, key=case.key)
        for path, value in case.point.items():
            rec[path] = value
        for name in SCENARIO_FIELDS:
            rec.setdefault(name, getattr(case.scenario, name, "cascade"))
        row = rows.get(case.key, {})
        keep = row if columns is None else {k: row.get(k) for k in ["status", *columns] if k in row or k in columns}
        for k, v in keep.items():
            rec.setdefault(k, v)
        records.append(rec)
    return pd.DataFrame.from_records(records)


# --------------------------------------------------------------------------- spec files

def metric_columns():
    """Column names :func:`feed_report` produces (what a spec's ``metrics`` may name)."""
    from drakecreep.sim.metrics import FeedMetrics

    names = [f.name for f in dataclasses.fields(FeedMetrics)]
    dummy = FeedMetrics(**{n: 0 for n in names})
    return ["status", "sim_time_s", "wall_time_s", "steps", *dummy.report()]


@dataclass
class SweepSpec:
    """A sweep read from YAML (:func:`load_spec`)."""

    base: object
    points: list
    scenario: dict
    metrics: list
    plot: dict
    source: str = ""


def _range(path, spec, max_cases=MAX_CASES):
    if not isinstance(path, str):
        raise InputError("axes", path, "a parameter path (text such as nut.axial_stiffness) or a scenario field")
    keys = set(spec)
    if keys <= {"start", "stop", "num", "scale"} and {"start", "stop", "num"} <= keys:
        start, stop, num, scale = spec["start"], spec["stop"], spec["num"], spec.get("scale", "linear")
        if isinstance(num, bool) or not isinstance(num, int) or num < 1:
            raise InputError(f"axes.{path}.num", num, "an integer >= 1")
        _check_size(num, max_cases, f"axes.{path}")
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and abs(v) < 1e300 and math.isfinite(v)
                   for v in (start, stop)):
            raise InputError(f"axes.{path}", spec, "finite numbers start and stop")
        if scale == "log":
            if start <= 0 or stop <= 0:
                raise InputError(f"axes.{path}", spec, "start, stop > 0 for a log scale")
            return [float(v) for v in np.geomspace(start, stop, num)]
        if scale != "linear":
            raise InputError(f"axes.{path}.scale", scale, "linear or log")
        return [float(v) for v in np.linspace(start, stop, num)]
    raise InputError(f"axes.{path}", spec, "a list of values or {start, stop, num[, scale: linear|log]}")


def load_spec(path, max_cases=MAX_CASES):
    """Read a sweep spec (YAML).

    ::

        base: {preset: paper}            # or {file: params.yaml} (relative to the spec); optional set: {path: value}
        scenario: {feed: 1.0e-3, load_case: 3, duration: 2.0}   # defaults of the scenario fields (SI)
        axes:                            # path -> list, or a range {start, stop, num, scale: linear|log}
          nut.axial_stiffness: {start: 5.0e6, stop: 1.0e8, num: 8, scale: log}
          feed: [0.2e-3, 0.5e-3, 1.0e-3]
        sample: {mode: grid}             # or {mode: random, n: 100, seed: 0} (axes then: list or {low, high, scale})
        metrics: [fluctuation_rate_percent, creep]      # columns to keep (default: all)
        plot: {x: nut.axial_stiffness, y: feed, color: fluctuation_rate_percent}   # optional stability map

    ``max_cases`` caps the number of cases (:data:`MAX_CASES` by default).

    Raises
    ------
    InputError
        Naming the key of the first problem.
    """
    from drakecreep.files import resolve_reference
    from drakecreep.params import load_params, load_yaml_file, preset

    path = Path(path)
    data = load_yaml_file(path, str(path), "a YAML sweep spec (a mapping with axes)")
    if not isinstance(data, dict):
        # the type, not the value: a file that is no spec (a path typo, a token) is never echoed
        raise InputError(str(path), f"a YAML {type(data).__name__}", "a mapping with base, scenario, axes, sample, metrics, "
                         "plot")
    known = {"base", "scenario", "axes", "sample", "metrics", "plot"}
    extra = sorted(set(data) - known)
    if extra:
        raise InputError(extra[0], data[extra[0]], "a spec key: " + ", ".join(sorted(known)))
    base_spec = data.get("base") or {"preset": "paper"}
    if not isinstance(base_spec, dict) or set(base_spec) - {"preset", "file", "set"} \
            or ("preset" in base_spec and "file" in base_spec):
        raise InputError("base", base_spec, "{preset: NAME} or {file: PATH}, optionally with set: {path: value}")
    # every error names the spec's key the value came from ('base.set.table.mass', not the params field alone)
    if "file" in base_spec:
        ref = resolve_reference(base_spec["file"], path, "base.file")
        base = renaming(lambda f: f"base.file {base_spec['file']}" + ("" if f == str(ref) else f": {f}"),
                           load_params, ref)
    else:
        base = renaming(lambda f: f"base.{f}", preset, base_spec.get("preset", "paper"))
    overrides = base_spec.get("set") or {}
    if not isinstance(overrides, dict):
        raise InputError("base.set", overrides, "a mapping path -> value")
    for key, value in overrides.items():
        if not isinstance(key, str):
            raise InputError("base.set", key, "parameter paths (text such as table.mass)")
        base = renaming(lambda f: f"base.set.{f}", with_value, base, key, value)
    scenario = data.get("scenario") or {}
    if not isinstance(scenario, dict):
        raise InputError("scenario", scenario, "a mapping of " + ", ".join(SCENARIO_FIELDS))
    axes = data.get("axes")
    if not isinstance(axes, dict) or not axes:
        raise InputError("axes", axes, "a non-empty mapping path -> values")
    sample = data.get("sample") or {"mode": "grid"}
    if not isinstance(sample, dict) or sample.get("mode", "grid") not in ("grid", "random") \
            or set(sample) - {"mode", "n", "seed"} \
            or (sample.get("mode", "grid") == "grid" and set(sample) - {"mode"}):  # n of a grid was ignored
        raise InputError("sample", sample, "{mode: grid} or {mode: random, n: N, seed: S}")
    if sample.get("mode", "grid") == "grid":
        expanded = {p: (_range(p, v, max_cases) if isinstance(v, dict) else v) for p, v in axes.items()}
        points = grid(expanded, max_cases)
    else:
        points = renaming(lambda f: f"sample.{f}" if f in ("n", "seed") else f, random_sample, axes,
                             sample.get("n"), seed=sample.get("seed", 0), max_cases=max_cases)
    # every path and value before anything runs, and before the plot names them (a misspelt axis is named as such)
    renaming(lambda f: f"axes.{f}" if f in axes else f"scenario.{f}" if f in scenario else f,
                make_cases, base, points, scenario)
    metrics = data.get("metrics")
    known_metrics = metric_columns()
    if metrics is not None:
        if not isinstance(metrics, list) or not metrics:
            raise InputError("metrics", metrics, "a list of: " + ", ".join(known_metrics))
        for name in metrics:
            if name not in known_metrics:
                raise InputError("metrics", name, "one of " + ", ".join(known_metrics))
    plot = data.get("plot") or {}
    if not isinstance(plot, dict) or set(plot) - {"x", "y", "color"} or (plot and "x" not in plot):
        raise InputError("plot", plot, "{x: PATH[, y: PATH, color: METRIC]}")
    # the map is drawn after the whole sweep: its axes are checked now, not after hours of computing
    swept = list(axes) + [f for f in SCENARIO_FIELDS if f not in axes]
    for key in ("x", "y"):
        if key in plot and plot[key] not in swept:
            raise InputError(f"plot.{key}", plot[key], "a swept path or scenario field: " + ", ".join(map(str, swept)))
    if "y" in plot and plot["y"] == plot["x"]:  # a map of an axis against itself: 'plot: {x: feed, y: feed}' drew one
        raise InputError("plot.y", plot["y"], f"a swept path or scenario field other than plot.x ({plot['x']})")
    if "color" in plot and plot["color"] not in known_metrics:
        raise InputError("plot.color", plot["color"], "one of " + ", ".join(known_metrics))
    color = plot.get("color", DEFAULT_MAP_COLOR)
    if plot and metrics is not None and color not in metrics:
        # the map colours by a column of the table: one the metrics leave out was no map, without a word
        raise InputError("plot.color", color if "color" in plot else f"{color} (the default)",
                         "one of the spec's metrics, " + ", ".join(metrics) + f" (or add {color} to metrics)")
    return SweepSpec(base=base, points=points, scenario=scenario, metrics=metrics, plot=plot, source=str(path))


