"""Simulate a feed: parameters + scenario -> Drake simulation -> time series + creep metrics.

Converged verdicts
------------------
A creep verdict must not depend on the integrator. Two things see to it:

* the target accuracy defaults per friction law (``simulation.accuracy: 0``, :data:`ACCURACY_BY_LAW`):
  the regularized ``coulomb`` and ``stribeck`` laws (a ``tanh`` of width 1 um/s, friction slope
  ~1e8 N s/m at zero speed) need 1e-5 where LuGre is converged at 1e-4. Measured on the paper preset,
  load case 3 (``analysis/convergence_study.py``): static Stribeck at 0.5-0.6 mm/s reads smooth at 1e-4
  but stick-slips at 1e-5 and 1e-6 with the same cycles and fluctuation (137 cycles, 142 % at both);
  LuGre gives the same verdict and fluctuation within 1.5 % at 1e-4, 1e-5 and 1e-6 (0.05-0.5 mm/s).
* an automatic check (``simulation.convergence_check``): the start of the run, from t = 0 to the first
  ``convergence_window`` seconds of the steady window, is simulated again at 10x tighter accuracy and the
  two runs are compared over that part of the window. They agree when the creep verdict is the same and
  the largest speed fluctuation differs by at most ``convergence_tolerance`` x feed (default 0.1: ten
  percentage points of the fluctuation rate, below the spacing of the paper's Tables 8-9 rows at a feed,
  far above the 1e-3 scatter of converged runs, and far below the 100 % jump of a missed stick-slip). When
  they disagree the whole run is repeated at the tighter accuracy and checked once more against 10x
  tighter again; ``metrics.converged`` says whether the last check agreed, and the run's stats whether its
  verdicts did (``convergence_verdict_agrees``): the largest fluctuation of a stick-slip is an extreme of its
  cycles and moves with any perturbation (0.1 mm/s on the paper preset, whole 5 s runs: 0.411 mm/s at 1e-5;
  0.370, 0.414, 0.428 and 0.412 mm/s at 1e-6 times 1 - 2e-16, 1, 1 + 2e-16 and 1.001; stuck 30-31 % of the time
  in each), so a creeping run can hold its verdict at every accuracy and still miss a tolerance of 10 % of the
  feed on its amplitude. The check restarts from t = 0
  because the missed stick-slip is decided in the start-up transient: steady sliding at 0.5 mm/s is
  locally stable (the Stribeck slope has faded), so switching a smooth run to 1e-6 after 1 s stays smooth.
  Cost: the start up to ``steady_start + convergence_window`` (1.5 s of a 5 s run by default) at 10x
  tighter accuracy; measured +45 % wall time on a 3 s LuGre run at 0.1 mm/s (3.1 -> 4.4 s) and about
  2x on static Stribeck (1e-6 is expensive there). Off for sweeps that must be fast
  (``simulation.convergence_check: false``); the batched sweep path has no check. Fixed-step
  integrators are not checked.

The default backend compiles the diagram into ``SymbolicVectorSystem``s (:mod:`drakecreep.sim.compiled`);
``backend="leaf"`` simulates the Python leaf systems directly (same equations, slower; kept as the
reference the fast path is tested against).
"""

import math
import numbers
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import VectorLogSink

from drakecreep.sim.compiled import compile_diagram
from drakecreep.model.diagram import build_diagram
from drakecreep.errors import InputError, Terminated
from drakecreep.sim.metrics import feed_metrics
from drakecreep.params import SimulationParams, save_params
from drakecreep.scenario import MAX_FEED

__all__ = ["SimulationResult", "simulate", "make_simulator", "integration_failure", "check_run", "check_log_period",
           "check_window", "shortest_run", "check_step_budget", "target_accuracy", "FIXED_STEP", "ACCURACY_BY_LAW",
           "MAX_SAMPLES", "MAX_STEPS", "MIN_WINDOW_SAMPLES", "MODELS", "MAX_TABLE_SPEED", "MIN_STEP", "SLOW_NOTICE",
           "slow_run_notice"]

