"""``drakecreep hertz``: screw-nut stiffness by Hertz contact theory (paper eqs. 12-16, Table 3).

Defaults are the paper's Table 3 inputs; lengths at this edge are in mm, angles in degrees.
"""

import json
import math

__all__ = ["add_parser", "run"]

#: the paper's Table 3 groove/ball radius ratio and preload, the defaults of --conformity and --preload
DEFAULT_CONFORMITY = 1.04
DEFAULT_PRELOAD_N = 579.0
PAPER = {"ka_N_per_m": 48.6e6, "fa_Hz": 1917.0, "kr_N_per_m": 1.83e5, "fr_Hz": 117.63}


def add_parser(subparsers):
    """Register ``hertz``."""
    p = subparsers.add_parser("hertz", help="screw-nut axial/radial stiffness by Hertz theory (Table 3)",
                              description=__doc__.split("\n\n")[0])
    p.add_argument("--balls", type=int, default=47, help="loaded balls z (default 47)")
    p.add_argument("--ball-diameter", type=float, default=3.175, metavar="MM", help="db (3.175)")
    p.add_argument("--diameter", type=float, default=25.0, metavar="MM", help="screw d0 (25)")
    p.add_argument("--contact-angle", type=float, default=45.0, metavar="DEG", help="beta (45)")
    p.add_argument("--lead", type=float, default=5.0, metavar="MM", help="Ph (5)")
    p.add_argument("--conformity", type=float, default=DEFAULT_CONFORMITY,
                   help=f"groove/ball radius ratio r ({DEFAULT_CONFORMITY:g})")
    p.add_argument("--preload", type=float, default=DEFAULT_PRELOAD_N, metavar="N",
                   help=f"axial force Fa ({DEFAULT_PRELOAD_N:g})")
    p.add_argument("--mass", type=float, default=0.335, metavar="KG", help="M for frequencies (0.335)")
    p.add_argument("--youngs-modulus", type=float, default=206.0, metavar="GPA",
                   help="E of screw, ball and nut (206, assumed: the paper prints none)")
    p.add_argument("--poisson", type=float, default=0.3, help="Poisson's ratio (0.3, assumed)")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=run)
    return p


