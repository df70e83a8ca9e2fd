"""Measured runs of a real feed drive: validated arrays in SI units plus the metadata needed to replay them.

A run is a CSV with a header of SI signal names (a unit may follow a name in brackets, ``x_motor[m]``,
and must then be the SI one; ``u`` must carry the unit of the metadata, ``u[V]``):

========== ======== ===================================================================
column     unit     meaning
========== ======== ===================================================================
``t``      s        time, strictly increasing, uniform within ``dt_rtol``; any origin (a run starts at its first sample)
``x_ref``  m        reference position
``x_motor`` m       motor encoder position at the table (angle x lead / 2 pi)
``x_table`` m       optional: linear scale
``u``      N, A, V  controller output, unit stated in the metadata
``f_ext``  N        optional: external force on the axis
``run``    text     optional: run label when a file holds several runs
========== ======== ===================================================================

Beside it, a metadata YAML (``<csv stem>.yaml`` by default) gives the units of ``u`` and the gain from
``u`` to axial force, the drive parameters (``drakecreep.params``, inline or as a file path), the
controller actually used (:class:`ControllerMeta`) and the sensor resolutions::

    u_units: V                  # N, A or V
    u_gain: 35.15               # N per unit of u (1 for N; for A derivable from params)
    params: rig.yaml            # optional: a drakecreep parameter file (relative to this YAML) or a mapping
    controller: {kind: p_p_cascade, kp: 160.18, kv: 243.45, saturation: 10.0, sample_time: 0.001,
                 position_filter: [0.5, 0.5]}
    sensors: {encoder_resolution: 1.0e-7, scale_resolution: 0.0}   # m per count; 0 = unknown/ideal
    source: free text

The EMPS benchmark files (``.mat``) map to the same form through :func:`load_emps`. Every error is a
:class:`drakecreep.errors.InputError` naming the column or key, the value and what is allowed.
"""

from __future__ import annotations

import csv
import dataclasses
import math

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from drakecreep.data import emps_data_dir
from drakecreep.errors import InputError, renaming
from drakecreep.files import write_atomic, write_text
from drakecreep.gap.formats import read_signals
from drakecreep.params import MAX_LOAD_FORCE

__all__ = [
    "U_UNITS",
    "MIN_U_GAIN",
    "MAX_U_GAIN",
    "MAX_SPEED",
    "MAX_TAPS",
    "MAX_TAP_GAIN",
    "COLUMNS",
    "CONTROLLER_KINDS",
    "ControllerMeta",
    "SensorMeta",
    "MeasuredMeta",
    "MeasuredRun",
    "MeasuredData",
    "load_measured",
    "check_recorded",
    "check_split",
    "controller_gains",
    "controller_ticks",
    "at_controller_rate",
    "on_controller_ticks",
    "TICK_SHARE",
    "save_measured",
    "load_emps",
    "emps_data_dir",
    "emps_path",
    "EMPS_FILES",
    "EMPS_CONTROLLER",
    "EMPS_ENCODER_RESOLUTION",
]

#: Units allowed for the controller output ``u``.
U_UNITS = ("N", "A", "V")
#: Column name -> (SI unit, required). ``u``'s unit comes from the metadata.
COLUMNS = {
    "t": ("s", True),
    "x_ref": ("m", True),
    "x_motor": ("m", True),
    "x_table": ("m", False),
    "u": (None, True),
    "f_ext": ("N", False),
    "run": (None, False),
}
_ARRAYS = ("t", "x_ref", "x_motor", "x_table", "u", "f_ext")
#: Range of ``u_gain`` [N per unit of u]: drives span about 1e-3 to 1e5 N/A or N/V; outside these bounds the
#: forces overflow or vanish in the identification
MIN_U_GAIN, MAX_U_GAIN = 1e-9, 1e9
#: Largest gain of a declared controller (``kp`` [1/s], ``kv`` [units of u per m/s]): no drive's is near it
MAX_GAIN = 1e9
#: Fastest plausible axis speed [m/s]: ball-screw feed drives traverse at up to about 2 m/s and linear motors at
#: about 5. A position column faster than this, or its time, is in the wrong unit (millimetres labelled ``m``, or
#: milliseconds labelled ``us``, move a thousand times too fast), which would otherwise run a whole diagnosis on a
#: model that cannot follow it
MAX_SPEED = 10.0
#: Smallest peak drive force [N] (``u x u_gain``) a measured run may have: no drive moves an axis with less than a
#: micronewton (a u of 1e-300 V ran to 'y: got all zero', an internal name, from the nominal's fit)
MIN_PEAK_FORCE = 1e-6
#: Share of a run's samples whose speed may exceed :data:`MAX_SPEED` (a reference step, an encoder glitch)
_FAST_SHARE = 0.01
#: Share of a position column's non-zero steps that may be shorter than half a declared count: a counting
#: sensor moves by whole counts, so more means the resolution is in the wrong unit or not the one recorded
_SUBCOUNT_SHARE = 0.02
#: Most taps of a declared ``position_filter``: drives average a few samples (EMPS: 2); each tap is a state of the
#: replay, so 128 taps took twice the replay time of 2 and 10000 never finished
MAX_TAPS = 256
#: Largest sum of the taps' magnitudes (the filter's gain on encoder noise; an extrapolating filter of order 3,
#: 4, -6, 4, -1, has 15): taps of 1e300 and -1e300 that sum to 1 replayed without end
MAX_TAP_GAIN = 1000.0
#: Largest recorded ``|u|`` of a P-P cascade's run, in its declared saturations: its output is clipped there,
#: though a command added after the clip passes it (the EMPS validation pulses: 10.84 V at a 10 V saturation)
_SATURATION_SLACK = 2.0
#: Largest factor between the travels of two position columns of a run (``x_motor`` against ``x_ref``,
#: ``x_table`` against ``x_motor``): a closed loop follows its reference, and the table its motor, within a few per
#: cent of a long travel; a unit written wrong on one column puts a thousand between them. Room for micro-motion:
#: in a stick test of a few micrometres the motor winds the screw up (100 N of friction on 50 N/um is 2 um)
#: while the table may hardly move
_TRAVEL_FACTOR = 100.0
#: a P-P run's sample time and its controller's ``sample_time`` this far apart are refused on loading, before the gain
#: fit (a time column in ms or min under a header in s); within it, a log every few ticks is replayed and any other
#: mismatch is refused by the replay, run by run (:func:`controller_ticks`)
_SAMPLE_TIME_FACTOR = 10.0
#: Largest factor between a declared P-P gain and the one the recorded ``u`` follows (:func:`controller_gains`):
#: a gain in the wrong unit (per mm/s for per m/s, a mistyped exponent) is off by decades; noise, quantization
#: and a computation delay move the fitted gains by per cent (EMPS: 0.02 % and 0.03 %)
_GAIN_FACTOR = 10.0
#: The fitted law must reproduce the unsaturated ``u`` within this share of its RMS for its gains to be read (a
#: command far from the P-P form says nothing about the declared gains)
_LAW_FIT = 0.5
#: Largest computation delay [samples] the gain check tries: the fitted gains are those of the best lag
_MAX_LAG = 10
#: Controller kinds of the metadata schema.
CONTROLLER_KINDS = ("p_p_cascade", "drakecreep")


def _finite(name, value, lo=None, lo_open=False, hi=None):
    if isinstance(value, (str, bool)):  # a quoted number is text in YAML, as the params files hold it
        raise InputError(name, value, "a finite number (not quoted)")
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):  # OverflowError: an integer of hundreds of digits
        raise InputError(name, value, "a finite number") from None
    if not math.isfinite(x):
        raise InputError(name, value, "a finite number")
    if lo is not None and (x < lo or (lo_open and x == lo)):
        raise InputError(name, value, f"a finite number {'>' if lo_open else '>='} {lo}")
    if hi is not None and x > hi:
        raise InputError(name, value, f"a finite number <= {hi:g}")
    return x


