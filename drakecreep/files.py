"""Reading inputs and writing results safely (base layer: imports only :mod:`drakecreep.errors`).

Inputs: :func:`read_input_text` reads a user's text file only if it is a regular file of bounded size
(``/dev/zero``, a FIFO or a directory are refused before anything is read) and decodes it as UTF-8, turning
every failure into an :class:`~drakecreep.errors.InputError` naming the file; :func:`resolve_reference` reads
a file named *inside* another file relative to that file. Neither ever echoes a file's content.

Outputs: :func:`write_atomic` replaces one file atomically; :class:`OutputSet` writes a set of files that
belong to one run, the manifest last (see there); :func:`check_output_dir` validates an output folder
before a long computation starts.

Every JSON the project writes or prints goes through :func:`to_jsonable`: NumPy scalars and arrays become
Python numbers and lists, NaN becomes ``null`` and an infinite value the string ``"inf"`` / ``"-inf"``
(JSON has neither; an infinite gain margin is a real answer, not a missing one).
"""

from __future__ import annotations

import dataclasses
import datetime
import errno
import hashlib
import json
import math
import os
import stat
import tempfile
import uuid
from pathlib import Path

from drakecreep.errors import InputError

__all__ = [
    "MAX_INPUT_BYTES",
    "MAX_DATA_BYTES",
    "to_jsonable",
    "write_atomic",
    "write_json",
    "write_text",
    "read_input_text",
    "csv_dialect",
    "read_csv_frame",
    "first_non_number",
    "check_input_file",
    "check_path_argument",
    "resolve_reference",
    "check_output_dir",
    "check_output_file",
    "OutputSet",
    "read_manifest",
]

#: largest parameter, metadata or spec file read (bytes): such files are a few kB; the bound keeps
#: ``/dev/zero``-like inputs and accidental multi-GB files from exhausting memory, and bounds the time the
#: YAML parser takes before it can refuse a file (4 MB, the bound until session 66, took 11-22 s; 1 MiB 2-5 s)
MAX_INPUT_BYTES = 1024 * 1024
#: largest measured data file read (bytes): the EMPS files are 1-2 MB; 2 GB is far beyond any rig log
MAX_DATA_BYTES = 2 * 1024 ** 3


def to_jsonable(obj):
    """``obj`` as plain JSON types (dicts, lists, str, int, float, bool, None), recursively.

    Dataclasses become dicts of their fields; NaN becomes None; +-inf becomes ``"inf"``/``"-inf"``.
    """
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        obj = dataclasses.asdict(obj)
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, set)):
        return [to_jsonable(v) for v in obj]
    if hasattr(obj, "tolist") and not isinstance(obj, (str, bytes)):
        return to_jsonable(obj.tolist())
    if isinstance(obj, bool) or obj is None or isinstance(obj, (str, int)):
        return obj
    if isinstance(obj, float):
        if math.isnan(obj):
            return None
        if math.isinf(obj):
            return "inf" if obj > 0 else "-inf"
        return obj
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    return obj


