"""Self-contained HTML report of the Drake-model gap diagnosis (plots embedded as base64 PNG) and its JSON form."""

from __future__ import annotations

import io
import json
import math

import numpy as np

from drakecreep.files import to_jsonable
from drakecreep.gap.claims import ALPHA
from drakecreep.gap.drake_replay import rms_force_error
from drakecreep.gap.where import fixed_verdict, order_peak, oscillation_line

__all__ = ["EDGE_UNITS", "drake_to_json_dict", "errors_by_run_figure", "ranking_json", "residual_figure", "where_parts",
           "write_drake_report"]


def ranking_json(nominal, nominal_test_errors, ranking):
    """JSON-ready ranking (also written alone, before the greedy augmentation and any late replay)."""
    rows = []
    for r in ranking:
        sc = r.screen
        row = {"effect": r.name, "screened_out": bool(r.screened_out), "passes": bool(r.passes)}
        if sc is not None:
            row["inverse_dynamics"] = {"held_out_force_error_percent": sc.test_error, "gain_points": sc.gain,
                                       "standard_error_points": sc.standard_error,
                                       "log_error_ratio": sc.log_ratio, "log_error_ratio_standard_error": sc.log_ratio_se,
                                       "passes": bool(sc.passes),
                                       "start": sc.start}
            if getattr(sc, "outside", None):  # fitted values outside the effect's bounds: name -> [value, lo, hi]
                row["inverse_dynamics"]["outside_bounds"] = {n: list(v) for n, v in sc.outside.items()}
            if getattr(sc, "alternative_start", None):  # the second closed-loop start (ScreenResult)
                row["inverse_dynamics"]["alternative_start"] = sc.alternative_start
            c = getattr(sc, "constancy", None)
            if c is not None:
                row["inverse_dynamics"]["constancy"] = {"per_run": list(c.per_run), "chi2": c.chi2, "dof": c.dof,
                                                        "p_value": c.p_value, "constant": bool(c.constant)}
        if not r.screened_out:
            from drakecreep.gap.drake_effects import DRAKE_EFFECTS

            names = DRAKE_EFFECTS[r.name].parameters if r.name in DRAKE_EFFECTS else ()
            row["closed_loop"] = {"held_out_force_error_percent": r.fit.test_force_error,
                                  "train_force_error_percent": r.fit.train_force_error,
                                  "gain_points": r.gain, "standard_error_points": r.standard_error,
                                  "log_error_ratio": r.log_ratio, "log_error_ratio_standard_error": r.log_ratio_se,
                                  "threshold_log_error_ratio": r.threshold,
                                  "sign_flip_p": r.p_sign_flip, "level_sign_flip_p": r.level_p_sign_flip,
                                  "level_log_error_ratio": r.level_log_ratio,
                                  "level_log_error_ratio_standard_error": r.level_log_ratio_se,
                                  "threshold_level_log_error_ratio": r.level_threshold,
                                  "claim_rule": r.rule, "level_test_alone": r.level_alone,
                                  "by_fallback_regime": r.fallback,
                                  "piece_log_error_ratio": r.piece_log_ratio,
                                  "piece_sign_flip_p": r.piece_p_sign_flip, "by_pieces": r.pieces,
                                  # its own training-run null (plain, level), when it was held to it (below the
                                  # nominal's; drake_diagnosis._claim_test)
                                  "own_training_run_null": list(r.own_null) or None,
                                  "started_from": r.closed_loop_start or None,
                                  # passes, but a fitted candidate that does not explains more: not claimed
                                  "outranked_by": r.outranked_by or None,
                                  "parameters": {n: r.fit.parameters[n] for n in names},
                                  "delay_samples": r.fit.delay, "seconds": r.fit.seconds,
                                  # which held-out runs carry it: each run's force error against the reference
                                  # it is measured against (an effect one fast run carries shows here)
                                  "held_out_force_error_percent_by_run": _by_run(r, nominal_test_errors)}
            if r.regime:  # the regime it must show in too, or may pass by (DrakeEffect.regime, fallback_regime)
                row["closed_loop"]["regime"] = {"name": r.regime, "log_error_ratio": r.regime_log_ratio,
                                                "log_error_ratio_standard_error": r.regime_log_ratio_se,
                                                "sign_flip_p": r.regime_p_sign_flip}
        rows.append(row)
    shown = ("mass",) + tuple(n for n in nominal.fitted if n != "mass")
    return to_jsonable({"nominal": {"parameters": {n: nominal.parameters[n] for n in shown},
                                    "ci95": nominal.ci95,
                                    "leave_one_run_out_std": nominal.jackknife_std,
                                    "warnings": list(nominal.warnings),
                                    "mass_source": getattr(nominal, "mass_source", None),
                                    "held_out_force_error_percent": rms_force_error(nominal_test_errors),
                                    "held_out_errors": nominal_test_errors},
                        "ranking": rows})


