"""Typed, validated parameters of a ball-screw feed drive, loaded from and saved to YAML.

Every quantity is SI (m, kg, s, N, rad). Each field carries its unit, its allowed range and a
one-line meaning in ``metadata``; invalid values raise :class:`drakecreep.errors.InputError`
naming the dotted field, the value and the allowed range.

The reference preset (:func:`preset`, ``"paper"``) is ``presets/paper.yaml`` beside this module;
the values the seed paper gives are marked there with their table, every other value is an
assumption with its source.
"""

import dataclasses
import math
import numbers
import re
import sys
import typing
from dataclasses import dataclass, field
from importlib import resources

import yaml

from drakecreep.errors import InputError, short_repr
from drakecreep.files import MAX_INPUT_BYTES, check_path_argument, read_input_text, write_text

__all__ = [
    "MEASURED_AXIS_KIND",
    "check_params",
    "MotorParams",
    "ScrewParams",
    "NutParams",
    "TableParams",
    "LoadCase",
    "LoadParams",
    "FrictionParams",
    "ControllerParams",
    "SensorParams",
    "SimulationParams",
    "DisturbanceParams",
    "CompensationParams",
    "COMPENSATION_METHODS",
    "DriveParams",
    "PRESETS",
    "preset",
    "preset_text",
    "load_params",
    "load_yaml_file",
    "save_params",
    "params_from_dict",
    "params_to_dict",
    "with_value",
    "get_value",
    "field_unit",
    "field_range",
    "two_mass_effects",
]

#: most YAML aliases (``*name``) one file may use: parameter files need none; a few hundred is generous,
#: and the bound stops an "alias bomb" (nested aliases that expand to billions of items) at the parser
MAX_YAML_ALIASES = 100


class _Loader(yaml.SafeLoader):
    """SafeLoader that also reads ``9.38e6`` (no exponent sign) as a float, as users write it.

    It refuses what SafeLoader silently accepts: a key given twice in one mapping (SafeLoader keeps the
    last one) and more than :data:`MAX_YAML_ALIASES` aliases.
    """

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            self._aliases = getattr(self, "_aliases", 0) + 1
            if self._aliases > MAX_YAML_ALIASES:
                event = self.peek_event()
                raise yaml.composer.ComposerError(
                    None, None, f"more than {MAX_YAML_ALIASES} aliases (*name)", event.start_mark)
        return super().compose_node(parent, index)

    def construct_object(self, node, deep=False):
        # a scalar its constructor refuses ('rotor_inertia: 2001-13-45', '!!float abc', an integer of 5000 digits)
        # raised a bare ValueError: 'internal error: ValueError: month must be in 1..12', exit 1
        try:
            return super().construct_object(node, deep=deep)
        except (ValueError, OverflowError) as err:
            digits = sys.get_int_max_str_digits()
            if node.tag == "tag:yaml.org,2002:int" and len(str(node.value)) > digits:
                problem = f"an integer of more than {digits} digits"
            else:
                problem = f"a value it cannot read ({err})"
            raise yaml.constructor.ConstructorError(None, None, problem, node.start_mark) from None

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = self.construct_object(key_node, deep=True)
                try:
                    duplicate = key in seen
                    seen.add(key)
                except TypeError:
                    continue  # unhashable key: SafeLoader reports it
                if duplicate:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"duplicate key {short_repr(key, 40)}", key_node.start_mark)
        return super().construct_mapping(node, deep=deep)


