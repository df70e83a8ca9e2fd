"""A self-contained HTML servo-loop report: parameters, margins, Bode, Nyquist, loci, pole map, simulations.

One file (``index.html``, plots embedded as base64 PNG) a person can hand to a colleague, plus the same
numbers as ``margins.json`` beside it. Everything is computed from the same Drake diagram the
simulation runs (:mod:`drakecreep.servo.linearize`, :mod:`drakecreep.servo.loops`, :mod:`drakecreep.servo.polemap`,
:func:`drakecreep.sim.simulation.simulate`, :mod:`drakecreep.paper.creep`).
"""

import datetime
import html
import json
import math
import time
from pathlib import Path

import numpy as np

from drakecreep.paper import creep

from drakecreep.report import loop_plots
from drakecreep.errors import InputError
from drakecreep.files import OutputSet, to_jsonable
from drakecreep.report.html import figure, page, table
from drakecreep.servo.loops import LOOPS, analyze_loops, resonance_text
from drakecreep.model.motor import motor_inertia
from drakecreep.params import params_to_dict, with_value
from drakecreep.servo.polemap import friction_slope_crossings, parameter_locus, pole_map
from drakecreep.scenario import Scenario
from drakecreep.model.screw import screw_inertia

__all__ = ["build_report", "check_sliding", "MARGIN_ROWS", "LOCI", "CROSSING_SPEEDS"]

#: rows of the margins table: key, label, format
MARGIN_ROWS = (
    ("gain_margin_dB", "gain margin (dB)", "{:.1f}"),
    ("phase_margin_deg", "phase margin (deg)", "{:.1f}"),
    ("delay_margin_ms", "delay margin (ms)", "{:.3g}"),
    ("crossover_Hz", "gain crossover (Hz)", "{:.3g}"),
    ("gain_crossovers_Hz", "all gain crossovers (Hz)", None),
    ("phase_crossover_Hz", "phase crossover (Hz)", "{:.3g}"),
    ("bandwidth_Hz", "closed-loop bandwidth, -3 dB (Hz)", "{:.3g}"),
    ("ms_peak", "sensitivity peak Ms", "{:.3f}"),
    ("ms_frequency_Hz", "frequency of Ms (Hz)", "{:.3g}"),
    ("closed_loop_stable", "closed loop stable", None),
    ("open_loop_unstable_poles", "open-loop unstable poles", None),
)

#: the root loci: parameter and values (stiffness scale, feed [m/s], table mass [kg]), at the operating feed
LOCI = (("stiffness", np.geomspace(0.25, 4.0, 25)), ("feed", np.geomspace(0.02e-3, 3e-3, 40)),
        ("mass", np.geomspace(10.0, 400.0, 25)))
#: feeds [m/s] bracketing the speeds where a pole crosses the imaginary axis
CROSSING_SPEEDS = np.geomspace(0.005e-3, 3e-3, 30)


def check_sliding(params, load_case, feeds, source="the params"):
    """Raise :class:`InputError` unless the drive slides steadily wherever the report linearizes it: at ``feeds``
    [m/s], the loci's (:data:`LOCI`) and the crossings' (:data:`CROSSING_SPEEDS`), its force within the drive's
    limit. A params file whose drive cannot hold its load and friction was refused in the loci, after the loop
    analysis, as 'feed: got 2e-05' (a speed of the feed locus, in m/s)."""
    from drakecreep.model.steady import drive_limit, sliding_overload

    speeds = dict(LOCI)["feed"]
    cases = [(params, v, None) for v in (*feeds, *speeds, *CROSSING_SPEEDS)]
    cases += [(with_value(params, "table.mass", float(m)), feeds[0], float(m)) for m in dict(LOCI)["mass"]]
    lo, hi = 1e3 * min(*feeds, *speeds, *CROSSING_SPEEDS), 1e3 * max(*feeds, *speeds, *CROSSING_SPEEDS)
    for p, v, mass in cases:
        overload = sliding_overload(p, Scenario(feed=float(v), load_case=load_case))
        if overload is not None:
            force, limit = overload
            where = f"{1e3 * v:.3g} mm/s" + (f" with a table mass of {mass:.3g} kg (the mass locus)" if mass else "")
            raise InputError("params", f"{source}, load case {load_case}: {force:.4g} N to slide at {where}",
                             f"a drive whose limit {limit:.4g} N ({drive_limit(p)[1]}) holds it "
                             f"sliding at the report's feeds, {lo:.3g} to {hi:.3g} mm/s, and table masses, "
                             f"{dict(LOCI)['mass'][0]:g} to {dict(LOCI)['mass'][-1]:g} kg")


