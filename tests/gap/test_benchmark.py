import numpy as np
import pytest

from drakecreep.gap import truth as T
from drakecreep.gap.benchmark import DEV_SEEDS, HELDOUT_SEEDS, benchmark_specs, design, out_and_back, score_rows


def test_specs_cover_every_effect_kind_and_axis_and_keep_seed_sets_apart():
    specs = benchmark_specs(HELDOUT_SEEDS, n_per_effect=4, tries=2, n_null=3, n_ool=2)
    seeds = [s[0] for s in specs]
    assert len(set(seeds)) == len(seeds)
    dev = {s[0] for s in benchmark_specs(DEV_SEEDS, n_per_effect=10, tries=3, n_null=10, n_ool=10)}
    assert not dev & set(seeds)
    for kind in T.CONTROLLER_KINDS:
        for e in T.LIBRARY_EFFECTS:
            mine = [s for s in specs if s[1] == (e,) and s[2] == kind]
            assert len(mine) == 8 and {s[3] for s in mine} == set(T.AXES)
        assert sum(1 for s in specs if s[1] == () and s[2] == kind) == 3
        assert sum(1 for s in specs if s[1] == ("time_ripple",) and s[2] == kind) == 2


def test_design_cycles_through_slots():
    got = [design(i)[0] for i in range(12)]
    assert got[:8] == [(e,) for e in T.LIBRARY_EFFECTS] and got[10:] == [(), ()]


def test_out_and_back_returns_home():
    x = out_and_back(0.05, 0.01)
    assert x[0] == pytest.approx(0.01) and x[-1] == pytest.approx(0.01, abs=1e-12)
    assert np.max(np.gradient(x, 1e-3)) == pytest.approx(0.05, rel=1e-3)


def _row(w, snr, claimed, kind="p_p_cascade", shrink=None, true=None, worse=False):
    cat = "null" if not w else ("out_of_library" if w[0] in T.OUT_OF_LIBRARY else "library")
    return {"withheld": w, "category": cat, "kind": kind, "axis": "rigid", "snr": snr, "claimed": claimed,
            "audit_shrink": shrink, "true_shrink": true, "worse": worse, "provisional": []}


def test_score_rows():
    rows = [_row(["cogging"], 5.0, ["cogging"], shrink=0.8, true=0.9),
            _row(["stribeck"], 4.0, ["load_friction"], shrink=-0.1, true=0.5, worse=True),
            _row(["stribeck"], 1.0, []),
            _row([], 0.0, []), _row([], 0.0, ["stribeck"]),
            _row(["time_ripple"], 4.0, [])]
    s = score_rows(rows)
    assert s["top1_snr3"] == {"rate": 0.5, "n": 2}
    assert s["claims_on_nulls"] == {"rate": 0.5, "n": 2}
    assert s["out_of_library_unexplained"] == {"rate": 1.0, "n": 1}
    assert s["median_relative_shrink_snr3"] == pytest.approx(0.5 * (0.8 / 0.9 - 0.2))
    assert s["claims_making_audit_worse"] == 1 and s["n_claims"] == 3
    assert s["per_effect"]["stribeck"]["n"] == 2 and s["per_effect"]["stribeck"]["n_snr3"] == 1
