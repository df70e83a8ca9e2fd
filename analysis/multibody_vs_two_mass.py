"""The two-mass model against the multibody model on the same scenarios: creep verdicts and velocity-loop margins.

1. Creep: paper preset, LuGre, load case 3, feeds ``--feeds`` (mm/s), ``--duration`` s; each model run by
   :func:`drakecreep.sim.simulation.simulate` with its convergence check (the accuracy the friction law
   gets by default, checked at 10x tighter). Prints verdict, fluctuation, stick-slip cycles, whether
   converged, and the wall time.
2. Velocity-loop margins at ``--margin-feed`` (mm/s), load case 3: the two-mass plant
   (:func:`drakecreep.servo.linearize.linearize_plant`) against the multibody plant linearized at steady
   sliding (:func:`drakecreep.multibody.linear.linearize_multibody_plant`, modes above 1e5 rad/s
   residualized), each closed by :func:`drakecreep.servo.loops.loop_transfer` and measured by
   :func:`drakecreep.servo.loops.loop_margins` (sampled loop: what the drive runs; continuous loop: margins from a
   dense frequency response, python-control's polynomial method overflows at this model order). Also the
   closed loop's least stable pole.

3. ``--boundary``: the creep boundary, convergence-checked. Each model of ``--models`` (:data:`BOUNDARY_MODELS`)
   at each feed of ``--feeds`` (ascending), ``--duration`` s (2 s, metrics from 1 s: as
   :func:`drakecreep.studies.paper_reproduction.simulated_creep_boundary`), with the convergence check on. A
   verdict counts only when converged; the boundary is bracketed by the highest converged creeping feed
   and the lowest converged sliding feed above it. ``--wall-limit`` stops a run after that many seconds
   (reported as such, not as a verdict). Rows go to ``boundary.json`` as they come.

Writes ``comparison.json`` to ``--out`` (default ``out/multibody_vs_two_mass``).

    python analysis/multibody_vs_two_mass.py [--feeds 0.1 0.5 1 2] [--duration 3] [--segments 6] [--skip-creep]
    python analysis/multibody_vs_two_mass.py --boundary --feeds 0.18 0.2 0.22 0.24 0.26 --duration 2 \
        --models two_mass rigid3_axial [--wall-limit 1200]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import control
import numpy as np

from drakecreep.multibody.diagram import MultibodyOptions
from drakecreep.multibody.linear import linearize_multibody_plant, residualize
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.servo.linearize import linearize_plant
from drakecreep.servo.loops import loop_margins, loop_transfer
from drakecreep.sim.simulation import simulate

__all__ = ["creep_rows", "margin_rows", "boundary_rows", "bracket", "BOUNDARY_MODELS", "main"]

#: models of the creep-boundary comparison: name -> simulate() keyword arguments
BOUNDARY_MODELS = {
    "two_mass": {},
    "rigid2_axial": dict(model="multibody", multibody=MultibodyOptions(n_segments=2, rigid_joints=True,
                                                                        screw_bending=False)),
    "rigid3_axial": dict(model="multibody", multibody=MultibodyOptions(n_segments=3, rigid_joints=True,
                                                                        screw_bending=False)),
    "rigid6_axial": dict(model="multibody", multibody=MultibodyOptions(n_segments=6, rigid_joints=True,
                                                                        screw_bending=False)),
    "rigid3": dict(model="multibody", multibody=MultibodyOptions(n_segments=3, rigid_joints=True)),
    "rigid3_axial_vie": dict(model="multibody", multibody=MultibodyOptions(
        n_segments=3, rigid_joints=True, screw_bending=False, integrator="velocity_implicit_euler")),
    "full6": dict(model="multibody", multibody=MultibodyOptions(n_segments=6)),
    "full4": dict(model="multibody", multibody=MultibodyOptions(n_segments=4)),
}

#: modes faster than this (rad/s) are residualized in the multibody plant before forming the loops
CUTOFF = 1e5


def creep_rows(params, feeds_mm_s, duration, models):
    """One row per (feed, model): the creep metrics of :func:`simulate`."""
    rows = []
    for feed in feeds_mm_s:
        scenario = Scenario(feed=feed * 1e-3, load_case=3, duration=duration)
        for name, kwargs in models.items():
            r = simulate(params, scenario, **kwargs)
            m = r.metrics
            row = dict(feed_mm_s=feed, model=name, status=r.status, wall_s=r.wall_time,
                       accuracy=r.stats.get("accuracy"))
            if m is not None:
                row.update(creep=bool(m.creep), max_fluctuation_mm_s=m.max_fluctuation * 1e3,
                           fluctuation_rate_percent=m.fluctuation_rate * 100, cycles=int(m.stick_slip_cycles),
                           mean_speed_mm_s=m.mean_speed * 1e3, converged=m.converged,
                           following_error_rms_um=m.following_error_rms * 1e6)
            rows.append(row)
            print(_creep_line(row), flush=True)
    return rows


def boundary_rows(params, feeds_mm_s, duration, models, wall_limit=None, out=None):
    """One row per (model, feed), convergence check on; written to ``out`` (a JSON path) after each run."""
    rows = []
    for name in models:
        for feed in sorted(feeds_mm_s):
            scenario = Scenario(feed=feed * 1e-3, load_case=3, duration=duration)
            start = time.process_time()
            r = simulate(params, scenario, wall_limit=wall_limit, **BOUNDARY_MODELS[name])
            row = dict(feed_mm_s=feed, model=name, status=r.status, wall_s=r.wall_time,
                       cpu_s=time.process_time() - start, accuracy=r.stats.get("accuracy"),
                       check_accuracy=r.stats.get("convergence_check_accuracy"),
                       check_runs=r.stats.get("convergence_runs"),
                       check_change_mm_s=r.stats.get("convergence_fluctuation_change_mm_s"))
            m = r.metrics
            if m is not None:
                row.update(creep=bool(m.creep), max_fluctuation_mm_s=m.max_fluctuation * 1e3,
                           fluctuation_rate_percent=m.fluctuation_rate * 100, cycles=int(m.stick_slip_cycles),
                           converged=m.converged)
            rows.append(row)
            print(_boundary_line(row), flush=True)
            if out is not None:
                Path(out).write_text(json.dumps(rows, indent=1, default=str))
    return rows


def bracket(rows, model):
    """``(highest converged creeping feed, lowest converged sliding feed above it)`` of ``model`` (mm/s; None
    when missing), and the feeds whose verdict was not converged or not reached."""
    mine = [r for r in rows if r["model"] == model]
    ok = [r for r in mine if r.get("converged") and r["status"] == "ok"]
    creeping = [r["feed_mm_s"] for r in ok if r["creep"]]
    hi = max(creeping) if creeping else None
    sliding = [r["feed_mm_s"] for r in ok if not r["creep"] and (hi is None or r["feed_mm_s"] > hi)]
    lo = min(sliding) if sliding else None
    open_ = [r["feed_mm_s"] for r in mine if not (r.get("converged") and r["status"] == "ok")]
    return hi, lo, open_


def _boundary_line(row):
    head = f"| {row['model']} | {row['feed_mm_s']:g} |"
    if "creep" not in row:
        return f"{head} - | - | - | - | {row['status']} | {row['cpu_s']:.0f} |"
    verdict = "creeps" if row["creep"] else "slides"
    if not row["converged"]:
        verdict = f"not converged (read {verdict})"
    status = "" if row["status"] == "ok" else row["status"]
    return (f"{head} {verdict} | {row['max_fluctuation_mm_s']:.4f} | {row['cycles']} | {row['accuracy']:g} / "
            f"{row['check_accuracy']:g}, {row['check_runs']} check(s), change {row['check_change_mm_s']:.4f} mm/s "
            f"| {status} | {row['cpu_s']:.0f} |")


def _creep_line(row):
    if "creep" not in row:
        return f"| {row['feed_mm_s']:g} | {row['model']} | {row['status']} |"
    return (f"| {row['feed_mm_s']:g} | {row['model']} | {'yes' if row['creep'] else 'no'} | "
            f"{row['max_fluctuation_mm_s']:.4f} | {row['fluctuation_rate_percent']:.2f} | {row['cycles']} | "
            f"{row['following_error_rms_um']:.2f} | {row['converged']} | {row['wall_s']:.0f} |")


def _margins(params, scenario, plant):
    out = {}
    for sampled in (True, False):
        L = loop_transfer(params, scenario, "velocity", sampled=sampled, plant=plant)
        cl = control.feedback(L, 1).poles()
        if sampled:
            m = loop_margins(L)
            worst = cl[np.argmax(np.abs(cl))]
            row = dict(phase_margin_deg=m["phase_margin_deg"], gain_margin_dB=m["gain_margin_dB"],
                       crossover_Hz=m["crossover_Hz"], ms_peak=m["ms_peak"], closed_loop_stable=m["closed_loop_stable"],
                       least_stable_pole_abs_z=float(abs(worst)),
                       least_stable_pole_Hz=float(abs(np.angle(worst)) / (2 * math.pi * L.dt)))
        else:
            w = np.logspace(-1, 5.5, 20000)
            gm, pm, _, _, wgc, _ = control.stability_margins(control.frd(L, w))
            worst = cl[np.argmax(cl.real)]
            row = dict(phase_margin_deg=float(pm), gain_margin_dB=float(20 * math.log10(gm)) if np.isfinite(gm) else math.inf,
                       crossover_Hz=float(wgc) / (2 * math.pi), closed_loop_stable=bool(worst.real <= 1e-9 * np.max(np.abs(cl))),
                       least_stable_pole=[float(worst.real), float(abs(worst.imag)) / (2 * math.pi)])
        out["sampled" if sampled else "continuous"] = row
    return out


def margin_rows(params, feed_mm_s, segments):
    """Velocity-loop margins of the two-mass plant and the multibody plant (full and rigid joints)."""
    scenario = Scenario(feed=feed_mm_s * 1e-3, load_case=3, duration=5.0)
    rows = {"two_mass": _margins(params, scenario, linearize_plant(params, scenario))}
    for name, options in ((f"multibody N={segments}", MultibodyOptions(n_segments=segments)),
                          (f"multibody N={segments} rigid joints", MultibodyOptions(n_segments=segments, rigid_joints=True))):
        lin = linearize_multibody_plant(params, scenario, options)
        A, B, C, D = residualize(lin["A"], lin["B"], lin["C"], lin["D"], CUTOFF)
        plant = control.ss(A, B, C, D, inputs=lin["inputs"], outputs=lin["outputs"])
        rows[name] = _margins(params, scenario, plant)
        rows[name]["states"] = int(lin["A"].shape[0])
        rows[name]["states_kept"] = int(A.shape[0])
        rows[name]["plant_fastest_lightly_damped_Hz"] = _lightly_damped(A)
    return rows


def _lightly_damped(A, zeta=0.01):
    """Frequencies (Hz) of the plant's complex modes with damping ratio below ``zeta``."""
    ev = np.linalg.eigvals(A)
    ev = ev[ev.imag > 1.0]
    return sorted(float(abs(e) / (2 * math.pi)) for e in ev if -e.real / abs(e) < zeta)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--feeds", type=float, nargs="+", default=[0.1, 0.5, 1.0, 2.0], help="mm/s")
    ap.add_argument("--duration", type=float, default=3.0, help="s (default 3: the multibody model is slow)")
    ap.add_argument("--segments", type=int, default=6)
    ap.add_argument("--rigid-joints", action="store_true", help="also simulate the multibody model with rigid joints")
    ap.add_argument("--margin-feed", type=float, default=1.0, help="mm/s")
    ap.add_argument("--skip-creep", action="store_true")
    ap.add_argument("--skip-margins", action="store_true")
    ap.add_argument("--no-check", action="store_true",
                    help="convergence check off in both models (faster; the verdicts are then unchecked)")
    ap.add_argument("--boundary", action="store_true", help="the convergence-checked creep boundary (only)")
    ap.add_argument("--models", nargs="+", default=["two_mass", "rigid3_axial"], choices=sorted(BOUNDARY_MODELS))
    ap.add_argument("--wall-limit", type=float, default=None, help="s per run (--boundary)")
    ap.add_argument("--max-step", type=float, default=None,
                    help="s: simulation.max_step of every run (--boundary; default the preset's 1 ms). The "
                         "implicit integrators' numerical damping at large steps can hide stick-slip and pass the "
                         "convergence check (docs/multibody.md)")
    ap.add_argument("--out", default="out/multibody_vs_two_mass")
    args = ap.parse_args(argv)
    if args.boundary:
        params = preset("paper")
        if args.max_step is not None:
            params = with_value(params, "simulation.max_step", args.max_step)
            print(f"simulation.max_step = {args.max_step:g} s")
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        print(f"Creep boundary, paper preset, {params.friction.law}, load case 3, {args.duration:g} s runs, metrics "
              f"from {params.simulation.steady_start:g} s, convergence check on")
        print("| model | feed (mm/s) | verdict | max fluctuation (mm/s) | cycles | accuracy / check, runs, change "
              "| status | CPU (s) |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
        rows = boundary_rows(params, args.feeds, args.duration, args.models, args.wall_limit, out / "boundary.json")
        for name in args.models:
            hi, lo, open_ = bracket(rows, name)
            print(f"{name}: highest creeping feed {hi} mm/s, lowest sliding feed above it {lo} mm/s"
                  + (f"; not converged / not finished at {open_} mm/s" if open_ else ""))
        return 0
    params = preset("paper")
    if args.no_check:
        params = with_value(params, "simulation.convergence_check", False)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    result = {"preset": "paper", "friction_law": params.friction.law, "load_case": 3}

    start = time.perf_counter()
    margins = {} if args.skip_margins else margin_rows(params, args.margin_feed, args.segments)
    result["margins"] = margins
    if margins:
        print(f"\nVelocity loop at {args.margin_feed:g} mm/s, load case 3 ({time.perf_counter() - start:.0f} s)")
        print("| plant | loop | PM (deg) | GM (dB) | crossover (Hz) | closed loop stable | least stable pole |")
        print("| --- | --- | --- | --- | --- | --- | --- |")
    for name, row in margins.items():
        for loop in ("sampled", "continuous"):
            r = row[loop]
            pole = (f"|z| = {r['least_stable_pole_abs_z']:.5f} at {r['least_stable_pole_Hz']:.0f} Hz" if loop == "sampled"
                    else f"{r['least_stable_pole'][0]:.3g} 1/s at {r['least_stable_pole'][1]:.0f} Hz")
            print(f"| {name} | {loop} | {r['phase_margin_deg']:.2f} | {r['gain_margin_dB']:.2f} | {r['crossover_Hz']:.2f} | "
                  f"{r['closed_loop_stable']} | {pole} |", flush=True)
        if "states" in row:
            print(f"|   ({row['states']} states, {row['states_kept']} kept below {CUTOFF:g} rad/s; lightly damped "
                  f"(zeta < 1 %) plant modes: {', '.join(f'{f:.0f}' for f in row['plant_fastest_lightly_damped_Hz'])} Hz) |")

    if not args.skip_creep:
        models = {"two_mass": {}, f"multibody N={args.segments}": dict(
            model="multibody", multibody=MultibodyOptions(n_segments=args.segments))}
        if args.rigid_joints:
            models[f"multibody N={args.segments} rigid"] = dict(
                model="multibody", multibody=MultibodyOptions(n_segments=args.segments, rigid_joints=True))
        print(f"\nCreep, load case 3, {args.duration:g} s, metrics from {params.simulation.steady_start:g} s")
        print("| feed (mm/s) | model | creep | max fluctuation (mm/s) | rate (%) | cycles | travel error rms (um) "
              "| converged | wall (s) |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        result["creep"] = creep_rows(params, args.feeds, args.duration, models)
    (out / "comparison.json").write_text(json.dumps(result, indent=1, default=str))
    print(f"wrote {out / 'comparison.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