def write_atomic(path, write):
    """Write a file atomically: ``write(tmp_path)`` then ``os.replace(tmp_path, path)``.

    A reader (or a resumed sweep) sees the old file or the whole new one, never a partial one; a failure
    (a full disk, a kill) leaves the old file and no temporary file behind (a SIGKILL may leave a hidden
    ``.<stem>.*.tmp<suffix>``, never a partial ``path``). The temporary file keeps the suffix of ``path``,
    so writers that pick a format by extension (``savefig``) work. The file is readable by the group and
    others (0666 less the umask), like any file a program writes.
    """
    path = Path(path)
    if path.is_dir():  # named before any work on the file (os.replace's error named the temporary file)
        raise IsADirectoryError(errno.EISDIR, "a folder is in the way of the file", str(path))
    if _special(path):  # os.replace put a regular file in its place: 'tune --write /dev/null' as root replaced the device
        raise FileExistsError(errno.EEXIST, "a device or other special file is in the way of the file", str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}")
    os.close(fd)
    try:
        write(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def _special(path):
    """Whether ``path`` names an existing device, FIFO or socket (or a link to one): no file to replace."""
    return path.exists() and not path.is_file() and not path.is_dir()


def write_text(path, text):
    """Write ``text`` to ``path`` atomically (UTF-8)."""
    def write(tmp):
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
    return write_atomic(path, write)


def write_json(path, obj, indent=None):
    """Write ``to_jsonable(obj)`` as JSON to ``path`` atomically."""
    return write_text(path, json.dumps(to_jsonable(obj), indent=indent) + ("\n" if indent else ""))


# --------------------------------------------------------------------------- inputs

def check_path_argument(path, field="path"):
    """Refuse what is no file path (None, a number, a mapping, an empty or blank string) by ``field``, before
    :class:`~pathlib.Path` says ``TypeError`` or the empty path is read as the current folder.

    Raises
    ------
    InputError
        Naming ``field``.
    """
    if isinstance(path, (str, bytes, os.PathLike)):
        name = os.fspath(path)
        if (name.strip() if isinstance(name, str) else name.strip(b" \t\n")) and "\0" not in str(name):
            return
    raise InputError(field, path, "a file path (a non-empty str or path-like naming a file)")


def check_input_file(path, field, max_bytes=MAX_INPUT_BYTES):
    """``path`` as a :class:`~pathlib.Path` if it is a regular file of at most ``max_bytes``.

    Raises
    ------
    FileNotFoundError
        If it does not exist (the CLI prints it in one line).
    InputError
        Naming ``field`` if it is not a regular file (a directory, ``/dev/zero``, a FIFO) or too large.
    """
    check_path_argument(path, field or "path")
    path = Path(path)
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise FileNotFoundError(errno.ENOENT, "No such file or directory", str(path)) from None
    except OSError as err:
        raise InputError(field, str(path), f"a readable file ({err.strerror})") from None
    if not stat.S_ISREG(info.st_mode):
        kind = "a directory" if stat.S_ISDIR(info.st_mode) else "not a regular file"
        raise InputError(field, f"{path} ({kind})", "a regular file")
    if info.st_size > max_bytes:
        raise InputError(field, f"{path} ({info.st_size} bytes)", f"a file of at most {max_bytes} bytes")
    return path


def csv_dialect(lines, separator=None, decimal=None):
    """``(separator, decimal)`` of a CSV from its first lines (``#`` comments and blank lines are skipped).

    Spreadsheet, scope and hammer-test exports in many locales separate fields by ``;`` or a tab and write a
    decimal comma. Without ``separator``: the one of ``,``, ``;`` and tab the header line (the first line
    read) uses most (``,`` when it has none). Without ``decimal``: ``,`` when the separator is not a comma and
    the first data row has a digit, a comma and a digit, else ``.``.

    Parameters
    ----------
    lines : iterable of str
        The file's lines from its start (only the first two that are not comments or blank are read).
    separator, decimal : str, optional
        Given values are kept.

    Returns
    -------
    tuple of str
    """
    import re

    found = []
    for line in lines:
        if line.strip() and not line.lstrip().startswith("#"):
            found.append(line)
            if len(found) == 2:
                break
    if separator is None:
        header = found[0] if found else ""
        counts = {sep: header.count(sep) for sep in (",", ";", "\t")}
        separator = max(counts, key=counts.get) if max(counts.values()) > 0 else ","
    if decimal is None:
        decimal = "," if separator != "," and len(found) > 1 and re.search(r"\d,\d", found[1]) else "."
    return separator, decimal


def read_csv_frame(source, field, allowed, separator=None, decimal=None, text_columns=()):
    """A CSV as a pandas DataFrame, the one CSV reader of measured runs and hammer tests.

    ``#`` lines are comments. The separator and the decimal mark come from :func:`csv_dialect` unless given.
    ``index_col=False``: a trailing comma on every line is an empty field, not a shift of every column under the
    header (pandas would take the first column as the index); an unnamed column left with no values (a trailing
    comma on the header line too) is dropped. Rows with more values than the header has names would lose data,
    so pandas' warning of that is an error here.

    Parameters
    ----------
    source : path-like or io.StringIO
    field : str
        What the file is, for messages.
    allowed : str
        What a readable file is, for the message of an unreadable one.
    separator, decimal : str, optional
    text_columns : sequence of str
        Columns read as text, as written (labels: read as numbers, ``1`` and ``1.0`` were one label, ``007`` was
        ``7.0``).

    Raises
    ------
    InputError
        Not UTF-8, rows longer than the header, or a file pandas cannot parse.
    """
    import io
    import re
    import warnings

    import pandas as pd

    if separator is None or decimal is None:
        if isinstance(source, io.StringIO):
            separator, decimal = csv_dialect(source.getvalue().splitlines(), separator, decimal)
        else:
            try:
                with open(source, encoding="utf-8", errors="strict") as fh:
                    separator, decimal = csv_dialect(fh, separator, decimal)
            except (UnicodeDecodeError, OSError):
                separator, decimal = separator or ",", decimal or "."  # pandas names the problem
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", pd.errors.ParserWarning)
            frame = pd.read_csv(source, comment="#", skipinitialspace=True, skip_blank_lines=True, index_col=False,
                                sep=separator, decimal=decimal, dtype={c: str for c in text_columns} or None)
    except pd.errors.ParserWarning:
        raise InputError(field, "data rows with more values than the header has column names",
                         "one value per header column (a trailing comma on every line is allowed)") from None
    except UnicodeDecodeError as err:
        raise InputError(field, f"byte 0x{err.object[err.start]:02x} at offset {err.start} is not UTF-8",
                         "a UTF-8 text CSV (not binary, not UTF-16)") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as err:
        raise InputError(field, f"unreadable CSV ({str(err).splitlines()[0][:80]})", allowed) from None
    empty = [c for c in frame.columns if re.fullmatch(r"Unnamed: \d+", str(c)) and frame[c].isna().all()]
    return frame.drop(columns=empty)


def first_non_number(values):
    """The first of ``values`` (cells of a table read as text) that ``float`` cannot read, for a message naming
    it; None when all can. A text with an underscore is not a number here, though ``float`` reads Python's digit
    grouping (``'1_000'`` as 1000): no table writes it, and ``'1_5'`` is likelier a typo than 15."""
    for value in values:
        if isinstance(value, str) and "_" in value:
            return value
        try:
            float(value)
        except (TypeError, ValueError):
            return value
    return None


def read_input_text(path, field=None, max_bytes=MAX_INPUT_BYTES):
    """The text of a user's input file: a regular file of at most ``max_bytes``, UTF-8 (a BOM is skipped).

    Parameters
    ----------
    path : path-like
    field : str, optional
        What the file is, for messages (default: the path).
    max_bytes : int

    Raises
    ------
    InputError
        Not a regular file, too large, not UTF-8 text (binary, UTF-16) or unreadable; the content is never
        quoted.
    FileNotFoundError
        If it does not exist.
    """
    field = field or str(path)
    where = "" if field == str(path) else f"{path}: "  # the message names the file once
    path = check_input_file(path, field, max_bytes)
    try:
        with open(path, "rb") as fh:
            raw = fh.read(max_bytes + 1)
    except IsADirectoryError:  # pragma: no cover - caught by check_input_file
        raise InputError(field, str(path), "a regular file") from None
    except PermissionError:
        raise
    except OSError as err:
        raise InputError(field, str(path), f"a readable file ({err.strerror})") from None
    if len(raw) > max_bytes:  # grew while we read it
        raise InputError(field, f"{path} (more than {max_bytes} bytes)", f"a file of at most {max_bytes} bytes")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise InputError(field, f"{where}byte 0x{raw[err.start]:02x} at offset {err.start} is not UTF-8",
                         "a UTF-8 text file (not binary, not UTF-16)") from None
    if "\x00" in text:
        raise InputError(field, f"{where}NUL byte at offset {text.index(chr(0))}", "a UTF-8 text file (not binary)")
    return text


def resolve_reference(value, referring_file, field, max_bytes=MAX_INPUT_BYTES):
    """The path of a file named inside ``referring_file`` (relative paths are relative to that file's folder).

    The file must be a regular file; its content is never echoed in a message.

    Raises
    ------
    InputError
        ``value`` not a non-empty string, the file missing, not a regular file or too large.
    """
    if not isinstance(value, (str, os.PathLike)) or not str(value).strip():
        raise InputError(field, value, "a file path (relative to the file that names it)")
    ref = Path(value)
    if not ref.is_absolute():
        ref = Path(referring_file).parent / ref
    try:
        return check_input_file(ref, field, max_bytes)
    except FileNotFoundError:
        raise InputError(field, str(value), f"an existing file (looked for {ref})") from None


# --------------------------------------------------------------------------- output sets

def check_output_dir(path, field="--out"):
    """Create the output folder ``path`` if needed and check it is a writable folder, before any work.

    Raises
    ------
    InputError
        Naming ``field`` if ``path`` (or one of its parents) is a file, or the folder cannot be created or
        written.
    """
    path = Path(path)
    problem = _folder_problem(path)
    if problem is not None:
        allowed, why = problem
        raise InputError(field, str(path), f"{allowed} ({why})" if why else allowed)
    return path


#: What an output folder that could not be created must be (:func:`_folder_problem`).
_CREATABLE = "a folder that can be created"


def _folder_problem(path):
    """None once ``path`` is a folder (created if needed) a file can be written in; else ``(allowed, why)``: what
    a folder must be, and why this one is not (None where ``allowed`` says it all). ``allowed`` is
    :data:`_CREATABLE` exactly when the folder could not be created."""
    try:  # a name longer than the system allows raises here (ENAMETOOLONG: 'File name too long: ...', no option)
        if path.exists() and not path.is_dir():
            return "a folder", "this is an existing file"
    except OSError as err:
        return _CREATABLE, err.strerror
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        return "a folder", "a parent is an existing file"
    except OSError as err:
        return _CREATABLE, err.strerror
    if not os.access(path, os.W_OK | os.X_OK):
        return "a writable folder", None
    try:  # what write_atomic will do (os.access says yes to root where a file system refuses, e.g. /sys)
        fd, tmp = tempfile.mkstemp(dir=path, prefix=".drakecreep.", suffix=".check")
    except OSError as err:  # (/proc answers ENOENT: 'No such file or directory' named a folder that exists)
        return "a writable folder", f"creating a file in it failed: {err.strerror}"
    os.close(fd)
    os.unlink(tmp)
    return None


def check_output_file(path, field="--out"):
    """Check, before any work, that a file can be written (atomically) at ``path``; its folder is created if needed.

    Raises
    ------
    InputError
        Naming ``field`` if ``path`` is an existing folder, or a file cannot be created in its folder.
    """
    path = Path(path)
    try:
        if path.is_dir():
            raise InputError(field, str(path), "a file name (this is an existing folder)")
        if _special(path):
            raise InputError(field, str(path), "a file name (this is a device or other special file, which writing "
                             "the file would replace)")
    except OSError as err:  # ENAMETOOLONG
        raise InputError(field, str(path), f"a file that can be written ({err.strerror})") from None
    # the file the user named, and what is wrong with its folder ('--write: got '/proc'; ... No such file or
    # directory' named the folder of /proc/version, which exists)
    problem = _folder_problem(path.parent)
    if problem is not None:
        allowed, why = problem
        why = "not writable" if why is None else f"cannot be created: {why}" if allowed == _CREATABLE else why
        raise InputError(field, str(path), f"a file in a writable folder ({path.parent}: {why})")
    try:  # what write_atomic will do: a temporary file beside the target
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".check")
    except OSError as err:
        raise InputError(field, str(path), f"a file in a writable folder (creating a file in {path.parent} failed: "
                         f"{err.strerror})") from None
    os.close(fd)
    os.unlink(tmp)
    return path


