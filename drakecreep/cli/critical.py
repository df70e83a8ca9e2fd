"""``drakecreep critical``: the paper's creep boundary (eqs. 3, 6, 10, 11) for one drive.

Prints the damping ratio ς (with the friction slope C1 derived from a Stribeck friction law at the
feed speed), D at the feed, the critical ratio D0 = sqrt(4πς) and the critical speed v0 in mm/s.
Units at this edge: stiffness N/µm, speeds mm/s, everything else SI.
"""

import json
import math

from drakecreep import creep
from drakecreep.errors import InputError

__all__ = ["add_parser", "run"]

# Defaults: K and C are the paper's screw-nut axial values (Table 4). The paper gives no table mass
# and no friction data: mass and friction defaults are the assumed values of the "paper" preset
# (drakecreep/presets/paper.yaml: 40 kg table + 0.335 kg nut, Fc ~ 17.8 N, Fs = 1.3 Fc,
# vs = 0.1 mm/s, Fv = 200 N s/m), rounded.
DEFAULTS = dict(stiffness=51.6, damping=898.88, mass=40.335, fs=23.1, fd=17.8,
                stribeck_velocity=0.1, viscous=200.0, feed=1.0)


def add_parser(subparsers):
    """Register ``critical``."""
    p = subparsers.add_parser(
        "critical", help="creep boundary: damping ratio, D0 and critical speed v0 (paper eq. 11)",
        description=__doc__.split("\n\n")[0])
    p.add_argument("--params", metavar="FILE",
                   help="parameter YAML (drakecreep.params); takes K, C (whole axial chain), M and "
                        "the friction law from it, overriding the options below")
    p.add_argument("--load-case", type=int, default=0, metavar="N",
                   help="with --params: load case index (0 = no external load; 1.. = file's cases)")
    p.add_argument("--stiffness", type=float, default=DEFAULTS["stiffness"], metavar="N_PER_UM",
                   help="drive stiffness K in N/um (default 51.6, paper Table 4 screw-nut axial)")
    p.add_argument("--damping", type=float, default=DEFAULTS["damping"], metavar="NS_PER_M",
                   help="structural damping C in N s/m (default 898.88, paper Table 4)")
    p.add_argument("--mass", type=float, default=DEFAULTS["mass"], metavar="KG",
                   help="driven mass M in kg (default 40.335: assumed table + paper nut mass)")
    p.add_argument("--fs", type=float, default=DEFAULTS["fs"], metavar="N",
                   help="static (breakaway) friction Fs in N (default 23.1, assumed)")
    p.add_argument("--fd", type=float, default=DEFAULTS["fd"], metavar="N",
                   help="dynamic (Coulomb) friction Fd in N (default 17.8, assumed)")
    p.add_argument("--stribeck-velocity", type=float, default=DEFAULTS["stribeck_velocity"],
                   metavar="MM_S", help="Stribeck velocity vs in mm/s (default 0.1, assumed)")
    p.add_argument("--viscous", type=float, default=DEFAULTS["viscous"], metavar="NS_PER_M",
                   help="viscous friction Fv in N s/m (default 200, assumed)")
    p.add_argument("--feed", type=float, default=DEFAULTS["feed"], metavar="MM_S",
                   help="feed speed at which C1 = dF/dv is taken, mm/s (default 1, as in the paper)")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=run)
    return p


def _positive(name, value, allow_zero=False):
    ok = math.isfinite(value) and (value >= 0.0 if allow_zero else value > 0.0)
    if not ok:
        raise InputError(name, value, ">= 0" if allow_zero else "> 0")


