"""Simulate a feed: parameters + scenario -> Drake simulation -> time series + creep metrics.

The default backend compiles the diagram into ``SymbolicVectorSystem``s (:mod:`drakecreep.sim.compiled`);
``backend="leaf"`` simulates the Python leaf systems directly (same equations, slower; kept as the
reference the fast path is tested against).
"""

import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import VectorLogSink

from drakecreep.sim.compiled import compile_diagram
from drakecreep.model.diagram import build_diagram
from drakecreep.errors import InputError
from drakecreep.sim.metrics import feed_metrics
from drakecreep.params import save_params

__all__ = ["SimulationResult", "simulate", "make_simulator", "FIXED_STEP"]

#: integrators without error control: they step at ``max_step``
FIXED_STEP = ("runge_kutta2",)


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

    def save(self, out_dir):
        """Write ``timeseries.csv``, ``metrics.json`` and ``params.yaml`` to ``out_dir``.

        The speed plot is :func:`drakecreep.report.plots.plot_feed` (reports read results, not the reverse).

        Returns
        -------
        dict
            name -> path of each written file.
        """
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        paths = {}
        names = list(self.signals)
        header = ",".join(["t_s"] + [f"{n}_{_unit_tag(self.units[n])}" for n in names])
        data = np.column_stack([self.time] + [self.signals[n] for n in names])
        paths["timeseries"] = out / "timeseries.csv"
        np.savetxt(paths["timeseries"], data, delimiter=",", header=header, comments="", fmt="%.10g")
        paths["metrics"] = out / "metrics.json"
        payload = dict(summary=self.summary(), scenario=asdict(self.scenario), units=self.units)
        paths["metrics"].write_text(json.dumps(payload, indent=2) + "\n")
        paths["params"] = out / "params.yaml"
        save_params(self.params, paths["params"])
        return paths


def _unit_tag(unit):
    return unit.replace(" ", "").replace("/", "_per_").replace("^", "")


def make_simulator(system, context, sim):
    """A Drake ``Simulator`` configured from :class:`~drakecreep.params.SimulationParams`."""
    simulator = Simulator(system, context)
    integrator = ResetIntegratorFromFlags(simulator, sim.integrator, sim.max_step)
    integrator.set_maximum_step_size(sim.max_step)
    if sim.integrator not in FIXED_STEP:
        integrator.set_target_accuracy(sim.accuracy)
    simulator.Initialize()
    return simulator


def simulate(params, scenario, *, backend=None):
    """Simulate ``scenario`` on the drive described by ``params``.

    Parameters
    ----------
    params : drakecreep.params.DriveParams
    scenario : drakecreep.scenario.Scenario
    backend : {"compiled", "leaf"}, optional
        Default ``params.simulation.backend``.

    Returns
    -------
    SimulationResult
        If the integrator fails part way, the result holds everything up to that point and
        ``status`` says why; metrics are computed when the steady window was reached.
    """
    sim = params.simulation
    backend = backend or sim.backend
    if backend not in ("compiled", "leaf"):
        raise InputError("backend", backend, "compiled or leaf")
    if sim.steady_start >= scenario.duration:
        raise InputError("simulation.steady_start", sim.steady_start, f"< duration ({scenario.duration} s)")
    feed_drive = build_diagram(params, scenario)
    units = feed_drive.signal_units()

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
        loggers = {}
        for i, (_, (sys_name, port_name, index), _) in enumerate(feed_drive.signals):
            key = f"{sys_name}.{port_name}"
            if key not in loggers:
                port = system.GetOutputPort(key)
                sink = builder.AddSystem(VectorLogSink(port.size(), sim.log_period))
                builder.Connect(port, sink.get_input_port())
                loggers[key] = (sink, [])
            loggers[key][1].append((i, index))
    root = builder.Build()
    context = root.CreateDefaultContext()
    if backend == "compiled":
        compiled.set_initial_state(root.GetMutableSubsystemContext(system, context))

    start = time.perf_counter()
    simulator = make_simulator(root, context, sim)
    status = "ok"
    try:
        simulator.AdvanceTo(scenario.duration)  # the log's periodic publish lands on `duration` too
    except RuntimeError as err:
        status = f"integration stopped at t = {context.get_time():.6g} s: {str(err).splitlines()[0]}"
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
    if len(t) and t[-1] > sim.steady_start + 2 * sim.log_period:
        # travel error: reference travel minus table travel (the reference starts where the position
        # feedback reads at rest, which for the encoder includes the screw's static stretch)
        metrics = feed_metrics(
            t, signals["table_speed"], signals["x_ref"] - signals["x_ref"][0],
            signals["table_position"] - signals["table_position"][0], scenario.feed,
            sim.steady_start, sim.stick_threshold,
        )
    integrator = simulator.get_integrator()
    stats = dict(
        backend=backend,
        integrator=sim.integrator,
        steps=int(integrator.get_num_steps_taken()),
        derivative_evaluations=int(integrator.get_num_derivative_evaluations()),
    )
    return SimulationResult(
        time=t, signals=signals, units=units, metrics=metrics, params=params, scenario=scenario,
        wall_time=wall, stats=stats, status=status,
    )
