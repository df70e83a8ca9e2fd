"""Self-contained HTML report of the ``drakecreep`` kind's gap diagnosis (the project's own Drake model and params
file, :func:`drakecreep.gap.drive_fit.diagnose_drive`), plots embedded as base64 PNG.

What ``drakecreep diagnose --out`` writes beside ``augmented_params.yaml``, ``diagnosis.json`` and ``summary.txt``
for runs of ``controller: {kind: drakecreep}``: the answer first (what is claimed, how far the held-out force error
shrinks), then the fitted params file fields with their intervals, each candidate's training and held-out tests,
every held-out run's errors, and where the augmented model's residual lies (:func:`where_parts`, shared with the
``p_p_cascade`` kind's report).
"""

from __future__ import annotations

import numpy as np

from drakecreep.gap.claims import POOLED_FACTOR
from drakecreep.gap.drake_replay import rms_force_error
from drakecreep.gap.drive_fit import MIN_TRAIN_SHARE, NOT_BOUNDED, claims_withheld
from drakecreep.report.gap_report import EDGE_UNITS, _fig_png, errors_by_run_figure, residual_figure, where_parts

__all__ = ["edge_value", "write_drive_report"]

def edge_value(value, unit):
    """``(value, unit)`` of an SI field value in the units feed-drive engineers read (:data:`EDGE_UNITS`: mm/s,
    N/um, a length in mm, or in um when it is below 1 mm); other units as they are."""
    if unit == "m" and abs(value) < 1e-3:
        return value * 1e6, "um"
    factor, shown = EDGE_UNITS.get(unit, (1.0, unit))
    return value * factor, shown


def _times_null(rt):
    """``"85.7 × null, "``: a replay test's pooled shrink as a multiple of its run-to-run null ("" without a null)."""
    return f"{rt['shrink'] / rt['threshold']:.1f} × null, " if rt.get("threshold") else ""


def _with_unit(value, unit):
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        return str(value)
    v, u = edge_value(float(value), unit)
    return f"{v:.4g}" + ("" if u in ("", "-") else f" {u}")


#: The bar of a candidate that improves the held-out replay with less training gain than a cause needs.
_UNDER_FLOOR = "tab:olive"


def _colour(candidate):
    """A candidate's bar: green if claimed on its held-out test, olive if it improves the replay under the training
    gain a cause needs, grey otherwise."""
    return "tab:green" if candidate.passes else _UNDER_FLOOR if candidate.improves else "tab:gray"


