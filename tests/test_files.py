"""The atomic writer and output sets under faults: a SIGKILL during a write, a failing writer, a full disk."""

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from drakecreep.errors import InputError
from drakecreep.files import (OutputSet, check_output_dir, check_output_file, read_input_text, read_manifest, resolve_reference,
                              write_atomic, write_text)

_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _child(code):
    """A Python child running ``code`` from the worktree root; it prints READY when it is mid-write."""
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], cwd=_ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _kill_when_ready(proc):
    line = proc.stdout.readline()
    if line.strip() != "READY":
        proc.kill()
        _, err = proc.communicate(timeout=10)
        raise AssertionError(err)
    proc.send_signal(signal.SIGKILL)
    proc.communicate(timeout=10)  # reaps the child and closes its pipes
    assert proc.returncode == -signal.SIGKILL


def test_sigkill_during_a_write_leaves_the_old_file_whole(tmp_path):
    target = tmp_path / "timeseries.csv"
    target.write_text("old,complete\n1,2\n")
    proc = _child(f"""
        import sys, time
        from drakecreep.files import write_atomic
        def write(tmp):
            with open(tmp, "w") as fh:
                fh.write("new,partial\\n" * 1000)
                fh.flush()
                print("READY", flush=True)
                time.sleep(60)
        write_atomic({str(target)!r}, write)
    """)
    _kill_when_ready(proc)
    assert target.read_text() == "old,complete\n1,2\n"
    # only a hidden temporary file may be left, never a partial target
    assert {p.name for p in tmp_path.iterdir() if not p.name.startswith(".")} == {"timeseries.csv"}


def test_sigkill_between_files_of_a_set_leaves_no_manifest(tmp_path):
    with OutputSet(tmp_path, "metrics.json") as out:
        out.write_text("timeseries.csv", "run 1\n")
        out.commit({"status": "ok"})
    assert read_manifest(tmp_path / "metrics.json") is not None
    proc = _child(f"""
        import time
        from drakecreep.files import OutputSet
        with OutputSet({str(tmp_path)!r}, "metrics.json") as out:
            out.write_text("timeseries.csv", "run 2\\n")
            print("READY", flush=True)
            time.sleep(60)
            out.commit({{"status": "ok"}})
    """)
    _kill_when_ready(proc)
    # the new CSV is there, but no metrics.json claims it (or the old run) complete
    assert (tmp_path / "timeseries.csv").read_text() == "run 2\n"
    assert not (tmp_path / "metrics.json").exists()


def test_manifest_names_the_files_of_its_run_and_detects_a_mix(tmp_path):
    with OutputSet(tmp_path, "manifest.json") as out:
        out.write_text("a.txt", "A")
        out.write("b.bin", lambda tmp: Path(tmp).write_bytes(b"\x00\x01"))
        out.commit({"status": "ok"})
    body = read_manifest(tmp_path / "manifest.json")
    assert set(body["files"]) == {"a.txt", "b.bin"} and body["status"] == "ok" and len(body["run_id"]) == 32
    (tmp_path / "a.txt").write_text("from another run")
    assert read_manifest(tmp_path / "manifest.json") is None
    assert read_manifest(tmp_path / "manifest.json", verify=False) is not None


def test_a_failing_writer_keeps_the_old_file_and_removes_its_temporary(tmp_path):
    target = tmp_path / "results.csv"
    target.write_text("old\n")

    def full_disk(tmp):
        with open(tmp, "w") as fh:
            fh.write("half a ro")
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space"):
        write_atomic(target, full_disk)
    assert target.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["results.csv"]


def test_files_are_written_0644_less_the_umask(tmp_path):
    old = os.umask(0o022)
    try:
        path = write_text(tmp_path / "x.json", "{}")
    finally:
        os.umask(old)
    assert oct(path.stat().st_mode & 0o777) == oct(0o644)


def test_temporary_keeps_the_suffix_for_format_by_extension(tmp_path):
    seen = []
    write_atomic(tmp_path / "plot.png", lambda tmp: (seen.append(tmp), Path(tmp).write_text("")))
    assert seen[0].endswith(".png")


def test_inputs_are_regular_bounded_utf8(tmp_path):
    (tmp_path / "ok.yaml").write_text("a: 1\n")
    assert read_input_text(tmp_path / "ok.yaml") == "a: 1\n"
    (tmp_path / "big.yaml").write_text("a" * 2000)
    with pytest.raises(InputError, match="at most 1000 bytes"):
        read_input_text(tmp_path / "big.yaml", max_bytes=1000)
    with pytest.raises(InputError, match="regular file"):
        read_input_text("/dev/zero")
    (tmp_path / "u16.yaml").write_bytes("a: 1\n".encode("utf-16"))
    with pytest.raises(InputError, match="UTF-8"):
        read_input_text(tmp_path / "u16.yaml")


@pytest.mark.parametrize("payload", [b"a: \x00\n", b"a: \xff\n"])
def test_a_message_names_the_file_once(payload, tmp_path):
    path = tmp_path / "bin.yaml"
    path.write_bytes(payload)
    with pytest.raises(InputError) as named_by_path:
        read_input_text(path)
    assert str(named_by_path.value).count("bin.yaml") == 1
    with pytest.raises(InputError) as named_by_field:
        read_input_text(path, field="--params")
    message = str(named_by_field.value)
    assert message.count("bin.yaml") == 1 and "--params" in message


