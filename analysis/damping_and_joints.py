"""What the loss-factor damping (defect 6) and the fixed seat joints (defect 7) do to the axial mode and the loops.

For the "paper" preset (and "paper_catalogue" with ``--preset``), four variants: the hammer-test damping
as viscous (today's default), as loss factors evaluated at the axial mode (``screw.chain_damping:
loss_factor``), the seat joints of Tables 1-2 in series (``paper.joints.axial_path_joints``), and both.
Per variant: chain K, the two-mass axial mode, the chain's damping ratio (lumped), the plant's first
resonance and its damping ratio (linearized, python-control), the resonance peak 1/(2 zeta) in dB, the
velocity and position loop margins at 1 mm/s, load case 3 (sampled controller), and the creep verdict and
fluctuation at 0.1 mm/s (LuGre, 3 s).

Run: ``python analysis/damping_and_joints.py [--preset paper]``
"""

import argparse
import math

from drakecreep.model.lumped import axial_mode_frequency, lumped
from drakecreep.paper.joints import axial_path_joints
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.servo.loops import analyze_loops
from drakecreep.sim.simulation import simulate


def variants(base):
    j = axial_path_joints()
    joints = {"screw.seat_joint_stiffness": j["bearing_seat"][0], "screw.seat_joint_damping": j["bearing_seat"][1],
              "nut.seat_joint_stiffness": j["nut_seat"][0], "nut.seat_joint_damping": j["nut_seat"][1]}
    loss = {"screw.chain_damping": "loss_factor"}
    out = []
    for label, changes in (("viscous (default)", {}), ("loss factor", loss), ("seat joints", joints),
                           ("loss factor + joints", {**loss, **joints})):
        p = base
        for path, value in changes.items():
            p = with_value(p, path, value)
        out.append((label, p))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--preset", default="paper")
    args = ap.parse_args()
    base = preset(args.preset)
    rows = []
    for label, p in variants(base):
        d = lumped(p, 3)
        s = analyze_loops(p, Scenario(feed=1e-3, load_case=3)).summary()
        m = simulate(p, Scenario(feed=0.1e-3, load_case=3, duration=3.0)).metrics
        z = s["resonance_damping"]
        rows.append({
            "variant": label,
            "K N/um": d.stiffness * 1e-6,
            "mode Hz": axial_mode_frequency(p),
            "zeta chain": d.damping / (2 * math.sqrt(d.stiffness * d.mass)),
            "plant resonance Hz": s["resonance_Hz"],
            "plant zeta": z,
            "peak 1/(2 zeta) dB": 20 * math.log10(1 / (2 * z)),
            "vel PM deg": s["velocity"]["phase_margin_deg"],
            "vel GM dB": s["velocity"]["gain_margin_dB"],
            "vel delay margin ms": s["velocity"]["delay_margin_ms"],
            "pos PM deg": s["position"]["phase_margin_deg"],
            "pos delay margin ms": s["position"]["delay_margin_ms"],
            "creep 0.1 mm/s": "yes" if m.creep else "no",
            "fluct 0.1 mm/s (mm/s)": m.max_fluctuation * 1e3,
        })
    keys = list(rows[0])
    print(f"preset {args.preset}, load case 3, {base.friction.law} friction, sampled cascade")
    print("| " + " | ".join(keys) + " |")
    print("|" + " --- |" * len(keys))
    for r in rows:
        print("| " + " | ".join(f"{r[k]:.4g}" if isinstance(r[k], float) else str(r[k]) for k in keys) + " |")


if __name__ == "__main__":
    main()
