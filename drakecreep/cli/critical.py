"""``drakecreep critical``: the paper's creep boundary (eqs. 3, 6, 10, 11) of a drive.

The drive is the preset's (or ``--params``') axial chain, moving mass and friction law under a load case,
reduced to one mass on one spring (:func:`drakecreep.model.lumped.lumped`), like every other command.
The mass carries the friction the model applies to the table: with the ball nut's drag on the screw (the
default) only the guides' share, which is what eq. 11's Fig. 2 mechanism sees.
Prints the damping ratio ς (with the friction slope C1 = dF/dv of the friction law at ``--feed``), D at the
feed, the critical ratio D0 = sqrt(4πς) and the critical speed v0 in mm/s. Any lumped value can be
overridden for a what-if. Units at this edge: stiffness N/µm, speeds mm/s, everything else SI.
"""

import dataclasses
import math

from drakecreep.cli._common import add_params_options, feed_from_mm_s, params_from_args, print_json
from drakecreep.errors import InputError
from drakecreep.params import ABSURD, MAX_CHAIN_DAMPING, MAX_LOAD_FORCE, MIN_STIFFNESS, MIN_TABLE_MASS

__all__ = ["add_parser", "run"]

#: override option -> (LumpedDrive field, factor from the option's unit to SI, may be zero, SI range): the ranges
#: of the parameter fields they stand for (a chain element's stiffness and damping, the table's mass, the largest
#: constant force of a load case for a friction level); --stiffness 1e-26 with --mass 1e-20, --damping 1e12 and
#: --fs 1e20 were accepted and printed a boundary of no drive
OVERRIDES = {
    "stiffness": ("stiffness", 1e6, False, (MIN_STIFFNESS, ABSURD)),
    "damping": ("damping", 1.0, True, (0.0, MAX_CHAIN_DAMPING)),
    "mass": ("mass", 1.0, False, (MIN_TABLE_MASS, 1e5)),
    "fs": ("breakaway", 1.0, False, (1e-6, MAX_LOAD_FORCE)),
    "fd": ("coulomb", 1.0, False, (1e-6, MAX_LOAD_FORCE)),
}
#: the overrides' units, as their options take them
_UNITS = {"stiffness": "N/um", "damping": "N s/m", "mass": "kg", "fs": "N", "fd": "N"}


def add_parser(subparsers):
    """Register ``critical``."""
    p = subparsers.add_parser(
        "critical", help="creep boundary: damping ratio, D0 and critical speed v0 (paper eq. 11)",
        description=__doc__.split("\n\n")[0])
    add_params_options(p)
    p.add_argument("--load-case", type=int, default=3, metavar="N",
                   help="load case (paper: 1-3; 0 = unloaded; default 3)")
    p.add_argument("--feed", type=float, default=1.0, metavar="MM_S",
                   help="feed speed at which C1 = dF/dv is taken, mm/s (default 1, as in the paper)")
    what_if = p.add_argument_group("what-if overrides of the drive's lumped values (default: from the parameters)")
    what_if.add_argument("--stiffness", type=float, metavar="N_PER_UM", help="axial stiffness K in N/um")
    what_if.add_argument("--damping", type=float, metavar="NS_PER_M", help="structural damping C in N s/m")
    what_if.add_argument("--mass", type=float, metavar="KG", help="moving mass M in kg")
    what_if.add_argument("--fs", type=float, metavar="N", help="static (breakaway) friction Fs in N")
    what_if.add_argument("--fd", type=float, metavar="N", help="dynamic (Coulomb) friction Fd in N")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=run)
    return p


def _drive(args):
    """The lumped drive of the parameters with the what-if overrides applied (validated), the source's name and the
    parameters."""
    from drakecreep.model.lumped import lumped

    params = params_from_args(args)
    n = len(params.loads.cases)
    if not 0 <= args.load_case <= n:
        raise InputError("--load-case", args.load_case, params.load_cases_allowed)
    drive = lumped(params, args.load_case)
    changes = {}
    for option, (field, unit, zero_ok, (lo, hi)) in OVERRIDES.items():
        value = getattr(args, option)
        if value is None:
            continue
        # the bounds of a parameter file's fields: 1e300 or 1e-300 overflowed to inf results
        if not (math.isfinite(value) and ((value == 0 and zero_ok) or lo <= value * unit <= hi)):
            raise InputError("--" + option, value, f"{'0 or ' if zero_ok and lo > 0 else ''}a number in "
                             f"[{lo / unit:g}, {hi / unit:g}] {_UNITS[option]}")
        changes[field] = value * unit
    drive = dataclasses.replace(drive, **changes)
    if drive.breakaway < drive.coulomb:
        if args.fs is None:  # the option given, not the params' value it contradicts ('--fs: got 7.781' for --fd 10)
            raise InputError("--fd", args.fd, f"<= Fs ({drive.breakaway:g} N, the parameters' breakaway; or give --fs)")
        raise InputError("--fs", drive.breakaway, f">= Fd ({drive.coulomb:g} N)")
    source = args.params or f"preset {args.preset}"
    return drive, source + (" with " + ", ".join("--" + o for o in OVERRIDES if getattr(args, o) is not None)
                            if changes else ""), params