def _img(path):
    return figure(path)


def _fmt(value, fmt):
    if isinstance(value, bool):
        return "yes" if value else '<span class="bad">NO</span>'
    if isinstance(value, (list, tuple)):
        return ", ".join(f"{v:.3g}" for v in value) or "-"
    if fmt is None:
        return html.escape(str(value))
    if isinstance(value, float) and not math.isfinite(value):
        return "inf" if value > 0 else ("-inf" if value < 0 else "-")
    return fmt.format(value)


def _table(header, rows):
    return table(header, rows, raw=True)


def build_report(params, out_dir, *, feed=1e-3, load_case=3, low_feed=1e-4, step_feed=10e-3,
                 source="preset paper", sim_grid=(6, 6), map_size=(16, 20), workers=1):
    """Compute everything and write ``index.html`` (self-contained), ``margins.json`` and the PNGs.

    Parameters
    ----------
    params : drakecreep.params.DriveParams
    out_dir : str or Path
    feed : float
        Operating feed (m/s) of the loop analysis (the paper's 1 mm/s by default).
    load_case : int
    low_feed : float
        Feed (m/s) of the low-speed simulation and of the pole map (on the falling Stribeck branch).
    step_feed : float
        Size (m/s) of the simulated speed step.
    source : str
        Where the parameters came from (shown in the report).
    sim_grid : (int, int) or None
        Coarse stiffness x damping grid simulated for the pole map's creep markers.
    map_size : (int, int)
        Stiffness x damping points of the pole map.
    workers : int
        Processes for the ``sim_grid`` simulations (:func:`~drakecreep.servo.polemap.pole_map`).

    Returns
    -------
    dict
        ``html``, ``json`` paths and ``timings`` (s per stage, ``total``).
    """
    for name, v in (("feed", feed), ("low_feed", low_feed), ("step_feed", step_feed)):
        Scenario(feed=v, load_case=0)  # validates the speed
        if v <= 0:
            raise InputError(name, v, "> 0")
    params.load_case(load_case)
    check_sliding(params, load_case, (feed, low_feed), source)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    timings = {}
    t_start = time.perf_counter()

    def lap(name, t0):
        timings[name] = time.perf_counter() - t0
        return time.perf_counter()

    t = time.perf_counter()
    scenario = Scenario(feed=feed, load_case=load_case)
    analysis = analyze_loops(params, scenario)
    summary = analysis.summary()
    op = analysis.op
    t = lap("loops", t)

    low = Scenario(feed=low_feed, load_case=load_case)
    loci = [parameter_locus(params, scenario, name, values) for name, values in LOCI]
    crossings = {m: friction_slope_crossings(params, load_case, CROSSING_SPEEDS, m) for m in ("mechanism", "closed_loop")}
    t = lap("loci", t)
    pm = pole_map(params, low, k_scales=np.geomspace(0.25, 4.0, map_size[0]), n_damping=map_size[1],
                  sim_grid=sim_grid, workers=workers)
    t = lap("pole_map", t)

    from drakecreep.sim.simulation import simulate

    p_step = with_value(with_value(params, "simulation.acceleration_time", 0.0), "simulation.steady_start", 0.15)
    step = simulate(p_step, Scenario(feed=step_feed, load_case=load_case, duration=0.3))
    p_low = with_value(params, "simulation.steady_start", 0.5)
    low_run = simulate(p_low, Scenario(feed=low_feed, load_case=load_case, duration=1.5))
    t = lap("simulations", t)

    # critical speed (paper eq. 11) as 'drakecreep critical' gives it: the lumped drive with the friction the model
    # applies to the moving mass (with the nut's drag on the screw the guides' alone; the loop analysis above lumps
    # the nut on the table instead, an approximation of the linearization, which gave 8.7 mm/s here against
    # critical's 0.52 mm/s on the paper preset)
    from drakecreep.model.lumped import lumped

    drive = lumped(params, load_case)
    condition = creep.creep_condition(drive, feed)
    v0, v0_sc = condition.critical_speed, condition.critical_speed_self_consistent
    t = lap("creep", t)

    fmt_cross = ", ".join(f"{v * 1e3:.3g}" for v in crossings["closed_loop"]["pole"]) or "none"
    th_cross = ", ".join(f"{v * 1e3:.3g}" for v in crossings["closed_loop"]["theory"]) or "none"
    # the files form one output set: the old manifest goes first, every file is replaced atomically, and
    # manifest.json, written last, names the files of this run (a kill part way leaves no manifest)
    outset = OutputSet(out, "manifest.json").start()
    png = {}
    png["bode"] = outset.write("bode.png", lambda p: loop_plots.plot_bode(analysis, p))
    png["nyquist"] = outset.write("nyquist.png", lambda p: loop_plots.plot_nyquist(analysis, p))
    png["gain_locus"] = outset.write("root_locus_gain.png", lambda p: loop_plots.plot_gain_locus(analysis, p))
    png["loci"] = outset.write("root_locus_parameters.png", lambda p: loop_plots.plot_parameter_loci(
        loci, p,
        labels={"stiffness": "stiffness factor", "feed": "feed, mm/s", "mass": "table mass, kg"},
        crossings=f"axis crossings at {fmt_cross} mm/s; C + C1 = 0 at {th_cross} mm/s",
    ))
    png["pole_map"] = outset.write("pole_map.png", lambda p: loop_plots.plot_pole_map(pm, p))
    png["sims"] = outset.write("simulations.png", lambda p: loop_plots.plot_step_and_feed(step, low_run, p))
    t = lap("plots", t)

    payload = to_jsonable(dict(
        source=source, feed_mm_s=feed * 1e3, load_case=load_case, margins=summary,
        critical_speed_mm_s=v0 * 1e3 if math.isfinite(v0) else None,
        critical_speed_self_consistent_mm_s=v0_sc * 1e3 if math.isfinite(v0_sc) else None,
        friction_slope_crossings_mm_s={m: {k: [x * 1e3 for x in v] for k, v in c.items()} for m, c in crossings.items()},
        low_feed=low_run.summary(), step=step.summary(),
        pole_map_agreement=pm.agreement() if len(pm.sim_creep) else None,
    ))
    json_path = outset.write_text("margins.json", json.dumps(payload, indent=2) + "\n")

    html_text = _html(params, source, analysis, summary, op, crossings, pm, step, low_run, drive, condition, png,
                      low_feed, timings)
    timings["total"] = time.perf_counter() - t_start
    html_text = html_text.replace("@@TOTAL@@", f"{timings['total']:.1f}")
    html_path = outset.write_text("index.html", html_text)
    outset.commit(dict(report="servo-loop report", source=source, html="index.html", json="margins.json"))
    return dict(html=html_path, json=json_path, timings=timings, pngs=png)