def _from_params(args):
    """K, C, M, Fc, Fs and the friction law from a parameter file (model engineer's modules)."""
    from drakecreep.friction import make_friction_law
    from drakecreep.params import LoadCase, load_params
    from drakecreep.screw import axial_damping, axial_stiffness
    from drakecreep.table import friction_levels, moving_mass

    params = load_params(args.params)
    cases = params.loads.cases
    if not 0 <= args.load_case <= len(cases):
        raise InputError("--load-case", args.load_case, f"0..{len(cases)}")
    load = LoadCase() if args.load_case == 0 else cases[args.load_case - 1]
    fc, fs = friction_levels(params, load)
    law = make_friction_law(params.friction)
    return dict(K=float(axial_stiffness(params.screw, params.nut)),
                C=float(axial_damping(params.screw, params.nut)), M=float(moving_mass(params)),
                Fs=float(fs), Fd=float(fc),
                law=lambda v: law.steady_state_force(v, fc, fs), source=str(args.params),
                law_name=params.friction.law)


def _from_options(args):
    from drakecreep.friction import StribeckFriction

    for name in ("stiffness", "mass", "fd", "stribeck_velocity"):
        _positive("--" + name.replace("_", "-"), getattr(args, name))
    for name in ("damping", "viscous"):
        _positive("--" + name, getattr(args, name), allow_zero=True)
    if not (math.isfinite(args.fs) and args.fs >= args.fd):
        raise InputError("--fs", args.fs, f">= --fd ({args.fd})")
    law = StribeckFriction(viscous=args.viscous, stribeck_velocity=args.stribeck_velocity * 1e-3,
                           regularization_velocity=1e-9)
    fc, fs = args.fd, args.fs
    return dict(K=args.stiffness * 1e6, C=args.damping, M=args.mass, Fs=fs, Fd=fc,
                law=lambda v: law.steady_state_force(v, fc, fs), source="options",
                law_name="stribeck")


def run(args):
    """Compute and print the creep boundary."""
    _positive("--feed", args.feed)
    d = _from_params(args) if args.params else _from_options(args)
    v = args.feed * 1e-3
    c1 = float(creep.friction_slope(d["law"], v))
    zeta = float(creep.damping_ratio(d["K"], d["M"], d["C"], c1))
    D = float(creep.friction_drop_ratio(d["Fs"], d["Fd"], v, d["K"], d["M"]))
    D0 = float(creep.critical_D0(zeta))
    v0 = float(creep.critical_speed(d["Fs"], d["Fd"], d["K"], d["M"], d["C"], c1))
    v0_sc = creep.critical_speed_self_consistent(d["law"], d["Fs"], d["Fd"], d["K"], d["M"],
                                                 d["C"])
    result = {
        "inputs": {"source": d["source"], "friction_law": d["law_name"],
                   "stiffness_N_per_um": d["K"] * 1e-6, "mass_kg": d["M"],
                   "damping_Ns_per_m": d["C"], "Fs_N": d["Fs"], "Fd_N": d["Fd"],
                   "feed_mm_per_s": args.feed},
        "C1_Ns_per_m": c1,
        "natural_frequency_Hz": float(creep.natural_frequency(d["K"], d["M"])) / (2 * math.pi),
        "zeta": zeta,
        "D": D,
        "D0": None if math.isnan(D0) else D0,
        "v0_mm_per_s": None if math.isnan(v0) else v0 * 1e3,
        "v0_self_consistent_mm_per_s": None if math.isnan(v0_sc) else v0_sc * 1e3,
        "creep_predicted": bool(creep.creep_predicted(v, d["Fs"], d["Fd"], d["K"], d["M"],
                                                      d["C"], c1)),
    }
    if args.json:
        print(json.dumps(result, indent=2))
        return 0
    i = result["inputs"]
    print(f"inputs ({i['source']}): K = {i['stiffness_N_per_um']:.4g} N/um, M = {i['mass_kg']:.4g} kg, "
          f"C = {i['damping_Ns_per_m']:.4g} N s/m, Fs = {i['Fs_N']:.4g} N, Fd = {i['Fd_N']:.4g} N, "
          f"law = {i['friction_law']}")
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
    print(f"creep at v        : {'yes' if result['creep_predicted'] else 'no'}")
    return 0