#: integrators without error control: they step at ``max_step``
FIXED_STEP = ("runge_kutta2",)
#: most recorded samples of one run: 2e6 samples of the ~20 signals are ~0.3 GB in memory and a 0.5 GB CSV;
#: a finer log (``log_period: 1e-8`` over seconds) would take minutes and gigabytes and show nothing more
MAX_SAMPLES = 2_000_000
#: most steps a run's settings may force: ``duration / simulation.max_step`` (every integrator steps at least that
#: often) and ``duration / controller.velocity_period`` (a sampled controller's updates). The defaults force 5e3
#: and 2e4 over 5 s, the longest run (3600 s) 3.6e6 and 1.4e7, about 15 minutes; a ``max_step`` or a
#: ``velocity_period`` of 1e-9 s forced 5e9 steps over 5 s, a run of days that looked like a hang
MAX_STEPS = 20_000_000
#: Fewest recorded samples in the metrics window: the creep metrics difference the logged speed and count its
#: stick-slip cycles; with fewer the result had no metrics at all, reported as a run that went well
MIN_WINDOW_SAMPLES = 20
#: divergence guard: largest table speed (m/s). Feed drives of this class traverse at 0.5-1 m/s
#: (:data:`drakecreep.scenario.MAX_FEED`); a table ten times faster has left the physics of a feed drive
#: (an unstable loop, a raised torque limit) and its results mean nothing
MAX_TABLE_SPEED = 10.0 * MAX_FEED
#: divergence guard: smallest step (s) an error-controlled integrator may take. The stiffest mode of the
#: drive (screw-nut contact, ~1e4 rad/s) needs steps of ~1e-6 s; steps a thousand times smaller mean the
#: integrator is chasing a divergence (2 M steps of 1e-11 s were seen) and would never finish
MIN_STEP = 1e-9
#: the guard looks at the signals every this many integrator steps (a Python call per step costs ~1 us)
GUARD_EVERY = 64
#: a run whose pace, measured after :data:`SLOW_NOTICE_AFTER` s of computing, projects more than this many seconds
#: in all gets one notice (``simulate(notice=...)``): the projection, the mean step and what to change. A feed of
#: 1 m/s on the paper preset (LuGre bristles relaxing at ~2e7 1/s, under Runge-Kutta 3's stable step) projected
#: tens of minutes for 5 s and showed nothing until it ended
SLOW_NOTICE = 120.0
SLOW_NOTICE_AFTER = 15.0
#: implicit integrators: stable on stiff friction, so a slow run on them is not helped by switching
_IMPLICIT = ("radau3", "implicit_euler")

#: default integrator target accuracy per friction law (``simulation.accuracy: 0``); see the module notes
ACCURACY_BY_LAW = {"lugre": 1e-4, "stribeck": 1e-5, "coulomb": 1e-5, "gms": 1e-5}

#: mechanics a run can simulate: the two-mass diagram (:mod:`drakecreep.model.diagram`) or the paper's
#: rig in a MultibodyPlant (:mod:`drakecreep.multibody.diagram`)
MODELS = ("two_mass", "multibody")

#: tightest accuracy the automatic convergence check goes to
_ACCURACY_FLOOR = 1e-9


def target_accuracy(params):
    """Integrator target accuracy of a run: ``simulation.accuracy``, or the friction law's default when 0."""
    acc = params.simulation.accuracy
    return acc if acc > 0 else ACCURACY_BY_LAW[params.friction.law]


class Diverged(RuntimeError):
    """The divergence guard stopped a run (``status`` of the result says why)."""


