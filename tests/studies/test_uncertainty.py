"""Uncertainty study: the spec covers every assumption, the sample is seeded and in range, the shares are right."""

import json
import re
from importlib import resources

import numpy as np
import pandas as pd
import pytest

from drakecreep.cli import main
from drakecreep.errors import InputError
from drakecreep.params import get_value, preset
from drakecreep.studies.uncertainty import (
    Distribution, load_uncertainty, run_uncertainty, sample_rigs, sensitivity, summarize, uncertainty_spec,
)


def _assumed_paths(name):
    """Dotted paths of the ``[assumed]`` values of a preset's YAML text."""
    text = resources.files("drakecreep").joinpath("presets", f"{name}.yaml").read_text()
    group, paths = None, []
    for line in text.splitlines():
        top = re.match(r"^([a-z_]+):", line)
        if top:
            group = top.group(1)
            continue
        item = re.match(r"^\s+([a-z_]+):.*#\s*\[assumed\]", line)
        if item and group:
            paths.append(f"{group}.{item.group(1)}")
    return paths


def test_every_assumed_value_of_the_paper_preset_is_sampled_or_held_fixed_with_a_reason():
    spec = uncertainty_spec("paper")
    assumed = _assumed_paths("paper")
    assert len(assumed) > 20
    missing = [p for p in assumed if p not in spec.paths and p not in spec.fixed]
    assert missing == []
    assert all(isinstance(r, str) and r.strip() for r in spec.fixed.values())
    base = preset("paper")
    for d in spec.distributions:
        assert d.source.strip()
        # a sampled value is an [assumed] one (the paper's values are not sampled)
        assert d.path in assumed
        assert isinstance(get_value(base, d.path), float)


def test_sample_is_seeded_latin_hypercube_within_the_ranges():
    spec = uncertainty_spec("paper")
    a, b = sample_rigs(spec, 40, seed=1), sample_rigs(spec, 40, seed=1)
    assert a == b and a != sample_rigs(spec, 40, seed=2)
    for d in spec.distributions:
        x = np.array([rig[d.path] for rig in a])
        assert x.min() >= d.low and x.max() <= d.high
        # Latin hypercube: exactly one rig per 1/40 stratum of the (log-)range
        strata = np.floor(d.unit(x) * 40).astype(int)
        assert sorted(strata) == list(range(40))


def test_distribution_validates_and_maps_quantiles():
    d = Distribution("friction.bristle_stiffness", "log-uniform", 1e7, 1e9, "test")
    assert d.ppf([0.0, 0.5, 1.0]) == pytest.approx([1e7, 1e8, 1e9])
    assert Distribution("x", "uniform", 1.0, 3.0, "s").ppf(0.5) == pytest.approx(2.0)
    with pytest.raises(InputError, match="sample.x.low"):
        Distribution("x", "log-uniform", 0.0, 1.0, "s")
    with pytest.raises(InputError, match="sample.x.high"):
        Distribution("x", "uniform", 2.0, 1.0, "s")
    with pytest.raises(InputError, match="sample.x.dist"):
        Distribution("x", "normal", 1.0, 2.0, "s")
    with pytest.raises(InputError, match="sample.x.source"):
        Distribution("x", "uniform", 1.0, 2.0, "")
    # an integer of hundreds of digits: 'internal error: OverflowError: int too large to convert to float', exit 1
    with pytest.raises(InputError, match=r"^sample\.x\.high: got 1000.*; allowed: a finite number$"):
        Distribution("x", "uniform", 1.0, 10**400, "s")


