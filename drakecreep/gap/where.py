"""Where the gap of the Drake replay model lies: its held-out residual by regime, frequency band, input, screw side.

:func:`where_gap` replays the held-out runs through the (augmented) Drake model with every parameter fixed and
decomposes what it still does not explain, measured force minus replayed force, with the functions of
:mod:`drakecreep.gap.residuals` (:func:`locate` does the decomposition of replays made elsewhere, e.g. the
``kind: drakecreep`` diagnosis's replays of its augmented params file):

* ``regimes``: share of the residual energy and of the time in each regime (dwell, stick, reversal,
  acceleration, constant speed);
* ``bands``: share of the residual energy per frequency band (Welch PSD over the runs), and its peak;
* ``independence``: the residual-input independence test of system identification (cross-correlation of the
  residual with the reference speed and the known external force, with a 99 % family-wise band): a residual
  correlated with an input is a model error, not noise;
* ``split``: for runs with a linear scale (``x_table``), the position gap before or after the screw;
* ``orders``: the residual against the measured position, pooled over the runs in orders (cycles per screw
  revolution when the lead is known, else per 10 mm of travel; :func:`~drakecreep.gap.residuals.order_spectrum`):
  an effect fixed to the screw or the travel (lead error, cogging) peaks at one order on runs of any speed, where
  its time frequency moves with the speed. A peak alone does not tell it from an effect fixed in time: on short
  runs the bins are coarse (the segment is the runs' travel), and two held-out runs at 25 and 35 mm/s put a
  17.3 Hz force ripple's residual 93 % within a bin of one order peak (the test rig of
  ``tests/gap/test_drive_fit.py``), as much as a lead error's (80 %) or a cogging's (93 %);
* ``fixed``: whether the residual's peak is fixed to the travel or to time, from its peak frequency at constant
  speed run by run against the runs' speeds (:func:`~drakecreep.gap.residuals.fixed_to`): what the order peak
  alone cannot say;
* ``operating``: the residual's RMS and energy by operating point, in five bins each of speed, position and drive
  force (:func:`~drakecreep.gap.residuals.operating_map`);
* ``oscillation``: a sustained oscillation of the measured force that the replay lacks (an unstable real loop,
  :func:`~drakecreep.gap.residuals.sustained_oscillation`), or None.

``diagnose_drake`` stores it as :attr:`~drakecreep.gap.drake_diagnosis.DrakeDiagnosis.where` ("unexplained":
what is left after the claimed effects, and where), ``diagnose_drive`` as
:attr:`~drakecreep.gap.drive_fit.DriveDiagnosis.where`.
"""

from __future__ import annotations

import math

import numpy as np

from drakecreep.gap.drake_replay import make_replay
from drakecreep.gap.residuals import (classify_regimes, fixed_to, frequency_bands, independence, motor_table_split,
                                      operating_map, order_spectrum, regime_shares, sustained_oscillation)

__all__ = ["where_gap", "locate", "where_lines", "where_summary", "order_peak", "fixed_verdict", "period_range",
           "oscillation_line", "ORDER_TRAVEL"]

#: Travel of one cycle [m] of the order spectrum when the screw's lead is not known (EMPS runs): 10 mm.
ORDER_TRAVEL = 1e-2


def where_gap(runs, parameters, *, flexible=False, delay=0.0, lags=25):
    """Decompose the closed-loop replay residual of ``runs`` under a fixed model.

    Parameters
    ----------
    runs : sequence of drakecreep.gap.measured.MeasuredRun
        Held-out runs (p_p_cascade).
    parameters : dict
        Axis parameters of the model (:data:`drakecreep.model.axis.AXIS_PARAMETERS`, SI).
    flexible : bool
        Two-mass axis.
    delay : float
        Computation delay [samples].
    lags : int
        Largest lag of the independence test [samples].

    Returns
    -------
    dict
        ``regimes`` (:func:`~drakecreep.gap.residuals.regime_shares` over all runs), ``bands``
        (:func:`~drakecreep.gap.residuals.frequency_bands`), ``independence`` (per input: ``max_abs``, ``band``,
        ``lag_of_max`` [samples], ``independent``, worst over the runs), ``split`` (per run with a scale), and
        ``force_rms_N`` of the residual, ``oscillation``
        (:func:`~drakecreep.gap.residuals.sustained_oscillation` of the measured and replayed force, or None);
        ``diverged``: the labels of runs whose replay diverged (non-finite), left out of the rest (all of them: no
        regimes, bands or independence, ``force_rms_N`` NaN and ``oscillation`` None); ``orders`` (per
        :data:`ORDER_TRAVEL` of travel), ``operating`` and ``fixed`` as :func:`locate` gives them.
    """
    sims = [make_replay(run, flexible=flexible, delay=delay, free=()).simulate(parameters) for run in runs]
    return locate(runs, sims, table_simulated=flexible, lags=lags)