@dataclass
class SimulationResult:
    """Time series and metrics of one simulated feed.

    Attributes
    ----------
    time : ndarray
        Sample times (s), uniform at ``params.simulation.log_period``.
    signals : dict
        Signal name -> ndarray (SI; units in ``units``). Besides the diagram's signals:
        ``motor_position`` and ``motor_velocity`` (motor rotation at the table: angle x lead / 2 pi).
    metrics : drakecreep.sim.metrics.FeedMetrics or None
        None when the run failed before the steady window.
    status : str
        ``"ok"`` or the one-line reason the run stopped early (what was computed is kept).
    """

    time: np.ndarray
    signals: dict
    units: dict
    metrics: object
    params: object
    scenario: object
    wall_time: float
    stats: dict = field(default_factory=dict)
    status: str = "ok"

    @property
    def ok(self):
        return self.status == "ok"

    def summary(self):
        """Flat dict for JSON output: metrics in report units plus run information."""
        out = dict(
            status=self.status,
            feed_mm_s=self.scenario.feed * 1e3,
            load_case=self.scenario.load_case,
            friction_law=self.params.friction.law,
            controller="sampled" if self.params.controller.sampled else "continuous",
            sim_time_s=float(self.time[-1]) if len(self.time) else 0.0,
            wall_time_s=self.wall_time,
        )
        if self.metrics is not None:
            out.update(self.metrics.report())
        out.update(self.stats)
        return out

    def to_dataframe(self):
        """The time series as a :class:`pandas.DataFrame`, SI units in the column names.

        Columns are those of ``timeseries.csv`` (:meth:`save`): ``t_s`` then ``<signal>_<unit>``, e.g.
        ``table_speed_m_per_s``, ``spring_force_N``; so ``pandas.read_csv("timeseries.csv")`` gives the
        same table.

        Returns
        -------
        pandas.DataFrame
        """
        import pandas as pd

        cols = {"t_s": np.asarray(self.time, dtype=float)}
        for name, values in self.signals.items():
            cols[f"{name}_{_unit_tag(self.units[name])}"] = np.asarray(values, dtype=float)
        return pd.DataFrame(cols)

    def save(self, out_dir, extra=None):
        """Write ``timeseries.csv``, ``params.yaml`` and, last, ``metrics.json`` to ``out_dir`` as one set.

        The files form a :class:`drakecreep.files.OutputSet` with ``metrics.json`` as its manifest: the old
        ``metrics.json`` is removed first, each file is written atomically, and ``metrics.json`` is written
        last naming the files of this run (sizes, SHA-256, ``run_id``). A kill or a full disk part way
        leaves no ``metrics.json``, never one beside files of another run.

        Parameters
        ----------
        out_dir : path-like
        extra : dict, optional
            ``file name -> write(path)`` of further files of the set, e.g. the speed plot of
            :func:`drakecreep.report.plots.plot_feed` (reports read results, not the reverse).

        Returns
        -------
        dict
            name -> path of each written file (the keys of ``extra`` are the file stems).
        """
        from drakecreep.files import OutputSet

        paths = {}
        names = list(self.signals)
        header = ",".join(["t_s"] + [f"{n}_{_unit_tag(self.units[n])}" for n in names])
        data = np.column_stack([self.time] + [self.signals[n] for n in names])
        with OutputSet(out_dir, "metrics.json") as out:
            paths["timeseries"] = out.write(
                "timeseries.csv",
                lambda tmp: np.savetxt(tmp, data, delimiter=",", header=header, comments="", fmt="%.10g"))
            paths["params"] = out.write("params.yaml", lambda tmp: save_params(self.params, tmp))
            for name, write in (extra or {}).items():
                paths[Path(name).stem] = out.write(name, write)
            payload = dict(summary=self.summary(), scenario=asdict(self.scenario), units=self.units)
            paths["metrics"] = out.commit(payload)
        return paths


def check_log_period(log_period, duration, steady_start=None):
    """Refuse a log period that records more than :data:`MAX_SAMPLES` samples over ``duration``, or (with
    ``steady_start``) fewer than :data:`MIN_WINDOW_SAMPLES` in the metrics window ``[steady_start, duration]``."""
    if duration / log_period > MAX_SAMPLES:
        raise InputError("simulation.log_period", log_period,
                         f">= {duration / MAX_SAMPLES:.3g} s for a {duration:g} s run (at most {MAX_SAMPLES} "
                         "recorded samples per run)")
    if steady_start is not None and (duration - steady_start) / log_period < MIN_WINDOW_SAMPLES:
        raise InputError("simulation.log_period", log_period,
                         f"<= {(duration - steady_start) / MIN_WINDOW_SAMPLES:.3g} s: at least {MIN_WINDOW_SAMPLES} "
                         f"recorded samples in the metrics window ({steady_start:g}-{duration:g} s; a longer "
                         "duration or an earlier simulation.steady_start widens it)")


def shortest_run(params):
    """The shortest run [s] :func:`check_window` takes: ``simulation.steady_start`` and then the metrics window's
    :data:`MIN_WINDOW_SAMPLES` samples at the finer of ``simulation.log_period`` and its default."""
    return params.simulation.steady_start + MIN_WINDOW_SAMPLES * _finest_log_period(params.simulation)


def _finest_log_period(sim):
    """The finer of ``sim.log_period`` and its default [s]: the log period a window too short is the duration's at."""
    return min(sim.log_period, SimulationParams().log_period)