def _by_run(ranked, nominal_test_errors):
    """``{label: {"reference", "candidate", "log_error_ratio"}}``: each held-out run's closed-loop force error [%]
    with the reference a fitted candidate is measured against (its equal-effort refit, else the nominal) and with
    the candidate, and their log ratio (the claim's per-run statistic)."""
    ref = ranked.reference_errors or nominal_test_errors
    out = {}
    for label, errors in ranked.fit.test_errors.items():
        if label not in ref:
            continue
        a, b = float(ref[label]["force"]), float(errors["force"])
        ratio = math.log(a / b) if a > 0 and b > 0 and math.isfinite(a) and math.isfinite(b) else float("nan")
        out[label] = {"reference": a, "candidate": b, "log_error_ratio": ratio}
    return out


def drake_to_json_dict(diagnosis, **extra):
    """JSON-ready form of a :class:`~drakecreep.gap.drake_diagnosis.DrakeDiagnosis` (plus ``extra`` keys:
    ``data``, ``train_runs``, ``test_runs``, ``scored``, ...)."""
    d = ranking_json(diagnosis.nominal, diagnosis.nominal_test_errors, diagnosis.ranking)
    d.update(to_jsonable({
        "model_kind": "drakecreep.measured_axis (Drake replay: P-P cascade + MeasuredAxis)",
        "nominal_friction": diagnosis.friction,
        "claimed": list(diagnosis.claimed),
        "model": diagnosis.model,
        "held_out_errors": diagnosis.test_errors,
        "held_out_force_error_percent": {"nominal": rms_force_error(diagnosis.nominal_test_errors),
                                         "augmented": rms_force_error(diagnosis.test_errors)},
        "not_ranked": diagnosis.not_ranked,
        "unexplained": diagnosis.where,
        "k_se": diagnosis.k_se,
        "training_run_null": {"log_error_ratio": diagnosis.null[0], "level_log_error_ratio": diagnosis.null[1],
                              # each left-out training run's signed move (plain, level), the null their largest size
                              "moves": [list(m) for m in diagnosis.null_moves]},
        "seconds": diagnosis.seconds,
        "summary": diagnosis.summary(),
    }))
    d.update(to_jsonable(extra))
    return d


