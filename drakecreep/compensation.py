"""Friction compensation: torque added to the cascade controller's command (Drake ``Adder``).

Every compensator is a ``TemplateSystem`` (float, AutoDiffXd, Expression) with continuous states
only, so :func:`drakecreep.compiled.compile_diagram` still turns the diagram into symbolic systems
(the fast path allows one sample rate, the controller's). They run in continuous time, i.e. as a
compensation added at the current-loop rate, and read what the drive has: the reference
``[x_ref, v_ref]``, the motor encoder port ``[counted angle, motor speed]`` (its speed is the
unquantized motor speed, an ideal tachometer; the table speed is not measured in the semi-closed
loop) and, for the disturbance observer, the controller's torque command.

Their friction model is the plant's nominal law -- levels ``Fc, Fs`` of the load case
(:func:`drakecreep.table.friction_levels`), shape from ``params.friction`` -- times the mismatch
factors of :class:`drakecreep.params.CompensationParams`.

Methods
-------
static
    Stribeck + viscous feedforward ``g(v_c) tanh(v_c / v_reg) + Fv v_c`` at the reference speed
    (``velocity_blend`` mixes in the measured motor speed; the :data:`VARIANTS` entry
    ``"static-measured"`` is the model on the measured speed alone, i.e. model-based feedback).
lugre
    LuGre model with a friction-state observer (Canudas de Wit, Olsson, Astrom, Lischinsky, IEEE TAC
    40(3), 1995): ``dz/dt = v - sigma0 |v| z / g(v) - k (v - v_ref)`` driven by the measured speed,
    ``F = sigma0 z + sigma1 dz/dt + Fv v``. The state is stored as ``w = sigma0 z / Fc`` as in
    :class:`drakecreep.friction.LuGreFriction`.
dob
    Disturbance observer (Ohnishi): ``d = Q(s) (tau - J_n s omega)`` with ``Q = L / (s + L)`` on the
    motor-side rigid-body inertia ``J_n`` (motor, coupling, screw and the reflected table mass);
    ``d`` is added to the command.
dither
    A sinusoidal force ``A Fc sin(2 pi f t)`` (no model of the speed at all); it breaks static
    friction by keeping the contact moving and adds its own ripple.

Evaluation helpers (:func:`evaluate`, :func:`critical_speed`, :func:`robustness`) run the feed
simulations for the comparison against no compensation.
"""

import dataclasses
import math

from pydrake.systems.framework import BasicVector_, LeafSystem_
from pydrake.systems.primitives import Adder
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep._scalar import exp, fabs, tanh
from drakecreep.disturbance import sin
from drakecreep.errors import InputError
from drakecreep.params import COMPENSATION_METHODS, COMPENSATION_STUDY_METHODS, COMPENSATION_VARIANTS, with_value
from drakecreep.screw import screw_inertia
from drakecreep.table import friction_levels, moving_mass

__all__ = [
    "FrictionModel",
    "compensator_model",
    "StaticCompensator",
    "StaticCompensator_",
    "LuGreCompensator",
    "LuGreCompensator_",
    "DisturbanceObserver",
    "DisturbanceObserver_",
    "DitherCompensator",
    "DitherCompensator_",
    "make_compensator",
    "add_compensation",
    "MISMATCH_FIELDS",
    "with_method",
    "VARIANTS",
    "method_names",
    "rigid_inertia",
    "DEFAULT_FEEDS_MM_S",
    "DEFAULT_METHODS",
    "EVAL_KEYS",
    "evaluate",
    "critical_speed",
    "critical_speeds",
    "robustness",
    "plot_comparison",
    "summary_markdown",
    "write_report",
]


@dataclasses.dataclass(frozen=True)
class FrictionModel:
    """The compensator's friction model, table side (N, m/s)."""

    fc: float
    fs: float
    stribeck_velocity: float
    exponent: float
    viscous: float
    sigma0: float
    sigma1: float
    regularization_velocity: float

    def g(self, v):
        """Stribeck curve ``Fc + (Fs - Fc) exp(-|v/vs|^delta)`` for any scalar type."""
        if self.exponent == 2.0:
            return self.fc + (self.fs - self.fc) * exp(-((v / self.stribeck_velocity) ** 2))
        return self.fc + (self.fs - self.fc) * exp(-(fabs(v / self.stribeck_velocity) ** self.exponent))


