"""Realistic withheld-effect benchmark of the gap diagnosis.

Datasets come from the independent, richer truth of :mod:`drakecreep.gap.truth` (two bodies with an axial
mode, LuGre on the table, run-to-run friction drift, force noise, encoder and scale quantisation, a current
loop), for both controller kinds (``p_p_cascade``, ``drakecreep``) and both a ``flexible`` and a ``rigid``
axis. A dataset has 10 runs at shuffled speeds and positions: 4 for training, 3 held out (the diagnosis
uses them to decide its claims) and 3 **audit** runs the diagnosis never sees, on which the benchmark
measures the closed-loop replay before and after the claimed effects.

Kinds of dataset (:func:`design`):

* ``null``: all the realism, no withheld effect: the right answer is no claim;
* one withheld effect of :data:`drakecreep.gap.truth.LIBRARY_EFFECTS`: the right answer is that effect
  (top-1 = the first claimed effect);
* one withheld effect of :data:`drakecreep.gap.truth.OUT_OF_LIBRARY`: the right answer is "unexplained"
  (no claim).

**SNR** of a dataset: ``sqrt(E_with / E_without - 1)``, with ``E`` the energy of the nominal
inverse-dynamics residual on the training runs, ``E_without`` from an effect-free twin simulated with the
same references, drift and noise. SNR >= 3 means the effect carries at least 9 times the energy of
everything else the rigid nominal does not explain (noise, drift, mode, LuGre, quantisation).

**Seeds**: development seeds (:data:`DEV_SEEDS`, used while designing the claim rule) and held-out seeds
(:data:`HELDOUT_SEEDS`, reported; never used for tuning). Each dataset seed is ``base + index``; the
index also fixes the effect, the controller kind and the axis (:func:`design`), so the held-out design is
the same as the development design on different draws.

**Scores** (:func:`score_rows`): top-1 where SNR >= 3; claims on nulls; out-of-library answered
"unexplained"; median audit replay shrink of the claimed model relative to what the true effect achieves
(the same nominal replay plus the effect fitted with the truth's label, i.e. the library's best fit of the
right effect); claims that make the audit replay worse.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field

import numpy as np

from drakecreep.errors import InputError
from drakecreep.gap import truth as T
from drakecreep.gap.truth import out_and_back

__all__ = [
    "DEV_SEEDS",
    "HELDOUT_SEEDS",
    "N_TRAIN",
    "N_TEST",
    "N_AUDIT",
    "Dataset",
    "out_and_back",
    "design",
    "generate_datasets",
    "generate_dataset",
    "benchmark_specs",
    "diagnose_dataset",
    "audit_replay",
    "evaluate",
    "run_benchmark",
    "score_rows",
]

#: First seed of the development set (used while designing the claim rule).
DEV_SEEDS = 1000
#: First seed of the held-out set (reported; never used while tuning).
HELDOUT_SEEDS = 7_000_000
N_TRAIN, N_TEST, N_AUDIT = 4, 3, 3
N_SAMPLES = 3000


@dataclass
class Dataset:
    """Runs (training, held-out, audit), the truth (hidden from the diagnosis) and the SNR."""

    seed: int
    withheld: tuple
    truth: T.Truth
    train: list
    test: list
    audit: list
    snr: float = 0.0
    twin_train: list = field(default_factory=list)

    @property
    def kind(self):
        return self.truth.kind

    @property
    def axis(self):
        return self.truth.axis

    @property
    def category(self):
        if not self.withheld:
            return "null"
        return "out_of_library" if self.withheld[0] in T.OUT_OF_LIBRARY else "library"


def design(index, kinds=T.CONTROLLER_KINDS):
    """What dataset ``index`` holds in a plain sequence: ``(withheld, kind, axis)``.

    Cycles through the 8 library effects, 2 out-of-library effects and 2 nulls (12 slots), and through
    the controller kinds and axes so that every effect meets each combination.
    """
    slots = [(e,) for e in T.LIBRARY_EFFECTS] + [(e,) for e in T.OUT_OF_LIBRARY] + [(), ()]
    withheld = slots[index % len(slots)]
    combo = index // len(slots)
    kinds = tuple(kinds)
    kind = kinds[combo % len(kinds)]
    axis = T.AXES[(combo // len(kinds) + index) % len(T.AXES)]
    return withheld, kind, axis


def _draw(seed, withheld, kind, axis, n_samples):
    rng = np.random.default_rng(seed)
    tr = T.draw_truth(rng, kind, axis, tuple(withheld))
    n_runs = N_TRAIN + N_TEST + N_AUDIT
    refs, pulses, _ = T.draw_profiles(rng, n_runs, n=n_samples)
    drift, noise = T.noise_draws(tr, n_runs, n_samples, rng)
    return tr, refs, pulses, drift, noise


def generate_datasets(specs, n_samples=N_SAMPLES, chunk=24):
    """Generate datasets in batches (one vectorised truth simulation per ``chunk`` datasets).

    Parameters
    ----------
    specs : sequence of tuple
        ``(seed, withheld, kind, axis)`` per dataset.
    n_samples : int
        Samples per run.
    chunk : int
        Datasets per batch.

    Returns
    -------
    list of Dataset
    """
    out = []
    specs = list(specs)
    for c in range(0, len(specs), chunk):
        part = specs[c: c + chunk]
        draws = [_draw(sd, w, k, a, n_samples) for sd, w, k, a in part]
        jobs = []
        for (sd, w, k, a), (tr, refs, pulses, drift, noise) in zip(part, draws):
            jobs.append((tr, refs, pulses, drift, noise, True))
            if w:  # the effect-free twin: same references, drift and noise
                jobs.append((tr, refs, pulses, drift, noise, False))
        sims = iter(T.simulate_batch(jobs))
        for (sd, w, k, a), (tr, refs, pulses, drift, noise) in zip(part, draws):
            runs = T.make_runs(tr, refs, pulses, next(sims))
            i, j = N_TRAIN, N_TRAIN + N_TEST
            ds = Dataset(seed=sd, withheld=tuple(w), truth=tr, train=runs[:i], test=runs[i:j], audit=runs[j:])
            if w:
                twin = next(sims)
                ds.twin_train = T.make_runs(tr, refs[:i], pulses[:i], {key: v[:i] for key, v in twin.items()})
                ds.snr = _snr(ds.train, ds.twin_train, tr.lead)
            out.append(ds)
    return out


def generate_dataset(seed, withheld=None, kind=None, axis=None, index=None, n_samples=N_SAMPLES):
    """Generate one dataset.

    Parameters
    ----------
    seed : int
        Seeds the truth, the profiles, the drift and the noise.
    withheld, kind, axis : optional
        Force the design; default from :func:`design` of ``index`` (default ``seed``).
    index : int, optional
        Design index.
    n_samples : int
        Samples per run.

    Returns
    -------
    Dataset
    """
    d = design(seed if index is None else index)
    withheld = tuple(d[0] if withheld is None else withheld)
    kind = d[1] if kind is None else kind
    axis = d[2] if axis is None else axis
    return generate_datasets([(seed, withheld, kind, axis)], n_samples=n_samples)[0]


def _snr(runs, twin, lead):
    from drakecreep.gap.diagnosis import DiagnosisConfig, fit_effect
    from drakecreep.gap.effects import idim_data

    cfg = DiagnosisConfig(screw_lead=lead)
    ctx = cfg.context(runs)
    vm = cfg.v_min_frac * ctx.v_max
    w, tw = idim_data(runs, v_min=vm), idim_data(twin, v_min=vm)
    e_w = fit_effect((), w, w, ctx, {}).sse_train / w.n
    e_tw = fit_effect((), tw, tw, ctx, {}).sse_train / tw.n
    return float(math.sqrt(max(e_w / e_tw - 1.0, 0.0)))


def diagnose_dataset(ds, replay=True, config=None):
    """Diagnose a dataset blind: only the training and held-out runs, their metadata and the screw lead."""
    from drakecreep.gap.diagnosis import DiagnosisConfig, diagnose

    cfg = config or DiagnosisConfig(screw_lead=ds.truth.lead)
    return diagnose(ds.train, ds.test, cfg, replay=replay)


def audit_replay(result, runs, also=()):
    """Closed-loop replay on the audit runs: nominal, claimed model, and the ranked effects named in ``also``.

    Returns
    -------
    dict
        ``{label: energy}`` with ``energy`` the mean over runs of the normalised replay residual energy
        (:func:`drakecreep.gap.claims.replay_energy`); ``None`` where the replay is unavailable.
    """
    from drakecreep.gap.claims import replay_energy

    fits = result["_fits"]
    out = {}
    for f in [fits["base"]] + [f for f in fits["ranking"] if f.label in also] + [fits["final"]]:
        if f.label in out:
            continue
        try:
            out[f.label] = float(np.mean(replay_energy(f, runs, fits["ctx"])))
        except InputError:
            out[f.label] = None
    return out


def evaluate(ds, replay=True):
    """Diagnose ``ds`` and score the answer against the truth: one benchmark row."""
    res = diagnose_dataset(ds, replay=replay)
    claimed = list(res["claimed"])
    ranked = [r["effect"] for r in res["ranking"]]
    row = {"seed": ds.seed, "withheld": list(ds.withheld), "category": ds.category, "kind": ds.kind,
           "axis": ds.axis, "snr": ds.snr, "claimed": claimed, "top3": ranked[:3],
           "unexplained": res.get("unexplained", {}).get("verdict"),
           "replay_available": res.get("claims", {}).get("replay_available"),
           "provisional": list(res.get("claims", {}).get("provisional", []))}
    if replay:
        audit = audit_replay(res, ds.audit, also=ds.withheld)
        row["audit_energy"] = audit
        nom = audit.get("nominal")
        fin = audit.get("+".join(claimed)) if claimed else nom
        true = audit.get(ds.withheld[0]) if ds.withheld else None
        row["audit_shrink"] = None if (nom is None or fin is None) else 1.0 - fin / nom
        row["true_shrink"] = None if (nom is None or true is None) else 1.0 - true / nom
        row["worse"] = bool(claimed and nom is not None and fin is not None and fin > nom)
    return row


def benchmark_specs(seed, kinds=T.CONTROLLER_KINDS, n_per_effect=10, tries=4.0, n_null=10, n_ool=6):
    """The candidate dataset list of a benchmark: ``(seed, withheld, kind, axis)``, round-robin over effects.

    Per controller kind: up to ``ceil(tries * n_per_effect)`` candidates per library effect (the first
    ``n_per_effect`` with SNR >= 3 are diagnosed, see :func:`run_benchmark`), ``n_ool`` per out-of-library
    effect and ``n_null`` nulls; axes alternate. Seeds are ``seed + 100000 * kind + 1000 * slot + j``.
    """
    slots = [(e,) for e in T.LIBRARY_EFFECTS] + [(e,) for e in T.OUT_OF_LIBRARY] + [()]
    counts = [n_null if not w else (n_ool if w[0] in T.OUT_OF_LIBRARY else int(math.ceil(tries * n_per_effect)))
              for w in slots]
    specs = []
    for j in range(max(counts + [0])):
        for kind in kinds:
            for si, (w, count) in enumerate(zip(slots, counts)):
                if j < count:
                    specs.append((seed + 100000 * T.CONTROLLER_KINDS.index(kind) + 1000 * si + j, w, kind,
                                  T.AXES[j % len(T.AXES)]))
    return specs


def run_benchmark(seed=HELDOUT_SEEDS, kinds=T.CONTROLLER_KINDS, n_per_effect=10, n_null=10, n_ool=6,
                  replay=True, progress=False, tries=4.0, n_samples=N_SAMPLES, chunk=24):
    """Generate the datasets of :func:`benchmark_specs` (in batches), diagnose each blind, score.

    Library effects: of the candidates (in seed order), the first ``n_per_effect`` with SNR >= 3 are
    diagnosed; the others are only counted (``low_snr_skipped``), and no further candidate of an effect
    is generated once it has enough. Nulls and out-of-library datasets are all diagnosed.

    Returns
    -------
    dict
        ``scores`` (:func:`score_rows`), ``datasets`` (rows), ``low_snr_skipped`` (per effect) and
        ``short`` (effects that did not reach ``n_per_effect`` datasets with SNR >= 3).
    """
    specs = benchmark_specs(seed, kinds, n_per_effect, tries, n_null, n_ool)
    rows, kept, skipped = [], {}, {}
    pos = 0
    done = 0
    while pos < len(specs):
        part = []
        while pos < len(specs) and len(part) < chunk:
            sd, w, k, a = specs[pos]
            pos += 1
            if w and w[0] in T.LIBRARY_EFFECTS and kept.get((k, w), 0) >= n_per_effect:
                continue
            part.append(specs[pos - 1])
        if not part:
            break
        if progress:
            print(f"[gap-benchmark] generating {len(part)} datasets (candidate {pos}/{len(specs)})",
                  file=sys.stderr, flush=True)
        for ds in generate_datasets(part, n_samples=n_samples, chunk=chunk):
            key = (ds.kind, ds.withheld)
            if ds.category == "library":
                if kept.get(key, 0) >= n_per_effect:
                    continue
                if ds.snr < 3:
                    name = f"{ds.kind}/{ds.withheld[0]}"
                    skipped[name] = skipped.get(name, 0) + 1
                    continue
            kept[key] = kept.get(key, 0) + 1
            row = evaluate(ds, replay=replay)
            rows.append(row)
            done += 1
            if progress:
                print(f"[gap-benchmark] {done} seed {ds.seed} {ds.kind}/{ds.axis}: withheld "
                      f"{list(ds.withheld) or 'none'} (SNR {ds.snr:.1f}) -> claimed {row['claimed'] or 'nothing'}"
                      + ("" if row["replay_available"] else " (replay unavailable)"), file=sys.stderr, flush=True)
    short = {f"{k}/{e}": kept.get((k, (e,)), 0) for k in kinds for e in T.LIBRARY_EFFECTS
             if kept.get((k, (e,)), 0) < n_per_effect}
    return {"scores": score_rows(rows), "datasets": rows, "low_snr_skipped": skipped, "short": short}


def score_rows(rows):
    """Aggregate benchmark rows: overall, per controller kind and per effect."""

    def rate(sel, ok):
        sel = list(sel)
        return {"rate": (sum(bool(ok(r)) for r in sel) / len(sel)) if sel else None, "n": len(sel)}

    def block(rs):
        lib = [r for r in rs if r["category"] == "library"]
        strong = [r for r in lib if r["snr"] >= 3]
        null = [r for r in rs if r["category"] == "null"]
        ool = [r for r in rs if r["category"] == "out_of_library"]
        rel = [r["audit_shrink"] / r["true_shrink"] for r in strong
               if r.get("audit_shrink") is not None and r.get("true_shrink") not in (None, 0.0) and r["true_shrink"] > 0]
        return {
            "n_datasets": len(rs),
            "top1_snr3": rate(strong, lambda r: r["claimed"] and r["claimed"][0] == r["withheld"][0]),
            "top1_all": rate(lib, lambda r: r["claimed"] and r["claimed"][0] == r["withheld"][0]),
            "claims_on_nulls": rate(null, lambda r: r["claimed"]),
            "provisional_top1_snr3": rate(strong, lambda r: r.get("provisional") and r["provisional"][0] == r["withheld"][0]),
            "provisional_on_nulls": rate(null, lambda r: r.get("provisional")),
            "out_of_library_unexplained": rate(ool, lambda r: not r["claimed"]),
            "median_relative_shrink_snr3": float(np.median(rel)) if rel else None,
            "claims_making_audit_worse": sum(1 for r in rs if r.get("worse")),
            "n_claims": sum(1 for r in rs if r["claimed"]),
        }

    out = block(rows)
    out["per_kind"] = {k: block([r for r in rows if r["kind"] == k]) for k in sorted({r["kind"] for r in rows})}
    out["per_axis"] = {a: block([r for r in rows if r["axis"] == a]) for a in sorted({r["axis"] for r in rows})}
    per = {}
    for r in rows:
        key = r["withheld"][0] if r["withheld"] else "null"
        per.setdefault(key, []).append(r)
    out["per_effect"] = {}
    for key, rs in per.items():
        right = (lambda r: not r["claimed"]) if key == "null" or key in T.OUT_OF_LIBRARY else \
            (lambda r: bool(r["claimed"]) and r["claimed"][0] == r["withheld"][0])
        strong = [r for r in rs if r["snr"] >= 3] if key not in ("null",) + T.OUT_OF_LIBRARY else rs
        out["per_effect"][key] = {"n": len(rs), "n_snr3": len(strong), "right": rate(strong, right),
                                  "median_snr": float(np.median([r["snr"] for r in rs])),
                                  "claimed": sorted({c for r in rs for c in r["claimed"]})}
    return out