def _fig_png(fig):
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def _drake_figures(diagnosis, residuals=None):
    import matplotlib.pyplot as plt

    figs = []
    ranked = list(diagnosis.ranking)
    if ranked:
        fig, ax = plt.subplots(figsize=(8, 0.45 * len(ranked) + 1.2))
        y = np.arange(len(ranked))[::-1]
        cl = [r.gain if not r.screened_out else np.nan for r in ranked]
        sc = [r.screen.gain if r.screen is not None else np.nan for r in ranked]
        ax.barh(y + 0.2, cl, 0.4, color=["tab:green" if r.passes else "tab:gray" for r in ranked],
                label=f"closed-loop replay (green: passes, {diagnosis.k_se:.3g} SE of the log error ratio)")
        ax.barh(y - 0.2, sc, 0.4, color="tab:blue", alpha=0.5, label="inverse dynamics (screen)")
        ax.axvline(0, color="k", lw=0.8)
        ax.set_yticks(y, [r.name + (" (screened out)" if r.screened_out else "") for r in ranked])
        ax.set_xlabel("held-out force error decrease [points of %]")
        # one wild screen score must not squash the others: clip the axis to the closed-loop gains' scale
        # (at least +-5 points) and write the clipped values at the edge
        span = max(5.0, 3.0 * np.nanmax(np.abs(np.r_[cl, 0.0])))
        ax.set_xlim(-span, span)
        for yi, v in zip(y, sc):
            if np.isfinite(v) and abs(v) > span:
                ax.text(np.sign(v) * span * 0.98, yi - 0.2, f"{v:+.3g}", va="center", fontsize=7,
                        ha="left" if v < 0 else "right")
        ax.legend(fontsize=8, loc="lower right")
        figs.append((_fig_png(fig), "Which effect: held-out gain against the nominal model, per candidate "
                                    "(green: passes the claim threshold)"))
    if diagnosis.nominal_test_errors:
        figs.append(errors_by_run_figure([
            ("nominal", diagnosis.nominal_test_errors),
            ("augmented: " + (" + ".join(diagnosis.claimed) or "nothing claimed"), diagnosis.test_errors)]))
    if residuals:
        figs.append(residual_figure(residuals))
    return figs


def errors_by_run_figure(series):
    """``(png, caption)``: the closed-loop replay force error of every held-out run, one bar per model of
    ``series`` (``[(legend, {run label: replay errors [%]}), ...]``, the runs of the first). Both diagnoses'
    reports."""
    import matplotlib.pyplot as plt

    labels = list(series[0][1])
    fig, ax = plt.subplots(figsize=(8, 3))
    x = np.arange(len(labels))
    width = 0.8 / len(series)
    for k, (name, errors) in enumerate(series):
        ax.bar(x + width * (k - (len(series) - 1) / 2), [errors[lab]["force"] for lab in labels], width, label=name)
    slanted = len(labels) > 12 or max((len(str(lab)) for lab in labels), default=0) > 6  # a few short labels: level
    ax.set_xticks(x, labels, rotation=30 if slanted else 0, fontsize=8 if slanted else 10)
    ax.set_ylabel("force error [% of ||F||]")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.3 if slanted else -0.12), ncol=len(series))
    return _fig_png(fig), "How far it shrinks: closed-loop replay force error of every held-out run"