def compensator_model(params, load_case):
    """:class:`FrictionModel` of the compensator: the plant's nominal friction times the mismatch factors."""
    c = params.compensation
    f = params.friction
    fc, fs = friction_levels(params, params.load_case(load_case))
    return FrictionModel(
        fc=fc * c.coulomb_factor, fs=fs * c.static_factor,
        stribeck_velocity=f.stribeck_velocity * c.stribeck_velocity_factor, exponent=f.stribeck_exponent,
        viscous=f.viscous * c.viscous_factor, sigma0=f.bristle_stiffness * c.bristle_stiffness_factor,
        sigma1=f.bristle_damping * c.bristle_damping_factor, regularization_velocity=f.regularization_velocity,
    )


def _declare_inputs(system):
    system.DeclareVectorInputPort("reference", 2)
    system.DeclareVectorInputPort("motor_measured", 2)
    system.DeclareVectorInputPort("torque_command", 1)
    system.DeclareVectorInputPort("table_state", 2)


def _measured_speed(system, context):
    """Speed the compensator uses (m/s, table side): motor speed through the lead, or the table's."""
    if system.velocity_source == "table":
        return system.get_input_port(3).Eval(context)[1]
    return system.get_input_port(1).Eval(context)[1] * system.ratio


@TemplateSystem.define("StaticCompensator_")
def StaticCompensator_(T):
    class Impl(LeafSystem_[T]):
        """Stribeck + viscous friction feedforward.

        Input ports ``reference`` (2), ``motor_measured`` (2), ``torque_command`` (1, unused);
        output ``torque`` (1, N m).
        """

        def _construct(self, model, lead, velocity_blend=0.0, velocity_source="motor", converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.model, self.lead, self.velocity_blend = model, float(lead), float(velocity_blend)
            self.velocity_source = velocity_source
            self.ratio = self.lead / (2.0 * math.pi)
            _declare_inputs(self)
            self.DeclareVectorOutputPort("torque", 1, self._calc)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.model, other.lead, other.velocity_blend, other.velocity_source,
                            converter=converter)

        def force(self, context):
            v_ref = self.get_input_port(0).Eval(context)[1]
            v = v_ref
            if self.velocity_blend > 0.0:
                v = (1.0 - self.velocity_blend) * v_ref + self.velocity_blend * _measured_speed(self, context)
            m = self.model
            return m.g(v) * tanh(v / m.regularization_velocity) + m.viscous * v

        def _calc(self, context, output):
            output.SetAtIndex(0, self.force(context) * self.ratio)

    return Impl


@TemplateSystem.define("LuGreCompensator_")
def LuGreCompensator_(T):
    class Impl(LeafSystem_[T]):
        """LuGre friction compensation with a friction-state observer; state ``w = sigma0 z / Fc``.

        Input ports ``reference`` (2), ``motor_measured`` (2), ``torque_command`` (1, unused);
        output ``torque`` (1, N m).
        """

        def _construct(self, model, lead, observer_gain=0.0, velocity_source="motor", converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.model, self.lead, self.observer_gain = model, float(lead), float(observer_gain)
            self.velocity_source = velocity_source
            self.ratio = self.lead / (2.0 * math.pi)
            _declare_inputs(self)
            self.DeclareContinuousState(BasicVector_[T]([0.0]))
            self.DeclareVectorOutputPort("torque", 1, self._calc)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.model, other.lead, other.observer_gain, other.velocity_source,
                            converter=converter)

        def _rates(self, context):
            m = self.model
            v_ref = self.get_input_port(0).Eval(context)[1]
            v = _measured_speed(self, context)
            w = context.get_continuous_state_vector().GetAtIndex(0)
            zdot = v - fabs(v) * w * m.fc / m.g(v) - self.observer_gain * (v - v_ref)
            return v, w, zdot

        def DoCalcTimeDerivatives(self, context, derivatives):
            _, _, zdot = self._rates(context)
            derivatives.get_mutable_vector().SetAtIndex(0, self.model.sigma0 / self.model.fc * zdot)

        def force(self, context):
            v, w, zdot = self._rates(context)
            m = self.model
            return m.fc * w + m.sigma1 * zdot + m.viscous * v

        def _calc(self, context, output):
            output.SetAtIndex(0, self.force(context) * self.ratio)

    return Impl


