"""Tables (formatting, identical interpolants) and the document (Markdown, self-contained HTML)."""
import base64
import os
import re

import pytest

from sdf_report import tables
from sdf_report.document import Document
from sdf_report.tables import Table


def test_number_formatting():
    assert tables.number(0) == "0"
    assert tables.number(0.0123456) == "0.01235"
    assert tables.number(123456.0) == "1.235e+05"
    assert tables.number(1.5e-5) == "1.500e-05"
    assert tables.number(None) == "n/a"
    assert tables.count(2097152) == "2,097,152"
    assert tables.rate(6.6e11) == "6.6e+11"
    assert tables.percent(0.0063) == "0.63%"


def test_identical_interpolants_are_labelled():
    assert tables.reconstruction_label("tricubic_lm", "fd", "cc-80x80x80/") == \
        "cc-80x80x80/tricubic_lm/fd (= catmull_rom: same function)"
    assert tables.reconstruction_label("tricubic_lm", "true") == "tricubic_lm/true"
    assert tables.reconstruction_label("catmull_rom", "fd") == "catmull_rom/fd"
    assert tables.split_curve_id("bcc_cubic/fd_weighted") == ("bcc_cubic", "fd_weighted")


def test_identical_interpolants_are_one_curve_in_plots():
    keys = [("catmull_rom", "fd"), ("tricubic_lm", "true"), ("tricubic_lm", "fd"), ("bcc_cubic", "fd")]
    assert tables.distinct_functions(keys) == [
        (("catmull_rom", "fd"), "catmull_rom/fd = tricubic_lm/fd (same function)"),
        (("tricubic_lm", "true"), "tricubic_lm/true"), (("bcc_cubic", "fd"), "bcc_cubic/fd")]
    # Alone, tricubic_lm/fd is plotted under its own name.
    assert tables.distinct_functions([("tricubic_lm", "fd")]) == [(("tricubic_lm", "fd"), "tricubic_lm/fd")]


def test_table_rows_must_match_the_header():
    t = Table(["a", "b"])
    with pytest.raises(ValueError):
        t.add([1])
    assert not t
    t.add(["x", "1,024"])
    t.add(["y", "2.5e-03"])
    assert t and t.text_columns() == {0}


def write_png(path):
    import matplotlib.image as mpimg
    import numpy as np
    mpimg.imsave(path, np.zeros((4, 4, 3)))


def test_markdown_and_self_contained_html(tmp_path):
    doc = Document(str(tmp_path))
    doc.heading(2, "Section <1>")
    doc.paragraph("Text with | a pipe & an ampersand.")
    doc.note("A note.")
    doc.table(Table(["name", "value"], [["a|b", "1.5"]]))
    write_png(str(tmp_path / "plot.png"))
    doc.image("plot.png", "A plot")
    md = doc.markdown()
    assert "## Section <1>" in md
    assert "> A note." in md
    assert "| a\\|b | 1.5 |" in md
    assert "![A plot](plot.png)" in md
    page = doc.html("title")
    assert "<h2>Section &lt;1&gt;</h2>" in page
    assert "<div class=\"table\"><table>" in page  # wide tables scroll, cells do not wrap
    assert "Text with | a pipe &amp; an ampersand." in page
    # Self-contained: every image is a data URI of the PNG's bytes, nothing is fetched.
    sources = re.findall(r"src=\"([^\"]*)\"", page)
    assert len(sources) == 1 and sources[0].startswith("data:image/png;base64,")
    assert base64.b64decode(sources[0].split(",", 1)[1]) == (tmp_path / "plot.png").read_bytes()
    assert not re.search(r"<link|<script|@import|url\(", page)
    doc.write("title")
    assert sorted(os.listdir(tmp_path)) == ["index.html", "plot.png", "report.md"]