def residual_figure(residuals, names=("nominal", "augmented")):
    """``(png, caption)``: one held-out run's measured minus replayed force [N] and motor position [µm] of the
    model before and after the claims (``residuals``: ``{"label", "t", "nominal": {"force", "position"},
    "augmented": {...}}``), ``names`` their legend entries. Both diagnoses' reports."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
    t = residuals["t"]
    for key, lab in zip(("nominal", "augmented"), names):
        axes[0].plot(t, residuals[key]["force"], lw=0.6, label=lab)
        axes[1].plot(t, 1e6 * np.asarray(residuals[key]["position"]), lw=0.6, label=lab)
    axes[0].set_ylabel("force residual [N]")
    axes[1].set_ylabel("position residual [µm]")
    axes[1].set_xlabel("time [s]")
    axes[0].legend(fontsize=8)
    return _fig_png(fig), f"Where: measured minus replayed, held-out run {residuals['label']}"



#: SI unit of a MeasuredAxis parameter -> (factor, unit at the edge): mm/s, mm, N/um in the report
EDGE_UNITS = {"m/s": (1e3, "mm/s"), "m": (1e3, "mm"), "N/m": (1e-6, "N/um")}


def _edge(name, value):
    """``(value, unit)`` of MeasuredAxis parameter ``name`` in the report's units (mm/s, mm, N/um; a lead error's
    amplitudes in um; else SI)."""
    from drakecreep.model.axis import AXIS_UNITS, LEAD_ERROR

    if name in LEAD_ERROR:
        return value * 1e6, "um"
    unit = AXIS_UNITS[name]
    factor, shown = EDGE_UNITS.get(unit, (1.0, unit))
    return value * factor, shown


def where_parts(where):
    """HTML parts of what a model still does not explain on the held-out runs, and where (a ``where`` dict of
    :func:`drakecreep.gap.where.locate`): regimes, frequency bands, residual-input independence, an oscillation,
    orders, fixed to the travel or to time, operating points, before or after the screw. Both diagnoses' reports."""
    from drakecreep.report.html import escape, table

    parts = []
    if where:
        parts.append("<h2>Unexplained: where the augmented model's held-out residual lies</h2>")
        if where.get("diverged"):
            parts.append("<p>The model's replay diverged on held-out run(s) "
                         f"{escape(', '.join(where['diverged']))}; they are left out below.</p>")
    if where and where.get("bands") is not None:
        parts.append(f"<p>Measured minus replayed force, {where['force_rms_N']:.3g} N rms over the held-out runs.</p>")
        parts.append(table(["regime", "share of the residual energy [%]", "share of the time [%]", "rms [N]"],
                           [[k.replace("_", " "), f"{100 * v['energy_share']:.1f}", f"{100 * v['time_share']:.1f}",
                             f"{v['rms']:.3g}"] for k, v in where["regimes"].items()]))
        parts.append(table(["frequency band [Hz]", "share of the residual energy [%]", "rms [N]"],
                           [[f"{b['lo_Hz']:g}-{b['hi_Hz']:.0f}", f"{100 * b['share']:.1f}", f"{b['rms']:.3g}"]
                            for b in where["bands"]["bands"]]))
        rows = [[name, "yes" if r["independent"] else "no", f"{r['max_abs']:.3f}", f"{r['band']:.3f}",
                 str(r["lag_of_max"]), r["run"]] for name, r in where["independence"].items()]
        if rows:
            parts.append("<p>Residual-input independence (cross-correlation over ±25 samples against a 99 % "
                         "family-wise band; a residual correlated with an input is a model error, not noise):</p>")
            parts.append(table(["input", "independent", "largest |r|", "band", "at lag [samples]", "worst run"], rows))
        if where.get("oscillation"):
            parts.append(f"<p><b>Unstable?</b> {escape(oscillation_line(where['oscillation'], 'held-out runs'))}</p>")
        o = where.get("orders")
        if o and o["peak_order"]:
            per = "per screw revolution" if o["per_revolution"] else f"per {1e3 * o['cycle_m']:g} mm of travel"
            parts.append(f"<p>Against the measured position (orders {per}, bins of {o['resolution']:.2g}): "
                         f"{escape(order_peak(o))}. An effect fixed to the screw or the travel peaks at one order on "
                         "runs of any speed, one fixed in time spreads over the orders as the runs' speeds differ; "
                         "bins as coarse as the runs' travel allows, or runs of like speeds, may not show the "
                         "difference.</p>")
        fx = where.get("fixed")
        if fx and fx["runs"] and fx["resolution_Hz"]:
            verdict = fixed_verdict(fx)
            parts.append(f"<p>{escape(verdict[0].upper() + verdict[1:])}; the residual's peak at constant speed, run "
                         f"by run, bins of {fx['resolution_Hz']:.3g} Hz:</p>")
            parts.append(table(["speed [mm/s]", "peak [Hz]"],
                               [[f"{1e3 * r['speed']:.3g}", f"{r['peak_Hz']:.3g}"] for r in fx["runs"]]))
        if where.get("operating"):
            rows = [[name, f"{scale * r['lo']:.3g}-{scale * r['hi']:.3g}", f"{r['rms']:.3g}",
                     f"{100 * r['energy_share']:.1f}", f"{100 * r['time_share']:.1f}"]
                    for axis, name, scale in (("speed", "speed [mm/s]", 1e3), ("position", "position [mm]", 1e3),
                                              ("force", "drive force [N]", 1.0))
                    for r in where["operating"][axis]]
            parts.append(table(["operating point", "bin", "rms [N]", "share of the residual energy [%]",
                                "share of the samples [%]"], rows))
        if where["split"]:
            parts.append(table(["run", "position gap", "motor rms [µm]", "transmission rms [µm]"],
                               [[lab, v["where"], f"{1e6 * v['motor_rms_m']:.3g}", f"{1e6 * v['transmission_rms_m']:.3g}"]
                                for lab, v in where["split"].items()]))
    return parts