@TemplateSystem.define("DisturbanceObserver_")
def DisturbanceObserver_(T):
    class Impl(LeafSystem_[T]):
        """First-order disturbance observer on the motor; state ``p`` with ``d = p - L J_n omega``.

        ``dp/dt = L (tau - p + L J_n omega)``, ``tau`` the torque sent to the motor (controller command
        plus ``d``), so that ``d = L/(s+L) (tau - J_n s omega)``. Output ``torque`` (1, N m) ``= d``.
        """

        def _construct(self, inertia, bandwidth, initial_torque=0.0, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.inertia, self.bandwidth = float(inertia), float(bandwidth)
            self.initial_torque = float(initial_torque)
            _declare_inputs(self)
            self.DeclareContinuousState(BasicVector_[T]([self.initial_torque]))
            self.DeclareVectorOutputPort(
                "torque", 1, self._calc,
                prerequisites_of_calc={self.xc_ticket(), self.input_port_ticket(self.get_input_port(1).get_index())},
            )

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.inertia, other.bandwidth, other.initial_torque, converter=converter)

        def _estimate(self, context):
            p = context.get_continuous_state_vector().GetAtIndex(0)
            omega = self.get_input_port(1).Eval(context)[1]
            return p, omega, p - self.bandwidth * self.inertia * omega

        def DoCalcTimeDerivatives(self, context, derivatives):
            p, omega, d = self._estimate(context)
            tau = self.get_input_port(2).Eval(context)[0] + d
            L = self.bandwidth
            derivatives.get_mutable_vector().SetAtIndex(0, L * (tau - p + L * self.inertia * omega))

        def _calc(self, context, output):
            output.SetAtIndex(0, self._estimate(context)[2])

    return Impl


@TemplateSystem.define("DitherCompensator_")
def DitherCompensator_(T):
    class Impl(LeafSystem_[T]):
        """Sinusoidal dither force ``A sin(2 pi f t)`` through the lead; output ``torque`` (1, N m)."""

        def _construct(self, amplitude, frequency, lead, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.amplitude, self.frequency, self.lead = float(amplitude), float(frequency), float(lead)
            _declare_inputs(self)
            self.DeclareVectorOutputPort("torque", 1, self._calc, prerequisites_of_calc={self.time_ticket()})

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.amplitude, other.frequency, other.lead, converter=converter)

        def _calc(self, context, output):
            t = context.get_time()
            output.SetAtIndex(0, self.amplitude * sin(2.0 * math.pi * self.frequency * t) * self.lead / (2.0 * math.pi))

    return Impl


StaticCompensator = StaticCompensator_[None]
LuGreCompensator = LuGreCompensator_[None]
DisturbanceObserver = DisturbanceObserver_[None]
DitherCompensator = DitherCompensator_[None]


def rigid_inertia(params):
    """Motor-side rigid-body inertia (kg m^2): rotor, coupling, screw and the reflected table mass."""
    ratio = params.screw.lead / (2.0 * math.pi)
    return (params.motor.rotor_inertia + params.motor.coupling_inertia + screw_inertia(params.screw)
            + moving_mass(params) * ratio**2)


def make_compensator(params, scenario):
    """The compensator system for ``params.compensation.method`` (None for ``"none"``)."""
    c = params.compensation
    if c.method == "none":
        return None
    model = compensator_model(params, scenario.load_case)
    lead = params.screw.lead
    if c.method == "static":
        return StaticCompensator(model, lead, c.velocity_blend, c.velocity_source)
    if c.method == "lugre":
        return LuGreCompensator(model, lead, c.observer_gain, c.velocity_source)
    if c.method == "dob":
        return DisturbanceObserver(rigid_inertia(params) * c.inertia_factor, c.dob_bandwidth)
    if c.method == "dither":
        return DitherCompensator(c.dither_amplitude * model.fc, c.dither_frequency, lead)
    raise InputError("compensation.method", c.method, "one of " + ", ".join(COMPENSATION_METHODS))