def test_spec_file_errors_name_the_key(tmp_path):
    bad = tmp_path / "u.yaml"
    bad.write_text("preset: paper\nsample:\n  friction.no_such: {dist: uniform, low: 1, high: 2, source: s}\n")
    with pytest.raises(InputError, match="friction.no_such"):
        load_uncertainty(bad)
    bad.write_text("preset: paper\nsample:\n  friction.static_ratio: {dist: uniform, low: 0.5, high: 2, source: s}\n")
    with pytest.raises(InputError) as err:  # 0.5 is outside the field's allowed range: the spec's key named
        load_uncertainty(bad)
    assert err.value.field == "sample.friction.static_ratio.low" and "a value of friction.static_ratio" in err.value.allowed
    with pytest.raises(InputError, match="preset"):
        uncertainty_spec("rigid_axis")
    # a path that is no parameter names the spec's key: it said '1: got '1'' and, under fixed, 'path: got 1'
    bad.write_text("preset: paper\nsample:\n  1: {dist: uniform, low: 1, high: 2, source: s}\n")
    with pytest.raises(InputError, match=r"^sample\.1: got '1'; allowed: a dotted path of field names"):
        load_uncertainty(bad)
    bad.write_text("preset: paper\nsample:\n  motor.peak_torque: {dist: uniform, low: 6, high: 10, source: s}\n"
                   "fixed: {1: why}\n")
    with pytest.raises(InputError, match=r"^fixed\.1: got 1; allowed: a dotted path of parameter fields"):
        load_uncertainty(bad)
    # an integer field: its first draw was refused as 'sensors.encoder_counts_per_rev: got 1363.04...'
    bad.write_text("preset: paper\nsample:\n  sensors.encoder_counts_per_rev: {dist: uniform, low: 1000, high: 2000, "
                   "source: s}\n")
    with pytest.raises(InputError) as err:
        load_uncertainty(bad)
    assert err.value.field == "sample.sensors.encoder_counts_per_rev" and "real-valued" in err.value.allowed
    # a key too many or too few, by name (the mapping was shown cut off after four items)
    bad.write_text("preset: paper\nsample:\n  table.mass: {dist: uniform, low: 30, high: 50, source: s, sorce: t}\n")
    with pytest.raises(InputError, match=r"^sample\.table\.mass\.sorce: got 'an unknown key'; allowed: one of dist, "):
        load_uncertainty(bad)
    bad.write_text("preset: paper\nsample:\n  table.mass: {dist: uniform, low: 30, source: s}\n")
    with pytest.raises(InputError, match=r"^sample\.table\.mass\.high: got 'nothing'; allowed: a value"):
        load_uncertainty(bad)


