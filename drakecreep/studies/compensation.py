"""The friction compensation study: each compensator of :mod:`drakecreep.model.compensators` against none.

Feeds, load cases and model mismatch (:func:`evaluate`, :func:`creep_boundaries`, :func:`robustness`),
with a Markdown/CSV/PNG report (:func:`write_report`).
"""

from drakecreep.errors import InputError
from drakecreep.files import write_atomic, write_text
from drakecreep.params import COMPENSATION_METHODS, COMPENSATION_STUDY_METHODS, COMPENSATION_VARIANTS, with_value
from drakecreep.scenario import MAX_DURATION, Scenario
from drakecreep.sim.simulation import MIN_WINDOW_SAMPLES, check_run, simulate
from drakecreep.studies.paper_reproduction import simulated_creep_boundary

__all__ = [
    "MISMATCH_FIELDS",
    "with_method",
    "VARIANTS",
    "method_names",
    "DEFAULT_FEEDS_MM_S",
    "DEFAULT_METHODS",
    "EVAL_KEYS",
    "check_duration",
    "evaluate",
    "creep_boundary",
    "creep_boundaries",
    "robustness",
    "plot_comparison",
    "summary_markdown",
    "write_report",
]



#: compensator model parameters varied in the robustness study, by method
MISMATCH_FIELDS = {
    "static": ("coulomb_factor", "static_factor", "stribeck_velocity_factor", "viscous_factor"),
    "lugre": ("coulomb_factor", "static_factor", "stribeck_velocity_factor", "viscous_factor",
              "bristle_stiffness_factor", "bristle_damping_factor"),
    "dob": ("inertia_factor",),
    "dither": ("coulomb_factor",),
}


#: named evaluation variants of a method: label -> (method, compensation settings)
VARIANTS = COMPENSATION_VARIANTS


def method_names():
    """Every name :func:`with_method` takes: the methods of ``compensation.method`` and :data:`VARIANTS`."""
    return tuple(COMPENSATION_METHODS) + tuple(VARIANTS)


def with_method(params, method, **settings):
    """``params`` with ``compensation.method = method`` and other compensation fields set.

    ``method`` may also name a :data:`VARIANTS` entry, whose settings come first (``settings`` override).
    """
    _check_method(method)
    if method in VARIANTS:
        method, preset_settings = VARIANTS[method]
        settings = {**preset_settings, **settings}
    out = with_value(params, "compensation.method", method)
    for key, value in settings.items():
        out = with_value(out, f"compensation.{key}", value)
    return out


#: feed grid of the comparison (mm/s)
DEFAULT_FEEDS_MM_S = (0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0)
#: methods compared, the baseline first
DEFAULT_METHODS = COMPENSATION_STUDY_METHODS
#: metric keys of one evaluation row (report units)
EVAL_KEYS = ("max_fluctuation_mm_s", "fluctuation_rate_percent", "stick_fraction", "creep",
             "following_error_max_um", "following_error_rms_um", "converged")


def _run_one(job):
    """One simulation of the comparison (module level, so a process pool can pickle it)."""
    params, label, feed_mm_s, load_case, duration = job
    res = simulate(params, Scenario(feed=feed_mm_s * 1e-3, load_case=load_case, duration=duration))
    row = dict(label=label, method=label.split(" ")[0], load_case=load_case, feed_mm_s=feed_mm_s,
               status=res.status)
    report = res.metrics.report() if res.metrics is not None else {}
    row.update({k: report.get(k, float("nan")) for k in EVAL_KEYS})
    return row


def _map(jobs, workers):
    for params, _, feed_mm_s, load_case, duration in jobs:  # every run's one-line refusal before any runs
        check_run(params, Scenario(feed=feed_mm_s * 1e-3, load_case=load_case, duration=duration))
    if workers <= 1:
        return [_run_one(j) for j in jobs]
    from drakecreep.processes import process_pool

    with process_pool(workers) as pool:  # a Ctrl-C or an error ends the workers at once
        return list(pool.map(_run_one, jobs))


def _check_method(method):
    if method not in COMPENSATION_METHODS and method not in VARIANTS:
        raise InputError("method", method, "one of " + ", ".join(method_names()))


def _steady(params, duration):
    """``params`` with the metrics window starting no later than half the run."""
    return with_value(params, "simulation.steady_start", min(params.simulation.steady_start, 0.5 * duration))


