"""A small document model that the sections fill, rendered as Markdown (report.md) and as
one self-contained HTML page (index.html: images embedded as data URIs, no external
stylesheet, script or font)."""

import base64
import html
import os


class Document:
    def __init__(self, out_dir):
        self.out_dir = out_dir
        self.blocks = []

    def heading(self, level, text):
        self.blocks.append(("heading", level, text))

    def paragraph(self, text):
        self.blocks.append(("paragraph", text))

    def note(self, text):
        self.blocks.append(("note", text))

    def table(self, table):
        """`table`: a tables.Table (header, rows)."""
        self.blocks.append(("table", table))

    def image(self, filename, caption):
        """`filename`: a PNG already written into out_dir."""
        self.blocks.append(("image", filename, caption))

    # ---- Markdown ---------------------------------------------------------------------------
    def markdown(self):
        out = []
        for block in self.blocks:
            kind = block[0]
            if kind == "heading":
                out.append("#" * block[1] + " " + block[2])
            elif kind == "paragraph":
                out.append(block[1])
            elif kind == "note":
                out.append("> " + block[1])
            elif kind == "table":
                out.extend(_markdown_table(block[1]))
            elif kind == "image":
                out.append("![%s](%s)" % (block[2], block[1]))
            out.append("")
        return "\n".join(out)

    # ---- HTML -------------------------------------------------------------------------------
    def html(self, title):
        parts = ["<!DOCTYPE html>",
                 "<html lang=\"en\"><head><meta charset=\"utf-8\"><title>%s</title>" % html.escape(title),
                 "<style>%s</style></head><body>" % _STYLE]
        for block in self.blocks:
            kind = block[0]
            if kind == "heading":
                parts.append("<h%d>%s</h%d>" % (block[1], html.escape(block[2]), block[1]))
            elif kind == "paragraph":
                parts.append("<p>%s</p>" % html.escape(block[1]))
            elif kind == "note":
                parts.append("<blockquote>%s</blockquote>" % html.escape(block[1]))
            elif kind == "table":
                parts.append(_html_table(block[1]))
            elif kind == "image":
                parts.append(self._html_image(block[1], block[2]))
        parts.append("</body></html>")
        return "\n".join(parts) + "\n"

    def _html_image(self, filename, caption):
        with open(os.path.join(self.out_dir, filename), "rb") as f:
            data = base64.b64encode(f.read()).decode("ascii")
        return ("<figure><img src=\"data:image/png;base64,%s\" alt=\"%s\"><figcaption>%s</figcaption></figure>"
                % (data, html.escape(caption), html.escape(caption)))

    def write(self, title):
        """Writes report.md and index.html into out_dir, each atomically."""
        for name, text in (("report.md", self.markdown()), ("index.html", self.html(title))):
            write_text_atomically(os.path.join(self.out_dir, name), text)


def write_text_atomically(path, text):
    tmp = os.path.join(os.path.dirname(path), "." + os.path.basename(path) + ".tmp")
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


_STYLE = ("body{font-family:sans-serif;max-width:80em;margin:2em auto;padding:0 1em;color:#222;line-height:1.4}"
          "table{border-collapse:collapse;margin:1em 0;font-size:85%}"
          "div.table{overflow-x:auto}"
          "td,th{border:1px solid #bbb;padding:.2em .5em;text-align:right;vertical-align:top}td{white-space:nowrap}"
          "th{background:#eee}td.text,th.text{text-align:left}"
          # Text cells wrap (numbers do not), so wide tables such as the runs' fit the page and
          # their last column (the check) is seen without scrolling.
          "td.text{white-space:normal;min-width:4em}"
          "tr:nth-child(even) td{background:#f7f7f7}"
          "blockquote{color:#555;border-left:3px solid #ccc;margin:1em 0;padding-left:1em}"
          "figure{margin:1em 0}figcaption{color:#555;font-size:90%}img{max-width:100%}")


def _markdown_cell(value):
    return str(value).replace("|", "\\|").replace("\n", " ")


def _markdown_table(table):
    lines = ["| " + " | ".join(_markdown_cell(h) for h in table.header) + " |",
             "|" + "|".join("---" for _ in table.header) + "|"]
    for row in table.rows:
        lines.append("| " + " | ".join(_markdown_cell(c) for c in row) + " |")
    return lines


def _html_table(table):
    text_columns = table.text_columns()
    def cell(tag, i, value):
        cls = " class=\"text\"" if i in text_columns else ""
        return "<%s%s>%s</%s>" % (tag, cls, html.escape(str(value)), tag)
    parts = ["<div class=\"table\"><table><thead><tr>" + "".join(cell("th", i, h) for i, h in enumerate(table.header)) +
             "</tr></thead><tbody>"]
    for row in table.rows:
        parts.append("<tr>" + "".join(cell("td", i, c) for i, c in enumerate(row)) + "</tr>")
    parts.append("</tbody></table></div>")
    return "\n".join(parts)