def run(args):
    """Compute and print the creep boundary."""
    from drakecreep.cli._common import POSITIVE_FEED
    from drakecreep.paper import creep

    if not (math.isfinite(args.feed) and args.feed > 0):
        raise InputError("--feed", args.feed, POSITIVE_FEED)
    feed_from_mm_s(args.feed)  # the range of every command (1e300 mm/s overflowed the friction law)
    d, source, params = _drive(args)
    law_name, nut_on = params.friction.law, params.friction.nut_friction_on
    # the lumped mass carries the friction the model applies to the table (drakecreep.model.lumped)
    friction_on_mass = ("guides only (the ball nut's drag acts on the screw, motor side of the spring)"
                        if nut_on == "screw" else "guides and ball nut")
    K, M, C, Fs, Fd = d.stiffness, d.mass, d.damping, d.breakaway, d.coulomb
    cond = creep.creep_condition(d, args.feed * 1e-3)
    c1, zeta, D, D0 = cond.friction_slope, cond.zeta, cond.D, cond.D0
    v0, v0_sc = cond.critical_speed, cond.critical_speed_self_consistent
    result = {
        "inputs": {"source": source, "load_case": d.load_case, "friction_law": law_name,
                   "friction_on_mass": friction_on_mass,
                   "stiffness_N_per_um": K * 1e-6, "mass_kg": M, "damping_Ns_per_m": C,
                   "Fs_N": Fs, "Fd_N": Fd, "feed_mm_per_s": args.feed},
        "C1_Ns_per_m": c1,
        "natural_frequency_Hz": cond.natural_frequency / (2 * math.pi),
        "zeta": zeta,
        "D": D,
        "D0": None if math.isnan(D0) else D0,
        "v0_mm_per_s": None if math.isnan(v0) else v0 * 1e3,
        "v0_self_consistent_mm_per_s": None if math.isnan(v0_sc) else v0_sc * 1e3,
        "creep_predicted": cond.creep,
    }
    overload = _overload(args, params, d.load_case)
    if overload is not None:  # a drive that cannot hold the feed is no stick-slip (it said 'creep at v: no')
        result["creep_predicted"] = None
        result["overload"] = {"force_N": overload[0], "limit_N": overload[1]}
    if args.json:
        print_json(result)
        return 0
    i = result["inputs"]
    print(f"inputs ({i['source']}, load case {d.load_case}): K = {i['stiffness_N_per_um']:.4g} N/um, "
          f"M = {M:.4g} kg, C = {C:.4g} N s/m, Fs = {Fs:.4g} N, Fd = {Fd:.4g} N, law = {law_name}")
    print(f"friction on the mass: {friction_on_mass}")
    print(f"feed v            = {args.feed:.4g} mm/s")
    print(f"C1 = dF/dv at v   = {c1:.4g} N s/m")
    print(f"zeta              = {zeta:.4g}")
    print(f"D at v            = {D:.4g}")
    print("D0 = sqrt(4 pi zeta) = " + ("n/a (C + C1 <= 0: creep at any speed)" if math.isnan(D0)
                                        else f"{D0:.4g}"))
    print("v0 (eq. 11)       = " + ("n/a (C + C1 <= 0: creep at any speed)" if math.isnan(v0)
                                    else f"{v0 * 1e3:.4g} mm/s"))
    print("v0, C1 at v0      = " + ("n/a (no root in 1e-4..1000 mm/s)" if math.isnan(v0_sc)
                                    else f"{v0_sc * 1e3:.4g} mm/s"))
    if overload is not None:
        print(f"creep at v        : no verdict: the drive cannot hold this feed (it takes {overload[0]:.4g} N, beyond "
              f"its force limit {overload[1]:.4g} N: {overload[2]})")
    else:
        print(f"creep at v        : {'yes' if result['creep_predicted'] else 'no'}")
    return 0


def _overload(args, params, load_case):
    """``(force, limit)`` [N] and where the limit comes from when the parameters' drive cannot slide at ``--feed``
    under the load case, else None; not asked with friction overrides (``--fs``, ``--fd``: a what-if of the lumped
    drive, not of the parameters)."""
    if args.fs is not None or args.fd is not None:
        return None
    from drakecreep.scenario import Scenario
    from drakecreep.model.steady import drive_limit, sliding_overload

    overload = sliding_overload(params, Scenario(feed=args.feed * 1e-3, load_case=load_case))
    return None if overload is None else (float(overload[0]), float(overload[1]), drive_limit(params)[1])