def check_window(params, duration, field="duration"):
    """Refuse a run ``duration`` (s) the recorded samples cannot measure even at the default log period: its metrics
    window after ``simulation.steady_start`` must hold :data:`MIN_WINDOW_SAMPLES` and the run at most
    :data:`MAX_SAMPLES`; an :class:`InputError` naming ``field`` (a CLI's option; ``simulate --duration 1.0000001``
    and ``--duration 600`` blamed 'simulation.log_period', a field nobody had set). What only the params file's own
    ``simulation.log_period`` makes too few or too many is the log period's, as :func:`check_log_period` says."""
    sim = params.simulation
    if not (duration > sim.steady_start
            and (duration - sim.steady_start) / _finest_log_period(sim) >= MIN_WINDOW_SAMPLES):
        least = shortest_run(params)
        raise InputError(field, duration, f">= {least:.6g} s: simulation.steady_start ({sim.steady_start:g} s) "
                         f"and then the metrics window's {MIN_WINDOW_SAMPLES} recorded samples, one every "
                         f"simulation.log_period ({sim.log_period:g} s)")
    coarsest = max(sim.log_period, SimulationParams().log_period)
    if duration / coarsest > MAX_SAMPLES:
        raise InputError(field, duration, f"<= {MAX_SAMPLES * coarsest:.6g} s: at most {MAX_SAMPLES} recorded samples "
                         f"per run, one every simulation.log_period ({sim.log_period:g} s; a coarser one in a params "
                         "file records a longer run)")
    return duration


def check_step_budget(params, duration):
    """Refuse a ``simulation.max_step`` or (sampled controller) ``controller.velocity_period`` that forces more than
    :data:`MAX_STEPS` steps over ``duration``, before the run starts."""
    limits = [("simulation.max_step", params.simulation.max_step, "integrator steps per run")]
    if params.controller.sampled:
        limits.append(("controller.velocity_period", params.controller.velocity_period,
                       "controller samples per run; or controller.sampled: false"))
    for name, period, what in limits:
        if duration / period > MAX_STEPS:
            raise InputError(name, period, f">= {duration / MAX_STEPS:.3g} s for a {duration:g} s run (at most "
                                           f"{MAX_STEPS:.0e} {what})")


def _unit_tag(unit):
    return unit.replace(" ", "").replace("/", "_per_").replace("^", "")


def integration_failure(err):
    """One line for a Drake integrator's ``RuntimeError`` ``err``: its first line; when the step-size control gave
    up, a divergence with the first sentence of Drake's message (it goes on with several sentences of advice, and
    was cut off mid-sentence)."""
    text = str(err).strip()
    first = text.splitlines()[0] if text else type(err).__name__
    if "minimum" in first.lower() and "step" in first.lower():
        sentence = first.split(". ")[0].rstrip(".")
        return f"diverged: the integrator needed a step below {MIN_STEP:g} s ({sentence})"
    return first


def make_simulator(system, context, sim, accuracy=None, integrator=None):
    """A Drake ``Simulator`` configured from :class:`~drakecreep.params.SimulationParams`.

    ``accuracy`` (the target accuracy) defaults to ``sim.accuracy``; pass :func:`target_accuracy` when
    ``sim.accuracy`` may be 0 (the friction law's default). ``integrator`` (a Drake integrator name)
    defaults to ``sim.integrator``.
    """
    accuracy = sim.accuracy if accuracy is None else accuracy
    name = sim.integrator if integrator is None else integrator
    if name not in FIXED_STEP and not accuracy > 0:
        raise InputError("simulation.accuracy", accuracy, "> 0 (0 is resolved per friction law by target_accuracy)")
    simulator = Simulator(system, context)
    integrator = ResetIntegratorFromFlags(simulator, name, sim.max_step)
    integrator.set_maximum_step_size(sim.max_step)
    if name not in FIXED_STEP:
        integrator.set_target_accuracy(accuracy)
        integrator.set_requested_minimum_step_size(min(MIN_STEP, sim.max_step))
        integrator.set_throw_on_minimum_step_size_violation(True)
    simulator.Initialize()
    return simulator


def slow_run_notice(t, until, elapsed, steps, integrator):
    """The one-line notice of a run whose pace projects more than :data:`SLOW_NOTICE` s of computing, or None.

    Parameters
    ----------
    t, until : float
        Simulated time reached and to reach (s).
    elapsed : float
        Seconds of computing so far.
    steps : int
        Integrator steps taken so far.
    integrator : str
        The integrator's name (:data:`drakecreep.params.INTEGRATORS`).
    """
    if not t > 0 or steps <= 0:
        return None
    projected = elapsed * until / t
    if projected <= SLOW_NOTICE:
        return None
    line = (f"slow run: {t:.3g} of {until:g} s simulated in {elapsed:.0f} s of computing, about "
            f"{projected / 60.0:.0f} min in all at this pace (mean step {t / steps:.2g} s, {integrator})")
    if integrator not in _IMPLICIT:
        line += ("; an explicit integrator on stiff friction (LuGre bristles at a high speed, a small "
                 "friction.regularization_velocity) steps far below the controller's period: simulation.integrator: "
                 "radau3 in a --params file steps over it")
    return line + "; --max-wall S stops the run and keeps what was computed"