#: :class:`ControllerMeta`'s fields of the P-P law alone (refused for kind ``drakecreep`` unless at their defaults)
_P_P_FIELDS = ("kp", "kv", "saturation", "position_filter")


@dataclass(frozen=True)
class ControllerMeta:
    """The controller that produced ``u`` during the run.

    ``kind="p_p_cascade"`` is the EMPS law, sampled every ``sample_time``::

        xf[k] = sum_i position_filter[i] * x[k-i]        (EMPS: 0.5 x[k] + 0.5 x[k-1])
        dx[k] = (xf[k] - xf[k-1]) / sample_time
        u[k]  = clip(kp * kv * (x_ref[k] - x[k]) - kv * dx[k], -saturation, saturation)

    with ``x`` the motor encoder (``feedback="motor"``) or the scale (``"table"``); ``u`` is held over
    the sample. ``kind="drakecreep"`` means the project's own cascade with the gains of
    ``params.controller``: the P-P law's ``kp``, ``kv``, ``saturation`` and ``position_filter`` are refused for it
    (:meth:`from_dict`) unless left at their defaults, and ``sample_time`` is unused.

    Parameters
    ----------
    kind : str
        ``"p_p_cascade"`` or ``"drakecreep"``.
    kp : float
        Position gain [1/s].
    kv : float
        Velocity gain [unit of u per m/s].
    saturation : float
        Output limit [unit of u], > 0 (``inf`` for none).
    sample_time : float
        Controller period [s].
    position_filter : tuple of float
        FIR taps on the position before the velocity difference; they must sum to 1.
    feedback : str
        ``"motor"`` or ``"table"``.
    """

    kind: str = "p_p_cascade"
    kp: float = 0.0
    kv: float = 0.0
    saturation: float = math.inf
    sample_time: float = 1e-3
    position_filter: tuple = (1.0,)
    feedback: str = "motor"

    def __post_init__(self):
        if self.kind not in CONTROLLER_KINDS:
            raise InputError("controller.kind", self.kind, "one of " + ", ".join(CONTROLLER_KINDS))
        if self.feedback not in ("motor", "table"):
            raise InputError("controller.feedback", self.feedback, "one of motor, table")
        p_p = self.kind == "p_p_cascade"
        for name in ("kp", "kv"):
            # bounded as u_gain is: a gain of 1e300 replayed to overflow; a P-P gain's sign is checked below, with
            # its zero (a negative one was told '>= 0.0', while 0 needs '> 0')
            object.__setattr__(self, name, _finite(f"controller.{name}", getattr(self, name), None if p_p else 0.0,
                                                   hi=MAX_GAIN))
            if p_p and getattr(self, name) <= 0.0:
                # Left out, a gain reads as 0: a P-P cascade without its position or velocity gain cannot
                # have produced a tracking run, and its replay would diagnose an open loop.
                raise InputError(f"controller.{name}", getattr(self, name),
                                 "a number > 0 (the P-P cascade's gain; required for kind p_p_cascade)")
        sat = self.saturation
        try:  # an integer of hundreds of digits overflows a float ('internal error: OverflowError')
            x = float(sat) if isinstance(sat, (int, float)) and not isinstance(sat, bool) else math.nan
        except OverflowError:
            x = math.nan
        if not x > 0:
            raise InputError("controller.saturation", sat, "a number > 0 (inf for none)")
        object.__setattr__(self, "saturation", x)
        object.__setattr__(self, "sample_time", _finite("controller.sample_time", self.sample_time, 0.0, True))
        taps = self.position_filter
        if isinstance(taps, (int, float)) and not isinstance(taps, bool):
            taps = (taps,)
        try:
            if isinstance(taps, (str, bytes, bool)) or any(isinstance(x, (str, bytes, bool)) for x in taps):
                raise TypeError  # a quoted '10' was read as the taps 1, 0 (its characters), true as 1
            taps = tuple(float(x) for x in taps)
        except (TypeError, ValueError, OverflowError):
            raise InputError("controller.position_filter", self.position_filter, "a list of numbers") from None
        if not taps or not all(math.isfinite(x) for x in taps) or abs(sum(taps) - 1.0) > 1e-9:
            raise InputError("controller.position_filter", self.position_filter, "a non-empty list summing to 1")
        gain = sum(abs(x) for x in taps)
        if len(taps) > MAX_TAPS or gain > MAX_TAP_GAIN:
            # each tap is a state of the replay (10000 taps replayed for hours), and taps of 1e300 and -1e300
            # summing to 1 passed and never finished replaying
            raise InputError("controller.position_filter", f"{len(taps)} taps, sum of |taps| {gain:.3g}",
                             f"at most {MAX_TAPS} taps whose magnitudes sum to at most {MAX_TAP_GAIN:g} (a drive's "
                             "position filter: EMPS 0.5, 0.5)")
        object.__setattr__(self, "position_filter", taps)

    @property
    def law(self):
        """The control law as one line of text."""
        if self.kind == "drakecreep":
            return "drakecreep cascade with params.controller"
        taps = " + ".join(f"{c:g} x[k-{i}]" if i else f"{c:g} x[k]" for i, c in enumerate(self.position_filter))
        return (f"u = clip(kp*kv*(x_ref - x) - kv*dx, +-{self.saturation:g}), dx = first difference of "
                f"({taps}) over {self.sample_time:g} s")

    def to_dict(self):
        """YAML-ready mapping (without the P-P law's fields for kind ``drakecreep``)."""
        d = dataclasses.asdict(self)
        if self.kind != "p_p_cascade":
            return {k: v for k, v in d.items() if k not in _P_P_FIELDS}
        d["position_filter"] = list(self.position_filter)
        if math.isinf(self.saturation):
            d["saturation"] = ".inf"
        return d

    @classmethod
    def from_dict(cls, data):
        """Validated instance from a YAML mapping (unknown keys are errors)."""
        if not isinstance(data, dict):
            raise InputError("controller", data, "a mapping of " + ", ".join(f.name for f in dataclasses.fields(cls)))
        names = {f.name for f in dataclasses.fields(cls)}
        for key in data:
            if key not in names:
                raise InputError.unknown_field(f"controller.{key}", names)
        data = dict(data)
        if data.get("saturation") in (".inf", "inf", "none", None) and "saturation" in data:
            data["saturation"] = math.inf
        if data.get("kind", cls.kind) == "p_p_cascade":
            for name in ("kp", "kv"):
                if name not in data:
                    raise InputError(f"controller.{name}", "nothing (the key is missing)",
                                     "a number > 0 (the P-P cascade's gain; required for kind p_p_cascade)")
        else:
            # the P-P law's fields mean nothing for the project's cascade, whose gains are the params file's: a kp
            # given here was ignored without a word (the defaults, which to_dict of an older version wrote, pass)
            made = cls(**data)
            for name in _P_P_FIELDS:
                if name in data and getattr(made, name) != getattr(cls, name):
                    raise InputError(f"controller.{name}", data[name],
                                     f"nothing for kind {made.kind}: its gains and periods are the params file's "
                                     "controller group (kp, kv, saturation and position_filter are the P-P law's)")
            return made
        return cls(**data)


@dataclass(frozen=True)
class SensorMeta:
    """Sensor resolutions of the run [m per count at the table]; 0 means unknown or ideal."""

    encoder_resolution: float = 0.0
    scale_resolution: float = 0.0

    def __post_init__(self):
        for f in dataclasses.fields(self):
            object.__setattr__(self, f.name, _finite(f"sensors.{f.name}", getattr(self, f.name), 0.0))