def _sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


class OutputSet:
    """Files of one run written to a folder so that a reader never mixes two runs.

    The protocol: (1) the previous manifest is removed first, so from then on the folder claims no complete
    run; (2) every file is written atomically (:func:`write_atomic`); (3) the manifest is written last,
    atomically, naming each file of this run with its size and SHA-256 and a fresh ``run_id``. A folder with
    a manifest holds a complete run; files the manifest does not name (left from an earlier run) are not part
    of it. A kill at any moment leaves either the new manifest with all its files, or no manifest.

    Parameters
    ----------
    out_dir : path-like
        The folder (created if needed; see :func:`check_output_dir`).
    manifest : str
        File name of the manifest (JSON), e.g. ``"metrics.json"`` or ``"manifest.json"``.
    field : str
        Option name for messages.

    Examples
    --------
    >>> with OutputSet(tmp, "manifest.json") as out:           # doctest: +SKIP
    ...     out.write_text("a.txt", "hello")
    ...     out.commit({"status": "ok"})
    """

    def __init__(self, out_dir, manifest="manifest.json", field="--out"):
        self.dir = check_output_dir(out_dir, field)
        self.manifest = self.dir / manifest
        self.run_id = uuid.uuid4().hex
        self.files = {}
        self.committed = False

    def start(self):
        """Remove the previous manifest (step 1); ``with OutputSet(...)`` does it on entry. Returns ``self``."""
        try:
            self.manifest.unlink()
        except FileNotFoundError:
            pass
        return self

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        return False

    def path(self, name):
        """Final path of file ``name`` in the set."""
        return self.dir / name

    def write(self, name, write):
        """Write file ``name`` atomically with ``write(tmp_path)`` and record it; returns its path."""
        path = write_atomic(self.dir / name, write)
        self.files[name] = dict(bytes=path.stat().st_size, sha256=_sha256(path))
        return path

    def write_text(self, name, text):
        """Write text file ``name`` (UTF-8) in the set."""
        def write(tmp):
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(text)
        return self.write(name, write)

    def commit(self, payload=None):
        """Write the manifest: ``payload`` plus ``run_id``, ``written`` (UTC) and ``files``; returns its path."""
        body = dict(to_jsonable(payload or {}))
        body["run_id"] = self.run_id
        body["written"] = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
        body["files"] = self.files
        write_text(self.manifest, json.dumps(to_jsonable(body), indent=2) + "\n")
        self.committed = True
        return self.manifest


def read_manifest(path, verify=True):
    """The manifest of an :class:`OutputSet`, or None when the set is incomplete.

    With ``verify``, every file it names must exist with the recorded size and SHA-256 (else None).
    """
    try:
        body = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(body, dict) or not isinstance(body.get("files"), dict):
        return None
    if verify:
        folder = Path(path).parent
        for name, info in body["files"].items():
            f = folder / name
            try:
                if f.stat().st_size != info["bytes"] or _sha256(f) != info["sha256"]:
                    return None
            except (OSError, KeyError, TypeError):
                return None
    return body
