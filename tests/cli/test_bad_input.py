"""Hostile input to the command line: every bad input is one line on stderr and exit code 2, before any work.

One test per class of bad input (parameter files, sweep specs, measured CSV + metadata, ``.mat`` files, output
folders, options), each parametrized over many malformed files. None of these may start a simulation: they
all fail while the input is checked, so the whole module takes a few seconds.
"""

import time

import numpy as np
import pytest

from drakecreep.cli import main

PASSWD_LIKE = "root:x:0:0:root:/root:/bin/bash\nsecret_token: s3cr3t-VALUE-never-echo\n"


def _bomb(levels=14):
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x]"]
    for i in range(1, levels):
        lines.append(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]")
    return "\n".join(lines) + "\n"


def _bomb_in_value():
    # the bomb sits where a value goes: the error message must not repr() it whole
    lines = ["x0: &x0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    for i in range(1, 8):
        lines.append(f"x{i}: &x{i} [" + ", ".join([f"*x{i - 1}"] * 10) + "]")
    return "\n".join(lines) + "\n"


def _run(argv, capsys, timeout=30.0):
    start = time.perf_counter()
    try:
        code = main(argv)
    except SystemExit as exit_:
        code = exit_.code
    captured = capsys.readouterr()
    assert time.perf_counter() - start < timeout
    return code, captured.out, captured.err


def _one_line_exit_2(code, err, *fragments):
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert len(lines[0]) < 1500
    for f in fragments:
        assert f in lines[0], (f, lines[0])


# --------------------------------------------------------------------------- parameter files

PARAM_TEXTS = {
    "empty": ("", "empty"),
    "comment_only": ("# nothing here\n\n   # still nothing\n", "empty"),
    "duplicate_key": ("table:\n  mass: 40\n  mass: 0.001\n", "duplicate key"),
    "duplicate_group": ("table: {mass: 40}\ntable: {mass: 3}\n", "duplicate key"),
    "absurd_mass": ("table: {mass: 1.0e300}\n", "table.mass"),
    "huge_integer": ("table: {mass: " + "9" * 400 + "}\n", "table.mass"),
    "huge_integer_int_field": ("sensors: {encoder_counts_per_rev: " + "7" * 400 + "}\n", "encoder_counts_per_rev"),
    "huge_integer_force": ("loads: {cases: [{fx: " + "1" * 400 + "}]}\n", "loads.cases[0].fx"),
    "absurd_unbounded": ("nut: {axial_stiffness: 1.0e200}\n", "nut.axial_stiffness"),
    "nan": ("table: {mass: .nan}\n", "table.mass"),
    "inf": ("friction: {viscous: .inf}\n", "friction.viscous"),
    "string_number": ("table: {mass: heavy}\n", "table.mass"),
    "list_top": ("- 1\n- 2\n", "a mapping"),
    "scalar_top": ("42\n", "a mapping"),
    "text_file": (PASSWD_LIKE, "YAML"),
    "unknown_group": ("tabel: {mass: 3}\n", "tabel"),
    "integer_key": ("1: {mass: 3}\n", "an unknown field"),
    "alias_bomb": (_bomb(), "aliases"),
    "bomb_in_value": ("table:\n  mass: &m [1, 2, 3]\n" + _bomb_in_value().replace("x0:", "junk:"), "table.mass"),
    "bad_syntax": ("table: {mass: [1, 2}\n", "invalid YAML"),
    "tab_indent": ("table:\n\tmass: 3\n", "invalid YAML"),
    "deep_nesting": ("a: " + "[" * 5000 + "]" * 5000 + "\n", "nested"),
    # the drive's force limit 2 pi peak_torque / lead overflowed: a still table reported as creep, exit 0 (margins,
    # tune and report said '--feed: got 1.0; allowed: a feed in mm/s the drive can slide at')
    "lead_tiny": ("screw: {lead: 1.0e-300}\n", "screw.lead: got 1e-300; allowed: a finite number in [0.0001, 0.1] m"),
    "too_many_load_cases": ("loads:\n  cases:\n" + "  - {fx: 1.0}\n" * 1001,
                            "loads.cases: got '1001 load cases'; allowed: at most 1000 load cases"),
    "log_period_tiny": ("simulation: {log_period: 1.0e-8}\n", "simulation.log_period"),
    # 19 samples in the 19 s metrics window: the run used to end "ok" with no metrics at all
    "log_period_coarse": ("simulation: {log_period: 1.0}\n", "at least 20 recorded samples in the metrics window"),
    # 2e10 integrator steps or controller samples over the 20 s run: it ran for days
    "max_step_tiny": ("simulation: {max_step: 1.0e-9}\n", "simulation.max_step"),
    "velocity_period_tiny": ("controller: {velocity_period: 1.0e-9, position_period: 1.0e-9}\n",
                             "controller.velocity_period"),
    "seed_like_bool": ("controller: {anti_windup: 3}\n", "anti_windup"),
    "binary_nul": ("table:\x00\x01\x02 {mass: 3}\n", "UTF-8"),
}


@pytest.mark.parametrize("name", sorted(PARAM_TEXTS))
def test_bad_parameter_files(name, tmp_path, capsys):
    text, fragment = PARAM_TEXTS[name]
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    argv = ["simulate", "--params", str(path), "--duration", "20", "--out", str(tmp_path / "out")]
    if name.startswith(("log_period", "max_step", "velocity_period")):
        argv += ["--load-case", "0"]
    code, _, err = _run(argv, capsys)
    _one_line_exit_2(code, err, fragment)
    assert "s3cr3t" not in err and "root:x" not in err
    assert not (tmp_path / "out" / "metrics.json").exists()


@pytest.mark.parametrize("payload", [
    "table: {mass: 3}\n".encode("utf-16"),
    "table: {mass: 3}\n".encode("utf-32"),
    bytes(range(256)) * 4,
    b"\x89PNG\r\n\x1a\n" + b"\x00" * 64,
    b"table: {mass: \xff\xfe}\n",
])
def test_binary_and_utf16_parameter_files(payload, tmp_path, capsys):
    path = tmp_path / "p.yaml"
    path.write_bytes(payload)
    code, _, err = _run(["params", "--check", str(path)], capsys)
    _one_line_exit_2(code, err, "UTF-8")


@pytest.mark.parametrize("target", ["/dev/zero", "/dev/null", "directory", "fifo"])
def test_non_regular_files_are_refused_without_reading(target, tmp_path, capsys):
    import os

    if target == "directory":
        target = str(tmp_path)
    elif target == "fifo":
        target = str(tmp_path / "fifo")
        os.mkfifo(target)
    code, _, err = _run(["params", "--check", target], capsys, timeout=10)
    _one_line_exit_2(code, err, "a regular file")
    assert "error: --check: got" in err  # the option (it was 'dir: got 'dir (a directory)'')


@pytest.mark.parametrize("argv, option", [
    (["simulate", "--params", "{dir}"], "--params"),
    (["diagram", "--params", "/dev/zero"], "--params"),
    (["uncertainty", "--spec", "{dir}"], "--spec"),
    (["diagnose", "{dir}"], "DATA"),  # it was 'metadata: got 'dir.yaml'', a file it never named
    (["diagnose", "{csv}", "--meta", "{dir}"], "--meta"),
    (["diagnose", "{csv}", "--score", "{dir}"], "--score"),
])
def test_a_folder_or_device_given_for_a_file_names_the_option(argv, option, tmp_path, capsys):
    """'simulate --params adir' said 'adir: got 'adir (a directory)'; allowed: a regular file', no option (found by
    the fourth fuzzing pass)."""
    from drakecreep.data import example_path

    (tmp_path / "d").mkdir()
    argv = [a.format(dir=tmp_path / "d", csv=example_path("emps_segment.csv")) for a in argv]
    code, _, err = _run(argv, capsys, timeout=30)
    _one_line_exit_2(code, err, f"error: {option}: got", "allowed: a regular file (this is a")


# --------------------------------------------------------------------------- sweep specs

SPECS = {
    "letter_index": ("axes:\n  loads.cases[x].fx: [1, 2]\n", "loads.cases[x].fx"),
    "index_too_large": ("axes:\n  loads.cases[99].fx: [1, 2]\n", "loads.cases[99].fx"),
    "negative_index": ("axes:\n  loads.cases[-1].fx: [1, 2]\n", "loads.cases[-1].fx"),
    "index_on_scalar": ("axes:\n  table[0].mass: [1, 2]\n", "table[0].mass"),
    "integer_axis_key": ("axes:\n  3: [1, 2]\n", "axes"),
    "float_axis_key": ("axes:\n  1.5: {start: 1, stop: 2, num: 2}\n", "axes"),
    "integer_axis_key_random": ("axes:\n  7: {low: 1, high: 2}\nsample: {mode: random, n: 2}\n", "axes"),
    "seed_text": ("axes:\n  table.mass: {low: 30, high: 40}\nsample: {mode: random, n: 2, seed: abc}\n", "seed"),
    "seed_negative": ("axes:\n  table.mass: {low: 30, high: 40}\nsample: {mode: random, n: 2, seed: -1}\n", "seed"),
    "seed_huge": ("axes:\n  table.mass: {low: 30, high: 40}\nsample: {mode: random, n: 2, seed: " + "9" * 400 + "}\n",
                  "seed"),
    # one description of a load case, the params file's: 1.0 said 'an integer >= 0', 7 'an integer in 0..3'
    "load_case_float": ("axes:\n  load_case: [1.0]\n", "axes.load_case: got 1.0; allowed: an integer in 0..3"),
    "load_case_missing": ("axes:\n  load_case: [7]\n", "axes.load_case: got 7; allowed: an integer in 0..3"),
    "n_huge": ("axes:\n  table.mass: {low: 30, high: 40}\nsample: {mode: random, n: 1000000000}\n", "--max-cases"),
    "grid_huge": ("axes:\n  table.mass: {start: 30, stop: 40, num: 100000}\n  feed: {start: 1.0e-4, stop: 1.0e-3, "
                  "num: 100000}\n", "--max-cases"),
    "num_huge": ("axes:\n  table.mass: {start: 30, stop: 40, num: " + "9" * 400 + "}\n", "--max-cases"),
    "range_huge_int": ("axes:\n  table.mass: {start: " + "9" * 400 + ", stop: 40, num: 3}\n", "axes.table.mass"),
    "value_huge_int": ("axes:\n  table.mass: [" + "9" * 400 + "]\n", "table.mass"),
    "absurd_value": ("axes:\n  table.mass: [1.0e300]\n", "table.mass"),
    "bad_plot_x": ("axes:\n  table.mass: [30, 40]\nplot: {x: nut.mass}\n", "plot.x"),
    "bad_plot_y": ("axes:\n  table.mass: [30, 40]\nplot: {x: table.mass, y: nope}\n", "plot.y"),
    # a map of an axis against itself: the sweep ran and drew feed against feed, exit 0 (found by the fifth pass)
    "plot_y_is_x": ("axes:\n  feed: [1.0e-3, 2.0e-3]\nplot: {x: feed, y: feed}\n",
                    "error: plot.y: got 'feed'; allowed: a swept path or scenario field other than plot.x (feed)"),
    "bad_plot_color": ("axes:\n  table.mass: [30, 40]\nplot: {x: table.mass, color: nope}\n", "plot.color"),
    # a map coloured by a metric the table leaves out: the sweep ran, exit 0, and drew no map without a word (found
    # by fuzzing in session 68)
    "plot_color_not_in_metrics": ("axes:\n  feed: [1.0e-3, 2.0e-3]\nmetrics: [creep]\nplot: {x: feed}\n",
                                  "error: plot.color: got 'fluctuation_rate_percent (the default)'; allowed: one of "
                                  "the spec's metrics, creep (or add fluctuation_rate_percent to metrics)"),
    "duplicate_axis": ("axes:\n  table.mass: [30]\n  table.mass: [40]\n", "duplicate key"),
    "empty": ("", "empty"),
    "base_dev_zero": ("base: {file: /dev/zero}\naxes:\n  table.mass: [30, 40]\n", "base.file"),
    "base_missing": ("base: {file: nothere.yaml}\naxes:\n  table.mass: [30, 40]\n", "base.file"),
    "base_text_file": ("base: {file: secret.txt}\naxes:\n  table.mass: [30, 40]\n", "YAML"),
    "base_set_int_key": ("base: {set: {3: 4}}\naxes:\n  table.mass: [30, 40]\n", "base.set"),
    "bomb": (_bomb(), "aliases"),
    "bomb_as_axis": ("axes:\n  table.mass: &m [30, 40]\n" + _bomb_in_value().replace("x0:", "junk:"), "junk"),
    "grid_with_n": ("axes:\n  table.mass: [30, 40]\nsample: {mode: grid, n: 3}\n", "sample"),
    "grid_with_seed": ("axes:\n  table.mass: [30, 40]\nsample: {seed: 3}\n", "sample"),
    "scenario_bad": ("scenario: {feed: fast}\naxes:\n  table.mass: [30]\n", "feed"),
    # a whole parameter group set to a number (session 59's fuzzing: exit 1 with nothing on stderr as a base value,
    # an AttributeError as an axis)
    "group_as_axis": ("axes:\n  table: [1, 2]\n", "table.mass"),
    "group_in_base": ("base: {set: {table: 1}}\naxes:\n  nut.mass: [0.3]\n", "not the whole group"),
    "cases_as_number": ("base: {set: {loads.cases: 1}}\naxes:\n  nut.mass: [0.3]\n", "loads.cases"),
    "max_step_tiny": ("axes:\n  simulation.max_step: [1.0e-3, 1.0e-9]\n", "simulation.max_step"),
    # each error names the spec's key the value is under (it named the params field or the library's parameter alone:
    # 'table.mass: got -1.0', 'preset: got 'nope'', 'seed: got -1', 'feed: got [0.001]'; found by the fourth pass)
    "base_set_bad": ("base: {set: {table.mass: -1}}\naxes:\n  nut.mass: [0.3]\n", "error: base.set.table.mass: got -1.0"),
    "base_set_unknown": ("base: {set: {table.mas: 1}}\naxes:\n  nut.mass: [0.3]\n", "error: base.set.table.mas: got 1"),
    "base_preset_bad": ("base: {preset: nope}\naxes:\n  nut.mass: [0.3]\n", "error: base.preset: got 'nope'"),
    "base_file_field": ("base: {file: rig.yaml}\naxes:\n  nut.mass: [0.3]\n", "error: base.file rig.yaml: table.mass: got"),
    "base_file_text": ("base: {file: secret.txt}\naxes:\n  nut.mass: [0.3]\n", "error: base.file secret.txt: got 'invalid YAML"),
    "sample_seed_named": ("axes:\n  table.mass: {low: 30, high: 40}\nsample: {mode: random, n: 2, seed: -1}\n",
                          "error: sample.seed: got -1"),
    "sample_n_named": ("axes:\n  table.mass: {low: 30, high: 40}\nsample: {mode: random}\n", "error: sample.n: got None"),
    "axis_value_named": ("axes:\n  feed: [[1.0e-3]]\n", "error: axes.feed: got [0.001]"),
    "axis_choice_named": ("axes:\n  friction.law: [coulomb, nope]\n", "error: axes.friction.law: got 'nope'"),
    "scenario_value_named": ("scenario: {load_case: 9}\naxes:\n  nut.mass: [0.3]\n", "error: scenario.load_case: got 9"),
}


@pytest.mark.parametrize("name", sorted(SPECS))
def test_bad_sweep_specs(name, tmp_path, capsys):
    text, fragment = SPECS[name]
    (tmp_path / "secret.txt").write_text(PASSWD_LIKE)
    (tmp_path / "rig.yaml").write_text("table: {mass: -1.0}\n")
    spec = tmp_path / "spec.yaml"
    spec.write_text(text)
    code, _, err = _run(["sweep", str(spec), "--out", str(tmp_path / "out"), "--workers", "1", "--no-progress"],
                        capsys)
    _one_line_exit_2(code, err, fragment)
    assert "s3cr3t" not in err and "root:x" not in err
    assert not (tmp_path / "out" / "results.csv").exists()


def test_references_resolve_relative_to_the_referring_file(tmp_path, capsys, monkeypatch):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "rig.yaml").write_text("table: {mass: 1.0e9}\n")
    spec = tmp_path / "sub" / "spec.yaml"
    spec.write_text("base: {file: rig.yaml}\naxes:\n  table.mass: [30, 40]\n")
    monkeypatch.chdir(tmp_path)  # the reference is found beside the spec, not in the working folder
    code, _, err = _run(["sweep", str(spec), "--out", str(tmp_path / "out"), "--workers", "1"], capsys)
    _one_line_exit_2(code, err, "table.mass")