def check_duration(params, duration):
    """Refuse a run time the study cannot measure (:class:`InputError` naming ``duration``): its metrics window,
    ``simulation.steady_start`` to the end and at least the run's last half, must start after the reference's
    acceleration ramp (``simulation.acceleration_time``) and hold :data:`MIN_WINDOW_SAMPLES` recorded samples
    (1e-300 s was refused as 'simulation.log_period: got 0.00025', a field nobody had set; 0.01 s measured the
    ramp of a 0.05 s acceleration and gave verdicts)."""
    sim = params.simulation
    least = max(min(sim.steady_start, MIN_WINDOW_SAMPLES * sim.log_period) + MIN_WINDOW_SAMPLES * sim.log_period,
                2.0 * sim.acceleration_time)
    if isinstance(duration, bool) or not (isinstance(duration, (int, float)) and 0 < duration <= MAX_DURATION and (
            # as simulate's check of the window (check_log_period), on the window this study gives the run
            (duration - min(sim.steady_start, 0.5 * duration)) / sim.log_period >= MIN_WINDOW_SAMPLES)
            and min(sim.steady_start, 0.5 * duration) >= sim.acceleration_time):
        raise InputError("duration", duration,
                         f"a time in [{least:.3g}, {MAX_DURATION:g}] s (the metrics window, from "
                         f"simulation.steady_start or the run's last half, starts after the reference's ramp, "
                         f"simulation.acceleration_time = {sim.acceleration_time:g} s, and needs {MIN_WINDOW_SAMPLES} "
                         f"recorded samples, one every simulation.log_period = {sim.log_period:g} s)")
    return duration


def evaluate(params, methods=DEFAULT_METHODS, feeds_mm_s=DEFAULT_FEEDS_MM_S, load_cases=(1, 2, 3), duration=2.0,
             workers=1):
    """Each method at each feed and load case: speed fluctuation, stick fraction, following error.

    Metrics over ``t >= simulation.steady_start`` (the window is shortened to half the run if the
    parameters start it later). ``workers > 1`` runs the simulations on a process pool.

    Returns
    -------
    list of dict
        One row per (method, load case, feed): ``label``, ``method``, ``load_case``, ``feed_mm_s``,
        ``status`` and :data:`EVAL_KEYS`; plus ``*_vs_none`` ratios of fluctuation and stick fraction
        against the uncompensated row of the same feed and load.
    """
    for m in methods:
        _check_method(m)
    base = _steady(params, check_duration(params, duration))
    jobs = [(with_method(base, m), m, float(f), lc, duration) for m in methods for lc in load_cases for f in feeds_mm_s]
    rows = _map(jobs, workers)
    _add_ratios(rows)
    return rows


def _add_ratios(rows, key=("load_case", "feed_mm_s")):
    ref = {tuple(r[k] for k in key): r for r in rows if r["method"] == "none" and r["label"] == "none"}
    for r in rows:
        b = ref.get(tuple(r[k] for k in key))
        if b is None:
            continue
        r["fluctuation_vs_none"] = r["max_fluctuation_mm_s"] / b["max_fluctuation_mm_s"]
        r["stick_fraction_vs_none"] = (r["stick_fraction"] / b["stick_fraction"] if b["stick_fraction"] > 0
                                       else (0.0 if r["stick_fraction"] == 0 else float("inf")))


def creep_boundary(params, method, load_case, **kwargs):
    """Lowest feed (m/s) without creep with ``method`` (see :func:`drakecreep.studies.paper_reproduction.simulated_creep_boundary`)."""
    _check_method(method)
    return simulated_creep_boundary(with_method(params, method), load_case, **kwargs)


def robustness(params, methods=DEFAULT_METHODS[1:], feeds_mm_s=(0.1, 0.2), load_case=3,
               factors=(0.7, 1.3), duration=2.0, workers=1):
    """The compensator's model off by each factor in each of its parameters (:data:`MISMATCH_FIELDS`).

    Returns
    -------
    list of dict
        Rows as :func:`evaluate` with ``label`` ``"<method> <field> x<factor>"`` (``"<method> nominal"``
        for the exact model, ``"none"`` for no compensation) and the ratios against ``none``.
    """
    for m in methods:
        _check_method(m)
    base = _steady(params, check_duration(params, duration))
    configs = [("none", with_method(base, "none"))]
    for m in methods:
        configs.append((f"{m} nominal", with_method(base, m)))
        for name in MISMATCH_FIELDS[VARIANTS[m][0] if m in VARIANTS else m]:
            for factor in factors:
                configs.append((f"{m} {name} x{factor:g}", with_method(base, m, **{name: factor})))
    jobs = [(p, label, float(f), load_case, duration) for label, p in configs for f in feeds_mm_s]
    rows = _map(jobs, workers)
    _add_ratios(rows)
    return rows


def creep_boundaries(params, methods=DEFAULT_METHODS, load_cases=(1, 2, 3), lo=0.01e-3, **kwargs):
    """Lowest feed without creep (mm/s) per method and load case.

    Returns
    -------
    list of dict
        Rows ``method, load_case, critical_mm_s, lowest_tested_mm_s``; ``critical_mm_s`` is 0 when no
        feed down to ``lo`` creeps (see :func:`drakecreep.studies.paper_reproduction.simulated_creep_boundary`).
    """
    return [dict(method=m, load_case=lc, critical_mm_s=creep_boundary(params, m, lc, lo=lo, **kwargs) * 1e3,
                 lowest_tested_mm_s=lo * 1e3)
            for m in methods for lc in load_cases]