def locate(runs, sims, *, table_simulated=True, lags=25, lead=None):
    """Decompose the residual of ``runs`` against their replays ``sims`` (:func:`where_gap`'s decomposition).

    Parameters
    ----------
    runs : sequence of drakecreep.gap.measured.MeasuredRun
        Held-out runs, of either controller kind.
    sims : sequence of drakecreep.gap.drake_replay.DrakeReplayResult
        Their replays, in the same order (``force``, ``x_motor`` and ``x_table`` on the runs' samples).
    table_simulated : bool
        The replay's ``x_table`` is the table's own (a two-mass axis: the ``kind: drakecreep`` diagram always);
        False for a rigid axis, whose table is its motor.
    lags : int
        Largest lag of the independence test [samples].
    lead : float, optional
        The screw's lead [m]: orders are then cycles per screw revolution; without it, per
        :data:`ORDER_TRAVEL` of travel.

    Returns
    -------
    dict
        As :func:`where_gap`, with ``fixed`` (:func:`~drakecreep.gap.residuals.fixed_to`), ``orders`` (``cycle_m``, the travel of one cycle, ``peak_order``, ``period_m``
        of the peak, ``peak_share``, ``flat_share``, ``peak_ratio``, ``resolution`` [orders], ``n_segments``;
        ``peak_order`` None
        when no stretch of motion is long enough) and ``operating``
        (:func:`~drakecreep.gap.residuals.operating_map`: ``speed`` [m/s], ``position`` [m] and ``force`` [N]).
    """
    residuals, labels, tests, split, diverged, forces = [], [], {}, {}, [], ([], [])
    motion = ([], [])  # measured position and speed of each run kept
    for run, sim in zip(runs, sims):
        e = run.force - sim.force
        if not np.all(np.isfinite(e)):
            diverged.append(run.label)
            continue
        residuals.append(e)
        speed = np.gradient(run.x_motor, run.dt)
        motion[0].append(np.asarray(run.x_motor, dtype=float))
        motion[1].append(speed)
        forces[0].append(run.force)
        forces[1].append(sim.force)
        labels.append(classify_regimes(run.t, run.x_ref, speed))
        inputs = {"reference speed": np.gradient(run.x_ref, run.dt)}
        if run.f_ext is not None and np.any(run.f_ext):
            inputs["external force"] = run.f_ext
        if e.size >= 4 * lags:
            for name, res in independence(e, inputs, lags=lags).items():
                tests.setdefault(name, []).append(dict(res, run=run.label))
        if run.x_table is not None:
            split[run.label] = motor_table_split(run.x_motor, run.x_table, sim.x_motor,
                                                 sim.x_table if table_simulated else None)
    indep = {}
    for name, results in tests.items():  # the worst run (largest |r| relative to its band), independent in all
        worst = max(results, key=lambda r: r["max_abs"] / r["band"])
        indep[name] = {"max_abs": worst["max_abs"], "band": worst["band"], "lag_of_max": worst["lag_of_max"],
                       "independent": all(r["independent"] for r in results), "run": worst["run"]}
    if not residuals:
        return {"regimes": {}, "bands": None, "independence": {}, "split": {}, "force_rms_N": float("nan"),
                "diverged": diverged, "oscillation": None, "orders": None, "operating": None, "fixed": None}
    flat = np.concatenate(residuals)
    cycle = float(lead) if lead else ORDER_TRAVEL
    spec = order_spectrum(motion[0], motion[1], residuals, cycle, segment="auto")
    orders = {"cycle_m": cycle, "per_revolution": bool(lead), "n_segments": spec["n_segments"],
              "peak_order": spec["peak_order"], "resolution": spec["resolution"], "peak_share": spec["peak_share"],
              "peak_ratio": spec["peak_ratio"], "flat_share": spec["flat_share"],
              "period_m": cycle / spec["peak_order"] if spec["peak_order"] else None}
    operating = operating_map(flat, np.abs(np.concatenate(motion[1])), np.concatenate(motion[0]),
                              np.abs(np.concatenate(forces[0])))
    operating["force"] = operating.pop("load")
    return {"regimes": regime_shares(flat, np.concatenate(labels)), "bands": frequency_bands(residuals, runs[0].dt),
            "independence": indep, "split": split, "force_rms_N": float(np.sqrt(np.mean(flat ** 2))),
            "diverged": diverged, "oscillation": sustained_oscillation(*forces, runs[0].dt), "orders": orders,
            "operating": operating, "fixed": fixed_to(residuals, motion[1], labels, runs[0].dt)}