def _guard(simulator, root, read_speeds, bounds, wall_limit, until=None, notice=None, integrator="", deadline=None):
    """Install the divergence guard as the simulator's monitor; returns the dict it reports into.

    ``wall_limit`` (s) stops the run at ``deadline`` (a ``time.perf_counter()`` reading; its start plus the
    limit when None): :func:`simulate` gives each of its runs the deadline of the whole command.

    With ``notice`` (a callable taking one line) and ``until``, a run whose pace projects more than
    :data:`SLOW_NOTICE` s gets one :func:`slow_run_notice` once :data:`SLOW_NOTICE_AFTER` s have passed."""
    from pydrake.systems.framework import EventStatus

    report = dict(reason=None)
    start = time.perf_counter()
    if wall_limit is not None and deadline is None:
        deadline = start + wall_limit
    calls = [0]
    pending = [notice is not None and until is not None]
    v_max, w_max = bounds

    def monitor(context):
        calls[0] += 1
        if calls[0] % GUARD_EVERY:
            return EventStatus.Succeeded()
        t = context.get_time()
        v, w = read_speeds(context)
        reason = None
        if not (math.isfinite(v) and math.isfinite(w)):
            reason = f"diverged at t = {t:.6g} s: non-finite state"
        elif abs(v) > v_max:
            reason = (f"diverged at t = {t:.6g} s: table speed {v:.3g} m/s beyond +-{v_max:g} m/s "
                      "(an unstable loop or a raised torque limit)")
        elif abs(w) > w_max:
            reason = (f"diverged at t = {t:.6g} s: motor speed {w:.3g} rad/s beyond +-{w_max:.3g} rad/s "
                      f"(the table speed limit {v_max:g} m/s through the lead)")
        elif deadline is not None and time.perf_counter() > deadline:
            reason = f"stopped at t = {t:.6g} s: wall-clock limit of {wall_limit:g} s reached"
        if pending[0] and time.perf_counter() - start > SLOW_NOTICE_AFTER:
            pending[0] = False
            line = slow_run_notice(t, until, time.perf_counter() - start,
                                   simulator.get_integrator().get_num_steps_taken(), integrator)
            if line is not None:
                notice(line)
        if reason is None:
            return EventStatus.Succeeded()
        report["reason"] = reason
        return EventStatus.ReachedTermination(None, reason)

    simulator.set_monitor(monitor)
    return report


def check_run(params, scenario, *, backend=None, model="two_mass", multibody=None):
    """Refuse a run :func:`simulate` would refuse, before it is built: a caller that runs many (a process pool)
    checks them all first, so bad input gets its one line before any work.

    Parameters
    ----------
    params, scenario, backend, model, multibody
        As :func:`simulate`.

    Returns
    -------
    str
        The backend the run uses (``backend`` or ``params.simulation.backend``).

    Raises
    ------
    InputError
        An unknown model or backend, a fractional computation delay on the compiled backend, a metrics window
        that starts after the run ends, too many recorded samples or steps (:func:`check_log_period`,
        :func:`check_step_budget`), a load case the params do not have.
    """
    from drakecreep.params import check_params
    from drakecreep.scenario import check_scenario

    # a script's preset name, mapping or feed where the objects go ended in 'internal error: AttributeError'
    check_params(params)
    check_scenario(scenario)
    sim = params.simulation
    if model not in MODELS:
        raise InputError("model", model, " or ".join(MODELS))
    if model == "two_mass" and multibody is not None:
        raise InputError("multibody", multibody, "None with model two_mass")
    backend = backend or sim.backend
    if backend not in ("compiled", "leaf"):
        raise InputError("backend", backend, "compiled or leaf")
    delay = params.controller.computation_delay
    if backend == "compiled" and params.controller.sampled and not float(delay).is_integer():
        # a fractional delay switches the command between samples: a second event timing, which the
        # symbolic fast path (one sampler) does not have; the leaf systems run it exactly
        raise InputError("controller.computation_delay", delay,
                         "a whole number of samples with simulation.backend: compiled (fractional: backend leaf)")
    if sim.steady_start >= scenario.duration:
        raise InputError("simulation.steady_start", sim.steady_start, f"< duration ({scenario.duration} s)")
    check_log_period(sim.log_period, scenario.duration, sim.steady_start)
    check_step_budget(params, scenario.duration)
    params.load_case(scenario.load_case)
    return backend