def test_sweep_cap_can_be_raised(tmp_path):
    from drakecreep.errors import InputError
    from drakecreep.sim.sweep import grid

    axes = {"table.mass": list(range(1, 31)), "feed": [1e-3 * k for k in range(1, 11)]}
    with pytest.raises(InputError, match="max-cases"):
        grid(axes, max_cases=100)
    with pytest.raises(InputError, match="at most 1 case in ") as err:  # not "1 cases"
        grid(axes, max_cases=1)
    assert "got '300 cases'" in str(err.value)
    assert len(grid(axes, max_cases=300)) == 300


# --------------------------------------------------------------------------- measured files

GOOD_META = "u_units: N\nu_gain: 1.0\n"
GOOD_CSV = "t,x_ref,x_motor,u\n" + "".join(f"{i * 0.001},{i * 1e-6},{i * 1e-6},0.5\n" for i in range(50))

MEASURED = {
    "csv_utf16": (None, GOOD_META, "UTF-8"),
    "csv_binary": (b"\x00\x01\x02\xff" * 100, GOOD_META, "UTF-8"),
    "csv_nul": (b"t,x_ref,x_motor,u\n0,0,0,\x000\n", GOOD_META, "column u"),
    "csv_empty": (b"", GOOD_META, "run.csv"),
    "csv_text_cell": (GOOD_CSV.replace("0.5\n", "half\n", 1).encode(), GOOD_META, "column u"),
    "csv_short_row": ((GOOD_CSV + "1,2\n").encode(), GOOD_META, "row 51"),
    "csv_huge_number": ((GOOD_CSV + "0.06," + "9" * 400 + ",0,0\n").encode(), GOOD_META, ""),
    "meta_empty": (GOOD_CSV.encode(), "", "empty"),
    "meta_duplicate": (GOOD_CSV.encode(), "u_units: N\nu_units: A\n", "duplicate key"),
    "meta_utf16": (GOOD_CSV.encode(), None, "UTF-8"),
    "meta_params_dev_zero": (GOOD_CSV.encode(), GOOD_META + "params: /dev/zero\n", "params"),
    "meta_params_missing": (GOOD_CSV.encode(), GOOD_META + "params: ../nothere/rig.yaml\n", "params"),
    "meta_params_text": (GOOD_CSV.encode(), GOOD_META + "params: secret.txt\n", "YAML"),
    "meta_bomb": (GOOD_CSV.encode(), _bomb(), "aliases"),
    "meta_bomb_value": (GOOD_CSV.encode(), "u_units: N\nnotes: &n [1]\n" + _bomb_in_value().replace("x0:", "zz:"),
                        "zz"),
    "meta_list": (GOOD_CSV.encode(), "- 1\n", "u_units"),
    # a run column with no label in some rows (NaN, empty): an IndexError before session 59
    "meta_gain_quoted": (GOOD_CSV.encode(), GOOD_META + "controller: {kind: p_p_cascade, kp: '160', kv: 200}\n",
                         "controller.kp: got '160'; allowed: a finite number (not quoted)"),
    "meta_gain_huge": (GOOD_CSV.encode(), GOOD_META + "controller: {kind: p_p_cascade, kp: 160, kv: 1.0e+300}\n",
                       "controller.kv: got 1e+300; allowed: a finite number <= 1e+09"),
    "x_table_constant": (GOOD_CSV.replace("t,x_ref,x_motor,u\n", "t,x_ref,x_motor,u,x_table\n").replace("0.5\n", "0.5,0\n")
                         .encode(), GOOD_META, "x_table (run run): got 'constant while x_motor moves'"),
    # an encoder that reads nothing while the reference moves: a whole diagnosis ran on it (found by the fuzzing pass)
    "x_motor_constant": (("t,x_ref,x_motor,u\n" + "".join(f"{i * 0.001},{i * 1e-6},0,0.5\n" for i in range(50))).encode(),
                         GOOD_META, "x_motor (run run): got 'constant while x_ref travels 4.9e-05 m'"),
    # read in seconds without a word (found by the fuzzing pass)
    "file_units_against_header": (GOOD_CSV.replace("t,", "t[ms],", 1).encode(), GOOD_META + "file: {units: {t: s}}\n",
                                  "run.csv: file.units.t: got 's'; allowed: the unit the file's header gives the column, ms"),
    "empty_unit_brackets": (GOOD_CSV.replace("t,", "t[],", 1).encode(), GOOD_META,  # read as SI (fuzzing pass)
                            "run.csv: column t unit: got ''; allowed: one of s, ms, us, µs in the brackets"),
    "u_corrupt_cell": (GOOD_CSV.replace("0.5\n", "1e300\n", 1).encode(), GOOD_META, "forces up to 1e+06 N"),
    # a u_gain far off (1e6 N/V for 35 on the EMPS run): diagnosed as a 2.7e6 kg axis, exit 0, under the former 1e7 N
    "u_gain_absurd": (GOOD_CSV.encode(), "u_units: V\nu_gain: 3.0e+6\n", "forces up to 1e+06 N (u x u_gain)"),
    "run_label_nan": (GOOD_CSV.replace("t,x_ref,x_motor,u\n", "t,x_ref,x_motor,u,run\n").replace("0.5\n", "0.5,nan\n")
                      .encode(), GOOD_META, "column run"),
    "run_label_empty": (GOOD_CSV.replace("t,x_ref,x_motor,u\n", "t,x_ref,x_motor,u,run\n").replace("0.5\n", "0.5,a\n")
                        .replace("0.001,1e-06,1e-06,0.5,a\n", "0.001,1e-06,1e-06,0.5,\n").encode(), GOOD_META,
                        "no label at data row 2"),
}