def add_compensation(builder, systems, params, scenario, ports):
    """Add the compensator and an ``Adder`` in front of the motor's torque input, when a method is set.

    Returns
    -------
    dict
        ``ports`` with ``torque`` replaced by the adder's input the controller's command goes to.
    """
    compensator = make_compensator(params, scenario)
    ports = dict(ports)
    if compensator is None:
        return ports
    compensator.set_name("compensator")
    builder.AddSystem(compensator)
    adder = builder.AddSystem(Adder(2, 1))
    adder.set_name("torque_sum")
    systems["compensator"], systems["torque_sum"] = compensator, adder
    c = builder.Connect
    c(systems["reference"].GetOutputPort("reference"), compensator.GetInputPort("reference"))
    c(systems["encoder"].GetOutputPort("motor_measured"), compensator.GetInputPort("motor_measured"))
    c(systems["controller"].GetOutputPort("torque_command"), compensator.GetInputPort("torque_command"))
    c(systems["table"].GetOutputPort("table_state"), compensator.GetInputPort("table_state"))
    c(compensator.GetOutputPort("torque"), adder.get_input_port(1))
    c(adder.get_output_port(0), ports["torque"])
    ports["torque"] = adder.get_input_port(0)
    return ports


# --------------------------------------------------------------------------- evaluation

#: compensator model parameters varied in the robustness study, by method
MISMATCH_FIELDS = {
    "static": ("coulomb_factor", "static_factor", "stribeck_velocity_factor", "viscous_factor"),
    "lugre": ("coulomb_factor", "static_factor", "stribeck_velocity_factor", "viscous_factor",
              "bristle_stiffness_factor", "bristle_damping_factor"),
    "dob": ("inertia_factor",),
    "dither": ("coulomb_factor",),
}


#: named evaluation variants of a method: label -> (method, compensation settings)
VARIANTS = COMPENSATION_VARIANTS


def method_names():
    """Every name :func:`with_method` takes: the methods of ``compensation.method`` and :data:`VARIANTS`."""
    return tuple(COMPENSATION_METHODS) + tuple(VARIANTS)


def with_method(params, method, **settings):
    """``params`` with ``compensation.method = method`` and other compensation fields set.

    ``method`` may also name a :data:`VARIANTS` entry, whose settings come first (``settings`` override).
    """
    _check_method(method)
    if method in VARIANTS:
        method, preset_settings = VARIANTS[method]
        settings = {**preset_settings, **settings}
    out = with_value(params, "compensation.method", method)
    for key, value in settings.items():
        out = with_value(out, f"compensation.{key}", value)
    return out


#: feed grid of the comparison (mm/s)
DEFAULT_FEEDS_MM_S = (0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0)
#: methods compared, the baseline first
DEFAULT_METHODS = COMPENSATION_STUDY_METHODS
#: metric keys of one evaluation row (report units)
EVAL_KEYS = ("max_fluctuation_mm_s", "fluctuation_rate_percent", "stick_fraction", "creep",
             "following_error_max_um", "following_error_rms_um")


def _run_one(job):
    """One simulation of the comparison (module level, so a process pool can pickle it)."""
    from drakecreep.scenario import Scenario
    from drakecreep.simulation import simulate

    params, label, feed_mm_s, load_case, duration = job
    res = simulate(params, Scenario(feed=feed_mm_s * 1e-3, load_case=load_case, duration=duration))
    row = dict(label=label, method=label.split(" ")[0], load_case=load_case, feed_mm_s=feed_mm_s,
               status=res.status)
    report = res.metrics.report() if res.metrics is not None else {}
    row.update({k: report.get(k, float("nan")) for k in EVAL_KEYS})
    return row


def _map(jobs, workers):
    if workers <= 1:
        return [_run_one(j) for j in jobs]
    import concurrent.futures as cf
    import multiprocessing

    with cf.ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        return list(pool.map(_run_one, jobs))


def _check_method(method):
    if method not in COMPENSATION_METHODS and method not in VARIANTS:
        raise InputError("method", method, "one of " + ", ".join(method_names()))


