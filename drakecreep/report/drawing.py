"""Draw a Drake diagram with Graphviz: ``.dot`` always, SVG/PNG when Graphviz's ``dot`` is installed."""

import shutil
import subprocess
from pathlib import Path

from drakecreep.errors import DrakecreepError, InputError
from drakecreep.files import write_atomic, write_text

__all__ = ["draw_diagram", "FORMATS"]

FORMATS = (".svg", ".png", ".dot", ".pdf")


def draw_diagram(diagram, path, max_depth=1, title=None):
    """Write ``diagram``'s Graphviz drawing to ``path`` (format from the suffix), atomically.

    Parameters
    ----------
    diagram : pydrake.systems.framework.Diagram
    path : str or Path
        ``.svg``, ``.png``, ``.pdf`` or ``.dot``.
    max_depth : int
        Levels of nested diagrams to expand.
    title : str, optional
        A caption drawn above the diagram: what the blocks alone do not show (a leaf system's settings, such
        as the controller's variant and sample times).

    Returns
    -------
    Path
        The file written. The Graphviz source is also written beside it as ``.dot``.

    Raises
    ------
    InputError
        Unknown suffix.
    DrakecreepError
        Graphviz's ``dot`` is not installed (the ``.dot`` source is still written).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise InputError("--out", str(path), "a file ending in " + ", ".join(FORMATS))
    source = diagram.GetGraphvizString(max_depth=max_depth)
    if title:
        head, _, rest = source.partition("\n")
        source = f"{head}\nlabel={_quoted(title)}\nlabelloc=t\nfontsize=16\n{rest}"
    dot_path = write_text(path.with_suffix(".dot"), source)
    if suffix == ".dot":
        return dot_path
    exe = shutil.which("dot")
    if exe is None:
        raise DrakecreepError(
            f"Graphviz 'dot' is not installed, so {path.name} was not drawn; the source is in {dot_path} "
            "(install Graphviz, e.g. 'apt-get install graphviz', or ask for a .dot file)"
        )
    return write_atomic(path, lambda tmp: subprocess.run([exe, f"-T{suffix[1:]}", str(dot_path), "-o", str(tmp)],
                                                         check=True, capture_output=True))


def _quoted(text):
    """``text`` as a Graphviz double-quoted string."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