def write_drake_report(diagnosis, out_dir, *, residuals=None, title="Sim-to-real gap diagnosis (Drake model)",
                       outset=None, **extra):
    """Write ``diagnosis.html`` and ``diagnosis.json`` of a typed Drake diagnosis into ``out_dir``.

    Parameters
    ----------
    diagnosis : drakecreep.gap.drake_diagnosis.DrakeDiagnosis
    out_dir : path-like
    residuals : dict, optional
        ``{"label", "t", "nominal": {"force", "position"}, "augmented": {...}}`` of one held-out run.
    outset : drakecreep.files.OutputSet, optional
        The output set to write into (its manifest is committed by the caller); default: a new one committed here.
    **extra
        Keys added to the JSON (``data``, ``train_runs``, ``test_runs``, ``scored``, ``log_rate``: how a log at
        another rate than the controller's tick was read, shown under the data line).

    Returns
    -------
    tuple of pathlib.Path
        ``(html_path, json_path)``.
    """
    from drakecreep.files import OutputSet
    from drakecreep.report.html import escape, figure, page, table

    own = outset is None
    if own:
        outset = OutputSet(out_dir, "manifest.json").start()
    data = drake_to_json_dict(diagnosis, **extra)
    json_path = outset.write_text("diagnosis.json", json.dumps(data, indent=1))
    k = diagnosis.k_se
    nom = diagnosis.nominal
    parts = [f"<h1>{escape(title)}</h1>"]
    if extra.get("data"):
        parts.append(f"<p>Data: <code>{escape(str(extra['data']))}</code>; training runs "
                     f"{escape(', '.join(extra.get('train_runs', [])))}; held-out runs "
                     f"{escape(', '.join(extra.get('test_runs', [])))}. Diagnosis {diagnosis.seconds:.0f} s.</p>")
    for line in extra.get("log_rate", ()):  # a log at another rate than the controller's tick: how it was read
        parts.append(f"<p class='note'>{escape(line)}</p>")
    claimed = " + ".join(diagnosis.claimed) or "nothing"
    parts.append(f"<h2>Answer</h2><p class='answer'><b>Claimed: {escape(claimed)}.</b> Held-out force error "
                 f"{rms_force_error(diagnosis.nominal_test_errors):.3f} % (nominal) → "
                 f"{rms_force_error(diagnosis.test_errors):.3f} % (augmented, closed-loop replay).</p>")
    parts.append("<ul>" + "".join(f"<li>{escape(s)}</li>" for s in diagnosis.summary()) + "</ul>")
    parts.append("<p class='note'>A candidate is claimed only when its closed-loop replay of the held-out runs "
                 f"(parameters fixed from the training runs) beats the current model, refitted by the same effort, "
                 f"by more than {k:.3g} standard errors of the per-run log error ratio (or with a sign-flip "
                 f"permutation p value of at most {ALPHA:g}: every held-out run better when there are five), both as the "
                 "errors are and "
                 "with each held-out run's friction scaled to its own level (friction drifts from run to run; "
                 "a candidate that only fits the level the held-out runs happen to have is not claimed; the level "
                 "test alone suffices when the plain mean log ratio is above its training-run null, which needs two "
                 "or more training runs, since drift mixes the plain ratios' signs; a friction "
                 "along the travel, which is a level over a short run, needs one of the two, with the other's mean "
                 "log ratio positive), "
                 + (f"by more than the nominal's held-out log error moves with one training run left out of its fit "
                    f"(the training-run null: {diagnosis.null[0]:.3f}, {diagnosis.null[1]:.3f} with the level), "
                    if getattr(nom, "jackknife", ()) else "")
                 + "where the candidate names a regime it must show in (a time ripple: at constant speed), "
                 "with a positive and significant log ratio of the force error in that regime too (an asymmetric "
                 "friction that fails the tests above is still claimed when one of the two passes, the other's mean "
                 "log ratio positive, and its error at constant speed shrinks so: its fallback regime; a lead "
                 "error, which one or two fast held-out runs may carry alone, is claimed when both its mean log "
                 "ratios exceed their training-run nulls and its log ratio over the quarters of the held-out runs "
                 "is significant), "
                 "and its "
                 "inverse-dynamics fit of the held-out runs' sliding samples beats the nominal's by more than one "
                 "standard error (the screen, on the same log ratio). A candidate that passes is still not claimed "
                 "when a fitted candidate that does not pass has a higher log ratio: the data do not single it out. "
                 "The augmented model is <code>augmented_model.yaml</code> beside this page.</p>")
    parts.append("<h2>Nominal model (training runs: IDIM start, closed-loop output error)</h2>")
    jack = nom.jackknife_std
    parts.append(table(["parameter", "value", "95 % half-width", "std, leave one training run out", "unit"],
                       [[n, f"{_edge(n, nom.parameters[n])[0]:.5g}",
                         f"{_edge(n, nom.ci95.get(n, float('nan')))[0]:.3g}",
                         f"{_edge(n, jack[n])[0]:.3g}" if n in jack else "-", _edge(n, 0.0)[1]]
                        for n in nom.fitted]
                       + ([["mass", f"{nom.parameters['mass']:.5g}", "-", "-", "kg"]] if "mass" not in nom.fitted
                          else [])))
    if "mass" not in nom.fitted:
        how = {"IDIM-IV start": "from inverse dynamics with the closed-loop replay of the least-squares model as "
                                "instruments (IDIM-IV)",
               "IDIM-LS start": "from inverse-dynamics least squares (IDIM-LS)"}
        how = how.get(getattr(nom, "mass_source", None), "given")
        parts.append(f"<p>The mass is {how}; output error does not refine it.</p>")
    if nom.warnings:
        parts.append("<ul>" + "".join(f"<li class='bad'>{escape(w)}</li>" for w in nom.warnings) + "</ul>")
    if diagnosis.null_moves:
        labels = list(extra.get("train_runs", ()))
        if len(labels) != len(diagnosis.null_moves):
            labels = [f"training run {i + 1}" for i in range(len(diagnosis.null_moves))]
        parts.append("<h3>Training-run null: the nominal's held-out log error with one training run left out</h3>")
        parts.append(table(["left-out training run", "move, mean ln(e_k / e)", "with each run's friction level"],
                           [[lab] + [f"{m:+.3f}" if np.isfinite(m) else "-" for m in move]
                            for lab, move in zip(labels, diagnosis.null_moves)]))
        parts.append("<p class='note'>The null is the largest size of these moves. A negative move: the nominal "
                     "fitted without that run replays the held-out runs better. A run that alone excites an effect "
                     "(a drive driven into its knee) biases the nominal so, and the null can then be as large as that "
                     "effect's own gain (docs/gap_benchmark.md, 3ba).</p>")
    rows = []
    for r in diagnosis.ranking:
        sc = r.screen
        scr = "-" if sc is None or not np.isfinite(sc.gain) else \
            f"{sc.gain:+.3f}; x{sc.error_ratio:.3f} ({sc.log_ratio:+.3f} ± {sc.log_ratio_se:.3f})"
        if r.screened_out:
            rows.append([r.name, scr, "screened out", "-", "-", "-", ""])
            continue
        from drakecreep.gap.drake_effects import DRAKE_EFFECTS

        names = DRAKE_EFFECTS[r.name].parameters if r.name in DRAKE_EFFECTS else ()
        params = "; ".join(f"{n} = {value:.4g}" + ("" if unit == "-" else f" {unit}")  # a share: no unit
                           for n in names for value, unit in [_edge(n, r.fit.parameters[n])])
        if r.name == "control_delay":
            params = f"delay = {r.fit.delay:.3g} controller samples"
        if r.diverged:
            rows.append([r.name, scr, "diverged", "-", "-", "no", params])
            continue
        rows.append([r.name, scr, f"{r.fit.test_force_error:.3f}", f"{r.gain:+.3f}",
                     f"x{r.error_ratio:.3f} ({r.log_ratio:+.3f} vs {r.threshold:.3f})"
                     + ("" if not np.isfinite(r.level_log_ratio) else
                        f"; own level {r.level_log_ratio:+.3f} vs {r.level_threshold:.3f}"),
                     ("yes" if r.passes else "no")
                     + (f" (by the {r.regime.replace('_', ' ')} fallback)" if r.fallback else "")
                     + (" (by the held-out runs' pieces)" if r.pieces else "")
                     + (f" (held to its own training-run null, {r.own_null[0]:.3f} / {r.own_null[1]:.3f})"
                        if r.own_null else "")
                     + ("" if r.name in diagnosis.claimed or not r.passes else
                        f" (not claimed: {r.outranked_by}, which does not pass, explains more)" if r.outranked_by
                        else " (not kept by the greedy step)"),
                     params])
    parts.append("<h2>Which effect: ranking on the held-out runs</h2>")
    parts.append(table(["effect", "inverse-dynamics gain [points of %]; error ratio (log ratio ± 1 SE)",
                        "closed-loop held-out force error [%]", "closed-loop gain [points of %]",
                        "error ratio (log ratio vs bar; with each run's own friction level)", "passes alone",
                        "fitted parameters"], rows))
    fitted = [r for r in diagnosis.ranking if not r.screened_out]
    if fitted:
        labels = list(diagnosis.nominal_test_errors)
        by_run = {r.name: _by_run(r, diagnosis.nominal_test_errors) for r in fitted}
        parts.append("<p>Which held-out runs carry each fitted candidate: force error [%] of the run, reference → "
                     "candidate (log ratio; positive: the candidate replays the run better). An effect that only "
                     "some runs excite (a saturating drive: the runs that command the most force) shows in those "
                     "runs alone; the claim needs the mean over the runs.</p>")
        parts.append(table(["effect"] + labels,
                           [[name] + [f"{v[lab]['reference']:.3g} → {v[lab]['candidate']:.3g} "
                                      f"({v[lab]['log_error_ratio']:+.2f})" if lab in v else "-" for lab in labels]
                            for name, v in by_run.items()]))
    parts.append("<h2>How far it shrinks (held-out runs, closed-loop replay)</h2>")
    sig = ("position", "velocity", "acceleration", "force")
    rows = [[lab] + [f"{diagnosis.nominal_test_errors[lab][s]:.4g} → {diagnosis.test_errors[lab][s]:.4g}"
                     for s in sig] for lab in diagnosis.nominal_test_errors]
    parts.append(table(["held-out run"] + [f"{s} error [%] nominal → augmented" for s in sig], rows))
    scored = extra.get("scored")
    if scored:
        parts.append(f"<h2>Scored on {escape(str(scored.get('data', '')))} (every parameter fixed)</h2>")
        rows = [[lab] + [f"{scored['nominal'][lab][s]:.4g} → {scored['augmented'][lab][s]:.4g}" for s in sig]
                for lab in scored["augmented"]]
        parts.append(table(["run"] + [f"{s} error [%] nominal → augmented" for s in sig], rows))
    parts += where_parts(diagnosis.where)
    parts.append("<h2>Never ranked</h2>")
    parts.append(table(["effect", "why"], [[n, why] for n, why in diagnosis.not_ranked.items()]))
    for png, caption in _drake_figures(diagnosis, residuals):
        parts.append(figure(png, caption))
    html_path = outset.write_text("diagnosis.html", page(title, parts))
    if own:
        outset.commit(dict(report=title, html="diagnosis.html", json="diagnosis.json"))
    return html_path, json_path