def _gain_figure(ranked):
    """Each candidate's held-out force gain beside its bar; green where it passes, hatched where it was decided on
    the screw's transmission (its force gain may then sit under its bar)."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    fig, ax = plt.subplots(figsize=(8, 0.45 * len(ranked) + 1.2))
    y = np.arange(len(ranked))[::-1]
    bars = ax.barh(y + 0.2, [c.gain for c in ranked], 0.4,
                   label=f"held-out gain (green: passes, over its bar or by a pooled shrink > {POOLED_FACTOR:g} × its "
                         "null)",
                   color=[_colour(c) for c in ranked])
    for bar, c in zip(bars, ranked):
        if c.on_transmission:
            bar.set_hatch("//")
            bar.set_edgecolor("k")
    ax.barh(y - 0.2, [c.threshold for c in ranked], 0.4, color="tab:red", alpha=0.4,
            label="its bar (t quantile x standard error of the per-run gains)")
    handles, _ = ax.get_legend_handles_labels()
    handles[0] = Patch(facecolor="tab:green", label=handles[0].get_label())  # not the first bar's hatch
    if any(c.improves and not c.passes for c in ranked):
        handles.append(Patch(facecolor=_UNDER_FLOOR,
                             label=f"improves the replay, but removes under {100 * MIN_TRAIN_SHARE:.0f} % of the "
                                   "training error: not claimed"))
    if any(c.on_transmission for c in ranked):
        handles.append(Patch(facecolor="white", edgecolor="k", hatch="//",
                             label="decided on the screw's transmission (linear scale), not on this force gain"))
    ax.axvline(0, color="k", lw=0.8)
    ax.set_yticks(y, [c.name for c in ranked])
    ax.set_xlabel("held-out force error decrease [points of %]")
    # under the figure, whose axes and labels the layout fits first (its tight bounding box grows to hold the
    # legend): inside the axes it hid the last candidates' bars
    fig.tight_layout()
    ax.legend(handles=handles, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, 0.0),
              bbox_transform=fig.transFigure)
    return fig


def _figures(result):
    figs = []
    ranked = [c for c in result.candidates if c.test_errors]
    if ranked:
        caption = "Which effect: each fitted candidate's held-out gain against its bar"
        if any(c.on_transmission for c in ranked):
            caption += " (hatched: decided on the screw's transmission, the force's gain and bar shown beside it)"
        figs.append((_fig_png(_gain_figure(ranked)), caption))
    if result.nominal_test_errors:
        figs.append(errors_by_run_figure([
            ("params file", result.prior_test_errors), ("fitted", result.nominal_test_errors),
            ("augmented: " + (" + ".join(result.claimed) or "nothing claimed"), result.test_errors)]))
    if result.residuals:
        figs.append(residual_figure(result.residuals, ("fitted", "augmented")))
    return figs


def write_drive_report(result, outset, *, title="Sim-to-real gap diagnosis (the project's Drake model)",
                       scored=None, **extra):
    """Write ``diagnosis.html`` of a :class:`drakecreep.gap.drive_fit.DriveDiagnosis` into an output set.

    Parameters
    ----------
    result : drakecreep.gap.drive_fit.DriveDiagnosis
    outset : drakecreep.files.OutputSet
        The output set to write into (its manifest is committed by the caller).
    title : str
    scored : dict, optional
        ``{"data": name, "errors_percent": {run label: replay errors [%]}}`` of the augmented params replayed,
        fixed, on another file.
    **extra
        ``data``, ``train_runs``, ``test_runs`` (shown at the top).

    Returns
    -------
    pathlib.Path
        The HTML file.
    """
    from drakecreep.params import field_unit
    from drakecreep.report.html import escape, figure, page, table

    parts = [f"<h1>{escape(title)}</h1>"]
    if extra.get("data"):
        parts.append(f"<p>Data: <code>{escape(str(extra['data']))}</code>; training runs "
                     f"{escape(', '.join(extra.get('train_runs', [])))}; held-out runs "
                     f"{escape(', '.join(extra.get('test_runs', [])))}. Diagnosis {result.seconds:.0f} s, "
                     f"{result.simulations} closed-loop replays of the Drake diagram.</p>")
    claimed = " + ".join(result.claimed) or "nothing"
    parts.append(f"<h2>Answer</h2><p class='answer'><b>Claimed: {escape(claimed)}.</b> Held-out force error "
                 f"{rms_force_error(result.prior_test_errors):.3f} % (params file) → "
                 f"{rms_force_error(result.nominal_test_errors):.3f} % (fitted) → "
                 f"{rms_force_error(result.test_errors):.3f} % (augmented, closed-loop replay)"
                 + (": the runs oscillate where the model does not, so these are the oscillation's errors and any "
                    "claim is made on the held-out spectrum" if claims_withheld(result.oscillation) else "")
                 + ". The augmented params file is <code>augmented_params.yaml</code> beside this page "
                 "(<code>drakecreep simulate/margins/report --params</code> take it).</p>")
    # the claim's reason when nothing is claimed, what is left unexplained, the hints, a note on the bar (the
    # headline has the rest), and the warnings that qualify every claim (a saturated command, a contradicted mass)
    parts.append("<ul>" + "".join(f"<li class='bad'>{escape(c)}</li>" for c in result.caveats)
                 + "".join(f"<li>{escape(line.strip())}</li>" for line in result.summary()
                           if line.startswith(("claimed: nothing", "hint", "unexplained", "explained"))
                           or line.strip().startswith("note:")) + "</ul>")
    parts.append("<p class='note'>A candidate is claimed only when it lowers the training runs' force error, its "
                 "closed-loop replay of the held-out runs (parameters fixed from the training runs) beats the fitted "
                 "params file by more than the t quantile times the standard error of the per-run gains (or its pooled "
                 f"shrink exceeds {POOLED_FACTOR:g} run-to-run nulls: a real effect's per-run gains can differ by "
                 "orders of magnitude), and the "
                 "pooled held-out force-error energy shrinks by more than the run-to-run null (the largest change "
                 "when the uncertain fields are refitted with one training run left out"
                 + ("" if result.replay_null is None else f": {100 * result.replay_null:.2f} %")
                 + f"), with most held-out runs better; and it must remove at least {100 * MIN_TRAIN_SHARE:.0f} % of "
                 "the training error, the share a cause of the gap explains (one that improves the replay with less "
                 "is listed, not claimed).</p>")
    parts.append("<h2>Fitted params file fields (training runs, closed-loop output error)</h2>")
    prior = result.prior
    parts.append(table(["field", "value", "95 % interval", "params file"],
                       [[f.path, _with_unit(f.value, f.unit),
                         f"{_with_unit(f.lower, f.unit)} – {_with_unit(f.upper, f.unit)}" if f.bounded()
                         else NOT_BOUNDED, _with_unit(f.prior, f.unit)] for f in result.fitted]))
    if result.warnings:
        parts.append("<ul>" + "".join(f"<li class='bad'>{escape(w)}</li>" for w in result.warnings) + "</ul>")
    rows = []
    for c in result.candidates:
        fitted = bool(c.values or c.test_errors)
        rt = c.replay or {}
        rows.append([c.name, f"{100 * c.train_gain:+.2f}" if fitted else "-",
                     f"{c.gain:+.3f} (bar {c.threshold:.3f})" if fitted else "-",
                     f"{100 * rt['shrink']:+.2f} ({_times_null(rt)}{rt['runs_better']} of {len(rt['log_ratios'])} "
                     "runs better)" if fitted and rt.get("log_ratios") else "-",
                     "yes" if c.name in result.claimed else "passes, not claimed" if c.passes else "no",
                     c.reason,
                     (f"fitted from the {c.start}'s values: " if c.start else "")
                     + "; ".join(f"{k} = {_with_unit(v, field_unit(prior, k))}" for k, v in c.values.items())])
    parts.append("<h2>Which effect: the candidates, best held-out gain first</h2>")
    parts.append(table(["effect", "training gain [% of SSE]", "held-out gain [points of %]",
                        "pooled held-out shrink [%] (× the run-to-run null)", "claimed", "why", "fitted fields"], rows))
    parts.append("<h2>How far it shrinks (held-out runs, closed-loop replay)</h2>")
    sig = [s for s in ("position", "velocity", "acceleration", "force", "table_position", "transmission")
           if all(s in e for e in result.test_errors.values())]
    parts.append(table(["held-out run"] + [f"{s.replace('_', ' ')} error [%] params file → fitted → augmented"
                                           for s in sig],
                       [[lab] + [f"{result.prior_test_errors[lab][s]:.4g} → {result.nominal_test_errors[lab][s]:.4g}"
                                 f" → {result.test_errors[lab][s]:.4g}" for s in sig]
                        for lab in result.test_errors]))
    if scored:
        errs = scored["errors_percent"]
        parts.append(f"<h2>Scored on {escape(str(scored.get('data', '')))} (the augmented params, fixed)</h2>")
        parts.append(table(["run", "position error [%]", "force error [%]"],
                           [[lab, f"{e['position']:.4g}", f"{e['force']:.4g}"] for lab, e in errs.items()]))
    if result.oscillation:
        parts.append("<h2>An oscillation of the measured runs</h2><ul>"
                     + "".join(f"<li>{escape(line.strip())}</li>" for line in result.oscillation_lines()) + "</ul>")
    parts += where_parts(result.where)
    if result.not_run:
        parts.append("<h2>Not run: candidates fitted only when named (--effects)</h2>")
        parts.append(table(["effect", "why not by default"], [[n, why] for n, why in result.not_run.items()]))
    parts.append("<h2>Never ranked</h2>")
    parts.append(table(["effect", "why"], [[n, why] for n, why in result.not_ranked.items()]))
    for png, caption in _figures(result):
        parts.append(figure(png, caption))
    return outset.write_text("diagnosis.html", page(title, parts))