def simulate(params, scenario, *, backend=None, wall_limit=None, model="two_mass", multibody=None, notice=None):
    """Simulate ``scenario`` on the drive described by ``params``, with a convergence check.

    Parameters
    ----------
    params : drakecreep.params.DriveParams
    scenario : drakecreep.scenario.Scenario
    backend : {"compiled", "leaf"}, optional
        Default ``params.simulation.backend``. With the multibody model: ``compiled`` compiles the loop
        around the MultibodyPlant (controller, sensors, friction laws; the plant stays Drake's),
        ``leaf`` runs the leaf systems.
    wall_limit : float, optional
        Stop after this many seconds of computing, the convergence check's runs included (the result says so
        in ``status``; a limit reached in the check keeps the complete run).
    model : {"two_mass", "multibody"}
        The mechanics (:data:`MODELS`): the two-mass diagram, or the paper's rig in a MultibodyPlant
        with the same controller, sensors, friction laws and load case
        (:func:`drakecreep.multibody.diagram.build_multibody_diagram`).
    multibody : drakecreep.multibody.diagram.MultibodyOptions, optional
        Segments, rigid joints, friction on/off and the integrator of the multibody model (its
        defaults when None).
    notice : callable, optional
        Called with one line when a run's pace projects more than :data:`SLOW_NOTICE` s of computing
        (:func:`slow_run_notice`; once per run, after :data:`SLOW_NOTICE_AFTER` s).

    Returns
    -------
    SimulationResult
        If the run stops part way, the result holds everything up to that point and ``status`` says
        why: the integrator failed, the divergence guard stopped it (table speed beyond
        :data:`MAX_TABLE_SPEED`, motor speed beyond its equivalent, non-finite state, a step below
        :data:`MIN_STEP`), the wall-clock limit, or Ctrl-C (``status`` starts with ``"interrupted"``);
        metrics are computed when the steady window was reached. ``metrics.converged`` is True/False when
        the convergence check ran (see the module notes), None when it was off or not possible; ``stats``
        holds the accuracy used and the check's numbers.
    """
    if wall_limit is not None:  # NumPy's numbers too (numbers.Real), as a float
        if isinstance(wall_limit, (bool, np.bool_)) or not isinstance(wall_limit, numbers.Real) \
                or not float(wall_limit) > 0:
            raise InputError("wall_limit", wall_limit, "a number of seconds > 0")
        wall_limit = float(wall_limit)
    # one deadline for every run below (the run, the convergence check's probe and rerun): the limit applied to
    # each of them let a 10 s --max-wall compute for up to 30 s
    deadline = None if wall_limit is None else time.perf_counter() + wall_limit
    backend = check_run(params, scenario, backend=backend, model=model, multibody=multibody)
    sim = params.simulation
    accuracy = target_accuracy(params)
    built = (_build(params, scenario, backend) if model == "two_mass"
             else _build_multibody(params, scenario, multibody, backend))
    result = _run(params, scenario, built, accuracy, scenario.duration, wall_limit, notice, deadline)
    check = sim.convergence_check and built[5]["integrator"] not in FIXED_STEP and result.ok \
        and result.metrics is not None
    if not check:
        result.stats.update(accuracy=accuracy)
        return result
    wall = result.wall_time
    end = min(scenario.duration, sim.steady_start + sim.convergence_window)
    attempts = 0
    while True:
        tight = max(accuracy / 10.0, _ACCURACY_FLOOR)
        probe = _run(params, scenario, built, tight, end, wall_limit, notice, deadline)
        wall += probe.wall_time
        if probe.status.startswith("interrupted") or "wall-clock limit" in probe.status:
            # a Ctrl-C or SIGTERM stops the command here too: it was read as a disagreement, the whole run was
            # simulated again at the tighter accuracy and the command ended 'converged' (exit 0). So does the
            # command's wall-clock limit. The run is kept, its convergence unknown
            result.status = f"{probe.status} in the convergence check (the run itself is complete, not checked)"
            result.wall_time = wall
            result.stats.update(accuracy=accuracy, convergence_check_accuracy=tight, convergence_runs=attempts)
            return result
        agree, change, same_verdict = _agree(result, probe, end, sim.convergence_tolerance)
        attempts += 1
        if agree or attempts == 2 or tight == accuracy:
            break
        # the verdict moved: the whole run again at the tighter accuracy, then check that one
        rerun = _run(params, scenario, built, tight, scenario.duration, wall_limit, notice, deadline)
        wall += rerun.wall_time
        if "wall-clock limit" in rerun.status:
            # the complete run is kept rather than the part of its rerun: its verdict disagreed with the check's
            result.status = (f"{rerun.status} in the convergence check's rerun at accuracy {tight:g} (the run at "
                             f"{accuracy:g} is complete and kept; the check at the tighter accuracy disagreed with it)")
            agree = False
            break
        result, accuracy = rerun, tight
        if result.metrics is None or not result.ok:  # (an interrupted rerun is not checked again either)
            break
    if result.metrics is not None:
        result.metrics = replace(result.metrics, converged=bool(agree))
    result.wall_time = wall
    result.stats.update(
        accuracy=accuracy, convergence_check_accuracy=tight, convergence_runs=attempts,
        convergence_fluctuation_change_mm_s=change * 1e3 if change is not None else None,
        convergence_tolerance_mm_s=sim.convergence_tolerance * abs(scenario.feed) * 1e3,
        convergence_verdict_agrees=same_verdict,
    )
    return result


