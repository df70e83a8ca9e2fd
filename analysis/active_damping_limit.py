"""How far could active damping from the linear scale lower the paper rig's critical speed?

The friction compensators (drakecreep/studies/compensation.py) cannot remove the paper rig's creep: it is the
table sticking and slipping on the screw's spring, and a torque added at the motor reaches that mode
about 11x weaker (motor-side inertia 463 kg against the table's 40 kg). Active damping is the
controls answer to a lightly damped mode, so this script bounds what it could achieve with an ideal
(unquantized, undelayed) table speed: the motor torque gets an extra ``u = c (Ph / 2 pi) s`` with the
signal ``s`` either the table speed or the spring's stretch rate (table speed minus motor speed at the
table's scale), for gains ``c`` of either sign. The loop is the continuous cascade of the ``paper``
preset, linearized with python-control at steady sliding (drakecreep.servo.linearize); a feed is stable
when every closed-loop pole has a negative real part. The lowest feed above which every feed on a
log grid is stable is the linear critical feed.

Run: python analysis/active_damping_limit.py [LOAD_CASE]   (about 1 minute)
"""

import argparse
import math
import sys

import control
import numpy as np

from drakecreep.errors import InputError
from drakecreep.servo.linearize import linearize_controller, linearize_plant
from drakecreep.params import preset
from drakecreep.scenario import Scenario

FEEDS = np.geomspace(0.05e-3, 0.5e-3, 31)
GAINS = (0.0, 1e4, 2e4, 3e4, 5e4, 1e5, 2e5, -1e4, -3e4)


def closed_loop_abscissa(params, feed, gain, signal, load_case=3):
    """Largest real part (1/s) of the closed-loop poles with the extra damping torque."""
    sc = Scenario(feed=feed, load_case=load_case, duration=2.0)
    P, K = linearize_plant(params, sc), linearize_controller(params, sc)
    r = params.screw.lead / (2 * math.pi)
    D = np.zeros((1, len(P.output_labels)))
    D[0, P.output_labels.index("table_speed")] = gain * r
    if signal == "stretch rate":
        D[0, P.output_labels.index("motor_speed")] = -gain * r * r
    damping = control.ss([], [], [], D, inputs=P.output_labels, outputs=["u_ad"], name="damping")
    total = control.summing_junction(inputs=["torque_command", "u_ad"], output="tau", name="sum")
    plant = control.ss(P.A, P.B, P.C, P.D, inputs=["tau"], outputs=P.output_labels, name="plant")
    sensors = control.ss([], [], [], np.eye(3), inputs=["motor_angle", "motor_speed", "table_position"],
                         outputs=["encoder_angle", "motor_speed_measured", "scale_position"], name="sensors")
    loop = control.interconnect([plant, K, sensors, damping, total], inplist=["x_ref", "v_ref"],
                                outlist=["table_speed"])
    return float(np.linalg.eigvals(loop.A).real.max())


def linear_critical_feed(params, gain, signal, load_case=3):
    """Lowest grid feed (m/s) above which all grid feeds are stable; nan if the highest is unstable."""
    stable = [closed_loop_abscissa(params, f, gain, signal, load_case) < 0 for f in FEEDS]
    for i in range(len(FEEDS)):
        if all(stable[i:]):
            return float(FEEDS[i])
    return float("nan")


def main(load_case=3):
    params = preset("paper")
    print(f"paper preset, load case {load_case}: linear critical feed (mm/s) with active damping from an ideal scale")
    print("| signal | c (N s/m) | critical feed (mm/s) |\n| --- | --- | --- |")
    for signal in ("table speed", "stretch rate"):
        for gain in GAINS:
            v = linear_critical_feed(params, gain, signal, int(load_case))
            print(f"| {signal} | {gain:+.0e} | {v * 1e3:.3f} |", flush=True)


def _load_case(text):
    """A load case number: an integer >= 0 (0 = unloaded)."""
    try:
        number = int(text)
    except ValueError:
        number = -1
    if number < 0:
        raise argparse.ArgumentTypeError(f"got {text!r}; allowed: an integer >= 0 (0 = unloaded)")
    return number


def cli(argv=None):
    """Parse ``argv``, check the load case against the preset and run :func:`main`; the exit status."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("load_case", nargs="?", default=3, type=_load_case, metavar="LOAD_CASE",
                    help="load case of the paper preset, 0 = unloaded (default 3)")
    a = ap.parse_args(argv)
    try:  # the preset's own range, before the first linearization
        preset("paper").load_case(a.load_case)
    except InputError as e:
        print(e, file=sys.stderr)
        return 2
    main(a.load_case)
    return 0


if __name__ == "__main__":
    sys.exit(cli())