def _param_rows(params, op):
    r = params.screw.lead / (2 * math.pi)
    J = motor_inertia(params.motor, screw_inertia(params.screw))
    g = params.controller
    f = params.friction
    return [
        ("screw lead Ph", f"{params.screw.lead * 1e3:g} mm"),
        ("axial stiffness K of the chain (at the operating point)", f"{op.stiffness * 1e-6:.4g} N/um"),
        ("axial damping C of the chain", f"{op.damping:.4g} N s/m"),
        ("moving mass M (table + nut)", f"{op.mass:.4g} kg"),
        ("motor-side inertia J, reflected J/r^2", f"{J:.3g} kg m^2, {J / r**2:.4g} kg"),
        ("current loop time constant", f"{params.motor.current_loop_time_constant * 1e3:g} ms"),
        ("friction law", f.law),
        ("Coulomb / breakaway friction Fc / Fs (load case" + (
            "; the ball nut's, on the screw, lumped with the guides' on the table for the linear analysis)"
            if f.nut_friction_on == "screw" else ")"), f"{op.Fc:.4g} N / {op.Fs:.4g} N"),
        ("Stribeck velocity vs, viscous Fv", f"{f.stribeck_velocity * 1e3:g} mm/s, {f.viscous:g} N s/m"),
        ("kv, ki (velocity PI)", f"{g.velocity_gain:.4g} N s/m, {g.velocity_integral_gain:.4g} N/m "
                                 f"(corner {g.velocity_integral_gain / g.velocity_gain / 2 / math.pi:.3g} Hz)"),
        ("kp (position), velocity feedforward", f"{g.position_gain:g} 1/s, {g.velocity_feedforward:g}"),
        ("position feedback", g.position_feedback),
        ("controller as configured", "sampled" if g.sampled else "continuous"),
        ("velocity / position sample period", f"{g.velocity_period * 1e3:g} ms / {g.position_period * 1e3:g} ms"),
    ]