@dataclass(frozen=True)
class MeasuredMeta:
    """Metadata of a measured file (shared by its runs).

    Parameters
    ----------
    u_units : str
        Unit of ``u``: ``"N"``, ``"A"`` or ``"V"``.
    u_gain : float
        Axial force per unit of ``u`` [N/unit]; 1 for ``N``.
    params : drakecreep.params.DriveParams or None
        The drive parameters of the rig, if known.
    controller : ControllerMeta or None
        The controller actually used.
    sensors : SensorMeta
        Resolutions.
    source : str
        Where the data come from.
    notes : str
        Anything a reader must know (conventions, deviations from the documentation).
    """

    u_units: str
    u_gain: float
    params: object = None
    controller: ControllerMeta | None = None
    sensors: SensorMeta = field(default_factory=SensorMeta)
    source: str = ""
    notes: str = ""

    def __post_init__(self):
        if self.u_units not in U_UNITS:
            raise InputError("u_units", self.u_units, "one of " + ", ".join(U_UNITS))
        gain = _finite("u_gain", self.u_gain, 0.0, True)
        if not MIN_U_GAIN <= gain <= MAX_U_GAIN:  # 1e300 overflowed the identification (axis.damping = inf)
            raise InputError("u_gain", self.u_gain, f"a gain in [{MIN_U_GAIN:g}, {MAX_U_GAIN:g}] N per {self.u_units}")
        if self.u_units == "N" and gain != 1.0:
            raise InputError("u_gain", self.u_gain, "1 when u_units is N (u is already a force)")
        object.__setattr__(self, "u_gain", gain)


def _as_array(name, value, n=None):
    a = np.asarray(value, dtype=float)
    if a.ndim == 2 and 1 in a.shape:
        a = a.ravel()
    if a.ndim != 1:
        raise InputError(name, f"shape {a.shape}", "a 1-D array")
    if n is not None and a.size != n:
        raise InputError(name, f"length {a.size}", f"length {n}, the length of t")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise InputError(name, f"{a[bad[0]]} at sample {bad[0]} ({bad.size} non-finite)", "finite numbers")
    return a


def _check_time(t, rtol, where="t"):
    if t.size < 3:
        raise InputError(where, f"{t.size} samples", "at least 3 samples")
    dt = np.diff(t)
    bad = np.flatnonzero(dt <= 0)
    if bad.size:
        k = bad[0]
        raise InputError(where, f"t[{k + 1}] = {float(t[k + 1])!r} after t[{k}] = {float(t[k])!r}",
                         "strictly increasing time")
    step = float(np.median(dt))
    dev = np.abs(dt - step) / step
    k = int(np.argmax(dev))
    if dev[k] > rtol:
        raise InputError(where, f"step {float(dt[k])!r} s at sample {k} (median step {step!r} s)",
                         f"uniform sampling within a relative tolerance of {rtol:g}")
    return step


@dataclass(frozen=True)
class MeasuredRun:
    """One measured run: SI arrays of equal length, validated on construction.

    Parameters
    ----------
    t, x_ref, x_motor, u : numpy.ndarray
        Time [s], reference [m], motor encoder at the table [m], controller output [u_units].
    meta : MeasuredMeta
        Units and gain of ``u``, drive parameters, controller, sensors.
    x_table, f_ext : numpy.ndarray or None
        Linear scale [m] and external force [N], if measured.
    label : str
        Run label.
    dt_rtol : float
        Allowed relative deviation of a time step from the median step.
    """

    t: np.ndarray
    x_ref: np.ndarray
    x_motor: np.ndarray
    u: np.ndarray
    meta: MeasuredMeta
    x_table: np.ndarray | None = None
    f_ext: np.ndarray | None = None
    label: str = "run"
    dt_rtol: float = 1e-3

    def __post_init__(self):
        t = _as_array("t", self.t)
        object.__setattr__(self, "t", t)
        for name in ("x_ref", "x_motor", "u", "x_table", "f_ext"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, _as_array(name, value, t.size))
        if not isinstance(self.meta, MeasuredMeta):
            raise InputError("meta", type(self.meta).__name__, "a MeasuredMeta")
        _check_time(t, self.dt_rtol, f"t (run {self.label})")
        for name in ("x_ref", "x_motor", "x_table"):
            a = getattr(self, name)
            if a is None:
                continue
            speed = float(np.quantile(np.abs(np.diff(a)) / np.diff(t), 1.0 - _FAST_SHARE))
            if speed > MAX_SPEED:
                raise InputError(f"{name} (run {self.label})",
                                 f"speeds of {speed:.3g} m/s (the {1 - _FAST_SHARE:.0%} quantile)",
                                 f"speeds up to {MAX_SPEED:g} m/s, a feed axis's (is a unit wrong? millimetres "
                                 "labelled m, or milliseconds labelled us, move a thousand times too fast)")
        for name, gain in (("u", self.meta.u_gain), ("f_ext", 1.0)):
            a = getattr(self, name)
            if a is None:
                continue
            i = int(np.argmax(np.abs(a)))
            # the largest plausible force: MAX_LOAD_FORCE, the bound of every load force (1e6 N; feed drives push
            # with up to tens of kN). A larger sample is a unit error or a corrupt cell (one cell of 1e300 ran a
            # diagnosis to a mass of 1e301 kg; a u_gain of 1e6 N/V on the EMPS run, 1.5e6 N at its peak under the
            # former 1e7 N bound, to a 2.7e6 kg axis, exit 0)
            if abs(float(a[i])) * gain > MAX_LOAD_FORCE:
                raise InputError(f"{name} (run {self.label})", f"{float(a[i]):.3g} at sample {i + 1}",
                                 f"forces up to {MAX_LOAD_FORCE:g} N" + (" (u x u_gain)" if name == "u" else "")
                                 + " (is a unit wrong, or a cell corrupt?)")
        for name in _ARRAYS:
            a = getattr(self, name)
            if a is not None:
                a.setflags(write=False)

    @property
    def n(self):
        """Number of samples."""
        return self.t.size

    @property
    def dt(self):
        """Mean sample time [s]."""
        return float((self.t[-1] - self.t[0]) / (self.t.size - 1))

    @property
    def u_gain(self):
        """Axial force per unit of ``u`` [N/unit]."""
        return self.meta.u_gain

    @property
    def force(self):
        """Total axial drive force [N]: ``u_gain * u`` plus ``f_ext`` when present."""
        f = self.u_gain * self.u
        return f + self.f_ext if self.f_ext is not None else f

    def slice(self, start=None, stop=None):
        """A run restricted to samples ``start:stop`` (same metadata)."""
        sl = slice(start, stop)
        kw = {name: (None if getattr(self, name) is None else getattr(self, name)[sl]) for name in _ARRAYS}
        return MeasuredRun(meta=self.meta, label=self.label, dt_rtol=self.dt_rtol, **kw)


@dataclass(frozen=True)
class MeasuredData:
    """The runs of one file with their shared metadata."""

    runs: tuple
    meta: MeasuredMeta

    def __post_init__(self):
        runs = tuple(self.runs)
        if not runs:
            raise InputError("runs", 0, "at least one run")
        labels = [r.label for r in runs]
        if len(set(labels)) != len(labels):
            raise InputError("run", labels, "distinct run labels")
        object.__setattr__(self, "runs", runs)

    def __len__(self):
        return len(self.runs)

    def __iter__(self):
        return iter(self.runs)

    @property
    def labels(self):
        """Run labels in file order."""
        return tuple(r.label for r in self.runs)

    def run(self, label=None):
        """The run named ``label``; without a label, the only run."""
        if label is None:
            if len(self.runs) != 1:
                raise InputError("run", None, "a label, one of " + ", ".join(self.labels))
            return self.runs[0]
        for r in self.runs:
            if r.label == label:
                return r
        raise InputError("run", label, "one of " + ", ".join(self.labels))