def test_a_spec_of_another_preset_is_refused(tmp_path, capsys, monkeypatch):
    """A spec naming rigid_axis ran on the paper preset (the default) and its JSON said preset 'rigid_axis'."""
    spec = tmp_path / "u.yaml"
    spec.write_text("preset: rigid_axis\nsample:\n  motor.peak_torque: {dist: uniform, low: 6, high: 10, source: s}\n")
    assert load_uncertainty(spec, "rigid_axis").preset == "rigid_axis"
    with pytest.raises(InputError) as err:
        load_uncertainty(spec, "paper")
    assert err.value.field == f"{spec}: preset" and "paper" in err.value.allowed
    import drakecreep.sim.sweep as sweep

    def started(*args, **kwargs):
        raise AssertionError("the rigs ran")

    monkeypatch.setattr(sweep, "run_sweep", started)
    assert main(["uncertainty", "--spec", str(spec), "--samples", "1", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "preset: got ['rigid_axis']; allowed: a spec of the preset it is used with, paper" in err[0]


def test_a_draw_that_makes_an_invalid_rig_names_the_specs_key(tmp_path, capsys, monkeypatch):
    """Bounds valid one by one, draws between them not: a velocity period of 0.2-0.25 ms (the 1 ms position period
    is no integer multiple of most of them) said 'controller.position_period: got 0.001', no key of the spec; a
    root diameter drawn above a nominal diameter drawn below it said 'screw.root_diameter: got ...'."""
    import drakecreep.sim.sweep as sweep

    def started(*args, **kwargs):
        raise AssertionError("a rig ran")

    monkeypatch.setattr(sweep, "run_case", started)
    spec = tmp_path / "u.yaml"
    spec.write_text("preset: paper\nsample:\n  controller.velocity_period: {dist: uniform, low: 2.0e-4, high: 2.5e-4, "
                    "source: s}\n")
    with pytest.raises(InputError) as err:
        run_uncertainty(preset("paper"), load_uncertainty(spec), 4, [1e-3], [3], duration=1.5, executor="serial",
                        progress=False)
    assert err.value.field == "sample.controller.velocity_period"
    assert err.value.allowed.startswith("a range whose every draw makes a valid rig (rig 0 drew this value; then "
                                        "controller.position_period = 0.001 is refused, allowed: an integer multiple")
    spec.write_text("preset: paper\nsample:\n"
                    "  screw.root_diameter: {dist: uniform, low: 0.020, high: 0.0249, source: s}\n"
                    "  screw.nominal_diameter: {dist: uniform, low: 0.0245, high: 0.030, source: s}\n")
    code = main(["uncertainty", "--spec", str(spec), "--samples", "500", "--feeds", "1", "--out", str(tmp_path / "o"),
                 "--no-progress"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert re.match(r"drakecreep uncertainty: error: sample\.screw\.nominal_diameter: got 0\.0245[0-9]*; allowed: a "
                    r"range whose every draw makes a valid rig \(rig [0-9]+ drew this value; then screw\.root_diameter",
                    err[0]), err[0]


def test_summary_shares_and_percentiles_from_a_known_table():
    table = pd.DataFrame(dict(
        feed=[1e-4] * 4 + [2e-4] * 4, load_case=[3] * 8, status=["ok"] * 7 + ["failed: x"],
        creep=[True, False, False, False, True, True, False, True],
        max_fluctuation_mm_s=[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 99.0],
        fluctuation_rate_percent=[10.0] * 8,
    ))
    s = summarize(table)
    assert list(s["rigs"]) == [4, 3] and list(s["failed"]) == [0, 1]
    assert s["creep_percent"].tolist() == pytest.approx([25.0, 200.0 / 3])
    assert s.loc[0, "fluctuation_p50_mm_s"] == pytest.approx(2.5)
    assert s.loc[1, "fluctuation_p95_mm_s"] < 7.0 + 1e-9  # the failed row is left out
    assert s.loc[0, "creep_low_percent"] < 25.0 < s.loc[0, "creep_high_percent"]


def test_sensitivity_finds_the_parameter_that_decides():
    spec = uncertainty_spec("paper")
    rigs = sample_rigs(spec, 60, seed=0)
    table = pd.DataFrame(rigs)
    # a synthetic verdict decided by sigma0 alone: creep in the upper half of its log range
    d = next(x for x in spec.distributions if x.path == "friction.bristle_stiffness")
    table["creep"] = d.unit(table[d.path]) > 0.5
    table["max_fluctuation_mm_s"] = table[d.path] * 1e-9
    table["status"] = "ok"
    s = sensitivity(table, spec)
    assert s.loc[0, "parameter"] == d.path and s.loc[0, "rho_creep"] > 0.8
    assert s.loc[0, "creep_low_half_percent"] == 0.0 and s.loc[0, "creep_high_half_percent"] == 100.0
    assert s["rho_creep"].abs().iloc[1] < 0.5


def test_eight_rigs_at_one_feed_run_through_the_sweep_engine():
    spec = uncertainty_spec("paper")
    result = run_uncertainty(preset("paper"), spec, 8, [1e-4], [3], seed=0, duration=1.3, executor="serial",
                             progress=False)
    t = result.table
    assert len(t) == 8 and result.failed == 0 and (t["status"] == "ok").all()
    assert sorted(t["rig"]) == list(range(8))
    # the rows carry the sampled values of their rig
    rigs = sample_rigs(spec, 8, seed=0)
    for _, row in t.iterrows():
        assert row["friction.bristle_stiffness"] == pytest.approx(rigs[int(row["rig"])]["friction.bristle_stiffness"])
    s = result.summary
    assert len(s) == 1 and s.loc[0, "rigs"] == 8
    assert s.loc[0, "creep_percent"] == pytest.approx(100.0 * t["creep"].mean())


def test_cli_bad_input_one_line_exit_2(capsys):
    assert main(["uncertainty", "--samples", "0"]) == 2
    assert "--samples" in capsys.readouterr().err
    assert main(["uncertainty", "--load-cases", "9"]) == 2
    assert "--load-cases" in capsys.readouterr().err
    assert main(["uncertainty", "--params", "x.yaml", "--samples", "2"]) == 2
    assert main(["simulate", "--uncertainty", "0"]) == 2
    assert "--uncertainty" in capsys.readouterr().err


def test_cli_writes_the_tables_and_says_the_share(tmp_path, capsys):
    code = main(["uncertainty", "--samples", "3", "--feeds", "0.1", "--duration", "1.2", "--workers", "1",
                 "--out", str(tmp_path), "--no-progress", "--json"])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["samples"] == 3 and len(out["summary"]) == 1
    assert out["summary"][0]["rigs"] == 3
    for name in ("summary.csv", "sensitivity.csv", "uncertainty.json", "results.csv"):
        assert (tmp_path / name).exists()