@pytest.mark.parametrize("name", sorted(MEASURED))
def test_bad_measured_files(name, tmp_path, capsys):
    csv_bytes, meta_text, fragment = MEASURED[name]
    (tmp_path / "secret.txt").write_text(PASSWD_LIKE)
    csv_path = tmp_path / "run.csv"
    csv_path.write_bytes(csv_bytes if csv_bytes is not None else GOOD_CSV.encode("utf-16"))
    meta = tmp_path / "run.yaml"
    if meta_text is None:
        meta.write_bytes(GOOD_META.encode("utf-16"))
    else:
        meta.write_text(meta_text)
    code, _, err = _run(["diagnose", str(csv_path)], capsys)
    _one_line_exit_2(code, err, fragment)
    assert "s3cr3t" not in err and "root:x" not in err


def _mat_bytes():
    from drakecreep.gap.measured import emps_path

    return emps_path("estimation").read_bytes()


@pytest.mark.parametrize("mangle", ["empty", "text", "header_only", "truncated_1k", "truncated_half", "flipped",
                                    "zeros"])
def test_bad_mat_files(mangle, tmp_path, capsys):
    data = _mat_bytes()
    payload = {
        "empty": b"",
        "text": b"this is not a mat file\n" * 10,
        "header_only": data[:128],
        "truncated_1k": data[:1024],
        "truncated_half": data[: len(data) // 2],
        "flipped": data[:200] + bytes(b ^ 0x5A for b in data[200:4000]) + data[4000:],
        "zeros": data[:128] + b"\x00" * 4096,
    }[mangle]
    path = tmp_path / "bad.mat"
    path.write_bytes(payload)
    code, _, err = _run(["diagnose", str(path)], capsys)
    _one_line_exit_2(code, err, str(path))


# --------------------------------------------------------------------------- output folders and options

@pytest.mark.parametrize("argv", [
    ["simulate", "--out", "{file}"],
    ["simulate", "--out", "{file}/sub"],
    ["report", "--out", "{file}"],
    ["diagnose", "estimation", "--out", "{file}"],
    ["sweep", "{spec}", "--out", "{file}", "--workers", "1"],
    ["uncertainty", "--samples", "2", "--feeds", "0.1", "--duration", "1.2", "--workers", "1", "--out", "{file}"],
    ["diagram", "--out", "{file}/d.svg"],
])
def test_output_folder_is_checked_before_the_work(argv, tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("keep me\n")
    spec = tmp_path / "spec.yaml"
    spec.write_text("axes:\n  table.mass: [30, 40]\n")
    argv = [a.format(file=afile, spec=spec) for a in argv]
    code, _, err = _run(argv, capsys, timeout=20)
    _one_line_exit_2(code, err, "--out")
    assert afile.read_text() == "keep me\n"


def test_a_sweep_checks_its_output_folder_before_it_builds_the_cases(tmp_path, capsys):
    """A 100 x 1000 grid took 27 s to build before '--out' was refused: the folder comes first (a spec with a
    bad axis shows the order without the wait)."""
    afile = tmp_path / "afile"
    afile.write_text("keep me\n")
    spec = tmp_path / "spec.yaml"
    spec.write_text("axes:\n  table.mas: [30, 40]\n")
    code, _, err = _run(["sweep", str(spec), "--out", str(afile)], capsys, timeout=20)
    _one_line_exit_2(code, err, "--out")


def test_missing_score_file_is_found_before_the_diagnosis(tmp_path, capsys):
    code, _, err = _run(["diagnose", "estimation", "--score", str(tmp_path / "nothere.mat")], capsys, timeout=20)
    _one_line_exit_2(code, err, "nothere.mat")


def test_a_score_file_that_cannot_be_replayed_is_named(tmp_path, capsys):
    """Errors of the replay's checks said 'run: got '10 samples'' or 'controller.sample_time: got 0.01', of the
    diagnosed file or of the scored one, unsaid (found by the fuzzing pass)."""
    from drakecreep.data import data_dir

    example = data_dir() / "examples" / "emps_segment.csv"
    meta = (example.with_suffix(".yaml")).read_text()
    rows = (example.read_text().splitlines()[3:])
    (tmp_path / "sc.csv").write_text("t[ms],x_ref[mm],x_motor[mm],u[V],f_ext[N],run\n" + "".join(
        f"{row},{'a' if i < 100 else 'b'}\n" for i, row in enumerate(rows[:110])))
    (tmp_path / "sc.yaml").write_text(meta)
    (tmp_path / "ts.csv").write_text(example.read_text())
    # a sample time of 1.5 ticks; one of two ticks whose u changes at every sample (since session 86 a log taken
    # several times a tick is cut to its ticks, where the held u changes)
    (tmp_path / "ts.yaml").write_text(meta.replace("sample_time: 0.001", "sample_time: 0.0015"))
    (tmp_path / "tu.csv").write_text(example.read_text())
    (tmp_path / "tu.yaml").write_text(meta.replace("sample_time: 0.001", "sample_time: 0.002"))
    for argv, fragment in (
            (["--score", str(tmp_path / "sc.csv")], f"--score {tmp_path / 'sc.csv'}: run b: got '10 samples'; allowed: "
                                                    "at least 20 samples"),
            (["--score", str(tmp_path / "ts.csv")], f"--score {tmp_path / 'ts.csv'}: controller.sample_time (run ts): "
                                                    "got 0.0015; allowed: the run's sample time 0.001 s, a whole "
                                                    "fraction of it"),
            (["--score", str(tmp_path / "tu.csv")], f"--score {tmp_path / 'tu.csv'}: u (run tu): got "),
            ([], None)):
        data = str(tmp_path / "ts.csv") if not argv else str(example)
        code, _, err = _run(["diagnose", data, "--train", "0", "--test", "1,2"] + argv, capsys, timeout=20)
        _one_line_exit_2(code, err, fragment or f"{data}: controller.sample_time (run ts@0): got 0.0015")
        if argv and "tu.csv" in argv[1]:
            assert "(or is controller.sample_time, 0.002 s, wrong?)" in err

@pytest.mark.parametrize("address", ["garbage", "tcp://127.0.0.1:1", "tcp://[::1", ""])
def test_bad_or_unreachable_scheduler(address, tmp_path, capsys, monkeypatch):
    import drakecreep.sim.sweep as sweep

    monkeypatch.setattr(sweep, "DASK_TIMEOUT", 1.0)
    spec = tmp_path / "spec.yaml"
    spec.write_text("axes:\n  table.mass: [30, 40]\n")
    code, _, err = _run(["sweep", str(spec), "--out", str(tmp_path / "o"), "--scheduler", address, "--no-progress"],
                        capsys, timeout=25)
    _one_line_exit_2(code, err, "--scheduler")


def test_scheduler_without_workers_times_out_with_a_message():
    from distributed import LocalCluster

    from drakecreep.errors import InputError
    from drakecreep.sim.sweep import connect_dask

    with LocalCluster(n_workers=0, processes=False, dashboard_address=None) as cluster:
        start = time.perf_counter()
        with pytest.raises(InputError, match="worker"):
            connect_dask(cluster.scheduler_address, timeout=1.0)
        assert time.perf_counter() - start < 10


# --------------------------------------------------------------------------- the top-level guard

def test_unexpected_error_is_one_line_and_points_to_debug(monkeypatch, capsys):
    import drakecreep.cli.params as cmd

    def boom(args):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(cmd, "run", boom)
    code, _, err = _run(["params"], capsys)
    assert code == 1 and len(err.strip().splitlines()) == 1
    assert "ZeroDivisionError: a bug" in err and "--debug" in err
    code, _, err = _run(["--debug", "params"], capsys)
    assert code == 1 and "Traceback" in err and "ZeroDivisionError: a bug" in err.strip().splitlines()[-1]


@pytest.mark.parametrize("argv, fragment", [
    (["hertz", "--balls", "9" * 400], "--balls"),
    (["hertz", "--balls", "0"], "--balls"),
    (["hertz", "--youngs-modulus", "1e308"], "--youngs-modulus"),
    (["hertz", "--preload", "inf"], "--preload"),
    # the load the user changed, not the catalogue groove they left: blamed '--conformity: got 1.04'
    (["hertz", "--preload", "1e7"], "--preload: got 10000000.0; allowed: an axial force below 1.487e+05 N for this "
                                    "groove (--conformity 1.04)"),
    (["hertz", "--preload", "1e7", "--conformity", "1.1"], "--conformity: got 1.1; allowed: a groove that keeps"),
    (["hertz", "--lead", "-1"], "--lead"),
    (["hertz", "--mass", "1e-300"], "--mass: got 1e-300"),
    (["hertz", "--contact-angle", "90"], "--contact-angle: got 90.0; allowed: an angle in [5, 85] deg"),
    # a ball load of 7e302 N: the contact left the ball and the message blamed '--conformity: got 1.04'
    (["hertz", "--contact-angle", "1e-300"], "--contact-angle: got 1e-300; allowed: an angle in [5, 85] deg (a ball"),
    (["hertz", "--contact-angle", "0.1"], "--contact-angle: got 0.1; allowed: an angle in [5, 85] deg"),
    (["hertz", "--diameter", "1"], "--ball-diameter: got 3.175; allowed: a diameter below --diameter (1 mm)"),
    (["hertz", "--conformity", "1"], "--conformity: got 1.0; allowed: a groove/ball radius ratio in (1, 10]"),
    (["hertz", "--conformity", "0.9"], "--conformity: got 0.9"),  # the model's 'conformity: got 0.9'
    (["hertz", "--conformity", "1e9"], "--conformity: got 1000000000.0"),
    (["hertz", "--conformity", "1.0000000001"], "--conformity: got 1.0000000001; allowed: a groove that keeps the contact within the ball"),
    (["sweep", "{tmp}/token.txt"], "got 'a YAML str'"),
    # a missing file named by its option (the generic line said only 'No such file or directory')
    (["simulate", "--params", "{tmp}/nothere.yaml"], "--params: got"),
    (["params", "--check", "{tmp}/nothere.yaml"], "--check: got"),  # 'No such file or directory: ...'
    (["diagnose", "{example}", "--meta", "{tmp}/nothere.yaml"], "--meta: got"),
    (["uncertainty", "--spec", "{tmp}/nothere.yaml"], "--spec: got"),
    # an option given twice: the last value won without a word
    (["simulate", "--out", "{tmp}/s", "--feed", "1", "--feed=2"], "--feed: got '1 then 2'; allowed: the option once"),
    (["margins", "--load-case", "0", "--load-case", "3"], "--load-case: got '0 then 3'; allowed: the option once"),
    # positional files too (they said 'No such file or directory: ...', no field)
    (["sweep", "{tmp}/nothere.yaml"], "nothere.yaml'; allowed: an existing file (no such file or directory)"),
    (["modal", "{tmp}/nothere.csv"], "nothere.csv'; allowed: an existing file (no such file or directory)"),
    (["modal", "{tmp}"], "'; allowed: a regular file (this is a folder)"),
    # the option and mm/s, not the scenario's field in m/s; a placement that fails names both targets
    (["report", "--out", "{tmp}/r", "--feed", "-1"], "--feed: got -1.0; allowed: a feed in [1e-4, 1000] mm/s (> 0"),
    # one description of a feed in every analysis ('a finite speed > 0 in mm/s' in critical)
    (["critical", "--feed", "0"], "--feed: got 0.0; allowed: a feed in [1e-4, 1000] mm/s (> 0"),
    (["report", "--out", "{tmp}/r", "--low-feed", "-0.1"], "--low-feed: got -0.1"),
    # without the creep simulations there is nothing to run on them: ignored without a word
    (["report", "--out", "{tmp}/r", "--no-sim-grid", "--workers", "2"], "--workers: got 2; allowed: only with the "
                                                                         "pole map's creep simulations"),
    (["margins", "--feed", "-1"], "--feed: got -1.0"),
    (["margins", "--friction", "gms"], "--friction: got 'gms'; allowed: coulomb, stribeck or lugre"),  # 'friction.law'
    (["tune", "--friction", "gms"], "--friction: got 'gms'"),
    (["report", "--out", "{tmp}/r", "--friction", "gms"], "--friction: got 'gms'"),
    # targets no drive is tuned for: 1e-300 Hz blamed '--phase-margin: got 60.0', 1e-300 deg was tuned, exit 0
    (["tune", "--bandwidth", "1e-300"], "--bandwidth: got 1e-300; allowed: a bandwidth of at least 0.01 Hz (a feed"),
    (["tune", "--bandwidth", "0"], "--bandwidth: got 0.0; allowed: a bandwidth of at least 0.01 Hz"),
    (["tune", "--phase-margin", "1e-300"], "--phase-margin: got 1e-300; allowed: an angle in [10, 90) deg (below"),
    (["tune", "--phase-margin", "-1"], "--phase-margin: got -1.0; allowed: an angle in [10, 90) deg"),
    # every crossover needs ki < 0: the pair is out of reach, named by the option given
    (["tune", "--phase-margin", "89.999"], "--phase-margin: got '40 Hz at a phase margin of 89.999 deg'; allowed: a "
                                           "bandwidth and phase margin this PI can place together (at every crossover"),
    # just under the sampled loop's bound (500 Hz): blamed '--phase-margin: got 60.0', an option not given
    (["tune", "--bandwidth", "499.99"], "--bandwidth: got '499.99 Hz at a phase margin of 60 deg'; allowed: a "
                                        "bandwidth and phase margin"),
    (["uncertainty", "--spec", "{tmp}/token.txt"], "got 'a YAML str'"),
    (["diagnose", "{example}", "--meta", "{tmp}/token.txt"], "got 'a YAML str'"),  # the axial frequency overflowed to inf, exit 0
    (["modal", "{tmp}/frf_1e300.csv"], "largest magnitude"),  # zeta = inf in the JSON, exit 0
    (["modal", "{tmp}/frf_1e-300.csv"], "largest magnitude"),  # zeta = 0 and k = 1.6e305, exit 0
    (["modal", "{tmp}/frf_negative_f.csv"], "f_Hz: got '-100 Hz at data row 1'"),  # 'frequency band: got (None, None)'
    (["modal", "{tmp}/frf_repeated_f.csv"], "values increasing row by row"),
    (["modal", "{tmp}/noise_t.csv"], "force: got \"no band excited within 10 dB"),  # said 'frequency band: ...'
    (["gap-benchmark", "--samples", "10"], "--samples"),
    (["gap-benchmark", "--n-per-effect", "0", "--n-null", "0", "--n-ool", "0"], "--n-per-effect"),
    (["margins", "--feed", "1e-300"], "--feed"),
    (["report", "--out", "{tmp}/r", "--low-feed", "1e-300"], "--low-feed"),
    (["simulate", "--out", "{tmp}/s", "--feed", "1e-300"], "--feed"),
    (["modal", "{tmp}/u16.csv"], "UTF-8"),
    (["modal", "/dev/zero"], "regular file"),
    (["sweep", "{tmp}/spec.yaml", "--max-cases", "0"], "--max-cases"),
    (["uncertainty", "--samples", "99999999999"], "--samples: got 99999999999; allowed: at most 20000 rigs"),
    (["uncertainty", "--feeds", "0.1,,0.2"], "no empty item"),
    (["uncertainty", "--feeds", "0.1,"], "no empty item"),
    (["uncertainty", "--load-cases", "1,,2"], "no empty item"),
    (["uncertainty", "--feeds", "0.1,0.1"], "distinct values"),
    (["uncertainty", "--seed", "99999999999999999999999"], "--seed: got 99999999999999999999999"),
    (["uncertainty", "--load-cases", "2,2"], "distinct values"),
    (["simulate", "--out", "{tmp}/s", "--uncertainty", "99999999999"], "--uncertainty: got 99999999999"),
    (["simulate", "--out", "{tmp}/s", "--seed", "3"], "--seed: got 3; allowed: only with --uncertainty"),
    (["simulate", "--out", "{tmp}/s", "--spec", "{tmp}/spec.yaml"], "--spec"),
    (["compensate", "--out", "{tmp}/c", "--feeds", "0.1,,1"], "no empty item"),
    (["compensate", "--out", "{tmp}/c", "--load-cases", "3,3"], "each once"),
    (["uncertainty", "--workers", "99999"], "--workers: got '99999'; allowed: an integer in [1, 256]"),
    (["sweep", "{tmp}/spec.yaml", "--workers", "100000"], "--workers: got '100000'; allowed: an integer in [1, 256]"),
    (["diagnose", "estimation", "--workers", "257"], "--workers: got '257'; allowed: an integer in [1, 256]"),
    (["compensate", "--out", "{tmp}/c", "--workers", "2.5"], "--workers: got '2.5'; allowed: an integer in [1, 256]"),
    # session 59's fuzzing: a retry count that repeats a deterministic failure for ever, a held-out run counted
    # twice (two held-out runs from one), blank or repeated candidates (',' ran none)
    (["sweep", "{tmp}/spec.yaml", "--retries", "99999999999"], "--retries: got 99999999999; allowed: an integer in"),
    (["diagnose", "{example}", "--test", "1,1"], "--test: got '1,1'; allowed: each run once"),
    (["diagnose", "{example}", "--train", "0,0"], "--train: got '0,0'; allowed: each run once"),
    (["diagnose", "{example}", "--effects", ","], "--effects: got ','; allowed: comma-separated names, none blank"),
    (["diagnose", "{example}", "--effects", "position_ripple,position_ripple"], "given twice"),
    (["gap-benchmark", "--effects", "stribeck,", "--n-per-effect", "1"], "--effects"),
    # the benchmark's own metadata: a --meta beside 'estimation' was ignored without a word (found by the fuzzing pass)
    (["diagnose", "estimation", "--meta", "{tmp}/spec.yaml"], "--meta: got '"),
    # the options, not the library's names ('duration: got 1000000000.0', 'calibration_rows: got (1,)')
    (["simulate", "--out", "{tmp}/s", "--duration", "1e9"], "--duration: got 1000000000.0; allowed: a time in (0, 3600]"),
    # a metrics window of 0.1 us: blamed 'simulation.log_period: got 0.00025', a field nobody had set
    (["simulate", "--out", "{tmp}/s", "--duration", "1.0000001"], "--duration: got 1.0000001; allowed: >= 1.005 s: "
                                                                  "simulation.steady_start (1 s) and then the metrics"),
    # a window of 5e-301 s: 'simulation.log_period: got 0.00025; allowed: <= 2.5e-302 s', a field nobody had set
    (["compensate", "--out", "{tmp}/c", "--duration", "1e-300"], "--duration: got 1e-300; allowed: a time in [0.1, 3600] s"),
    (["compensate", "--out", "{tmp}/c", "--duration", "1e9"], "--duration: got 1000000000.0; allowed: a time in [0.1, 3600]"),
    # an option with no effect: a continuous controller's compensators read the ideal speed (the same CSV, exit 0);
    # a method given twice was run once without a word, where --feeds 1,1 is refused
    (["compensate", "--out", "{tmp}/c", "--params", "{tmp}/continuous.yaml", "--speed-source", "encoder"],
     "--speed-source: got 'encoder'; allowed: only with a sampled controller"),
    (["compensate", "--out", "{tmp}/c", "--method", "static", "--method", "static"],
     "--method: got 'static,static'; allowed: each method once (static given twice)"),
    # inside the 0.05 s acceleration ramp: verdicts on the ramp, exit 0
    (["compensate", "--out", "{tmp}/c", "--duration", "0.01"], "--duration: got 0.01; allowed: a time in [0.1, 3600]"),
    (["uncertainty", "--duration", "1e9"], "--duration: got 1000000000.0; allowed: a time in (0, 3600]"),
    # more samples than a run records at the default log period, and a window too short: both blamed a field
    # nobody had set ('simulation.log_period: got 0.00025', 'duration: got 1.001' from the sweep under the study)
    (["simulate", "--out", "{tmp}/s", "--duration", "600"], "--duration: got 600.0; allowed: <= 500 s: at most "
                                                           "2000000 recorded samples per run"),
    (["uncertainty", "--duration", "3600", "--samples", "1"], "--duration: got 3600.0; allowed: <= 500 s"),
    (["uncertainty", "--duration", "1.001", "--samples", "1"], "--duration: got 1.001; allowed: >= 1.005 s"),
    (["uncertainty", "--preset", "rigid_axis", "--samples", "1"], "--preset: got 'rigid_axis'; allowed: a preset "
                                                                  "with an uncertainty spec"),
    (["reproduce-paper", "--out", "{tmp}/p", "--calibrate", "1"], "--calibrate: got '1'; allowed: two rows"),
    # one rule in every message: '4,4' said 'one or two distinct rows', contradicting '1' (two rows)
    (["reproduce-paper", "--out", "{tmp}/p", "--calibrate", "4,4"], "--calibrate: got '4,4'; allowed: two rows of "
                                                                     "[1, 2, 3, 4, 5, 6] from different experiments"),
    (["reproduce-paper", "--out", "{tmp}/p", "--calibrate", "1,2,3"], "--calibrate: got '1,2,3'; allowed: two rows of "
                                                                       "[1, 2, 3, 4, 5, 6] from different experiments"),
    # a name longer than the system allows: 'File name too long: /tmp/...', no option (found by the fourth pass)
    (["simulate", "--params", "{tmp}/" + "a" * 300 + ".yaml"], "--params: got"),
    (["diagnose", "{tmp}/" + "a" * 300 + ".csv"], "DATA: got"),
    (["diagnose", "{tmp}/spec.yaml", "--meta", "{tmp}/" + "a" * 300 + ".yaml"], "--meta: got"),
    (["uncertainty", "--spec", "{tmp}/" + "a" * 300 + ".yaml"], "--spec: got"),
    (["modes", "--out", "{tmp}/" + "a" * 300], "--out: got"),
    # a negative number in exponent form was taken for an option: 'argument --table-position: expected one argument'
    (["modes", "--table-position", "-1e3"], "--table-position: got -1000.0; allowed: in (-100, 500) mm"),
    (["hertz", "--preload", "-1e-3"], "--preload: got -0.001; allowed: a finite number in [1e-06, 1e+07]"),
    (["tune", "--feed", "-inf"], "--feed: got '-inf'; allowed: a finite number"),
])
def test_bad_options(argv, fragment, tmp_path, capsys):
    (tmp_path / "u16.csv").write_bytes("f_Hz,re,im\n1,2,3\n".encode("utf-16"))
    (tmp_path / "token.txt").write_text("ghp_s3cr3tTOKEN\n")
    f = np.linspace(0.0, 300.0, 301)
    h = 1.0 / (1.62e5 - 0.335 * (2 * np.pi * f) ** 2 + 1j * 1.68 * 2 * np.pi * f)
    rng, t = np.random.default_rng(0), np.arange(4096) / 2000.0  # a time file of noise: no impulse
    np.savetxt(tmp_path / "noise_t.csv", np.column_stack([t, rng.normal(size=t.size), rng.normal(size=t.size)]),
               delimiter=",", header="t,force,response", comments="")
    for name, freq in (("negative_f", f - 100.0), ("repeated_f", np.where(f == 150.0, 149.0, f))):
        np.savetxt(tmp_path / f"frf_{name}.csv", np.column_stack([freq, h.real, h.imag]), delimiter=",",
                   header="f_Hz,re,im", comments="")
    for name, scale in (("1e300", 1e300), ("1e-300", 1e-300)):  # a receptance in SI units scaled far beyond any test
        h = scale / (1.62e5 - 0.335 * (2 * np.pi * f) ** 2 + 1j * 1.68 * 2 * np.pi * f)
        np.savetxt(tmp_path / f"frf_{name}.csv", np.column_stack([f, h.real, h.imag]), delimiter=",",
                   header="f_Hz,re,im", comments="")
    (tmp_path / "spec.yaml").write_text("axes:\n  table.mass: [30, 40]\n")
    (tmp_path / "continuous.yaml").write_text("controller: {sampled: false}\n")
    from drakecreep.data import example_path

    example = example_path("emps_segment.csv")
    code, _, err = _run([a.format(tmp=tmp_path, example=example) for a in argv], capsys)
    _one_line_exit_2(code, err, fragment)
    assert "s3cr3t" not in err


def test_full_disk_is_one_line_exit_1(monkeypatch, capsys):
    import errno

    import drakecreep.cli.params as cmd

    def full(args):
        raise OSError(errno.ENOSPC, "No space left on device", "/out/results.csv")

    monkeypatch.setattr(cmd, "run", full)
    code, _, err = _run(["params"], capsys)
    assert code == 1 and len(err.strip().splitlines()) == 1 and "No space left on device" in err


def test_too_long_a_path_is_bad_input(capsys):
    code, _, err = _run(["emps", "--data", "9" * 400], capsys)
    _one_line_exit_2(code, err, "File name too long")


@pytest.mark.parametrize("argv, fragment", [
    (["simulate", "--params", ""], "--params"),
    (["simulate", "--out", ""], "--out"),
    (["simulate", "--out", "  "], "--out"),
    (["params", "--check", ""], "--check"),
    (["report", "--out", ""], "--out"),
    (["diagnose", ""], "DATA"),
    (["diagnose", "estimation", "--effects", ""], "--effects"),
    (["diagnose", "estimation", "--train", ""], "--train"),
    (["reproduce-paper", "--calibrate", ""], "--calibrate"),
    (["emps", "--data", ""], "--data"),
    (["tune", "--write", ""], "--write"),
    (["sweep", ""], "SPEC.yaml"),
])
def test_empty_values_are_refused_not_read_as_absent(argv, fragment, tmp_path, capsys, monkeypatch):
    # "" used to mean "not given": the default preset ran, the outputs landed in the working folder, every
    # effect was diagnosed; a shell variable left unset must not silently change what runs
    monkeypatch.chdir(tmp_path)
    code, _, err = _run(argv, capsys, timeout=10)
    _one_line_exit_2(code, err, fragment + ": got ''" if "  " not in argv else fragment)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("target", ["{tmp}", "{tmp}/afile/p.yaml", "/proc/no/such/p.yaml"])
def test_tune_write_target_is_checked_before_the_tuning(target, tmp_path, capsys, monkeypatch):
    import drakecreep.servo.tuning as tuning

    def started(*args, **kwargs):
        raise AssertionError("the tuning started before --write was checked")

    monkeypatch.setattr(tuning, "tune", started)
    (tmp_path / "afile").write_text("keep me\n")
    code, _, err = _run(["tune", "--write", target.format(tmp=tmp_path)], capsys)
    _one_line_exit_2(code, err, "--write")
    assert (tmp_path / "afile").read_text() == "keep me\n"


def test_tune_does_not_write_over_its_own_params_file(tmp_path, capsys):
    """--write onto --params replaced the commented input file (its sources and assumptions) without a word."""
    path = tmp_path / "p.yaml"
    code, out, _ = _run(["params", "--preset", "paper"], capsys)
    path.write_text(out)
    code, _, err = _run(["tune", "--params", str(path), "--write", str(path)], capsys)
    _one_line_exit_2(code, err, "--write: got ", "allowed: a file other than --params")
    assert path.read_text() == out


def test_a_drive_that_cannot_slide_names_the_feed_option_or_the_params(tmp_path, monkeypatch, capsys):
    """margins, tune and report at a feed whose force is beyond the drive's limit said 'feed: got 0.001' (the
    scenario's field in m/s); the report, for its own loci's speeds, 'feed: got 2e-05' after the loop analysis."""
    from drakecreep.params import preset, save_params, with_value
    from drakecreep.report import loop_report

    weak = tmp_path / "weak.yaml"
    save_params(with_value(preset("paper"), "motor.peak_torque", 0.001), weak)
    # no feed slides at all: the load case (it said '--feed: got 1.0', an option not given, 'allowed: a feed the
    # drive can slide at', where none can)
    for argv in (["margins"], ["tune"], ["report", "--out", str(tmp_path / "r")]):
        code, _, err = _run(argv + ["--params", str(weak), "--load-case", "0"], capsys)
        _one_line_exit_2(code, err, "--load-case: got 0; allowed: a load case the drive can hold at some feed: this "
                                    "one takes at least ")
    code, _, err = _run(["margins", "--params", str(weak), "--load-case", "0", "--feed", "5"], capsys)
    _one_line_exit_2(code, err, "--load-case: got 0")
    # Stribeck friction that rises at low speed: 1 mm/s slides, 0.1 mm/s and the loci's 0.02 mm/s do not
    stribeck = preset("paper")
    for path, value in (("motor.peak_torque", 0.6), ("friction.law", "stribeck"), ("friction.static_ratio", 3.0),
                        ("friction.stribeck_velocity", 5e-4)):
        stribeck = with_value(stribeck, path, value)
    save_params(stribeck, tmp_path / "stribeck.yaml")
    stribeck = tmp_path / "stribeck.yaml"

    def started(*args, **kwargs):
        raise AssertionError("the loop analysis started")

    monkeypatch.setattr(loop_report, "analyze_loops", started)
    code, _, err = _run(["report", "--params", str(stribeck), "--out", str(tmp_path / "r")], capsys)
    _one_line_exit_2(code, err, "--low-feed: got 0.1; allowed: a feed in mm/s the drive can slide at")
    code, _, err = _run(["report", "--params", str(stribeck), "--out", str(tmp_path / "r"), "--low-feed", "1"], capsys)
    _one_line_exit_2(code, err, "params: got '", "stribeck.yaml, load case 3: ", "N to slide at 0.02 mm/s'",
                     "the report's feeds, 0.005 to 3 mm/s")


def test_a_parameter_file_of_more_than_one_mebibyte_is_refused_before_it_is_parsed(tmp_path, capsys):
    from drakecreep.files import MAX_INPUT_BYTES

    path = tmp_path / "big.yaml"
    # valid YAML all through (a comment block after one field): only its size is wrong
    path.write_text("table: {mass: 3}\n" + "# padding\n" * (MAX_INPUT_BYTES // 10 + 1))
    code, _, err = _run(["params", "--check", str(path)], capsys)
    _one_line_exit_2(code, err, f"allowed: a file of at most {MAX_INPUT_BYTES} bytes")
    assert MAX_INPUT_BYTES == 1024 * 1024
    path.write_text("table: {mass: 3}\n" + "# padding\n" * (MAX_INPUT_BYTES // 10 - 10))  # just under: read
    code, _, err = _run(["params", "--check", str(path)], capsys)
    assert "at most" not in err


def test_an_empty_mapping_as_parameter_file_is_refused_not_read_as_all_defaults(tmp_path, capsys):
    path = tmp_path / "p.yaml"
    path.write_text("{}  # nothing\n")
    code, _, err = _run(["simulate", "--params", str(path), "--load-case", "0", "--out", str(tmp_path / "o")], capsys)
    _one_line_exit_2(code, err, "got 'an empty mapping ({})'; allowed: a YAML mapping of parameter groups")
    assert not (tmp_path / "o").exists()


def test_a_missing_positional_file_is_named_by_its_metavar(tmp_path, capsys):
    """sweep's SPEC.yaml and modal's FILE.csv said 'No such file or directory: ...', no field."""
    for argv, field in ((["sweep", str(tmp_path / "nothere.yaml")], "SPEC.yaml"),
                        (["modal", str(tmp_path / "nothere.csv")], "FILE.csv")):
        code, _, err = _run(argv, capsys)
        _one_line_exit_2(code, err, f"error: {field}: got '{argv[1]}'; allowed: an existing file")


def test_options_that_collect_may_repeat():
    """--method collects, -v counts, a flag twice says the same thing: none is refused; what follows -- is no option."""
    from drakecreep import cli

    parser = cli.build_parser()
    for argv in (["compensate", "--method", "static", "--method", "lugre", "--out", "x"],
                 ["margins", "-v", "-v", "-q", "-q"], ["sweep", "--", "--out"]):
        args, _ = parser.parse_known_args(argv)
        cli._check_no_repeated_options(parser, args, argv)


def test_a_friction_map_is_named_by_the_linear_analyses_and_simulated(tmp_path, capsys):
    """A params file with a friction along the travel (``friction.position_map_*``, an augmented file of the
    diagnosis's ``position_friction``): margins, tune and report refuse it in one line naming the field, before
    their work; simulate runs it."""
    from drakecreep.params import preset, save_params, with_value

    mapped = tmp_path / "mapped.yaml"
    save_params(with_value(preset("paper"), "friction.position_map_2", 0.3), mapped)
    for argv in (["margins"], ["tune"], ["report", "--out", str(tmp_path / "r")]):
        code, _, err = _run(argv + ["--params", str(mapped), "--load-case", "0"], capsys)
        _one_line_exit_2(code, err, "friction.position_map_2: got 0.3; allowed: 0 for the linear analyses")
    assert not (tmp_path / "r").exists() or not any((tmp_path / "r").iterdir())  # nothing written
    code, out, _ = _run(["simulate", "--params", str(mapped), "--load-case", "0", "--duration", "1.1", "--out",
                         str(tmp_path / "s")], capsys)
    assert code == 0 and "creep (stick-slip)" in out and (tmp_path / "s" / "metrics.json").exists()


def test_a_drive_that_saturates_below_its_load_names_the_saturation(tmp_path, capsys):
    """A saturation torque under what the friction takes (0.05 N m, 63 N at the table, against 118 N): the drive
    applies at most that, whatever its peak torque; simulate and critical say so by the field, not by
    motor.peak_torque alone."""
    from drakecreep.params import preset, save_params, with_value

    weak = tmp_path / "weak.yaml"
    save_params(with_value(preset("paper"), "motor.saturation_torque", 0.05), weak)
    code, _, err = _run(["simulate", "--params", str(weak), "--load-case", "0", "--out", str(tmp_path / "s")], capsys)
    _one_line_exit_2(code, err, "beyond the drive's limit 62.83 N (motor.peak_torque through motor.saturation_torque "
                                "and screw.lead against")
    code, out, _ = _run(["critical", "--params", str(weak), "--load-case", "0", "--feed", "1"], capsys)
    assert code == 0 and "force limit 62.83 N: motor.peak_torque through motor.saturation_torque" in out