# --------------------------------------------------------------------------- metadata YAML

def _named(prefix, build, *args, **kwargs):
    """``build(*args, **kwargs)``, its :class:`InputError` naming the file the field is in (``prefix`` + field): a
    diagnosis reads several files (runs, metadata, params, a scored file), so 'screw.lead: got -1.0' alone did not
    say which."""
    # an error that names the file already ('rig.yaml: got 'invalid YAML ...'') names it once
    return renaming(lambda field: field if prefix == f"{field}: " else f"{prefix}{field}", build, *args, **kwargs)


def _check_controller_and_params(where, raw, ctrl, params, units, gain):
    """Refuse metadata a diagnosis would ignore without a word: a params file beside a controller that does not
    replay it (the ``p_p_cascade`` law is the metadata's own; a params file gives it only the torque constant, for
    ``u_units: A`` without ``u_gain``), and a ``kind: drakecreep`` controller's ``feedback`` or ``sample_time`` that
    contradict the params file, whose controller is the one replayed (both were accepted and ignored)."""
    drakecreep = ctrl is not None and ctrl.kind == "drakecreep"
    if params is not None and not drakecreep and not (units == "A" and gain is None):
        raise InputError(f"{where}: params", "a params file",
                         "only with controller kind drakecreep, whose cascade it describes, or to derive u_gain from "
                         "u_units A (a p_p_cascade run replays the law of its metadata, not the params file's)")
    if not drakecreep or params is None or not isinstance(raw, dict):
        return
    g = params.controller
    if "feedback" in raw and ctrl.feedback != g.position_feedback:
        raise InputError(f"{where}: controller.feedback", ctrl.feedback,
                         f"the params file's controller.position_feedback ({g.position_feedback}), or left out: "
                         "kind drakecreep replays the params file's controller")
    if "sample_time" in raw and not math.isclose(ctrl.sample_time, g.position_period, rel_tol=1e-6):
        raise InputError(f"{where}: controller.sample_time", ctrl.sample_time,
                         f"the params file's controller.position_period ({g.position_period:g} s), or left out: "
                         "kind drakecreep replays the params file's controller")


def _meta_from_dict(data, meta_path):
    from drakecreep.files import resolve_reference
    from drakecreep.params import load_params, params_from_dict

    where = str(meta_path)
    if not isinstance(data, dict):
        raise InputError(where, f"a YAML {type(data).__name__}", "a YAML mapping with at least u_units and u_gain")  # not echoed
    known = {"u_units", "u_gain", "params", "controller", "sensors", "source", "notes", "file"}
    for key in data:
        if key not in known:
            raise InputError.unknown_field(f"{where}: {key}", known)
    if "u_units" not in data:
        raise InputError(f"{where}: u_units", None, "one of " + ", ".join(U_UNITS) + " (required)")
    params = data.get("params")
    if isinstance(params, str):
        # relative to the metadata file; a regular file only; its content is never echoed
        path = resolve_reference(params, meta_path, f"{where}: params")
        params = _named(f"{path}: ", load_params, path)
    elif isinstance(params, dict):
        if not params:  # 'params: {}' silently meant the default rig, not the user's
            raise InputError(f"{where}: params", "an empty mapping ({})",
                             "a parameter file path or a mapping of parameter groups")
        params = _named(f"{where}: params.", params_from_dict, params)
    elif params is not None:
        raise InputError(f"{where}: params", params, "a parameter file path or a mapping")
    units = data["u_units"]
    gain = data.get("u_gain")
    if gain is None:
        if units == "N":
            gain = 1.0
        elif units == "A" and params is not None:
            gain = params.motor.torque_constant * 2.0 * math.pi / params.screw.lead
        else:
            allowed = "a number > 0 [N per A] (or params to derive it)" if units == "A" else "a number > 0 [N per V]"
            raise InputError(f"{where}: u_gain", None, allowed)
    raw = data.get("controller")
    ctrl = _named(f"{where}: ", ControllerMeta.from_dict, raw) if raw is not None else None
    _check_controller_and_params(where, raw, ctrl, params, units, data.get("u_gain"))
    sensors = data.get("sensors") or {}
    if not isinstance(sensors, dict):
        raise InputError(f"{where}: sensors", sensors, "a mapping encoder_resolution, scale_resolution")
    try:
        sensors = _named(f"{where}: ", SensorMeta, **sensors)
    except TypeError:
        raise InputError(f"{where}: sensors", sensors, "keys encoder_resolution, scale_resolution") from None
    text = {}
    for key in ("source", "notes"):
        value = data.get(key)
        if isinstance(value, (dict, list)):  # it was kept as its Python repr ("{'rig': 'A'}") and saved so
            raise InputError(f"{where}: {key}", f"a YAML {'mapping' if isinstance(value, dict) else 'list'}",
                             "free text (a string; a YAML block scalar, '|', keeps several lines)")
        text[key] = "" if value is None else str(value)  # an empty 'notes:' was the text 'None'
    return _named(f"{where}: ", MeasuredMeta, u_units=units, u_gain=gain, params=params, controller=ctrl,
                  sensors=sensors, **text)


def _meta_to_dict(meta):
    from drakecreep.params import params_to_dict

    d = {"u_units": meta.u_units, "u_gain": meta.u_gain}
    if meta.params is not None:
        d["params"] = params_to_dict(meta.params)
    if meta.controller is not None:
        d["controller"] = meta.controller.to_dict()
    d["sensors"] = dataclasses.asdict(meta.sensors)
    if meta.source:
        d["source"] = meta.source
    if meta.notes:
        d["notes"] = meta.notes
    return d


# --------------------------------------------------------------------------- CSV

def _file_options(opts, meta_path):
    """The metadata's ``file:`` mapping (``columns``, ``units``, ``key``, ``separator``, ``decimal``) as keyword
    arguments of read_signals."""
    from drakecreep.gap.formats import DECIMALS, SEPARATORS

    if opts is None:
        return {}
    where = f"{meta_path}: file"
    if not isinstance(opts, dict) or set(opts) - {"columns", "units", "key", "separator", "decimal"}:
        raise InputError(where, opts, "a mapping with columns (signal: file column), units (signal: unit), key (HDF5), "
                                      "separator and decimal (CSV)")
    separator, decimal = opts.get("separator"), opts.get("decimal")
    if separator is not None and not (isinstance(separator, str) and separator in SEPARATORS):
        raise InputError(f"{where}.separator", separator, "one of ',', ';', 'tab'")
    if decimal is not None and not (isinstance(decimal, str) and decimal in DECIMALS):
        raise InputError(f"{where}.decimal", decimal, "'.' or ','")
    if separator is not None and SEPARATORS[separator] == decimal:
        raise InputError(f"{where}.decimal", decimal, "a mark other than the separator")
    for name in ("columns", "units"):
        value = opts.get(name)
        if value is not None and not (isinstance(value, dict) and all(isinstance(v, str) for v in value.values())):
            raise InputError(f"{where}.{name}", value, "a mapping of signal names to strings")
    if "run" in (opts.get("units") or {}):  # was ignored without a word
        raise InputError(f"{where}.units.run", opts["units"]["run"], "no unit: the run column holds labels")
    key = opts.get("key")
    if key is not None and not isinstance(key, str):
        raise InputError(f"{where}.key", key, "a string (the HDF5 table's key)")
    return dict(columns=opts.get("columns"), units=opts.get("units"), key=key,
                separator=None if separator is None else SEPARATORS[separator], decimal=decimal)