def run(args):
    """Compute and print the Hertz stiffness."""
    from drakecreep.errors import InputError
    from drakecreep.paper.hertz import (CONTACT_ANGLE_DEG, CONTACT_ANGLE_REASON, BallScrewNut, Material,
                                        ballscrew_stiffness)

    # sanity bounds (no ball screw is outside them; beyond them the contact arithmetic under- or overflows)
    if not (math.isfinite(args.youngs_modulus) and 1.0 <= args.youngs_modulus <= 2000.0):
        raise InputError("--youngs-modulus", args.youngs_modulus, "in [1, 2000] GPa")
    if not 1 <= args.balls <= 10000:
        raise InputError("--balls", args.balls, "an integer in [1, 10000]")
    # lower bounds too: a 1e-300 kg nut overflowed the axial frequency to inf
    for option, value, lo, hi in (("--ball-diameter", args.ball_diameter, 1e-2, 1e3),
                                  ("--diameter", args.diameter, 1e-1, 1e4), ("--lead", args.lead, 1e-2, 1e3),
                                  ("--preload", args.preload, 1e-6, 1e7), ("--mass", args.mass, 1e-6, 1e5)):
        if not (math.isfinite(value) and lo <= value <= hi):
            raise InputError(option, value, f"a finite number in [{lo:g}, {hi:g}]")
    # in the options' own units (the model's checks named its fields, in rad and m)
    lo, hi = CONTACT_ANGLE_DEG  # the model's bounds, in degrees
    if not (math.isfinite(args.contact_angle) and lo <= args.contact_angle <= hi):
        raise InputError("--contact-angle", args.contact_angle, f"an angle in [{lo:g}, {hi:g}] deg ({CONTACT_ANGLE_REASON})")
    if not args.ball_diameter < args.diameter:
        raise InputError("--ball-diameter", args.ball_diameter, f"a diameter below --diameter ({args.diameter:g} mm)")
    if not (math.isfinite(args.conformity) and 1.0 < args.conformity <= 10.0):  # the model said 'conformity: got 1.0'
        raise InputError("--conformity", args.conformity, "a groove/ball radius ratio in (1, 10] (the groove wider "
                         "than the ball)")
    if not (math.isfinite(args.poisson) and 0.0 <= args.poisson < 0.5):
        raise InputError("--poisson", args.poisson, "in [0, 0.5)")
    steel = Material(args.youngs_modulus * 1e9, args.poisson)
    nut = BallScrewNut(balls=args.balls, ball_diameter=args.ball_diameter * 1e-3,
                       nominal_diameter=args.diameter * 1e-3,
                       contact_angle=math.radians(args.contact_angle), lead=args.lead * 1e-3,
                       conformity=args.conformity, preload=args.preload, mass=args.mass,
                       screw=steel, ball=steel, nut=steel)
    try:
        r = ballscrew_stiffness(nut)
    except InputError as err:  # the option, not the model's field
        if err.field != "conformity":
            raise
        if args.conformity == DEFAULT_CONFORMITY and args.preload != DEFAULT_PRELOAD_N:
            # the load the user changed, not the catalogue groove they left (--preload 1e7 blamed '--conformity')
            raise InputError("--preload", args.preload,
                             f"an axial force below {err.load_limit:.4g} N for this groove (--conformity "
                             f"{args.conformity:g}) and ball: beyond, the contact ellipse outgrows the ball and Hertz "
                             "theory does not apply") from None
        raise err.renamed("--conformity") from None
    out = {
        "ball_load_N": r.ball_load,
        "helix_angle_deg": math.degrees(r.helix),
        "screw_contact": {"a_mm": float(r.screw_contact.a) * 1e3, "b_mm": float(r.screw_contact.b) * 1e3,
                          "kappa": r.screw_contact.coefficients.kappa,
                          "deformation_um": float(r.screw_contact.approach) * 1e6,
                          "max_pressure_MPa": float(r.screw_contact.max_pressure) * 1e-6},
        "nut_contact": {"a_mm": float(r.nut_contact.a) * 1e3, "b_mm": float(r.nut_contact.b) * 1e3,
                        "kappa": r.nut_contact.coefficients.kappa,
                        "deformation_um": float(r.nut_contact.approach) * 1e6,
                        "max_pressure_MPa": float(r.nut_contact.max_pressure) * 1e-6},
        "axial_deflection_um": r.axial_deflection * 1e6,
        "ka_N_per_m": r.ka_tangent,
        "ka_secant_N_per_m": r.ka_secant,
        "fa_Hz": r.fa,
        "kr_N_per_m": r.kr_paper_tangent,
        "fr_Hz": r.fr_paper,
        "kr_physical_N_per_m": r.kr_physical,
        "fr_physical_Hz": r.fr_physical,
        "paper_table3": PAPER,
        "notes": "ka: tangent dFa/d(delta_a) (eq. 15); kr: tangent with the paper's eq. 16 "
                 "(cos(beta) sin(lambda)); kr_physical: z/2 k_ball cos^2(beta)",
    }
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"ball load P = {r.ball_load:.4g} N, helix angle = {math.degrees(r.helix):.4g} deg")
    for name in ("screw_contact", "nut_contact"):
        c = out[name]
        print(f"{name:14s}: a = {c['a_mm']:.4g} mm, b = {c['b_mm']:.4g} mm, a/b = {c['kappa']:.4g}, "
              f"delta = {c['deformation_um']:.4g} um, p0 = {c['max_pressure_MPa']:.4g} MPa")
    print(f"{'':16s}{'computed':>12s} {'paper T3':>12s}")
    print(f"{'Ka (N/m)':16s}{r.ka_tangent:12.4g} {PAPER['ka_N_per_m']:12.4g}   (secant {r.ka_secant:.4g})")
    print(f"{'fa (Hz)':16s}{r.fa:12.4g} {PAPER['fa_Hz']:12.4g}")
    print(f"{'Kr eq.16 (N/m)':16s}{r.kr_paper_tangent:12.4g} {PAPER['kr_N_per_m']:12.4g}"
          f"   (physical z/2 k cos^2 b: {r.kr_physical:.4g})")
    print(f"{'fr eq.16 (Hz)':16s}{r.fr_paper:12.4g} {PAPER['fr_Hz']:12.4g}   (physical {r.fr_physical:.4g})")
    return 0