def _agree(result, probe, end, tolerance):
    """Same creep verdict and fluctuation within ``tolerance`` x feed over ``[steady_start, end]``.

    Returns ``(agree, change, same_verdict)``: the fluctuation's change [m/s] and whether the verdicts agree
    (None, None when the probe failed)."""
    if probe.metrics is None or not probe.ok:
        return False, None, None
    sim = result.params.simulation
    feed = result.scenario.feed
    keep = result.time <= end + 0.5 * sim.log_period
    a = _window_metrics(result, keep)
    b = probe.metrics
    change = abs(a.max_fluctuation - b.max_fluctuation)
    return (a.creep == b.creep and change <= tolerance * abs(feed)), change, a.creep == b.creep


def _window_metrics(result, keep):
    s = result.signals
    return feed_metrics(
        result.time[keep], s["table_speed"][keep], (s["x_ref"] - s["x_ref"][0])[keep],
        (s["table_position"] - s["table_position"][0])[keep], result.scenario.feed,
        result.params.simulation.steady_start, result.params.simulation.stick_threshold,
    )


def _build(params, scenario, backend):
    """The diagram with its loggers, built once for the run and its convergence check.

    Returns ``(feed_drive, root, loggers, init, read_speeds, info)``: ``init(context)`` sets the compiled
    path's initial state, ``read_speeds(context)`` the table and motor speeds the divergence guard watches,
    ``info`` the backend and integrator names (and what else goes into the result's ``stats``).
    """
    sim = params.simulation
    feed_drive = build_diagram(params, scenario)

    builder = DiagramBuilder()
    if backend == "compiled":
        compiled = compile_diagram(feed_drive)
        system = builder.AddSystem(compiled.diagram)
        port = system.get_output_port(0)
        logger = builder.AddSystem(VectorLogSink(port.size(), sim.log_period))
        builder.Connect(port, logger.get_input_port())
        loggers = {"all": (logger, list(range(len(feed_drive.signals))))}
    else:
        system = builder.AddSystem(feed_drive.diagram)
        loggers = _log_ports(builder, system, feed_drive, sim.log_period)
    root = builder.Build()
    names = feed_drive.signal_names
    init = None
    if backend == "compiled":
        i_v, i_w = names.index("table_speed"), names.index("motor_speed")

        def set_initial_state(context):
            compiled.set_initial_state(root.GetMutableSubsystemContext(system, context))

        init = set_initial_state

        def read_speeds(context):
            y = port.Eval(root.GetSubsystemContext(system, context))
            return float(y[i_v]), float(y[i_w])
    else:
        table, motor = feed_drive.diagram.GetSubsystemByName("table"), feed_drive.diagram.GetSubsystemByName("motor")

        def read_speeds(context):
            diagram_context = root.GetSubsystemContext(system, context)
            t_ctx = feed_drive.diagram.GetSubsystemContext(table, diagram_context)
            m_ctx = feed_drive.diagram.GetSubsystemContext(motor, diagram_context)
            return (float(table.GetOutputPort("table_state").Eval(t_ctx)[1]),
                    float(motor.GetOutputPort("motor_state").Eval(m_ctx)[1]))
    return feed_drive, root, loggers, init, read_speeds, dict(backend=backend, integrator=sim.integrator)


def _log_ports(builder, system, feed_drive, log_period):
    """One ``VectorLogSink`` per exported port of the recorded signals: ``{key: (sink, [(signal, index)])}``."""
    loggers = {}
    for i, (_, (sys_name, port_name, index), _) in enumerate(feed_drive.signals):
        key = f"{sys_name}.{port_name}"
        if key not in loggers:
            port = system.GetOutputPort(key)
            sink = builder.AddSystem(VectorLogSink(port.size(), log_period))
            builder.Connect(port, sink.get_input_port())
            loggers[key] = (sink, [])
        loggers[key][1].append((i, index))
    return loggers