# YAML 1.1 reads 1:30 as 90 (base 60), 050 as 40 (octal) and 0b11 as 3: a parameter file's "mass: 1:30" loaded as
# 90 kg without a word. Here integers are decimal (or 0x hex) and floats have no base-60 form; the rest stays text,
# which the fields refuse by name.
_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag not in ("tag:yaml.org,2002:int", "tag:yaml.org,2002:float")]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:int",
    re.compile(r"^(?:[-+]?(?:0|[1-9][0-9_]*)|[-+]?0x[0-9a-fA-F_]+)$"),
    list("-+0123456789"),
)
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(
        r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
        |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
        |[-+]?\.[0-9_]+(?:[eE][-+]?[0-9]+)?
        |[-+]?\.(?:inf|Inf|INF)
        |\.(?:nan|NaN|NAN))$""",
        re.X,
    ),
    list("-+0123456789."),
)


def _yaml_load(text):
    return yaml.load(text, Loader=_Loader)


def load_yaml_file(path, field=None, what="a YAML mapping", max_bytes=MAX_INPUT_BYTES):
    """Read a user's YAML file with the hardened loader; every failure is an :class:`InputError`.

    The file must be a regular UTF-8 file of at most ``max_bytes`` (:func:`drakecreep.files.read_input_text`);
    duplicate keys and alias bombs are refused; an empty or comment-only file is refused (it would silently
    mean "all defaults"). Messages name the file and the line, never the content.

    Parameters
    ----------
    path : path-like
    field : str, optional
        Name for messages (default: the path).
    what : str
        What the file should hold, for messages.

    Returns
    -------
    object
        The loaded document (not None).
    """
    field = field or str(path)
    text = read_input_text(path, field, max_bytes)
    try:
        data = _yaml_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark is not None else ""
        problem = getattr(err, "problem", None) or "syntax error"
        raise InputError(field, f"invalid YAML{where}: {str(problem)[:80]}", what) from None
    except RecursionError:
        raise InputError(field, "YAML nested too deeply", what) from None
    if data is None:
        raise InputError(field, "empty (no values, only comments or blank lines)", what)
    if data == {}:  # as empty as no file: a parameter file '{}' silently meant "all defaults"
        raise InputError(field, "an empty mapping ({})", what)
    return data


INTEGRATORS = ("runge_kutta2", "runge_kutta3", "runge_kutta5", "bogacki_shampine3", "radau3", "implicit_euler")


def _q(default, unit, lo=None, hi=None, *, lo_open=False, choices=None, doc=""):
    """A field with its unit, allowed range (closed unless ``lo_open``) or choices, and meaning."""
    return field(
        default=default,
        metadata=dict(unit=unit, lo=lo, hi=hi, lo_open=lo_open, choices=choices, doc=doc),
    )


def _allowed(meta, integer=False):
    """What a field takes, in words: its choices, or a number (an integer for an int field: '-1' and '1.5' of one
    field were answered 'a finite number >= 0' and 'an integer') in its range and unit."""
    if meta.get("choices"):
        return "one of " + ", ".join(str(c) for c in meta["choices"])
    lo, hi = meta.get("lo"), meta.get("hi")
    unit = f" {meta['unit']}" if meta.get("unit") not in (None, "", "-") else ""
    word = "an integer" if integer else "a finite number"
    if lo is not None and hi is not None:
        left = "(" if meta.get("lo_open") else "["
        return f"{word} in {left}{lo}, {hi}]{unit}"
    if lo is not None:
        return f"{word} {'>' if meta.get('lo_open') else '>='} {lo}{unit}"
    return f"{word}{unit}"


#: largest magnitude of a float field without a stated upper bound, in its SI unit: 1e8 times the largest
#: real quantity of a feed drive (Young's modulus, ~2e11 Pa), so "rigid" idealisations (a 2e19 Pa shaft)
#: stay possible, while products and squares of fields stay far from float overflow (1e300 kg gave
#: nonsense or runs that never end)
ABSURD = 1e20
#: smallest stiffness of an element of the axial chain [N/m] (bearing, shaft E A / length, nut, a seat joint that is
#: not rigid): 7-8 decades below a real one's (9.4e6 to 1.2e8 N/m on the paper's rig); a smaller one underflows the
#: chain's series sums (1/k, k^2) to a division by 0 ('internal error: ZeroDivisionError' at 1e-300 N/m)
MIN_STIFFNESS = 1.0


def _check_stiffness(name, value, off=False):
    """An element of the axial chain at least :data:`MIN_STIFFNESS` (or 0 where ``off`` says 0 means rigid)."""
    if value < MIN_STIFFNESS and not (off and value == 0.0):
        raise InputError(name, value, ("0 (rigid, off) or " if off else "") + f"a stiffness of at least "
                         f"{MIN_STIFFNESS:g} N/m (smaller underflows the stiffness chain in series)")


#: largest damping of an element of the axial chain [N s/m] (bearing, screw-nut pair, a seat joint), the upper end of
#: their ranges: four decades above a real one's (60 and 900 N s/m on the paper's rig) and 50x the critical damping of
#: a 1000 kg table on a 1e9 N/m chain. At 1e9-1e20 N s/m ``margins`` printed 'nan Hz' for the mode it overdamps and,
#: at 1e20, an open-loop unstable pole the rounding of its -c/m eigenvalue made
MAX_CHAIN_DAMPING = 1e8
#: largest lost motion of the screw-nut [m] (``nut.backlash``): a millimetre, fifty times a worn nut's 20 um
MAX_BACKLASH = 1e-3
#: largest force [N] of a load (a load case's fx, fy, fz, the constant force) and of a friction level (critical's
#: --fs, --fd): 1000 t, three decades above a heavy machine axis's thrust. A load case's fz of -1e12 N was
#: accepted, and simulate reported a table that cannot move (3e9 N of guide friction) as sliding without creep
MAX_LOAD_FORCE = 1e6
#: largest bristle damping [N s/m] (LuGre sigma1), the upper end of its range: three decades above the paper rig's
#: 2e3; 1e8-1e10 ran for minutes to a creep verdict on a table pushed backwards
MAX_BRISTLE_DAMPING = 1e6
#: largest viscous friction [N s/m], the upper end of its range: the pole map's damping axis reaches 5e6 N s/m (the
#: paper's D^2 curve), the paper rig has 200; 1e9 projected minutes of a run, 1e12 diverged at once
MAX_VISCOUS = 1e8
#: bristle stiffness range [N/m] (LuGre sigma0): from a chain element's least (:data:`MIN_STIFFNESS`) to three decades
#: above the paper rig's 1e8 (1e20 diverged at once; 1e-300 was accepted)
MAX_BRISTLE_STIFFNESS = 1e11
#: fewest counts per revolution of a motor encoder that is not ideal (0): a resolver or the coarsest incremental
#: encoder gives thousands; 1 count per turn ran past 90 s to a creep verdict of a table at -64 mm/s
MIN_ENCODER_COUNTS = 100
#: shortest period [m] of a lead error or a cogging along the travel: 10 um, forty times below the finest ball
#: passage of a 5 mm lead (Ph/12 = 417 um); 1e-12 m diverged at once, a 1e-15 m cogging projected 47 min
MIN_DISTURBANCE_PERIOD = 1e-5
#: largest gains of the PI cascade, the upper ends of their ranges: 3-4 decades above any feed drive's (kp 40 1/s,
#: kv 1.2e5 N s/m, ki 7.5e6 N/m on the paper's rig; a kv of 1e9 N s/m puts the velocity loop's crossover on a 300 kg
#: axis near 0.5 MHz, far beyond any sampled loop). Gains of 1e20 were accepted and ran as an unstable loop chattering
#: in saturation at every sample, minutes per simulated second on the leaf backend
MAX_POSITION_GAIN = 1e4
MAX_VELOCITY_GAIN = 1e9
MAX_VELOCITY_INTEGRAL_GAIN = 1e12
#: smallest Stribeck velocity [m/s], the lower end of its range: measured ones are 1e-5 to 1e-2 m/s; below 1 pm/s
#: the curve's (v / vs)^delta overflows a float at a feed axis's speeds (margins ended in 'internal error:
#: OverflowError' at 1e-300 m/s)
MIN_STRIBECK_VELOCITY = 1e-12
#: shortest velocity-loop sample time [s], the lower end of its range: digital drives sample at 5-100 kHz (1e-5 s
#: and up); below about 1e-16 s the sampled loop's model rounds exp(p T) to 1 (margins printed a phase margin of
#: -2.5 deg for 75.2 at 1e-20 s, and ended in 'internal error: ValueError' at 1e-300 s)
MIN_SAMPLE_PERIOD = 1e-9
#: shortest screw lead [m], the lower end of its range: a ball screw's lead is 1 to 50 mm; 0.1 mm is a decade below
#: the finest. At 1e-300 m the force limit 2 pi peak_torque / lead and the motor's speed feed 2 pi / lead left every
#: float: simulate reported a still table and creep, exit 0, and margins, tune and report blamed '--feed: got 1.0'
MIN_LEAD = 1e-4
#: lightest table [kg], the lower end of ``table.mass``'s range: a gram, four decades below a feed drive's table
#: (10-1000 kg; the paper's rig about 40 kg). At 1e-30 kg ``margins`` printed a damping ratio of 5e13 and negative
#: margins, ``critical`` a creep verdict, and ``simulate`` stopped after 1 ms with a divergence; 1e-3 kg runs
MIN_TABLE_MASS = 1e-3
#: shortest current-loop time constant [s] other than 0 (ideal): a microsecond, two decades below a PWM drive's
#: current loop (bandwidth 400-1600 Hz, 1e-4 to 4e-4 s). At 1e-15 s ``simulate`` diverged after 1 ms and
#: ``margins`` overflowed; 1e-6 s runs (34 s for 1.5 s simulated), 0 is the ideal loop
MIN_CURRENT_LOOP_TIME_CONSTANT = 1e-6
#: tightest integrator target accuracy [-] other than 0 (the friction law's default): near a double's rounding of
#: the scaled states; at 1e-300 ``simulate`` diverged after 1 ms (1e-12 runs, in about a minute per 1.5 s)
MIN_ACCURACY = 1e-12
#: most load cases a parameter set may define: a drive is tested under a handful (the paper's Table 7 has 3), and a
#: file of 100 000 cases was read, built and checked for 49 s before a command said anything
MAX_LOAD_CASES = 1000
#: largest integer field (encoder counts per revolution: 2^40 is beyond any encoder; float-exact)
MAX_INT = 2**40


def _check_items(name, value, meta):
    """A list field (``loads.cases``) holds at most ``meta["max_items"]`` items, checked before they are built."""
    most = meta.get("max_items")
    if most is not None and len(value) > most:
        raise InputError(name, f"{len(value)} {meta['items']}", f"at most {most} {meta['items']} ({meta['why']})")


class _Params:
    """Mixin: validates scalar fields against their metadata after construction."""

    def __post_init__(self):
        hints = typing.get_type_hints(type(self))
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            meta = f.metadata
            kind = hints[f.name]
            if dataclasses.is_dataclass(kind):
                if not isinstance(value, kind):  # DriveParams(motor="x") failed deep in Drake, or not at all
                    raise InputError(f.name, value, f"a {kind.__name__}")
                continue
            if typing.get_origin(kind) is tuple:
                (item,) = {a for a in typing.get_args(kind) if a is not Ellipsis}
                if isinstance(value, list):
                    value = tuple(value)
                    object.__setattr__(self, f.name, value)
                if not isinstance(value, tuple) or not all(isinstance(v, item) for v in value):
                    raise InputError(f.name, value, f"a tuple of {item.__name__}")
                _check_items(f.name, value, meta)
                continue
            if kind is bool:
                if not isinstance(value, bool):
                    raise InputError(f.name, value, "true or false")
                continue
            if kind is str:
                if not isinstance(value, str) or (meta.get("choices") and value not in meta["choices"]):
                    raise InputError(f.name, value, _allowed(meta))
                continue
            # numbers.Real and Integral: NumPy's scalars (np.float32, np.int64) are numbers too
            integer = kind is int
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise InputError(f.name, value, _allowed(meta, integer))
            if kind is int and not isinstance(value, int):
                if isinstance(value, numbers.Integral) or float(value).is_integer():
                    value = int(value)
                    object.__setattr__(self, f.name, value)
                else:
                    raise InputError(f.name, value, _allowed(meta, integer))
            if kind is float:
                try:
                    value = float(value)
                except OverflowError:  # an integer of hundreds of digits
                    raise InputError(f.name, value, _allowed(meta)) from None
                object.__setattr__(self, f.name, value)
            if kind is int and abs(value) > MAX_INT:
                raise InputError(f.name, value, f"an integer of magnitude <= {MAX_INT}")
            if not math.isfinite(value):
                raise InputError(f.name, value, _allowed(meta, integer))
            lo, hi = meta.get("lo"), meta.get("hi")
            if hi is None and abs(value) > ABSURD:
                raise InputError(f.name, value, _allowed(meta, integer) + f" of magnitude <= {ABSURD:g} (larger is no "
                                 "feed drive)")
            if lo is not None and (value < lo or (meta.get("lo_open") and value == lo)):
                raise InputError(f.name, value, _allowed(meta, integer))
            if hi is not None and value > hi:
                raise InputError(f.name, value, _allowed(meta, integer))
        self._check()

    def _check(self):
        """Cross-field checks; overridden where needed."""


# Upper bounds that are not physics limits but sanity limits, stated once: masses and inertias at most
# 100 t (table), 1 t (nut), 10 kg m^2 (rotor, coupling: servo motors of feed drives are below 0.1 kg m^2),
# torque 1e5 N m; any other unbounded field at most ABSURD in its SI unit.


@dataclass(frozen=True)
class MotorParams(_Params):
    """Servo motor: rotor, torque limit and the closed current loop seen as a first-order lag."""

    rotor_inertia: float = _q(1.3e-4, "kg m^2", 0.0, 10.0, lo_open=True, doc="rotor inertia")
    coupling_inertia: float = _q(2.0e-5, "kg m^2", 0.0, 10.0, doc="coupling inertia (motor side)")
    torque_constant: float = _q(0.9, "N m/A", 0.0, lo_open=True, doc="torque constant (reports current)")
    peak_torque: float = _q(7.1, "N m", 0.0, 1e5, lo_open=True, doc="torque limit of the drive")
    current_loop_time_constant: float = _q(
        2.0e-4, "s", 0.0, 0.1, doc="closed current loop as a first-order lag; 0 = ideal"
    )
    viscous_damping: float = _q(1.0e-4, "N m s/rad", 0.0, doc="motor and bearing viscous drag")
    saturation_torque: float = _q(
        0.0, "N m", 0.0, 1e5,
        doc="torque above which the drive's torque constant falls off: it applies tau / sqrt(1 + (tau / tau_s)^2) "
            "of a command tau (drakecreep.model.axis.saturating); 0 = a linear drive; assumption: 0, the paper "
            "gives none",
    )

    def _check(self):
        tau = self.current_loop_time_constant
        if 0.0 < tau < MIN_CURRENT_LOOP_TIME_CONSTANT:
            raise InputError("current_loop_time_constant", tau, f"0 (ideal) or a finite number in "
                             f"[{MIN_CURRENT_LOOP_TIME_CONSTANT:g}, 0.1] s (a current loop is 1e-4 s to 4e-4 s)")


@dataclass(frozen=True)
class ScrewParams(_Params):
    """Ball screw shaft and its thrust bearing: the axial stiffness chain up to the nut."""

    lead: float = _q(5.0e-3, "m", MIN_LEAD, 0.1, doc="lead Ph (Table 3)")
    nominal_diameter: float = _q(25.0e-3, "m", 0.0, 0.5, lo_open=True, doc="nominal diameter d0 (Table 3)")
    root_diameter: float = _q(21.8e-3, "m", 0.0, 0.5, lo_open=True, doc="root diameter (shaft section)")
    length: float = _q(0.6, "m", 0.0, 20.0, lo_open=True, doc="shaft length (rotating inertia)")
    youngs_modulus: float = _q(2.06e11, "Pa", 0.0, lo_open=True, doc="shaft steel")
    density: float = _q(7850.0, "kg/m^3", 0.0, lo_open=True, doc="shaft steel")
    mounting: str = _q("fixed-free", "-", choices=("fixed-free", "fixed-fixed"), doc="axial support")
    nut_start_distance: float = _q(
        0.1, "m", 0.0, lo_open=True, doc="thrust bearing to nut at table position 0"
    )
    bearing_stiffness: float = _q(9.38e6, "N/m", 0.0, lo_open=True, doc="bearing axial stiffness (Table 6)")
    bearing_damping: float = _q(60.61, "N s/m", 0.0, MAX_CHAIN_DAMPING, doc="bearing axial damping (Table 6)")
    chain_damping: str = _q(
        "viscous", "-", choices=("viscous", "loss_factor"),
        doc="bearing/nut damping as identified (viscous), or as hysteretic loss factors evaluated at damping_frequency",
    )
    damping_frequency: float = _q(
        73.5, "Hz", 0.0, 1e5, lo_open=True, doc="loss_factor: frequency of the mode the damping acts on (paper rig: 73.5)",
    )
    bearing_test_mass: float = _q(
        2.31, "kg", 0.0, lo_open=True, doc="loss_factor: mass of the bearing's hammer test (identification frequency)",
    )
    seat_joint_stiffness: float = _q(
        0.0, "N/m", 0.0, doc="fixed joints of the bearing seat in series with the bearing (0 = rigid, off)",
    )
    seat_joint_damping: float = _q(0.0, "N s/m", 0.0, MAX_CHAIN_DAMPING, doc="damping of the bearing seat joints")

    def _check(self):
        if self.root_diameter > self.nominal_diameter:
            raise InputError("root_diameter", self.root_diameter, f"<= nominal_diameter ({self.nominal_diameter} m)")
        if self.nut_start_distance >= self.length:
            raise InputError("nut_start_distance", self.nut_start_distance, f"< length ({self.length} m)")
        _check_stiffness("bearing_stiffness", self.bearing_stiffness)
        _check_stiffness("seat_joint_stiffness", self.seat_joint_stiffness, off=True)
        k = self.youngs_modulus * math.pi / 4.0 * self.root_diameter**2 / self.length
        if not k >= MIN_STIFFNESS:
            # root_diameter 1e-300 made the section pi d^2 / 4 zero, youngs_modulus 1e-300 the stiffness E A / a
            # near it: simulate, margins and report ended in 'internal error: ZeroDivisionError: float division by zero'
            field, value = (("youngs_modulus", self.youngs_modulus) if self.youngs_modulus < 1e9
                            else ("root_diameter", self.root_diameter))
            raise InputError(field, value, f"a shaft whose axial stiffness E pi d^2 / 4 / length is at least "
                             f"{MIN_STIFFNESS:g} N/m (youngs_modulus {self.youngs_modulus:g} Pa, root_diameter "
                             f"{self.root_diameter:g} m and length {self.length:g} m make it {k:.3g} N/m)")


@dataclass(frozen=True)
class NutParams(_Params):
    """Screw-nut pair: contact stiffness and damping, and its share of friction."""

    axial_stiffness: float = _q(51.6e6, "N/m", 0.0, lo_open=True, doc="screw-nut axial stiffness (Table 4)")
    axial_damping: float = _q(898.88, "N s/m", 0.0, MAX_CHAIN_DAMPING, doc="screw-nut axial damping (Table 4)")
    mass: float = _q(0.335, "kg", 0.0, 1e3, doc="nut mass (Table 3), lumped into the table")
    preload_torque: float = _q(
        0.09, "N m", 0.0, doc="preload drag torque of the nut (THK: 0.05 tan(lead angle)^-0.5 Fa0 Ph / 2 pi)"
    )
    load_friction_coefficient: float = _q(
        0.08, "-", 0.0, 1.0, doc="nut friction per N of axial load, 1/efficiency - 1 (0.05-0.11 for 0.9-0.95)"
    )
    seat_joint_stiffness: float = _q(
        0.0, "N/m", 0.0, doc="fixed joints of the nut seat (nut-seat, seat-table) in series with the nut (0 = rigid, off)",
    )
    seat_joint_damping: float = _q(0.0, "N s/m", 0.0, MAX_CHAIN_DAMPING, doc="damping of the nut seat joints")
    backlash: float = _q(
        0.0, "m", 0.0, MAX_BACKLASH,
        doc="axial lost motion of the screw-nut: no force through the chain within +-backlash/2 (0 = a preloaded "
            "nut; assumption: 4-20 um for a nut without preload or a worn one)",
    )

    def _check(self):
        _check_stiffness("axial_stiffness", self.axial_stiffness)
        _check_stiffness("seat_joint_stiffness", self.seat_joint_stiffness, off=True)


@dataclass(frozen=True)
class TableParams(_Params):
    """Table (workbench) on rolling guides."""

    mass: float = _q(40.0, "kg", MIN_TABLE_MASS, 1e5, doc="table, nut seat and sliders")
    guide_friction_coefficient: float = _q(0.003, "-", 0.0, 1.0, doc="rolling guides, per N of normal load")
    seal_force: float = _q(4.0, "N", 0.0, doc="seal and wiper drag of the slider blocks")
    mode_mass_share: float = _q(
        0.0, "-", 0.0, 0.9,
        doc="share of the moving mass on a structural mode of its own (a workpiece and fixture, the carriage's upper "
            "structure): 0 = a rigid table, off",
    )
    mode_frequency: float = _q(100.0, "Hz", 0.1, 1e4, doc="the structural mode's natural frequency on the table")
    mode_damping_ratio: float = _q(0.03, "-", 0.0, 10.0, doc="the structural mode's damping ratio (assumed 1-5 %)")


@dataclass(frozen=True)
class LoadCase(_Params):
    """External load on the table (air cylinders in the paper): X axial, Y lateral, Z vertical.

    Sign convention: ``fx`` > 0 opposes a feed in +x; ``fz`` > 0 pushes the table down onto its guides
    (adds to its weight), ``fz`` < 0 lifts it; ``fy`` either way. The guides' normal load is
    ``|m g + fz| + |fy|`` (:func:`drakecreep.model.nut_table.friction_split`).
    """

    fx: float = _q(0.0, "N", -MAX_LOAD_FORCE, MAX_LOAD_FORCE, doc="axial force opposing the feed")
    fy: float = _q(0.0, "N", -MAX_LOAD_FORCE, MAX_LOAD_FORCE, doc="lateral force on the guides")
    fz: float = _q(0.0, "N", -MAX_LOAD_FORCE, MAX_LOAD_FORCE,
                   doc="vertical force on the table, downwards positive (< 0 lifts)")


@dataclass(frozen=True)
class LoadParams(_Params):
    """The load cases (Table 7) and gravity."""

    cases: typing.Tuple[LoadCase, ...] = field(default_factory=tuple, metadata=dict(
        unit="-", max_items=MAX_LOAD_CASES, items="load cases",
        why="a drive is tested under a handful, the paper's Table 7 under 3; each is a run of its own"))
    gravity: float = _q(9.81, "m/s^2", 0.0, 100.0, doc="gravity (table weight on the guides)")
    constant_force: float = _q(
        0.0, "N", -MAX_LOAD_FORCE, MAX_LOAD_FORCE,
        doc="an axial force on the table in every load case, the unloaded one included, added to its fx (> 0 "
            "opposes a feed in +x): a drive's current offset, the weight on an inclined axis, a cable carrier's "
            "pull; assumption: 0, the paper gives none",
    )


@dataclass(frozen=True)
class FrictionParams(_Params):
    """Friction law and the shape of its curve; the levels come from the load case."""

    law: str = _q("lugre", "-", choices=("coulomb", "stribeck", "lugre", "gms"), doc="friction law")
    static_ratio: float = _q(1.5, "-", 1.0, 10.0, doc="breakaway / Coulomb force Fs/Fc")
    stribeck_velocity: float = _q(1.0e-4, "m/s", MIN_STRIBECK_VELOCITY, 1.0, doc="vs")
    stribeck_exponent: float = _q(2.0, "-", 0.2, 4.0, doc="delta in exp(-|v/vs|^delta)")
    viscous: float = _q(200.0, "N s/m", 0.0, MAX_VISCOUS, doc="viscous coefficient Fv")
    coulomb_asymmetry: float = _q(
        0.0, "-", -0.9, 0.9,
        doc="dry-friction levels (1 + a) times their mean moving +x, (1 - a) moving -x (seals, gravity on an "
            "inclined axis); assumption: 0, the paper gives none; the friction compensators model it symmetric",
    )
    viscous_asymmetry: float = _q(
        0.0, "-", -0.9, 0.9,
        doc="viscous coefficient (1 + a) Fv moving +x, (1 - a) Fv moving -x; assumption: 0, the paper gives none",
    )
    bristle_stiffness: float = _q(2.0e7, "N/m", MIN_STIFFNESS, MAX_BRISTLE_STIFFNESS, doc="LuGre sigma0")
    bristle_damping: float = _q(2.0e3, "N s/m", 0.0, MAX_BRISTLE_DAMPING, doc="LuGre sigma1")
    regularization_velocity: float = _q(
        1.0e-6, "m/s", 0.0, 1.0, lo_open=True, doc="tanh width replacing sign() in coulomb/stribeck"
    )
    nut_friction_on: str = _q(
        "screw", "-", choices=("table", "screw"),
        doc="nut friction lumped on the table, or as a drag torque on the screw's rotation",
    )
    gms_elements: int = _q(4, "-", 1, 50, doc="GMS: number of Maxwell-slip elements (sum of stiffnesses = sigma0)")
    gms_attraction: float = _q(
        1.0e4, "N/s", 0.0, lo_open=True, doc="GMS: attraction C of a sliding element to its Stribeck share",
    )
    position_map_0: float = _q(
        0.0, "-", -0.9, 0.9,
        doc="friction level along the travel: the table's friction is 1 + m(x) times the law's, m(x) the sum of "
            "position_map_k tanh((x - c_k) / w) over four steps spread evenly over [position_map_start, "
            "position_map_end] (drakecreep.model.axis.friction_map); assumption: 0, the paper gives none",
    )
    position_map_1: float = _q(0.0, "-", -0.9, 0.9, doc="second step of the friction level along the travel")
    position_map_2: float = _q(0.0, "-", -0.9, 0.9, doc="third step of the friction level along the travel")
    position_map_3: float = _q(0.0, "-", -0.9, 0.9, doc="fourth step of the friction level along the travel")
    position_map_start: float = _q(
        0.0, "m", -10.0, 10.0,
        doc="table position where the friction map's travel starts (the level is held beyond it)",
    )
    position_map_end: float = _q(
        1.0, "m", -10.0, 10.0, doc="table position where the friction map's travel ends (> position_map_start)",
    )
    time_drift: float = _q(
        0.0, "1/s", -1.0, 1.0,
        doc="the table's friction level changes by this share of itself per second from the start of a run, "
            "1 + time_drift t, floored at 0 (a warm-up: < 0 as the grease warms); assumption: 0, the paper gives none",
    )

    def _check(self):
        if not self.position_map_end > self.position_map_start:
            raise InputError("position_map_end", self.position_map_end,
                             f"a position > position_map_start ({self.position_map_start} m)")
        total = sum(abs(a) for a in self.position_map)
        if total >= 1.0:
            raise InputError("position_map_0..3", f"magnitudes summing to {total:.3g}",
                             "magnitudes summing to < 1 (the level 1 + m(x) must stay positive)")

    @property
    def position_map(self):
        """The four step amplitudes ``position_map_0`` .. ``_3`` of the friction level along the travel."""
        return (self.position_map_0, self.position_map_1, self.position_map_2, self.position_map_3)

    @property
    def has_position_map(self):
        """Whether any step of the friction level along the travel is switched on."""
        return any(a != 0.0 for a in self.position_map)


@dataclass(frozen=True)
class ControllerParams(_Params):
    """PI cascade: position P with velocity feedforward, velocity PI with anti-windup.

    Gains are on table-side linear quantities: the position loop maps m to m/s, the velocity loop
    maps m/s to an axial force (N) which the drive turns into torque through the lead.
    """

    position_gain: float = _q(40.0, "1/s", 0.0, MAX_POSITION_GAIN, doc="kp")
    velocity_feedforward: float = _q(1.0, "-", 0.0, 2.0, doc="share of the reference speed fed forward")
    velocity_gain: float = _q(1.2e5, "N s/m", 0.0, MAX_VELOCITY_GAIN, lo_open=True, doc="kv (proportional)")
    velocity_integral_gain: float = _q(7.5e6, "N/m", 0.0, MAX_VELOCITY_INTEGRAL_GAIN, doc="ki (integral)")
    anti_windup: bool = field(default=True, metadata=dict(unit="-", doc="stop integrating in saturation"))
    position_feedback: str = _q(
        "motor", "-", choices=("motor", "table"), doc="semi-closed (encoder) or closed loop (scale)"
    )
    sampled: bool = field(default=True, metadata=dict(unit="-", doc="discrete controller; false = continuous"))
    velocity_period: float = _q(2.5e-4, "s", MIN_SAMPLE_PERIOD, 0.1, doc="velocity loop sample time")
    position_period: float = _q(1.0e-3, "s", 0.0, 1.0, lo_open=True, doc="position loop sample time")
    computation_delay: float = _q(
        1.0, "samples", 0.0, 100.0,
        doc="sampled only: velocity samples from reading the encoder to applying the command (fractions allowed)",
    )

    def _check(self):
        ratio = self.position_period / self.velocity_period
        if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
            raise InputError(
                "position_period", self.position_period,
                f"an integer multiple (>= 1) of velocity_period ({self.velocity_period} s)",
            )

    @property
    def position_divider(self):
        """Velocity-loop samples per position-loop sample."""
        return int(round(self.position_period / self.velocity_period))


@dataclass(frozen=True)
class SensorParams(_Params):
    """Motor encoder and linear scale (grating); 0 means an ideal, unquantized sensor."""

    encoder_counts_per_rev: int = _q(2**23, "counts/rev", 0, doc="motor encoder resolution")
    scale_resolution: float = _q(50e-9, "m", 0.0, 1e-3, doc="linear scale resolution")
    scale_interpolation_error: float = _q(
        0.0, "m", 0.0, 1e-4, doc="amplitude of the scale's interpolation error, periodic in x with the signal period"
    )
    scale_signal_period: float = _q(20e-6, "m", 0.0, 1e-2, lo_open=True, doc="signal period of the scale's grating")
    speed_meter_period: float = _q(
        1e-3, "s", 0.0, 1.0, lo_open=True,
        doc="sample period of a speed measured by differencing the scale (studies.table_fluctuation)",
    )

    def _check(self):
        if 0 < self.encoder_counts_per_rev < MIN_ENCODER_COUNTS:
            raise InputError("encoder_counts_per_rev", self.encoder_counts_per_rev,
                             f"0 (ideal) or an integer >= {MIN_ENCODER_COUNTS} counts/rev (a resolver or the "
                             "coarsest incremental encoder gives thousands)")


@dataclass(frozen=True)
class SimulationParams(_Params):
    """Integrator, logging and the window over which metrics are taken."""

    integrator: str = _q("runge_kutta3", "-", choices=INTEGRATORS, doc="Drake integrator")
    accuracy: float = _q(
        0.0, "-", 0.0, 0.1,
        doc="integrator target accuracy (scaled states); 0 = the friction law's default (sim.simulation.ACCURACY_BY_LAW)",
    )
    max_step: float = _q(1e-3, "s", 0.0, 1.0, lo_open=True, doc="largest integrator step")
    log_period: float = _q(2.5e-4, "s", 0.0, 1.0, lo_open=True, doc="sample time of the recorded signals")
    acceleration_time: float = _q(0.05, "s", 0.0, 100.0, doc="reference ramps up to the feed in this time")
    steady_start: float = _q(1.0, "s", 0.0, doc="metrics are taken from this time to the end")
    stick_threshold: float = _q(
        0.2, "-", 0.0, 0.5, lo_open=True,
        doc="stuck when v < this x feed (above the regularized laws' creep while stuck, see sim.metrics.stick_slip; "
            "at most half the feed: at 1.0 a smooth run's ripple about the feed counted as stick-slip)",
    )
    backend: str = _q("compiled", "-", choices=("compiled", "leaf"), doc="symbolic fast path or leaf systems")
    convergence_check: bool = field(
        default=True, metadata=dict(unit="-", doc="rerun the start at 10x tighter accuracy and compare the verdict"),
    )
    convergence_window: float = _q(
        0.5, "s", 0.0, 3600.0, lo_open=True, doc="steady-window time compared by the convergence check"
    )
    convergence_tolerance: float = _q(
        0.1, "-", 0.0, 10.0, lo_open=True, doc="largest fluctuation change accepted by the check, x feed"
    )

    def _check(self):
        if 0.0 < self.accuracy < MIN_ACCURACY:
            raise InputError("accuracy", self.accuracy, f"0 (the friction law's default) or a finite number in "
                             f"[{MIN_ACCURACY:g}, 0.1]")
        if self.steady_start < self.acceleration_time:
            # metrics taken on the ramp measure the acceleration, not the feed: a creep verdict from them is wrong
            raise InputError("steady_start", self.steady_start, f">= acceleration_time ({self.acceleration_time:g} s): "
                             "the metrics window starts after the reference's ramp")


@dataclass(frozen=True)
class DisturbanceParams(_Params):
    """Periodic disturbances of a real rig that the base model leaves out; all amplitudes 0 = off.

    ``lead_error``: a kinematic error of the screw-nut pair, the nut advancing
    ``x + a sin(2 pi x / period + phase) + a2 sin(4 pi x / period + phase2)`` for a travel
    ``x = theta Ph / 2 pi`` (a lead-error harmonic and its second harmonic, ball-passage waviness); the motor
    encoder cannot see it. The error is fixed to the screw: ``phase`` and ``phase2`` are its phases at the screw
    position a measured run's ``x_motor`` counts from; a simulation starts there. The drive force of a lead
    error grows with the square of its order, so a second harmonic of a quarter of the fundamental's amplitude
    pushes the table as hard as the fundamental.
    ``load_ripple``: the axial load of the load case (the paper's air cylinders) pulsates as
    ``Fx (1 + r sin(2 pi f t + ripple_phase))``; ``force_ripple`` adds ``-A sin(2 pi f t + ripple_phase)`` to the
    push on the table.
    ``cogging``: a load torque on the motor fixed to its angle (a servo motor's cogging, a support bearing's
    defect), ``(Ph / 2 pi) [c sin(psi + phase) + c2 sin(2 psi + phase2)]`` with ``psi = 2 pi x / period`` for the
    motor's travel ``x = theta Ph / 2 pi``: ``c``, ``c2`` are its amplitudes at the table's scale (N), ``period``
    the lead over its order per motor revolution. Unlike the lead error the encoder sees its motion. See
    :mod:`drakecreep.model.disturbances`.
    """

    lead_error_amplitude: float = _q(0.0, "m", 0.0, 1e-3, doc="amplitude a of the kinematic lead error")
    lead_error_period: float = _q(
        5.0e-3 / 12.0, "m", MIN_DISTURBANCE_PERIOD, 0.1, doc="travel per cycle of the lead error"
    )
    lead_error_phase: float = _q(0.0, "rad", -2.0 * math.pi, 2.0 * math.pi,
                                 doc="phase of the lead error at the screw's position 0")
    lead_error_2_amplitude: float = _q(0.0, "m", 0.0, 1e-3,
                                       doc="amplitude a2 of the lead error's second harmonic (travel period "
                                           "lead_error_period / 2)")
    lead_error_2_phase: float = _q(0.0, "rad", -2.0 * math.pi, 2.0 * math.pi,
                                   doc="phase of the lead error's second harmonic at the screw's position 0")
    force_ripple: float = _q(0.0, "N", 0.0, 1e4, doc="amplitude A of a fixed-frequency force ripple on the table")
    load_ripple: float = _q(0.0, "-", 0.0, 1.0, doc="relative amplitude r of the axial load pulsation")
    ripple_frequency: float = _q(5.0, "Hz", 0.0, 1e4, lo_open=True, doc="frequency f of both ripples")
    ripple_phase: float = _q(0.0, "rad", -2.0 * math.pi, 2.0 * math.pi,
                             doc="phase of both ripples at t = 0, a simulation's start (a replayed run's first sample)")
    cogging_force: float = _q(0.0, "N", 0.0, 1e4, doc="amplitude c of a cogging torque on the motor, at the "
                                                       "table's scale (torque x 2 pi / lead)")
    cogging_period: float = _q(5.0e-3 / 6.0, "m", MIN_DISTURBANCE_PERIOD, 0.1,
                               doc="travel per cycle of the cogging: the lead over its order per motor revolution")
    cogging_phase: float = _q(0.0, "rad", -2.0 * math.pi, 2.0 * math.pi,
                              doc="phase of the cogging at the screw's position 0")
    cogging_2_force: float = _q(0.0, "N", 0.0, 1e4, doc="amplitude c2 of the cogging's second harmonic (travel period "
                                                         "cogging_period / 2)")
    cogging_2_phase: float = _q(0.0, "rad", -2.0 * math.pi, 2.0 * math.pi,
                                doc="phase of the cogging's second harmonic at the screw's position 0")

    def _check(self):
        slope = 2.0 * math.pi * (self.lead_error_amplitude + 2.0 * self.lead_error_2_amplitude) / self.lead_error_period
        if slope >= 1.0:
            # the nut's travel x + e(x) turns back where e' < -1: a 1 mm error at the 0.42 mm default period ran the
            # nut backwards, a creep verdict on a kinematics no screw has
            raise InputError("lead_error_amplitude", self.lead_error_amplitude,
                             f"a lead error whose slope 2 pi (a + 2 a2) / period stays below 1 (here {slope:.3g} at "
                             f"lead_error_period {self.lead_error_period:g} m): the nut's travel turns back beyond")

    @property
    def has_lead_error(self):
        """Whether either harmonic of the lead error is switched on."""
        return self.lead_error_amplitude > 0.0 or self.lead_error_2_amplitude > 0.0

    @property
    def has_cogging(self):
        """Whether either harmonic of the cogging is switched on."""
        return self.cogging_force > 0.0 or self.cogging_2_force > 0.0


#: friction compensation methods (:mod:`drakecreep.studies.compensation`)
COMPENSATION_METHODS = ("none", "static", "lugre", "dob", "dither")
#: named variants of a method for evaluations: label -> (method, compensation settings)
COMPENSATION_VARIANTS = {
    # the static model at the measured speed instead of the reference: model-based feedback rather
    # than feedforward (Armstrong-Helouvry, Dupont, Canudas de Wit, Automatica 30(7), 1994, sec. 6)
    "static-measured": ("static", {"velocity_blend": 1.0}),
}
#: the methods a compensation study compares by default, the baseline first
COMPENSATION_STUDY_METHODS = ("none", "static", "static-measured", "lugre", "dob", "dither")


@dataclass(frozen=True)
class CompensationParams(_Params):
    """Friction compensation added to the controller's torque command (:mod:`drakecreep.studies.compensation`).

    The compensator's friction model is the plant's nominal one (levels of the load case, shape of
    ``friction``) times the ``*_factor`` mismatch factors (1 = exact model).
    """

    method: str = _q("none", "-", choices=COMPENSATION_METHODS, doc="compensation method")
    coulomb_factor: float = _q(1.0, "-", 0.0, 10.0, doc="model Fc / plant Fc")
    static_factor: float = _q(1.0, "-", 0.0, 10.0, doc="model Fs / plant Fs")
    stribeck_velocity_factor: float = _q(1.0, "-", 0.0, 10.0, lo_open=True, doc="model vs / plant vs")
    viscous_factor: float = _q(1.0, "-", 0.0, 10.0, doc="model Fv / plant Fv")
    bristle_stiffness_factor: float = _q(1.0, "-", 0.0, 10.0, lo_open=True, doc="model sigma0 / plant sigma0")
    bristle_damping_factor: float = _q(1.0, "-", 0.0, 10.0, doc="model sigma1 / plant sigma1")
    inertia_factor: float = _q(1.0, "-", 0.0, 10.0, lo_open=True, doc="DOB nominal inertia / plant inertia")
    observer_gain: float = _q(0.0, "-", 0.0, 1e3, doc="LuGre observer correction k (dz/dt -= k (v - v_ref))")
    dob_bandwidth: float = _q(300.0, "rad/s", 0.0, 1e5, lo_open=True, doc="DOB Q-filter bandwidth")
    dither_amplitude: float = _q(0.5, "-", 0.0, 10.0, doc="dither force amplitude / model Fc")
    dither_frequency: float = _q(200.0, "Hz", 0.0, 1e4, lo_open=True, doc="dither frequency")
    velocity_blend: float = _q(
        0.0, "-", 0.0, 1.0, doc="static: share of the measured speed (0 = reference speed, feedforward)"
    )
    velocity_source: str = _q(
        "motor", "-", choices=("motor", "table"),
        doc="measured speed of static/lugre: motor encoder (semi-closed) or table speed (ideal linear scale)",
    )
    speed_source: str = _q(
        "encoder", "-", choices=("encoder", "ideal"),
        doc="sampled controller: compensators run at the velocity-loop rate on the backward difference of the "
            "counts, output held and delayed like the command (encoder), or continuously on the true speed (ideal)",
    )


@dataclass(frozen=True)
class DriveParams(_Params):
    """Everything that defines a feed drive and how it is simulated."""

    motor: MotorParams = field(default_factory=MotorParams)
    screw: ScrewParams = field(default_factory=ScrewParams)
    nut: NutParams = field(default_factory=NutParams)
    table: TableParams = field(default_factory=TableParams)
    loads: LoadParams = field(default_factory=LoadParams)
    friction: FrictionParams = field(default_factory=FrictionParams)
    controller: ControllerParams = field(default_factory=ControllerParams)
    sensors: SensorParams = field(default_factory=SensorParams)
    simulation: SimulationParams = field(default_factory=SimulationParams)
    disturbance: DisturbanceParams = field(default_factory=DisturbanceParams)
    compensation: CompensationParams = field(default_factory=CompensationParams)

    @property
    def load_cases_allowed(self):
        """What a load case number may be, as an error message says it."""
        n = len(self.loads.cases)
        if n == 0:
            return "0 (unloaded): these parameters define no load cases (loads.cases adds them)"
        return f"an integer in 0..{n} (0 = unloaded)"

    def load_case(self, number):
        """The :class:`LoadCase` numbered ``number`` (1-based); 0 means no external load. Its ``fx`` includes
        ``loads.constant_force``, so every model of the drive sees that force through this one method."""
        allowed = self.load_cases_allowed
        if isinstance(number, bool) or not isinstance(number, numbers.Integral):  # True was case 1
            raise InputError("load_case", number, allowed)
        number = int(number)  # np.int64 too
        if number == 0:
            case = LoadCase()
        elif not 1 <= number <= len(self.loads.cases):
            raise InputError("load_case", number, allowed)
        else:
            case = self.loads.cases[number - 1]
        if self.loads.constant_force == 0.0:
            return case
        return dataclasses.replace(case, fx=case.fx + self.loads.constant_force)


# --------------------------------------------------------------------------- YAML I/O

def _from_dict(cls, data, path):
    if not isinstance(data, dict):
        # the type, not the value: a file that is no parameter file (a path typo) is never echoed
        raise InputError(path or "params", f"a YAML {type(data).__name__}", f"a mapping of {cls.__name__} fields")
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}
    kwargs = {}
    for key, value in data.items():
        dotted = f"{path}.{key}" if path else str(key)
        if key not in names:
            raise InputError.unknown_field(dotted[:80], names)
        kind = hints[key]
        if dataclasses.is_dataclass(kind):
            kwargs[key] = _from_dict(kind, value, dotted)
        elif typing.get_origin(kind) is tuple:
            (item,) = {a for a in typing.get_args(kind) if a is not Ellipsis}
            if not isinstance(value, list):
                raise InputError(dotted, value, f"a list of {item.__name__} mappings")
            _check_items(dotted, value, {f.name: f for f in dataclasses.fields(cls)}[key].metadata)
            kwargs[key] = tuple(_from_dict(item, v, f"{dotted}[{i}]") for i, v in enumerate(value))
        else:
            kwargs[key] = value
    try:
        return cls(**kwargs)
    except InputError as err:
        raise err.renamed(f"{path}.{err.field}" if path else err.field) from None


def params_from_dict(data):
    """Build validated :class:`DriveParams` from a (YAML-loaded) mapping; missing fields take defaults."""
    return _from_dict(DriveParams, data if data is not None else {}, "")


def params_to_dict(params):
    """Plain nested dict (YAML/JSON-ready) of a parameter dataclass."""
    return dataclasses.asdict(params)


#: ``kind`` of the model file a ``p_p_cascade`` diagnosis writes (``augmented_model.yaml``,
#: :meth:`drakecreep.gap.drake_diagnosis.DrakeDiagnosis.save_model`): an axis of the replay model, not a drive
MEASURED_AXIS_KIND = "drakecreep.measured_axis"


def load_params(path):
    """Load and validate :class:`DriveParams` from a YAML file.

    Raises
    ------
    InputError
        For a YAML syntax error, a duplicate key, an empty file, a file that is not regular UTF-8 text,
        an unknown key, a wrong type or a value out of range.
    FileNotFoundError
        If ``path`` does not exist.
    """
    check_path_argument(path)  # None, a number or '' named as the path, not str(path)
    data = load_yaml_file(path, str(path), "a YAML mapping of parameter groups")
    if isinstance(data, dict) and "u_units" in data:
        # a measured run's metadata named as the params file (its own 'params:' pointing at itself, a --params slip)
        raise InputError(str(path), "a measured run's metadata file (it has u_units)",
                         "a drakecreep params file (parameter groups motor, screw, nut, table, friction, ...)")
    if isinstance(data, dict) and data.get("kind") == MEASURED_AXIS_KIND:
        raise InputError(f"{path}: kind", data["kind"],
                         "a drakecreep params file (parameter groups motor, screw, nut, table, friction, ...); this "
                         "file is the measured axis that drakecreep diagnose fitted to P-P cascade runs, read by "
                         "drakecreep.gap.drake_diagnosis.load_model")
    return params_from_dict(data)


def save_params(params, path):
    """Write ``params`` to ``path`` as YAML (SI units); :func:`load_params` reads it back identically."""
    check_params(params)
    check_path_argument(path)
    write_text(path, yaml.safe_dump(params_to_dict(params), sort_keys=False))  # atomically: all or the old file


PRESETS = ("paper", "paper_calibrated", "rigid_axis", "paper_catalogue")


def preset_text(name="paper"):
    """The commented YAML text of a preset (assumptions and their sources are in the comments)."""
    if name not in PRESETS:
        raise InputError("preset", name, "one of " + ", ".join(PRESETS))
    return resources.files("drakecreep").joinpath("presets", f"{name}.yaml").read_text()


def preset(name="paper"):
    """Validated :class:`DriveParams` of a named preset (``"paper"``: the seed paper's rig)."""
    data = _yaml_load(preset_text(name))
    try:
        return params_from_dict(data)
    except InputError as err:  # pragma: no cover - a broken preset is a bug, say where
        raise RuntimeError(f"preset {name!r} is invalid: {err}") from None


# --------------------------------------------------------------------------- dotted access

def get_value(params, path):
    """Value at a dotted path such as ``"screw.lead"`` or ``"loads.cases[2].fx"``."""
    _check_path(path)
    obj = params
    for part in path.split("."):
        name, index = _split_index(part, path)
        if not dataclasses.is_dataclass(obj) or name not in {f.name for f in dataclasses.fields(obj)}:
            raise InputError(path, part, "a dotted path of existing parameter fields")
        obj = getattr(obj, name)
        if index is not None:
            if not isinstance(obj, tuple):
                raise InputError(path, part, "an index only on a list field (loads.cases)")
            obj = _item(obj, index, path, part)
    return obj


def _field(params, path):
    """The :class:`dataclasses.Field` at dotted ``path`` of ``params``."""
    obj, found = params, None
    for part in path.split("."):
        name, index = _split_index(part)
        fields = {f.name: f for f in dataclasses.fields(obj)} if dataclasses.is_dataclass(obj) else {}
        if name not in fields:
            raise InputError(path, part, "a dotted path of existing parameter fields")
        found = fields[name]
        obj = getattr(obj, name)
        if index is not None:
            obj = obj[index]
    return found


def field_unit(params, path):
    """SI unit of the field at dotted ``path`` (``"N/m"``, ``"-"`` for dimensionless; ``""`` when unknown)."""
    return _field(params, path).metadata.get("unit", "") or ""


def field_range(params, path):
    """Allowed range ``(lower, upper)`` of the number field at dotted ``path``, in its SI unit; ``None`` where a
    side is open-ended (the validation's own range: a value outside it is refused by :func:`with_value`)."""
    meta = _field(params, path).metadata
    return meta.get("lo"), meta.get("hi")


def two_mass_effects(params):
    """The effects ``params`` switches on that only the two-mass Drake diagram has (the drive's ``Motor``,
    ``ScrewDrive``, ``NutTable``; not the plain-Python baseline, not the multibody diagram): one list, so that the
    next such effect is added in one place.

    Returns
    -------
    list of (str, float, str)
        ``(field, value, what)`` in a fixed order, the first field of each effect that is set: the lead error, the
        cogging, the drive's saturation, the friction map, the nut's lost motion, the friction drift, the
        structural mode on the table (``what`` in words).
    """
    d, out = params.disturbance, []
    groups = (("the lead error", (("disturbance.lead_error_amplitude", d.lead_error_amplitude),
                                  ("disturbance.lead_error_2_amplitude", d.lead_error_2_amplitude))),
              ("the cogging", (("disturbance.cogging_force", d.cogging_force),
                               ("disturbance.cogging_2_force", d.cogging_2_force))),
              ("the drive's saturation", (("motor.saturation_torque", params.motor.saturation_torque),)),
              ("the friction map", tuple((f"friction.position_map_{k}", a)
                                         for k, a in enumerate(params.friction.position_map))),
              ("the nut's lost motion", (("nut.backlash", params.nut.backlash),)),
              ("the friction drift", (("friction.time_drift", params.friction.time_drift),)),
              ("the structural mode on the table", (("table.mode_mass_share", params.table.mode_mass_share),)))
    for what, fields in groups:
        for path, value in fields:
            if value != 0.0:
                out.append((path, value, what))
                break
    return out


def check_params(params, field="params"):
    """Refuse what is no :class:`DriveParams` (a preset's name, a mapping, None) by ``field``, before an attribute
    of it is read (``AttributeError: 'str' object has no attribute 'controller'`` from a script)."""
    if not isinstance(params, DriveParams):
        raise InputError(field, params, "a DriveParams (drakecreep.preset(name) or drakecreep.load_params(path))")
    return params


def with_value(params, path, value):
    """A copy of ``params`` with the field at dotted ``path`` set to ``value`` (validated).

    ``path`` may index load cases: ``"loads.cases[2].fx"``. Errors name the full dotted field.
    """
    if not dataclasses.is_dataclass(params) or isinstance(params, type):  # 'a: got 1' for with_value('paper', 'a', 1)
        check_params(params)
    _check_path(path)
    head, _, rest = path.partition(".")
    name, index = _split_index(head, path)
    if not dataclasses.is_dataclass(params) or name not in {f.name for f in dataclasses.fields(params)}:
        raise InputError(path, value, "a dotted path of existing parameter fields")
    if index is not None:
        child = getattr(params, name)
        if not isinstance(child, tuple):
            raise InputError(path, value, "an index only on a list field (loads.cases)")
        _item(child, index, path, value)
    try:
        if not rest:
            if index is not None:
                raise InputError(name, value, "a path ending in a field, not a list item")
            current = getattr(params, name)
            if dataclasses.is_dataclass(current) and not isinstance(value, type(current)):
                raise InputError(name, value, "a path to one of its fields (" + ", ".join(
                    f"{name}.{f.name}" for f in dataclasses.fields(current)) + "), not the whole group")
            if isinstance(current, tuple) and not isinstance(value, tuple):
                raise InputError(name, value, f"a path to one of its items' fields ({name}[INDEX].FIELD)")
            return dataclasses.replace(params, **{name: value})
        child = getattr(params, name)
        if index is not None:
            items = list(child)
            items[index] = with_value(items[index], rest, value)
            return dataclasses.replace(params, **{name: tuple(items)})
        return dataclasses.replace(params, **{name: with_value(child, rest, value)})
    except InputError as err:
        if not rest:
            raise
        # the error names a field relative to the child: prefix this level's name
        raise err.renamed(f"{head}.{err.field}") from None


_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)(?:\[([0-9]{1,6})\])?$")


def _split_index(part, path=None):
    """``"cases[2]"`` -> ``("cases", 2)``; ``"lead"`` -> ``("lead", None)``; anything else an InputError."""
    match = _PART.match(part)
    if match is None:
        raise InputError(path or part, part, "a dotted path of field names, a list item as name[INDEX] with INDEX >= 0")
    name, idx = match.groups()
    return name, None if idx is None else int(idx)


def _check_path(path):
    if not isinstance(path, str) or not path:
        raise InputError("path", path, "a dotted path of parameter fields such as screw.lead or loads.cases[0].fx")
    if len(path) > 200:
        raise InputError("path", path, "a dotted path of at most 200 characters")


def _item(seq, index, path, value):
    if not 0 <= index < len(seq):
        raise InputError(path, value, f"an index in 0..{len(seq) - 1}" if seq else "an index of an existing item (the list is empty)")
    return seq[index]
