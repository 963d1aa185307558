"""Tables and the formatting of their cells: numbers, counts, times and rates, and the labels
of reconstructions (with interpolants that are the same function marked as such)."""

import re


class Table:
    def __init__(self, header, rows=None):
        self.header = list(header)
        self.rows = []
        for row in rows or []:
            self.add(row)

    def add(self, row):
        row = list(row)
        if len(row) != len(self.header):
            raise ValueError("table row has %d cells, the header %d: %r" % (len(row), len(self.header), row))
        self.rows.append(row)

    def __bool__(self):
        return bool(self.rows)

    def text_columns(self):
        """Indices of the columns holding words rather than figures (left-aligned in HTML)."""
        out = set()
        for i in range(len(self.header)):
            cells = [str(r[i]) for r in self.rows if str(r[i]) not in ("", "-", "n/a")]
            if cells and not all(_NUMERIC.match(c) for c in cells):
                out.add(i)
        return out


_NUMERIC = re.compile(r"^[-+]?[\d,.]+(e[-+]?\d+)?[*%x]?( ?[a-z]{0,2})?$")


def number(value, digits=4):
    """Four significant digits; scientific notation outside [1e-3, 1e5)."""
    if value is None:
        return "n/a"
    if value == 0:
        return "0"
    if abs(value) >= 1e5 or abs(value) < 1e-3:
        return "%.*e" % (digits - 1, value)
    return "%.*g" % (digits, value)


def count(value):
    """An integer with thousands separators: 2,097,152."""
    return "{:,}".format(int(value))


def rate(value):
    """A throughput (pairs or points per second): 3 significant digits, scientific."""
    return "%.3g" % value if value else "0"


def percent(fraction, digits=2):
    return "%.*f%%" % (digits, 100.0 * fraction)


# ---- reconstructions ---------------------------------------------------------------------------

# Interpolants that are the same function as another on the same lattice (docs/reconstruction.md,
# "Derivative sources"): tricubic_lm with central-difference derivatives is exactly Catmull-Rom
# (cubic Hermite interpolation with central differences; the tests check equality to 1e-12).
# bcc_box_linear, the four-direction box spline, is linear on every Delaunay tetrahedron and
# interpolates: the same function as bcc_linear (equal to 1e-14 in box_spline_filters_test).
SAME_FUNCTION = {("tricubic_lm", "fd"): ("catmull_rom", "fd"), ("bcc_box_linear", "fd"): ("bcc_linear", "fd")}


def same_function_as(interpolator, derivatives):
    """The (interpolator, derivatives) this one is identical to, or None."""
    return SAME_FUNCTION.get((interpolator, derivatives))


def reconstruction_label(interpolator, derivatives, prefix=""):
    """'cc-80x80x80/tricubic_lm/fd (= catmull_rom: same function)' for identical interpolants."""
    label = "%s%s/%s" % (prefix, interpolator, derivatives)
    twin = same_function_as(interpolator, derivatives)
    if twin:
        label += " (= %s: same function)" % twin[0]
    return label


def distinct_functions(keys):
    """[(key, label)] for the (interpolator, derivatives) keys to plot: a key identical to
    another present key is left out and that one labelled with both names (one line, not
    two lines drawn on top of each other)."""
    keys = list(keys)
    twins = {same_function_as(*k): k for k in keys if same_function_as(*k) in keys}
    out = []
    for key in keys:
        if key in twins.values():
            continue
        label = "%s/%s" % key
        if key in twins:
            label += " = %s/%s (same function)" % twins[key]
        out.append((key, label))
    return out


def split_curve_id(curve_id):
    """'tricubic_lm/fd' -> ('tricubic_lm', 'fd')."""
    interpolator, _, derivatives = curve_id.partition("/")
    return interpolator, derivatives