def load_measured(csv_path, meta_path=None, dt_rtol=1e-3):
    """Load measured runs from a CSV and its metadata YAML.

    Parameters
    ----------
    csv_path : str or pathlib.Path
        The data file: CSV (``#`` comment lines ignored), Parquet, HDF5 or MATLAB ``.mat``; column names
        with units in brackets (``t[ms]``, ``x_motor[mm]``) are converted to SI, and the metadata's
        ``file.columns`` / ``file.units`` map a file's own names (:mod:`drakecreep.gap.formats`,
        ``docs/measured_format.md``).
    meta_path : str or pathlib.Path, optional
        The metadata YAML; default: the CSV path with suffix ``.yaml`` (or ``.yml``).
    dt_rtol : float
        Allowed relative deviation of a time step from the median step of its run.

    Returns
    -------
    MeasuredData
        One run per label of the ``run`` column (file order), or a single run named after the file.

    Raises
    ------
    InputError
        Missing or unknown column, unknown unit, unknown ``u_units``, a non-number, NaN, non-monotonic or
        non-uniform time, missing metadata, a sensor resolution the positions contradict or a ``u`` that is
        zero throughout (:func:`check_recorded`).
    FileNotFoundError
        If the CSV does not exist.
    """
    from drakecreep.files import check_path_argument

    check_path_argument(csv_path, "csv_path")  # None ended in pathlib's TypeError
    if meta_path is not None:
        check_path_argument(meta_path, "meta_path")
    csv_path = Path(csv_path)
    if meta_path is None:
        candidates = [csv_path.with_suffix(".yaml"), csv_path.with_suffix(".yml")]
        meta_path = next((p for p in candidates if p.exists()), None)
        if meta_path is None:
            raise InputError("metadata", str(candidates[0]),
                             "a metadata YAML beside the CSV (or name it: diagnose --meta FILE)")
    from drakecreep.files import MAX_DATA_BYTES, check_input_file
    from drakecreep.params import load_yaml_file

    meta_path = Path(meta_path)
    meta_data = load_yaml_file(meta_path, str(meta_path), "a YAML mapping with at least u_units and u_gain")
    meta = _meta_from_dict(meta_data, meta_path)

    check_input_file(csv_path, str(csv_path), MAX_DATA_BYTES)  # a regular file of bounded size, before reading
    file_opts = meta_data.get("file") if isinstance(meta_data, dict) else None
    signals = read_signals(csv_path, meta.u_units, **_file_options(file_opts, meta_path))
    unknown = [name for name in signals if name not in COLUMNS]
    if unknown:
        raise InputError(f"{csv_path}: header", unknown[0],
                         "columns among " + ", ".join(COLUMNS) + " (or map the file's names in file.columns)")
    missing = [c for c, (_, req) in COLUMNS.items() if req and c not in signals]
    if missing:
        if isinstance(file_opts, dict) and file_opts.get("columns"):  # the header's names are not read then
            raise InputError(f"{meta_path}: file.columns", ", ".join(signals),
                             "a mapping that names the columns of " + ", ".join(missing) + " as well (with "
                             "file.columns every signal is read from the column it names, none by the header)")
        raise InputError(f"{csv_path}: header", ",".join(signals), "the columns " + ", ".join(missing) + " as well")
    n_rows = len(next(iter(signals.values())))
    if n_rows < 1:
        raise InputError(str(csv_path), "no data rows", "at least 3 rows")
    arrays = {}
    for name, values in signals.items():
        if name == "run":
            continue
        arrays[name] = values
        bad = np.flatnonzero(~np.isfinite(values))  # an inf is named by its data row too, as a NaN is
        if bad.size:
            first = "NaN" if np.isnan(values[bad[0]]) else f"{values[bad[0]]:g}"
            raise InputError(f"{csv_path}: column {name}",
                             f"{first} at data row {bad[0] + 1} ({bad.size} NaN, inf or empty)", "finite numbers")
    cols = {"run": signals["run"]} if "run" in signals else {}
    if "run" in cols:
        labels = np.array(cols["run"], dtype=object)
        blank = [i for i, lab in enumerate(labels.tolist())
                 if lab is None or (isinstance(lab, float) and math.isnan(lab))
                 or str(lab).strip().lower() in ("", "nan", "none", "na", "<na>")]
        if blank:  # (a NaN label equals no label: its rows would belong to no run)
            raise InputError(f"{csv_path}: column run", f"no label at data row {blank[0] + 1} ({len(blank)} rows)",
                             "a run label (text or a number) in every row")
        order = list(dict.fromkeys(labels.tolist()))
        groups = [(lab, np.flatnonzero(labels == lab)) for lab in order]
        for lab, idx in groups:  # a run's rows in two blocks would read as one run with a jump in time
            if idx[-1] - idx[0] + 1 != idx.size:
                gap = int(np.flatnonzero(np.diff(idx) > 1)[0])
                raise InputError(f"{csv_path}: column run", f"{lab}: data rows {idx[0] + 1}-{idx[gap] + 1} and "
                                 f"again from {idx[gap + 1] + 1}", "each run's rows together, one block per label")
    else:
        groups = [(csv_path.stem, np.arange(n_rows))]
    runs = []
    for label, idx in groups:
        kw = {name: (arrays[name][idx] if name in arrays else None) for name in _ARRAYS}
        try:
            runs.append(MeasuredRun(meta=meta, label=str(label), dt_rtol=dt_rtol, **kw))
            check_recorded(runs[-1])
        except InputError as err:
            raise err.renamed(f"{csv_path}: {err.field}") from None
    return MeasuredData(runs=tuple(runs), meta=meta)