def _speed(v, missing):
    """A speed in mm/s for the report's tables, ``missing`` where it is not finite."""
    return f"{v * 1e3:.4g} mm/s" if math.isfinite(v) else missing


def _html(params, source, analysis, summary, op, crossings, pm, step, low_run, drive, condition, png, low_feed,
          timings):
    import yaml

    main = summary["controller"]
    on_mass = ("the guides alone (the ball nut&#39;s drag acts on the screw, on the motor side of the spring)"
               if params.friction.nut_friction_on == "screw" else "the guides and the ball nut")
    variants = [main] + [v for v in analysis.margins if v != main]
    header = ["measure"] + [f"{loop} loop, {v}" for loop in LOOPS for v in variants]
    rows = []
    for key, label, fmt in MARGIN_ROWS:
        rows.append([label] + [_fmt(analysis.margins[v][loop][key], fmt) for loop in LOOPS for v in variants])
    cost = summary.get("sampling_phase_cost_deg")
    cost_text = ""
    if cost:
        def said(loop):  # (None: the loop is unstable when closed, so it has no margins to take a difference of)
            return "n/a (unstable when closed)" if cost[loop] is None else f"<b>{cost[loop]:.1f} deg</b>"

        cost_text = (f"<p>Sampling and hold cost {said('velocity')} of phase margin in the velocity loop "
                     f"and {said('position')} in the position loop (continuous minus sampled).</p>")
    mech = crossings["mechanism"]
    whole = crossings["closed_loop"]

    def mm(vals):
        return ", ".join(f"{v * 1e3:.4g}" for v in vals) or "none"

    zoom = resonance_text(analysis.resonance_Hz, analysis.resonance_damping, ".4g")
    cl = analysis.closed_loop_poles
    worst = cl[np.argmax(cl.real)]
    lm, sm_ = low_run.metrics, step.metrics
    n_creep = int(np.sum(pm.sim_creep)) if len(pm.sim_creep) else 0
    agree = pm.agreement() if len(pm.sim_creep) else {}
    yaml_text = yaml.safe_dump(params_to_dict(params), sort_keys=False)
    now = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    parts = [
        "<h1>Feed-drive servo loops: margins, loci and creep</h1>",
        f"<p>Parameters: <b>{html.escape(source)}</b>. Operating point: feed <b>{op.feed * 1e3:g} mm/s</b>, "
        f"load case <b>{analysis.scenario.load_case}</b>. Generated {now} by <code>drakecreep report</code> in "
        f"@@TOTAL@@ s.</p>",
        "<div class='note'>All loop numbers come from one Drake diagram (the same systems the simulation runs), "
        "linearized by AutoDiff at steady sliding (<code>FirstOrderTaylorApproximation</code>; the feed ramp is the "
        "trajectory, the model describes deviations from it). The sampled variant discretizes that linearization "
        "with a zero-order hold at the velocity period, takes the speed as the backward difference of the encoder "
        "angle and lifts the inner loop to the position period (exact for this multirate cascade).</div>",
        "<h2>Parameters used</h2>",
        _table(["quantity", "value"], _param_rows(params, op)),
        f"<details><summary>full parameter set (YAML, SI)</summary><pre>{html.escape(yaml_text)}</pre></details>",
        "<h2>Operating point</h2>",
        _table(["quantity", "value"], [
            ("spring force = Fx + F(v)", f"{op.spring_force:.4g} N"),
            ("friction force F(v)", f"{op.friction_force:.4g} N"),
            ("friction slope C1 = dF/dv", f"{op.friction_slope:.4g} N s/m"),
            ("paper damping ratio (C + C1) / 2 sqrt(KM)", f"{op.zeta:.4g}"),
            ("first mechanical resonance (plant, loops open)", zoom),
            ("rightmost closed-loop pole (continuous controller)", f"{worst.real:.4g} +- {abs(worst.imag):.4g}j 1/s"),
        ]),
        "<h2>Margins</h2>",
        _table(header, rows),
        cost_text,
        "<p>Velocity loop: broken at the speed feedback with the position loop open. Position loop: broken at the "
        "position feedback with the velocity loop closed. Delay margin: the smallest, over all gain crossovers, "
        "of the extra lag that brings the phase to -180 deg. The screw resonance lifts the velocity loop's gain "
        "above 0 dB again near the resonance (phase-stabilized), which is why it has more than one gain crossover "
        "and why its delay margin is set there rather than at the nominal crossover.</p>",
        "<h2>Bode</h2>", _img(png["bode"]),
        "<h2>Nyquist</h2>", _img(png["nyquist"]),
        "<h2>Root locus versus the velocity-loop gain</h2>",
        "<p>Closed-loop poles of the velocity loop as both PI gains are scaled by a common factor (the PI corner "
        "stays).</p>", _img(png["gain_locus"]),
        "<h2>Root loci versus physical parameters</h2>",
        "<p>Poles of the whole linearized drive (continuous controller) as one parameter varies: the stiffness of "
        "the screw chain, the feed speed (which moves the friction slope C1 along the Stribeck curve) and the "
        "table mass.</p>", _img(png["loci"]),
        "<h2>Friction slope and the imaginary axis</h2>",
        _table(["model", "C + C1 = 0 at (mm/s)", "rightmost pole crosses the axis at (mm/s)"], [
            ["paper mechanism (motor motion prescribed)", mm(mech["theory"]), mm(mech["pole"])],
            ["whole servo loop", mm(whole["theory"]), mm(whole["pole"])],
        ]),
        f"<p>With a static friction law the mechanism's pole crosses exactly where C + C1 changes sign (paper eq. 2; "
        f"checked in the tests). With the {html.escape(params.friction.law)} law used here "
        + ("the bristle state adds its own dynamics: at the resonance the friction acts with the bristle damping "
           "sigma1 rather than the static slope, so the crossing moves, and at very low speed the bristles behave "
           "like a spring and re-stabilize the mode. " if params.friction.law == "lugre" else "")
        + "In the whole servo loop the motor side is not a prescribed motion but a controlled inertia; the "
        "crossing therefore differs from the paper's condition, and the table above shows by how much.</p>",
        "<h2>Pole map: stiffness x damping, with the paper's creep condition</h2>", _img(png["pole_map"]),
        f"<p>Plane at the low-speed feed {low_feed * 1e3:g} mm/s (on the falling Stribeck branch, so negative "
        "effective damping is reachable). K is varied by scaling every stiffness of the screw chain; C + C1 through "
        "the viscous friction coefficient. Colour: real part of the rightmost pole of the whole loop. "
        + (f"Like the loop analysis, the map and its simulations lump the ball nut's friction on the table, so its "
           f"paper condition uses their whole friction drop (Fs - Fc = {pm.friction_drop:.3g} N), not the guides' "
           "of the critical speed below. " if params.friction.nut_friction_on == "screw" else "")
        + (f"Markers: {len(pm.sim_creep)} nonlinear simulations (sampled controller, 1 s each), {n_creep} of them "
           f"creep; simulated creep agrees with the whole-loop linear boundary at {agree['linear']} of "
           f"{agree['points']} points and with the paper's condition at {agree['paper']} of {agree['points']}. "
           if len(pm.sim_creep) else "")
        + "</p><div class='note'><b>Where the boundaries disagree, and why.</b> The paper's D<sup>2</sup> = 4 pi "
        "zeta lies far above C + C1 = 0: it asks whether the first slip after a breakaway from <i>static</i> "
        "friction decays (a large-signal condition involving the friction drop Fs - Fc), while the linear "
        "boundaries ask whether small deviations from steady sliding grow. Between the two lines the paper "
        "predicts creep although steady sliding is linearly stable; the simulations show which of the two the "
        "modelled drive follows here. The whole-loop linear boundary lies below C + C1 = 0 because the velocity "
        "loop damps the motor side and the table is not driven by a prescribed motion as in the paper's Fig. 2.</div>",
        "<h2>Simulations (nonlinear model, sampled controller, quantized sensors)</h2>", _img(png["sims"]),
        _table(["run", "max fluctuation (mm/s)", "fluctuation rate (%)", "stick fraction (%)", "stick-slip cycles"], [
            [f"speed step {step.scenario.feed * 1e3:g} mm/s"] + _metric_cells(sm_),
            [f"low-speed feed {low_run.scenario.feed * 1e3:g} mm/s"] + _metric_cells(lm),
        ]),
        "<h2>Critical speed (paper eq. 11)</h2>",
        f"<p>As <code>drakecreep critical</code> gives it: the friction on the moving mass is the one the model "
        f"applies to the table, {on_mass}: "
        f"Fs {drive.breakaway:.4g} N, Fd {drive.coulomb:.4g} N; K {drive.stiffness * 1e-6:.4g} N/um, "
        f"C {drive.damping:.4g} N s/m, M {drive.mass:.4g} kg.</p>",
        _table(["quantity", "value"], [
            ("C1 = dF/dv at the operating feed", f"{condition.friction_slope:.4g} N s/m"),
            ("zeta, D, D0 = sqrt(4 pi zeta) at the operating feed", f"{condition.zeta:.4g}, {condition.D:.4g}, "
             + ("n/a" if math.isnan(condition.D0) else f"{condition.D0:.4g}")),
            ("v0 with C1 taken at the operating feed", _speed(condition.critical_speed, "n/a (C + C1 <= 0)")),
            ("v0 with C1 taken at v0 (self-consistent)", _speed(condition.critical_speed_self_consistent, "n/a")),
            (f"simulated creep at the low-speed feed ({low_run.scenario.feed * 1e3:g} mm/s)",
             "n/a" if lm is None else "yes" if lm.creep else "no"),
            ("linearized whole loop unstable between (mm/s)", mm(whole["pole"])),
        ]),
        "<p>Equation 11 puts the onset of creep where the paper's large-signal condition is met; the linearized "
        "loop only says where steady sliding stops being stable to small deviations. A drive can slide steadily "
        "below v0 when the servo loop damps the motor side (compare the pole map's simulated markers).</p>",
    ]
    return page("drakecreep servo-loop report", parts)


def _metric_cells(m):
    if m is None:
        return ["-"] * 4
    return [f"{m.max_fluctuation * 1e3:.4g}", f"{m.fluctuation_rate * 100:.3g}", f"{m.stick_fraction * 100:.3g}",
            f"{m.stick_slip_cycles}"]
