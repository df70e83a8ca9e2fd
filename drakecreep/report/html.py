"""One look for every HTML report: the page skeleton, the style, tables and embedded figures.

Reports are self-contained files (figures embedded as base64 PNG), so they can be mailed or archived alone.
"""

from __future__ import annotations

import base64
import html
import re
from pathlib import Path

__all__ = ["CSS", "page", "table", "figure", "png_data", "escape"]

CSS = """
body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.8em}
table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #ccc;padding:.25em .6em;text-align:right}
th{background:#f3f3f3}td:first-child,th:first-child,.text{text-align:left}img{max-width:100%;border:1px solid #eee}
figure{margin:1em 0}figcaption{font-size:.9em;color:#555}
.note{background:#f7f7ee;border-left:4px solid #cc9;padding:.5em 1em}pre{background:#f6f6f6;padding:.6em;overflow:auto;font-size:.85em}
.bad{color:#b00;font-weight:bold}.good{color:#070}.answer{font-size:1.1em}
"""

escape = html.escape


def page(title, body):
    """A complete HTML document: ``title`` (plain text) and ``body`` (HTML parts, a string or a list)."""
    if not isinstance(body, str):
        body = "\n".join(body)
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{escape(title)}</title>"
            f"<style>{CSS}</style></head><body>\n{body}\n</body></html>\n")


def table(header, rows, *, raw=False):
    """An HTML table; cells are escaped unless ``raw`` (cells already HTML). ``""`` when there are no rows,
    so a report never shows an empty table. A column of words (most of its filled cells not figures, see
    :data:`_FIGURE`) is left-aligned with its header; figures stay right-aligned, so digits line up."""
    rows = list(rows)
    if not rows:
        return ""
    cell = (lambda c: str(c)) if raw else (lambda c: escape(str(c)))
    cells = [[cell(c) for c in row] for row in rows]
    words = [j > 0 and _words(col, raw) for j, col in enumerate(_columns(cells, len(header)))]

    def td(j, tag, text):
        return f'<{tag} class="text">{text}</{tag}>' if j < len(words) and words[j] else f"<{tag}>{text}</{tag}>"

    out = ["<table><tr>" + "".join(td(j, "th", escape(str(h))) for j, h in enumerate(header)) + "</tr>"]
    for row in cells:
        out.append("<tr>" + "".join(td(j, "td", c) for j, c in enumerate(row)) + "</tr>")
    return "\n".join(out) + "</table>"


#: A cell read as a figure: it starts with a digit, a sign, a decimal point or a factor's "x" before a digit, or
#: it is a figure's placeholder (a dash, n/a, nan, inf).
_FIGURE = re.compile(r"\s*([-+\u2212\u00b1.x\u00d7]?\s*[0-9.]|[-\u2013\u2014]\s*$|n/a\s*$|[-+]?(nan|inf)\b)",
                     re.IGNORECASE)


def _columns(cells, n):
    """The table's columns (rows shorter than the header leave theirs out)."""
    width = max([n] + [len(r) for r in cells])
    return [[r[j] for r in cells if j < len(r)] for j in range(width)]


def _words(column, raw):
    """Whether most of a column's filled cells are words, not figures (the first column, a row's label, is
    left-aligned by the style whatever it holds)."""
    shown = [(re.sub(r"<[^>]*>", "", c) if raw else html.unescape(c)).strip() for c in column]
    filled = [c for c in shown if c]
    return bool(filled) and sum(not _FIGURE.match(c) for c in filled) > len(filled) / 2


def png_data(source):
    """Base64 text of a PNG: ``source`` is a path or the PNG's bytes."""
    data = source if isinstance(source, (bytes, bytearray)) else Path(source).read_bytes()
    return base64.b64encode(bytes(data)).decode("ascii")


def figure(source, caption="", alt=None):
    """An embedded PNG (path or bytes) with an optional caption."""
    alt = alt if alt is not None else (Path(source).stem if not isinstance(source, (bytes, bytearray)) else caption)
    img = f'<img alt="{escape(str(alt))}" src="data:image/png;base64,{png_data(source)}">'
    if not caption:
        return img
    return f"<figure>{img}<figcaption>{escape(caption)}</figcaption></figure>"