def evaluate(params, methods=DEFAULT_METHODS, feeds_mm_s=DEFAULT_FEEDS_MM_S, load_cases=(1, 2, 3), duration=2.0,
             workers=1):
    """Each method at each feed and load case: speed fluctuation, stick fraction, following error.

    Metrics over ``t >= simulation.steady_start`` (the window is shortened to half the run if the
    parameters start it later). ``workers > 1`` runs the simulations on a process pool.

    Returns
    -------
    list of dict
        One row per (method, load case, feed): ``label``, ``method``, ``load_case``, ``feed_mm_s``,
        ``status`` and :data:`EVAL_KEYS`; plus ``*_vs_none`` ratios of fluctuation and stick fraction
        against the uncompensated row of the same feed and load.
    """
    for m in methods:
        _check_method(m)
    base = with_value(params, "simulation.steady_start", min(params.simulation.steady_start, 0.5 * duration))
    jobs = [(with_method(base, m), m, float(f), lc, duration) for m in methods for lc in load_cases for f in feeds_mm_s]
    rows = _map(jobs, workers)
    _add_ratios(rows)
    return rows


def _add_ratios(rows, key=("load_case", "feed_mm_s")):
    ref = {tuple(r[k] for k in key): r for r in rows if r["method"] == "none" and r["label"] == "none"}
    for r in rows:
        b = ref.get(tuple(r[k] for k in key))
        if b is None:
            continue
        r["fluctuation_vs_none"] = r["max_fluctuation_mm_s"] / b["max_fluctuation_mm_s"]
        r["stick_fraction_vs_none"] = (r["stick_fraction"] / b["stick_fraction"] if b["stick_fraction"] > 0
                                       else (0.0 if r["stick_fraction"] == 0 else float("inf")))


def critical_speed(params, method, load_case, **kwargs):
    """Lowest feed (m/s) without creep with ``method`` (see :func:`drakecreep.paper_reproduction.critical_speed`)."""
    from drakecreep.paper_reproduction import critical_speed as _critical

    _check_method(method)
    return _critical(with_method(params, method), load_case, **kwargs)


def robustness(params, methods=DEFAULT_METHODS[1:], feeds_mm_s=(0.1, 0.2), load_case=3,
               factors=(0.7, 1.3), duration=2.0, workers=1):
    """The compensator's model off by each factor in each of its parameters (:data:`MISMATCH_FIELDS`).

    Returns
    -------
    list of dict
        Rows as :func:`evaluate` with ``label`` ``"<method> <field> x<factor>"`` (``"<method> nominal"``
        for the exact model, ``"none"`` for no compensation) and the ratios against ``none``.
    """
    for m in methods:
        _check_method(m)
    base = with_value(params, "simulation.steady_start", min(params.simulation.steady_start, 0.5 * duration))
    configs = [("none", with_method(base, "none"))]
    for m in methods:
        configs.append((f"{m} nominal", with_method(base, m)))
        for name in MISMATCH_FIELDS[VARIANTS[m][0] if m in VARIANTS else m]:
            for factor in factors:
                configs.append((f"{m} {name} x{factor:g}", with_method(base, m, **{name: factor})))
    jobs = [(p, label, float(f), load_case, duration) for label, p in configs for f in feeds_mm_s]
    rows = _map(jobs, workers)
    _add_ratios(rows)
    return rows


def critical_speeds(params, methods=DEFAULT_METHODS, load_cases=(1, 2, 3), lo=0.01e-3, **kwargs):
    """Lowest feed without creep (mm/s) per method and load case.

    Returns
    -------
    list of dict
        Rows ``method, load_case, critical_mm_s, lowest_tested_mm_s``; ``critical_mm_s`` is 0 when no
        feed down to ``lo`` creeps (see :func:`drakecreep.paper_reproduction.critical_speed`).
    """
    return [dict(method=m, load_case=lc, critical_mm_s=critical_speed(params, m, lc, lo=lo, **kwargs) * 1e3,
                 lowest_tested_mm_s=lo * 1e3)
            for m in methods for lc in load_cases]


def _critical_cell(row):
    if row["critical_mm_s"] > 0:
        return f"{row['critical_mm_s']:.4f}"
    if row["critical_mm_s"] == 0:
        return f"no creep down to {row.get('lowest_tested_mm_s', 0.01):g}"
    return "creeps at every feed tested"