def check_recorded(run):
    """Raise :class:`InputError` where a measured run contradicts its metadata or cannot be diagnosed.

    * A position that a counting sensor recorded moves by whole counts: when more than 2 % of the non-zero
      steps of ``x_motor`` (``x_table``) are shorter than half the declared ``sensors.encoder_resolution``
      (``scale_resolution``), the resolution is in the wrong unit (5e-5 for a 50 nm count: millimetres written
      as metres), or not the one the positions were recorded at; the replay would count with it.
    * A drive command ``u`` that is zero, or one value, throughout gives the fit nothing to match.
    * A P-P cascade clips its output at ``controller.saturation``: a recorded ``|u|`` beyond twice it contradicts it.
    * A closed loop follows its reference and the table its motor: a travel of ``x_motor`` (``x_table``) more than
      100 times ``x_ref``'s (``x_motor``'s) or less than a hundredth of it has a unit wrong on one of them.
    * A P-P cascade's declared ``kp`` or ``kv`` more than ten times off the gain the recorded ``u`` follows
      (:func:`controller_gains`) is in the wrong unit, or not the controller that ran.

    Only measured files are checked: simulated positions (replays, instruments) are not counted.
    """
    sensors = run.meta.sensors
    for column, field_name in (("x_motor", "encoder_resolution"), ("x_table", "scale_resolution")):
        a, res = getattr(run, column), getattr(sensors, field_name)
        if a is None or res <= 0.0:
            continue
        steps = np.abs(np.diff(a))
        steps = steps[steps > max(1e-12, 64 * np.finfo(float).eps * float(np.max(np.abs(a))))]  # not rounding
        if steps.size < 20:
            continue
        share = float(np.mean(steps < 0.5 * res))
        if share > _SUBCOUNT_SHARE:
            raise InputError(f"sensors.{field_name} (run {run.label})", res,
                             f"the count {column} was recorded with, in m at the load, or 0 for none: "
                             f"{share:.0%} of its non-zero steps are shorter than half of {res:g} m (the shortest "
                             f"{steps.min():.3g} m), so it moves by less than a count (a unit error?)")
    if not np.any(run.u):
        raise InputError(f"u (run {run.label})", "zero throughout", "the drive command the controller gave")
    peak = float(np.max(np.abs(run.u))) * run.meta.u_gain
    if peak < MIN_PEAK_FORCE:
        raise InputError(f"u (run {run.label})", f"a peak drive force u x u_gain of {peak:.3g} N",
                         f"at least {MIN_PEAK_FORCE:g} N (is the unit of u or u_gain wrong?)")
    ctrl = run.meta.controller
    if ctrl is not None and ctrl.kind == "p_p_cascade" and math.isfinite(ctrl.saturation):
        # the P-P cascade clips its output at the saturation, so a recorded u far beyond it contradicts it: a
        # saturation of 1e-300 replayed a drive that cannot push and ran a whole diagnosis on it (exit 0). Up to
        # twice it is let be: a command added after the clip passes it (EMPS validation pulses: 10.84 V at 10 V)
        i = int(np.argmax(np.abs(run.u)))
        if abs(float(run.u[i])) > _SATURATION_SLACK * ctrl.saturation:
            raise InputError(f"controller.saturation (run {run.label})", ctrl.saturation,
                             f"at least half the largest recorded |u|, {abs(float(run.u[i])):g} {run.meta.u_units} at "
                             f"data row {i + 1} of the run (the controller clips its output at its saturation)")
    if np.ptp(run.x_motor) == 0.0 and np.ptp(run.x_ref) > 10.0 * run.meta.sensors.encoder_resolution:
        # an encoder that reads nothing while the reference travels (unplugged, or the wrong column): the travel
        # check below compares travels that are not zero, and a whole diagnosis ran on a motor that never moved;
        # a reference of a few counts (a stick test) may leave a counting encoder where it was
        raise InputError(f"x_motor (run {run.label})", f"constant while x_ref travels {np.ptp(run.x_ref):.4g} m",
                         "the motor encoder's reading at the load (a closed loop follows its reference: an encoder "
                         "that reads one value throughout is unplugged, or the wrong column)")
    for column, against, what in (("x_motor", "x_ref", "the motor follows its reference"),
                                  ("x_table", "x_motor", "the table follows its motor")):
        a, b = getattr(run, column), getattr(run, against)
        if a is None or b is None or not np.ptp(a) > 0.0 or not np.ptp(b) > 0.0:
            continue
        ratio = float(np.ptp(a) / np.ptp(b))
        if not 1.0 / _TRAVEL_FACTOR <= ratio <= _TRAVEL_FACTOR:
            raise InputError(f"{column} (run {run.label})", f"a travel of {np.ptp(a):.4g} m against {against}'s "
                             f"{np.ptp(b):.4g} m", f"a travel within a factor of {_TRAVEL_FACTOR:g} of {against}'s "
                             f"({what}; is the unit of one of them wrong?)")
    if ctrl is not None and ctrl.kind == "p_p_cascade":
        if not 1.0 / _SAMPLE_TIME_FACTOR <= run.dt / ctrl.sample_time <= _SAMPLE_TIME_FACTOR:
            # decades apart: the time column in another unit, which the gain fit below blamed on kv (a small
            # mismatch is the replay's to refuse, run by run: drake_replay.check_replayable)
            raise InputError(f"controller.sample_time (run {run.label})", ctrl.sample_time,
                             f"the run's sample time {run.dt:g} s, or a whole fraction or multiple of it within a "
                             f"factor of {_SAMPLE_TIME_FACTOR:g} (is the unit of t wrong?)")
        # a log taken several times a tick is fitted at its ticks (its u is held between them)
        fitted = controller_gains(on_controller_ticks(run))
        if fitted is not None:
            kp, kv, lag, misfit = fitted
            for name, got, follows in (("kv", ctrl.kv, kv), ("kp", ctrl.kp, kp)):
                if not 1.0 / _GAIN_FACTOR <= follows / got <= _GAIN_FACTOR:
                    raise InputError(
                        f"controller.{name} (run {run.label})", got,
                        f"the gain the recorded u follows, within a factor of {_GAIN_FACTOR:g}: the P-P law fitted to "
                        f"its unsaturated samples has kp = {kp:.4g} 1/s, kv = {kv:.4g} {run.meta.u_units} per m/s "
                        f"(delay {lag} samples; it reproduces u within {100 * misfit:.1f} % RMS); is a unit wrong?")
    if run.x_table is not None and np.ptp(run.x_table) == 0.0 and np.ptp(run.x_motor) > 0.0:
        # a scale that reads nothing while the motor moves (unplugged, or the wrong column): every replay error
        # relative to it was a division by zero ('y: got all zero')
        raise InputError(f"x_table (run {run.label})", "constant while x_motor moves",
                         "the linear scale's reading of the table, or no x_table column (a motion within one count "
                         "of the scale cannot be scored against it)")
    if np.ptp(run.u) == 0.0:
        # a closed loop moves its command (a u of 1.0 in every row diagnosed to NaN errors, exit 0, and an
        # inverse-dynamics mass of 5e-15 kg written to augmented_model.yaml)
        raise InputError(f"u (run {run.label})", f"constant at {float(run.u[0]):g} {run.meta.u_units} throughout",
                         "the drive command the controller gave (a closed loop moves it)")


def controller_ticks(run):
    """Controller ticks per logged sample of a ``p_p_cascade`` run (1 for any other kind, or none).

    A drive often logs its trace every few ticks of its position loop (a 1 ms loop logged every 4 ms). The replay
    runs the controller on its own tick (:func:`at_controller_rate`) and compares the logged samples.

    Raises
    ------
    InputError
        When the run's sample time is not a whole number of ``controller.sample_time`` (within 1e-6): a log taken
        several times a tick is cut to its ticks first (:func:`on_controller_ticks`), any other ratio is refused.
    """
    ctrl = run.meta.controller
    if ctrl is None or ctrl.kind != "p_p_cascade":
        return 1
    m = _whole_ratio(run.dt, ctrl.sample_time)
    if m is None:
        if _samples_per_tick(run) > 1:
            raise InputError(f"controller.sample_time (run {run.label})", ctrl.sample_time,
                             f"the run's sample time {run.dt:g} s or a whole fraction of it here: a log taken "
                             "several times a tick goes through on_controller_ticks first (load_runs does)")
        raise InputError(f"controller.sample_time (run {run.label})", ctrl.sample_time,
                         f"the run's sample time {run.dt:g} s, a whole fraction of it (the log taken every few "
                         "controller ticks) or a whole multiple of it (the log taken several times a tick)")
    return m


def _samples_per_tick(run):
    """Logged samples per controller tick of a ``p_p_cascade`` run logged several times a tick (``sample_time`` a
    whole multiple ``k >= 2`` of its sample time, within 1e-6); 1 otherwise."""
    ctrl = run.meta.controller
    if ctrl is None or ctrl.kind != "p_p_cascade":
        return 1
    return _whole_ratio(ctrl.sample_time, run.dt) or 1


def _whole_ratio(a, b):
    """``a / b`` when it is a whole number >= 1 within 1e-6 of ``a``, else None."""
    n = int(round(a / b))
    return n if n >= 1 and abs(a - n * b) <= 1e-6 * a else None


#: Least share of the changes of ``u`` (its total variation) that :func:`on_controller_ticks` asks to fall on one
#: phase of the controller's ticks: a command computed at each tick and held changes there alone
TICK_SHARE = 0.9