def test_references_are_relative_to_the_referring_file(tmp_path, monkeypatch):
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "rig.yaml").write_text("x: 1\n")
    monkeypatch.chdir("/")
    assert resolve_reference("rig.yaml", tmp_path / "d" / "meta.yaml", "params") == tmp_path / "d" / "rig.yaml"
    for bad in ("nothere.yaml", "/dev/zero", "", 3, None):
        with pytest.raises(InputError, match="params"):
            resolve_reference(bad, tmp_path / "d" / "meta.yaml", "params")


def test_output_dir_checks(tmp_path):
    (tmp_path / "afile").write_text("x")
    for bad in (tmp_path / "afile", tmp_path / "afile" / "sub"):
        with pytest.raises(InputError, match="--out"):
            check_output_dir(bad)
    assert check_output_dir(tmp_path / "new" / "dir").is_dir()


def test_output_dir_is_probed_with_a_file(tmp_path, monkeypatch):
    """os.access says yes to root where the file system refuses (/sys): the check creates a file, as the writes
    will, so the refusal comes before the work (report --out /sys/kernel failed after 12.7 s of it before)."""
    import tempfile

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    with pytest.raises(InputError, match=r"--out: got .*; allowed: a writable folder \(creating a file in it failed: "
                                         r"Permission denied\)"):
        check_output_dir(tmp_path)
    # a file in such a folder is named itself, with what is wrong with its folder ('--write: got '/proc'; ... No
    # such file or directory' named the folder of /proc/version, which exists)
    with pytest.raises(InputError, match=r"--write: got '.*p.yaml'; allowed: a file in a writable folder \(.*: "
                                         r"creating a file in it failed: Permission denied\)"):
        check_output_file(tmp_path / "p.yaml", "--write")


def test_output_file_checks(tmp_path):
    (tmp_path / "afile").write_text("x")
    for bad, why in ((tmp_path, "existing folder"), (tmp_path / "afile" / "p.yaml", "afile: this is an existing file"),
                     ("/proc/no/such/p.yaml", "--write: got '/proc/no/such/p.yaml'; allowed: a file in a writable "
                                              "folder \\(/proc/no/such: cannot be created: ")):
        with pytest.raises(InputError, match=why):
            check_output_file(bad, "--write")
    assert check_output_file(tmp_path / "new" / "p.yaml", "--write") == tmp_path / "new" / "p.yaml"
    assert sorted(p.name for p in (tmp_path / "new").iterdir()) == []  # the probe file is gone, nothing written


def test_csv_dialect_reads_the_separator_from_the_header_and_the_decimal_mark_from_the_first_row():
    from drakecreep.files import csv_dialect

    assert csv_dialect(["# a comment; with, marks", "", "t;x;u", "0,5;1,25;2"]) == (";", ",")
    assert csv_dialect(["t;x;u", "0.5;1.25;2"]) == (";", ".")
    assert csv_dialect(["t\tx", "1,5\t2"]) == ("\t", ",")
    assert csv_dialect(["t,x", "1.5,2"]) == (",", ".")
    assert csv_dialect(["t"]) == (",", ".")  # one column: nothing to tell, the default
    assert csv_dialect(["t;x", "1,5;2"], separator=";", decimal=".") == (";", ".")  # given values are kept


def test_a_folder_in_the_way_of_a_file_is_named(tmp_path):
    """os.replace onto a folder failed naming the hidden temporary file; the error names the target, and no
    temporary file is left."""
    (tmp_path / "params.yaml").mkdir()
    with pytest.raises(IsADirectoryError) as err:
        write_text(tmp_path / "params.yaml", "x")
    assert err.value.filename == str(tmp_path / "params.yaml")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["params.yaml"]


def test_a_device_or_fifo_in_the_way_of_a_file_is_refused_not_replaced(tmp_path):
    """'tune --write /dev/null' (as root) wrote the tuned parameters and replaced the device /dev/null with a regular
    file (os.replace onto it), exit 0; the check and the write now refuse a target that is no regular file."""
    fifo = tmp_path / "pipe.yaml"
    os.mkfifo(fifo)
    link = tmp_path / "link.yaml"
    link.symlink_to(fifo)
    for target in (fifo, link):
        with pytest.raises(InputError, match=r"^--write: got .*; allowed: a file name \(this is a device or other "
                                             r"special file, which writing the file would replace\)"):
            check_output_file(target, "--write")
        with pytest.raises(FileExistsError) as err:
            write_text(target, "x")
        assert err.value.filename == str(target)
    assert fifo.is_fifo() and link.is_symlink() and sorted(p.name for p in tmp_path.iterdir()) == ["link.yaml",
                                                                                                   "pipe.yaml"]


def test_a_name_longer_than_the_system_allows_names_the_option(tmp_path):
    """'report --out /tmp/aaa...' (300 characters in one name) said 'File name too long: /tmp/aaa...', no option."""
    long = tmp_path / ("a" * 300)
    with pytest.raises(InputError, match=r"^--out: got .*; allowed: a folder that can be created \(File name too long\)"):
        check_output_dir(long)
    with pytest.raises(InputError, match=r"^--write: got .*; allowed: a file that can be written \(File name too long\)"):
        check_output_file(tmp_path / ("p" * 300 + ".yaml"), "--write")


@pytest.mark.parametrize("path", [None, 3.5, b"", "", "\t", "x\0y"])
def test_an_input_file_that_is_no_path_is_named_by_its_field(path):
    from drakecreep.files import check_input_file

    with pytest.raises(InputError, match=r"^meta: got .*; allowed: a file path"):
        check_input_file(path, "meta")