def plot_comparison(rows, path, title=None):
    """Fluctuation and stick fraction against feed, one column per load case, one line per method."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    loads = sorted({r["load_case"] for r in rows})
    methods = list(dict.fromkeys(r["label"] for r in rows))
    fig, axes = plt.subplots(2, len(loads), figsize=(4.2 * len(loads), 7), squeeze=False, constrained_layout=True)
    for j, lc in enumerate(loads):
        for m in methods:
            sel = sorted((r for r in rows if r["load_case"] == lc and r["label"] == m), key=lambda r: r["feed_mm_s"])
            f = [r["feed_mm_s"] for r in sel]
            axes[0, j].loglog(f, [r["fluctuation_rate_percent"] for r in sel], "o-", ms=3, label=m)
            axes[1, j].semilogx(f, [r["stick_fraction"] * 100 for r in sel], "o-", ms=3, label=m)
        axes[0, j].set_title(f"load case {lc}", fontsize=9)
        axes[0, j].set_ylabel("fluctuation rate (%)")
        axes[1, j].set_ylabel("stick fraction (%)")
        axes[1, j].set_xlabel("feed (mm/s)")
    axes[0, 0].legend(fontsize=7)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def summary_markdown(rows, critical=None, robust=None, params_name="paper"):
    """A Markdown summary of :func:`evaluate`, :func:`critical_speeds` and :func:`robustness` rows."""
    lines = [f"# Friction compensation ({params_name})", "",
             "Ratios are against no compensation at the same feed and load (< 1 is better).", "",
             "| method | load case | feed (mm/s) | fluctuation (mm/s) | vs none | stick (%) | creep | "
             "following error max (um) |", "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        lines.append(f"| {r['label']} | {r['load_case']} | {r['feed_mm_s']:g} | {r['max_fluctuation_mm_s']:.4g} | "
                     f"{r.get('fluctuation_vs_none', float('nan')):.3g} | {r['stick_fraction'] * 100:.2f} | "
                     f"{r['creep']} | {r['following_error_max_um']:.3f} |")
    if critical:
        loads = sorted({c["load_case"] for c in critical})
        lines += ["", "## Lowest feed without creep (mm/s)", "",
                  "| method | " + " | ".join(f"load case {lc}" for lc in loads) + " |",
                  "| --- |" + " --- |" * len(loads)]
        for m in dict.fromkeys(c["method"] for c in critical):
            cells = {c["load_case"]: _critical_cell(c) for c in critical if c["method"] == m}
            lines.append(f"| {m} | " + " | ".join(cells[lc] for lc in loads) + " |")
    if robust:
        lines += ["", "## Robustness: the compensator's model off by a factor (load case "
                  f"{robust[0]['load_case']})", "",
                  "| configuration | feed (mm/s) | fluctuation (mm/s) | vs none | stick (%) |", "| --- | --- | --- | --- | --- |"]
        for r in robust:
            lines.append(f"| {r['label']} | {r['feed_mm_s']:g} | {r['max_fluctuation_mm_s']:.4g} | "
                         f"{r.get('fluctuation_vs_none', float('nan')):.3g} | {r['stick_fraction'] * 100:.2f} |")
    return "\n".join(lines) + "\n"


def write_report(out_dir, rows, critical=None, robust=None, params_name="paper"):
    """Write ``compensation.csv``, ``summary.md``, ``rows.json`` and ``comparison.png``; return the paths."""
    import csv
    import json
    from pathlib import Path

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = dict(csv=out / "compensation.csv", markdown=out / "summary.md", json=out / "rows.json",
                 plot=out / "comparison.png")
    keys = list(dict.fromkeys(k for r in rows + (robust or []) for k in r))
    with paths["csv"].open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=keys + ["study"])
        writer.writeheader()
        for study, group in (("grid", rows), ("robustness", robust or [])):
            for r in group:
                writer.writerow(dict(r, study=study))
    paths["markdown"].write_text(summary_markdown(rows, critical, robust, params_name))
    paths["json"].write_text(json.dumps(dict(rows=rows, critical=critical, robustness=robust), indent=2) + "\n")
    plot_comparison(rows, paths["plot"], f"Friction compensation against none ({params_name})")
    return paths