def on_controller_ticks(run):
    """A ``p_p_cascade`` run logged several times per controller tick, at its ticks: every ``k``-th sample.

    ``controller.sample_time`` is ``k`` times the run's sample time (``k >= 2``); the ticks fall where the held
    command ``u`` changes: of the ``k`` phases, the one that holds most of ``u``'s changes, at least
    :data:`TICK_SHARE` of them. The samples before the first tick are dropped, and the run keeps its label. A run
    logged every tick or every few is returned as it is (:func:`controller_ticks`).

    Raises
    ------
    InputError
        When ``u`` changes between ticks as much as at them (a current, not the controller's held command: where
        the ticks fall cannot be told), or when fewer than two ticks are logged.
    """
    k = _samples_per_tick(run)
    if k == 1:
        return run
    du = np.abs(np.diff(np.asarray(run.u, float)))  # du[i - 1]: the change at sample i
    share = np.array([du[(np.arange(du.size) + 1) % k == o].sum() for o in range(k)])
    total = float(share.sum())
    o = int(np.argmax(share))
    if not total > 0 or share[o] < TICK_SHARE * total:
        raise InputError(f"u (run {run.label})", f"{100 * share[o] / total if total > 0 else 0:.0f} % of its "
                         f"changes on one of the {k} samples of a controller tick",
                         f"a command held between ticks, changing on one phase (at least {100 * TICK_SHARE:.0f} %): "
                         "a log taken several times a tick is cut to the ticks where u changes (or is "
                         f"controller.sample_time, {run.meta.controller.sample_time:g} s, wrong?)")
    picked = run.slice(o, None)
    if (picked.n + k - 1) // k < 2:
        raise InputError(f"run {run.label}", f"{run.n} samples", "at least two controller ticks")
    kept = {name: None if getattr(picked, name) is None else getattr(picked, name)[::k] for name in _ARRAYS}
    return MeasuredRun(meta=run.meta, label=run.label, dt_rtol=run.dt_rtol, **kept)


def at_controller_rate(run):
    """The run on its controller's tick: ``run`` itself when it is logged every tick (:func:`controller_ticks`).

    Logged every ``m`` ticks, the ticks between two samples take the reference and the positions linear between
    them (the first-order hold the replay puts on the reference anyway) and ``u`` and ``f_ext`` held; the result
    has ``(n - 1) m + 1`` samples on a uniform clock, sample ``k m`` at the run's sample ``k``, and its controller's
    ``sample_time`` is the run's sample time over ``m``. Only the reference, ``f_ext`` and the first samples (the
    initial state) are read by a replay; its result is taken back at every ``m``-th tick.
    """
    m = controller_ticks(run)
    if m == 1:
        return run
    n = (run.n - 1) * m + 1
    at = np.arange(n) / m
    logged = np.arange(run.n)

    def linear(a):
        return None if a is None else np.interp(at, logged, a)

    def held(a):
        return None if a is None else np.repeat(a, m)[:n]

    ctrl = dataclasses.replace(run.meta.controller, sample_time=run.dt / m)
    return MeasuredRun(t=run.t[0] + np.arange(n) * (run.dt / m), x_ref=linear(run.x_ref), x_motor=linear(run.x_motor),
                       x_table=linear(run.x_table), u=held(run.u), f_ext=held(run.f_ext),
                       meta=dataclasses.replace(run.meta, controller=ctrl), label=run.label, dt_rtol=run.dt_rtol)


def controller_gains(run):
    """The P-P cascade's gains that the recorded ``u`` of ``run`` follows: a least-squares fit of the declared law
    (its position filter and feedback, :class:`ControllerMeta`) to the unsaturated samples.

    ``u[k] = kp kv (x_ref - x)[k - d] - kv dx[k - d]`` is fitted for each delay ``d`` of 0 to :data:`_MAX_LAG`
    samples, and the best delay's gains are returned. An independent reading of the controller from the data, for
    :func:`check_recorded` to hold the declared gains against (a unit error puts decades between them).

    Parameters
    ----------
    run : MeasuredRun
        A run whose metadata declares a ``p_p_cascade`` controller.

    Returns
    -------
    tuple or None
        ``(kp [1/s], kv [unit of u per m/s], delay [samples], misfit)``, ``misfit`` the fit's RMS residual over the
        RMS of ``u``; None when the run says nothing about them: fewer than 50 unsaturated samples, a fit that
        leaves more than :data:`_LAW_FIT` of ``u`` (not the P-P form), or gains that are not both positive.
    """
    ctrl = run.meta.controller
    x = run.x_motor if ctrl.feedback == "motor" or run.x_table is None else run.x_table
    taps = np.asarray(ctrl.position_filter, float)
    xf = np.convolve(x, taps)[: x.size] if abs(run.dt - ctrl.sample_time) <= 1e-3 * ctrl.sample_time else x
    dx = np.diff(xf) / run.dt
    e = (run.x_ref - x)[1:]
    u = np.asarray(run.u[1:], float)
    valid = np.abs(u) < 0.9 * ctrl.saturation
    valid[: taps.size] = False
    best = None
    for lag in range(_MAX_LAG + 1):
        rows = np.flatnonzero(valid[lag:]) + lag
        if rows.size < 50:
            continue
        a = np.c_[e[rows - lag], -dx[rows - lag]]
        sol, *_ = np.linalg.lstsq(a, u[rows], rcond=None)
        misfit = float(np.sqrt(np.mean((u[rows] - a @ sol) ** 2) / np.mean(u[rows] ** 2)))
        if best is None or misfit < best[3]:
            best = (sol[0], sol[1], lag, misfit)
    if best is None or not best[3] <= _LAW_FIT or not (best[0] > 0 and best[1] > 0):
        return None
    gain, kv, lag, misfit = best
    return float(gain / kv), float(kv), lag, misfit


