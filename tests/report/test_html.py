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


def test_columns_of_words_are_left_aligned_and_figures_right_aligned():
    t = table(["label", "value", "gain", "why", "empty", "minus"],
              [("first", "3.36 N", "-0.003 (bar 0.031)", "passes on the scale", "", "\u22120.5"),
               ("second", "-", "n/a", "no gain", "", "NaN"),
               ("third", "inf N", "+1", "-", "", "-2 runs, no gain")])
    assert "<td>3.36 N</td>" in t and "<td>-0.003 (bar 0.031)</td>" in t and "<td></td>" in t
    assert "<td>-</td>" in t and "<td>n/a</td>" in t and "<td>NaN</td>" in t and "<td>\u22120.5</td>" in t
    assert '<th class="text">why</th>' in t and '<td class="text">passes on the scale</td>' in t
    assert '<td class="text">-</td>' in t  # a placeholder in a column of words goes with its column
    assert "<td>first</td>" in t and "<th>label</th>" in t  # a row's label: left-aligned by the style
    assert t.count('class="text"') == 4
    assert '<td class="text"><b>yes</b></td>' in table(["h", "i"], [("a", "<b>yes</b>")], raw=True)
    assert "<td><b>+1.5</b></td>" in table(["h", "i"], [("a", "<b>+1.5</b>")], raw=True)
    assert table(["h", "i"], [("a", "nanometres")]).count('class="text"') == 2
    assert table(["h", "i"], [("a", "x0.942 (+0.059 vs 0.381)"), ("b", "\u00d71.5")]).count('class="text"') == 0
    assert table(["h", "i"], [("a", "xenon")]).count('class="text"') == 2