def _critical_cell(row):
    if row["critical_mm_s"] > 0:
        return f"{row['critical_mm_s']:.4f}"
    if row["critical_mm_s"] == 0:
        return f"no creep down to {row.get('lowest_tested_mm_s', 0.01):g}"
    return "creeps at every feed tested"


def plot_comparison(rows, path, title=None):
    """Fluctuation and stick fraction against feed, one column per load case, one line per method."""
    import matplotlib.pyplot as plt

    loads = sorted({r["load_case"] for r in rows})
    methods = list(dict.fromkeys(r["label"] for r in rows))
    fig, axes = plt.subplots(2, len(loads), figsize=(4.2 * len(loads), 7), squeeze=False, constrained_layout=True)
    for j, lc in enumerate(loads):
        for m in methods:
            sel = sorted((r for r in rows if r["load_case"] == lc and r["label"] == m), key=lambda r: r["feed_mm_s"])
            f = [r["feed_mm_s"] for r in sel]
            axes[0, j].loglog(f, [r["fluctuation_rate_percent"] for r in sel], "o-", ms=3, label=m)
            axes[1, j].semilogx(f, [r["stick_fraction"] * 100 for r in sel], "o-", ms=3, label=m)
        axes[0, j].set_title(f"load case {lc}", fontsize=9)
        axes[0, j].set_ylabel("fluctuation rate (%)")
        axes[1, j].set_ylabel("stick fraction (%)")
        axes[1, j].set_xlabel("feed (mm/s)")
    axes[0, 0].legend(fontsize=7)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def summary_markdown(rows, critical=None, robust=None, params_name="paper"):
    """A Markdown summary of :func:`evaluate`, :func:`creep_boundaries` and :func:`robustness` rows."""
    lines = [f"# Friction compensation ({params_name})", "",
             "Ratios are against no compensation at the same feed and load (< 1 is better).", "",
             "| method | load case | feed (mm/s) | fluctuation (mm/s) | vs none | stick (%) | creep | "
             "following error max (um) |", "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        lines.append(f"| {r['label']} | {r['load_case']} | {r['feed_mm_s']:g} | {r['max_fluctuation_mm_s']:.4g} | "
                     f"{r.get('fluctuation_vs_none', float('nan')):.3g} | {r['stick_fraction'] * 100:.2f} | "
                     f"{r['creep']} | {r['following_error_max_um']:.3f} |")
    if critical:
        loads = sorted({c["load_case"] for c in critical})
        lines += ["", "## Lowest feed without creep (mm/s)", "",
                  "| method | " + " | ".join(f"load case {lc}" for lc in loads) + " |",
                  "| --- |" + " --- |" * len(loads)]
        for m in dict.fromkeys(c["method"] for c in critical):
            cells = {c["load_case"]: _critical_cell(c) for c in critical if c["method"] == m}
            lines.append(f"| {m} | " + " | ".join(cells[lc] for lc in loads) + " |")
    if robust:
        lines += ["", "## Robustness: the compensator's model off by a factor (load case "
                  f"{robust[0]['load_case']})", "",
                  "| configuration | feed (mm/s) | fluctuation (mm/s) | vs none | stick (%) |", "| --- | --- | --- | --- | --- |"]
        for r in robust:
            lines.append(f"| {r['label']} | {r['feed_mm_s']:g} | {r['max_fluctuation_mm_s']:.4g} | "
                         f"{r.get('fluctuation_vs_none', float('nan')):.3g} | {r['stick_fraction'] * 100:.2f} |")
    return "\n".join(lines) + "\n"


def write_report(out_dir, rows, critical=None, robust=None, params_name="paper"):
    """Write ``compensation.csv``, ``summary.md``, ``rows.json`` and ``comparison.png``; return the paths."""
    import csv
    import json
    from pathlib import Path

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = dict(csv=out / "compensation.csv", markdown=out / "summary.md", json=out / "rows.json",
                 plot=out / "comparison.png")
    keys = list(dict.fromkeys(k for r in rows + (robust or []) for k in r))

    def write_csv(tmp):
        with open(tmp, "w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=keys + ["study"])
            writer.writeheader()
            for study, group in (("grid", rows), ("robustness", robust or [])):
                for r in group:
                    writer.writerow(dict(r, study=study))

    # every file atomically: a failure (a full disk, a kill) leaves the previous file whole
    write_atomic(paths["csv"], write_csv)
    write_text(paths["markdown"], summary_markdown(rows, critical, robust, params_name))
    write_text(paths["json"], json.dumps(dict(rows=rows, critical=critical, robustness=robust), indent=2) + "\n")
    write_atomic(paths["plot"], lambda tmp: plot_comparison(rows, tmp, f"Friction compensation against none ({params_name})"))
    return paths
