"""The shared HTML helper: escaping, no empty tables, embedded figures."""

from drakecreep.report.html import figure, page, table


def test_table_escapes_cells_unless_raw():
    t = table(["a<b", "c"], [("<script>", 1.5)])
    assert "&lt;script&gt;" in t and "a&lt;b" in t and "<td>1.5</td>" in t
    assert "<b>x</b>" in table(["h"], [("<b>x</b>",)], raw=True)


def test_no_rows_no_table():
    assert table(["a"], []) == ""


def test_figure_embeds_the_png_and_page_has_one_style(tmp_path):
    png = b"\x89PNG\r\n\x1a\n" + b"0" * 20
    html = page("t & t", [figure(png, caption="a < b")])
    assert html.count("<style>") == 1 and "data:image/png;base64," in html
    assert "<title>t &amp; t</title>" in html and "<figcaption>a &lt; b</figcaption>" in html