def where_lines(where):
    """Lines of text (edge units: N, Hz, %)."""
    diverged = where.get("diverged") or []
    gone = (f"the model's replay diverged on held-out run{'s' * (len(diverged) > 1)} {', '.join(diverged)}"
            if diverged else "")
    if where.get("bands") is None:
        return [f"unexplained: not located ({gone})"]
    reg = sorted(where["regimes"].items(), key=lambda kv: -kv[1]["energy_share"])
    lines = [f"unexplained: held-out force residual {where['force_rms_N']:.3g} N rms; by regime: "
             + ", ".join(f"{k.replace('_', ' ')} {100 * v['energy_share']:.0f} % of the energy in "
                         f"{100 * v['time_share']:.0f} % of the time" for k, v in reg if v["time_share"] >= 0.005)
             + (f" ({gone}: left out)" if gone else "")]
    b = where["bands"]
    lines.append("  by frequency: " + ", ".join(f"{r['lo_Hz']:g}-{r['hi_Hz']:.0f} Hz {100 * r['share']:.0f} %"
                                                for r in b["bands"]) + f" (peak {b['peak_hz']:.3g} Hz)")
    o = where.get("orders")
    if o and o["peak_order"]:
        per = (f"cycles per screw revolution, lead {1e3 * o['cycle_m']:g} mm" if o["per_revolution"] else
               f"cycles per {1e3 * o['cycle_m']:g} mm of travel")
        lines.append(f"  by order ({per}; bins of {o['resolution']:.2g}): {order_peak(o)}")
    elif o:
        lines.append("  by order: no stretch of motion long enough")
    fx = where.get("fixed")
    if fx and fx["runs"]:
        peaks = ", ".join(f"{1e3 * r['speed']:.3g} mm/s {r['peak_Hz']:.3g} Hz" for r in fx["runs"])
        verdict = fixed_verdict(fx)
        lines.append(f"  {verdict}; peak at constant speed per run: {peaks} (bins of {fx['resolution_Hz']:.3g} Hz)"
                     if fx["resolution_Hz"] else f"  {verdict}")
    if where.get("operating"):
        lines.append("  by operating point (5 bins each, the bin with the largest rms): " + "; ".join(
            _top_bin(where["operating"][axis], name, scale, unit, where["force_rms_N"])
            for axis, name, scale, unit in (("speed", "speed", 1e3, "mm/s"), ("position", "position", 1e3, "mm"),
                                            ("force", "drive force", 1.0, "N"))))
    for name, r in where["independence"].items():
        verdict = "independent" if r["independent"] else \
            f"CORRELATED (|r| {r['max_abs']:.2f} > band {r['band']:.2f} at lag {r['lag_of_max']} samples, run {r['run']})"
        lines.append(f"  residual vs {name}: {verdict}")
    for label, s in where["split"].items():
        lines.append(f"  {label}: position gap {s['where']} (motor {1e6 * s['motor_rms_m']:.3g} um rms, "
                     f"transmission {1e6 * s['transmission_rms_m']:.3g} um rms)")
    if where.get("oscillation"):
        lines.append("  " + oscillation_line(where["oscillation"], "held-out runs"))
    return lines