def save_measured(data, csv_path, meta_path=None):
    """Write runs as CSV + metadata YAML; :func:`load_measured` reads them back identically.

    Parameters
    ----------
    data : MeasuredData or MeasuredRun
        What to write. Optional columns are written when every run has them.
    csv_path : str or pathlib.Path
        The CSV to write (floats with 17 significant digits: exact round trip).
    meta_path : str or pathlib.Path, optional
        Default: the CSV path with suffix ``.yaml``.

    Returns
    -------
    tuple of pathlib.Path
        ``(csv_path, meta_path)``.
    """
    if isinstance(data, MeasuredRun):
        data = MeasuredData(runs=(data,), meta=data.meta)
    csv_path = Path(csv_path)
    meta_path = Path(meta_path) if meta_path is not None else csv_path.with_suffix(".yaml")
    names = ["t", "x_ref", "x_motor"]
    if all(r.x_table is not None for r in data.runs):
        names.append("x_table")
    names.append("u")
    if all(r.f_ext is not None for r in data.runs):
        names.append("f_ext")
    multi = len(data.runs) > 1 or data.runs[0].label != csv_path.stem
    header = [f"{n}[{data.meta.u_units if n == 'u' else COLUMNS[n][0]}]" for n in names]
    if multi:
        header.append("run")
    def write_csv(tmp):
        with open(tmp, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(header)
            for r in data.runs:
                block = np.column_stack([getattr(r, n) for n in names])
                for row in block:
                    cells = [repr(float(x)) for x in row]
                    w.writerow(cells + [r.label] if multi else cells)

    write_atomic(csv_path, write_csv)  # a failure keeps the old file, never half of a new one
    write_text(meta_path, yaml.safe_dump(_meta_to_dict(data.meta), sort_keys=False))
    return csv_path, meta_path


# --------------------------------------------------------------------------- EMPS benchmark

#: The benchmark's files: role -> file name.
EMPS_FILES = {"estimation": "DATA_EMPS.mat", "validation": "DATA_EMPS_PULSES.mat"}

#: The EMPS controller as documented (data folder README): position P / velocity P cascade, 1 ms,
#: 2-tap mean on the position before the first difference, output saturated at 10 V.
EMPS_CONTROLLER = ControllerMeta(kind="p_p_cascade", kp=160.18, kv=243.45, saturation=10.0, sample_time=1e-3,
                                 position_filter=(0.5, 0.5), feedback="motor")

_EMPS_NOTES = (
    "x_ref = qg, x_motor = qm, u = controller output in V, force = gtau*u + f_ext. "
    "In DATA_EMPS_PULSES.mat the recorded vir jumps by +5/-5 at every edge of pulses_N and the documented "
    "law reproduces vir - pulses_N, not vir: the pulses were added to the drive command in volts "
    "(5 V = 5*gtau N), not applied as 5 N. So u = vir - pulses_N and f_ext = gtau*pulses_N [N], "
    "which keeps the total drive force gtau*vir. "
    "Encoder: 50000 counts/rev (documented); qm of DATA_EMPS.mat lies on a 50 nm grid, so one count is "
    "5e-8 m at the load (a 2.5 mm lead); qm of DATA_EMPS_PULSES.mat is not on that grid (stored processed)."
)

#: One encoder count at the load [m], read from DATA_EMPS.mat (every qm is a multiple of it).
EMPS_ENCODER_RESOLUTION = 5e-8


def emps_path(which="estimation"):
    """Path of an EMPS file: ``"estimation"`` (DATA_EMPS.mat) or ``"validation"`` (held-out test set)."""
    if which not in EMPS_FILES:
        raise InputError("which", which, "one of " + ", ".join(EMPS_FILES))
    return emps_data_dir() / EMPS_FILES[which]


def load_emps(path=None):
    """Load an EMPS benchmark ``.mat`` file as :class:`MeasuredData` (one run, labelled by the file stem).

    Parameters
    ----------
    path : str or pathlib.Path, optional
        A ``.mat`` file, or ``"estimation"`` / ``"validation"`` for the files of :func:`emps_data_dir`.
        Default: the estimation set.

    Returns
    -------
    MeasuredData
        ``x_ref = qg``, ``x_motor = qm`` [m]; ``u`` the controller output [V] with ``u_gain = gtau``
        [N/V]; ``f_ext = gtau * pulses_N`` [N] when the file has pulses (see ``meta.notes``: the pulses
        are volts added to the drive command, so ``u = vir - pulses_N``); the controller is
        :data:`EMPS_CONTROLLER` with the file's ``kp`` and ``kv``.
    """
    import scipy.io

    if path is None:
        path = "estimation"
    if isinstance(path, str) and path in EMPS_FILES:
        path = emps_path(path)
    from drakecreep.files import MAX_DATA_BYTES, check_input_file

    path = check_input_file(path, str(path), MAX_DATA_BYTES)
    try:
        mat = scipy.io.loadmat(str(path))
    except MemoryError:
        raise
    except Exception as err:  # noqa: BLE001 - empty, truncated, corrupt: OSError, IndexError, MatReadError, zlib.error...
        raise InputError(str(path), f"not a readable MATLAB file ({type(err).__name__})",
                         "a MATLAB .mat file (v4-v7.2) with the EMPS variables") from None
    missing = [k for k in ("t", "qm", "qg", "vir", "gtau", "kp", "kv") if k not in mat]
    if missing:
        raise InputError(f"{path}: variables", ",".join(sorted(k for k in mat if not k.startswith("__"))),
                         "the EMPS variables t, qm, qg, vir, gtau, kp, kv")

    def array(name):
        if np.iscomplexobj(mat[name]):  # as floats, the real part alone with a ComplexWarning (read_signals refuses it)
            raise InputError(f"{path}: {name}", f"complex numbers ({mat[name].dtype})", "real numbers")
        try:
            return np.asarray(mat[name], dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{path}: {name}", f"{type(mat[name]).__name__} {getattr(mat[name], 'dtype', '')}",
                             "a numeric array") from None

    def scalar(name):
        a = array(name)
        if a.size != 1:
            raise InputError(f"{path}: {name}", f"shape {a.shape}", "a scalar")
        return float(a.item())

    gtau = scalar("gtau")
    vir = array("vir").ravel()
    u, f_ext = vir, None
    if "pulses_N" in mat:
        pulses = array("pulses_N").ravel()
        if pulses.size != vir.size:
            raise InputError(f"{path}: pulses_N", f"length {pulses.size}", f"length {vir.size} like vir")
        u = vir - pulses
        f_ext = gtau * pulses
    try:  # the metadata's checks too ('u_gain: got -35.15', 'controller.kp: got 1e+300' named no file)
        controller = dataclasses.replace(EMPS_CONTROLLER, kp=scalar("kp"), kv=scalar("kv"))
        meta = MeasuredMeta(u_units="V", u_gain=gtau, controller=controller,
                            sensors=SensorMeta(encoder_resolution=EMPS_ENCODER_RESOLUTION, scale_resolution=0.0),
                            source=f"EMPS benchmark (Janot, Gautier, Brunot 2019): {path.name}",
                            notes=_EMPS_NOTES)
        run = MeasuredRun(t=array("t"), x_ref=array("qg"), x_motor=array("qm"), u=u, f_ext=f_ext, meta=meta,
                          label=path.stem)
        check_recorded(run)  # as a measured CSV's runs: a vir of zeros reached the fit as 'y: got 'all zero''
    except InputError as err:  # the file's variables, not the run's columns ('x_motor: got nan at sample 100')
        if err.field.startswith(str(path)):  # (a check that names the file already)
            raise
        name = _EMPS_VARIABLES.get(err.field.split(" ", 1)[0])
        raise err.renamed(f"{path}: {name}" if name else f"{path}: {err.field}") from None
    return MeasuredData(runs=(run,), meta=meta)


#: a run's columns and metadata fields -> the EMPS file's variables they are read from (``u`` is ``vir`` less the
#: pulses)
_EMPS_VARIABLES = {"t": "t", "x_ref": "qg", "x_motor": "qm", "u": "vir", "f_ext": "pulses_N", "u_gain": "gtau",
                   "controller.kp": "kp", "controller.kv": "kv"}


def check_split(train, test):
    """``(train, test)`` as lists of :class:`MeasuredRun`, each run in one of them once (:class:`InputError` naming
    ``train`` or ``test``).

    A run held out that is also a training run scores the fit on its own data, and one held out twice counts twice
    in the claim threshold's spread. Runs are the same when they are the same object, or carry the same label and
    the same samples (``t``, ``x_ref``, ``x_motor``, ``u``). A string, a number or None where a list of runs goes
    ended in ``AttributeError`` or ``TypeError``.
    """
    def runs_of(value, group):
        if isinstance(value, (str, bytes, MeasuredRun)) or not hasattr(value, "__iter__"):
            raise InputError(group, value, "a list of MeasuredRun (drakecreep.gap.measured.load_measured(...).runs)")
        runs = list(value)
        for r in runs:
            if not isinstance(r, MeasuredRun):
                raise InputError(group, r, "MeasuredRun items (drakecreep.gap.measured.load_measured(...).runs)")
        return runs

    def same(a, b):
        return a is b or (a.label == b.label and all(np.array_equal(getattr(a, k), getattr(b, k))
                                                     for k in ("t", "x_ref", "x_motor", "u")))

    train, test = runs_of(train, "train"), runs_of(test, "test")
    for group, runs in (("train", train), ("test", test)):
        for i, r in enumerate(runs):
            if any(same(r, q) for q in runs[:i]):
                raise InputError(group, f"run {r.label} twice", "each run once")
    for r in test:
        if any(same(r, q) for q in train):
            raise InputError("test", f"run {r.label}, a training run too",
                             "held-out runs that are not training runs (a held-out run scores the fit on data it "
                             "was not fitted on)")
    return train, test