def _build_multibody(params, scenario, options, backend="compiled"):
    """:func:`_build` for the multibody model: its diagram with loggers on the exported signal ports (the loop
    compiled with ``backend == "compiled"``, the plant always Drake's own)."""
    from drakecreep.multibody.diagram import MultibodyOptions, build_multibody_diagram

    options = MultibodyOptions() if options is None else options
    feed_drive = build_multibody_diagram(params, scenario, options,
                                         compiler=compile_diagram if backend == "compiled" else None)
    builder = DiagramBuilder()
    system = builder.AddSystem(feed_drive.diagram)
    loggers = _log_ports(builder, system, feed_drive, params.simulation.log_period)
    root = builder.Build()

    def init(context):
        feed_drive.set_initial_state(root.GetMutableSubsystemContext(system, context))

    table, motor = system.GetOutputPort("table.table_state"), system.GetOutputPort("motor.motor_state")

    def read_speeds(context):
        sub = root.GetSubsystemContext(system, context)
        return float(table.Eval(sub)[1]), float(motor.Eval(sub)[1])

    info = dict(backend=f"multibody {backend}", integrator=options.integrator, model="multibody",
                n_segments=options.n_segments, rigid_joints=options.rigid_joints, friction=options.friction)
    return feed_drive, root, loggers, init, read_speeds, info


def _run(params, scenario, built, accuracy, until, wall_limit=None, notice=None, deadline=None):
    """One simulation from t = 0 to ``until`` at target ``accuracy`` on a diagram from :func:`_build`, watched
    by the divergence guard (which stops it at ``deadline``, from ``wall_limit``: :func:`_guard`)."""
    sim = params.simulation
    feed_drive, root, loggers, init, read_speeds, info = built
    units = feed_drive.signal_units()
    context = root.CreateDefaultContext()
    if init is not None:
        init(context)
    v_max = MAX_TABLE_SPEED
    bounds = (v_max, v_max * 2.0 * math.pi / params.screw.lead)

    start = time.perf_counter()
    other = {} if info["integrator"] == sim.integrator else dict(integrator=info["integrator"])
    simulator = make_simulator(root, context, sim, accuracy, **other)
    guard = _guard(simulator, root, read_speeds, bounds, wall_limit, until, notice, info["integrator"], deadline)
    status = "ok"
    try:
        simulator.AdvanceTo(until)  # the log's periodic publish lands on `until` too
    except RuntimeError as err:
        status = f"integration stopped at t = {context.get_time():.6g} s: {integration_failure(err)}"
    except KeyboardInterrupt as err:
        why = "SIGTERM" if isinstance(err, Terminated) else "Ctrl-C"
        status = f"interrupted ({why}) at t = {context.get_time():.6g} s"
    if guard["reason"] is not None:
        status = guard["reason"]
    wall = time.perf_counter() - start

    columns = [None] * len(feed_drive.signals)
    t = None
    for key, (sink, picks) in loggers.items():
        log = sink.FindLog(context)
        t = log.sample_times()
        data = log.data()
        if key == "all":
            for i in picks:
                columns[i] = data[i]
        else:
            for i, index in picks:
                columns[i] = data[index]
    signals = {name: np.asarray(col) for name, col in zip(feed_drive.signal_names, columns)}
    ratio = params.screw.lead / (2.0 * math.pi)
    signals["motor_position"] = signals["motor_angle"] * ratio
    signals["motor_velocity"] = signals["motor_speed"] * ratio
    units.update(motor_position="m", motor_velocity="m/s")
    t = np.asarray(t)

    metrics = None
    diverged = "diverged" in status
    if len(t) and t[-1] > sim.steady_start + 2 * sim.log_period and not diverged:
        # travel error: reference travel minus table travel (the reference starts where the position
        # feedback reads at rest, which for the encoder includes the screw's static stretch)
        metrics = feed_metrics(
            t, signals["table_speed"], signals["x_ref"] - signals["x_ref"][0],
            signals["table_position"] - signals["table_position"][0], scenario.feed,
            sim.steady_start, sim.stick_threshold,
        )
    integrator = simulator.get_integrator()
    stats = dict(
        **info,
        steps=int(integrator.get_num_steps_taken()),
        derivative_evaluations=int(integrator.get_num_derivative_evaluations()),
    )
    return SimulationResult(
        time=t, signals=signals, units=units, metrics=metrics, params=params, scenario=scenario,
        wall_time=wall, stats=stats, status=status,
    )