def where_summary(where):
    """The figures of a :func:`locate` result that say where the gap lies, as a small plain dict (for benchmark
    rows): ``force_rms_N``; ``regime`` (the regime whose share of the energy most exceeds its share of the time)
    and its two shares; ``bands`` (share per band, lower edge [Hz] as key) and ``peak_hz``; the order spectrum's
    ``order`` (``peak_order``, ``period_m``, ``peak_share``, ``peak_ratio``, ``resolution``, ``cycle_m``); ``fixed``
    (:func:`~drakecreep.gap.residuals.fixed_to`'s verdict);
    ``correlated`` (the inputs the residual is not independent of); ``split`` (run label -> before / after the
    screw / both). Empty for an empty ``where``; without bands (every replay diverged) only ``diverged``.
    """
    if not where:
        return {}
    if where.get("bands") is None:
        return {"diverged": list(where.get("diverged") or [])}
    regimes = {k: v for k, v in where["regimes"].items() if v["time_share"] > 0}
    top = max(regimes, key=lambda k: regimes[k]["energy_share"] / regimes[k]["time_share"]) if regimes else None
    o = where.get("orders") or {}
    return {"force_rms_N": where["force_rms_N"], "diverged": list(where.get("diverged") or []),
            "regime": top, "regime_energy_share": regimes[top]["energy_share"] if top else None,
            "regime_time_share": regimes[top]["time_share"] if top else None,
            "bands": {f"{b['lo_Hz']:g}": b["share"] for b in where["bands"]["bands"]},
            "peak_hz": where["bands"]["peak_hz"],
            "order": {k: o.get(k) for k in ("peak_order", "period_m", "peak_share", "peak_ratio", "resolution",
                                            "cycle_m")} if o else None,
            "fixed": (where.get("fixed") or {}).get("verdict"),
            "correlated": [name for name, r in where["independence"].items() if not r["independent"]],
            "split": {label: v["where"] for label, v in where["split"].items()}}


def order_peak(orders):
    """The order spectrum's peak of a :func:`locate` result as a phrase (edge units: mm, %)."""
    o = orders
    return (f"peak at order {o['peak_order']:.3g}, a {1e3 * o['period_m']:.3g} mm period ({period_range(o)} within a "
            f"bin), {100 * o['peak_share']:.0f} % of the energy within a bin of it (a flat spectrum's "
            f"{100 * o['flat_share']:.0f} %), {o['peak_ratio']:.3g} x its neighbours")


def fixed_verdict(fixed):
    """:func:`~drakecreep.gap.residuals.fixed_to`'s verdict as a phrase (edge unit: mm)."""
    if fixed["verdict"] == "travel":
        return f"fixed to the travel (its frequency grows with the speed: a {1e3 * fixed['period_m']:.3g} mm period)"
    if fixed["verdict"] == "time":
        return "fixed to time (one frequency at every speed)"
    return "fixed to the travel or to time: cannot tell (runs at like speeds, bins too coarse, or peaks of no one effect)"


def period_range(orders):
    """The travel periods within a bin of an order spectrum's peak, as text in mm (``orders``: ``locate``'s)."""
    o = orders
    lo = o["cycle_m"] / (o["peak_order"] + o["resolution"])
    hi = o["cycle_m"] / (o["peak_order"] - o["resolution"]) if o["peak_order"] > o["resolution"] else math.inf
    return f"{1e3 * lo:.3g}-{1e3 * hi:.3g} mm" if math.isfinite(hi) else f"over {1e3 * lo:.3g} mm"


def _top_bin(rows, name, scale, unit, rms):
    top = max(rows, key=lambda r: r["rms"])
    return (f"{name} {scale * top['lo']:.3g}-{scale * top['hi']:.3g} {unit}, {top['rms'] / rms:.2g} x the whole's rms "
            f"({100 * top['energy_share']:.0f} % of the energy in {100 * top['time_share']:.0f} % of the samples)")


def oscillation_line(oscillation, runs="runs"):
    """One sentence on a :func:`~drakecreep.gap.residuals.sustained_oscillation` (edge units: Hz, N, %), of the
    ``runs`` it was found on (e.g. ``"held-out runs"``)."""
    o = oscillation
    return (f"the measured force oscillates at {o['freq_Hz']:.0f} Hz ({o['runs']} of {o['of']} {runs}; "
            f"{o['rms']:.3g} N RMS in its band, {100 * o['share']:.0f} % of the force's variance), the model's "
            f"replay {o['model_rms']:.3g} N: the real loop is unstable (or nearly) where the model is stable. A "
            "replay sample by sample cannot follow an oscillation whose phase is free, so no claim rests on its "
            "samples.")
