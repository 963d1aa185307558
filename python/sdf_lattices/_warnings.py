"""The warnings of sdf_lattices, raised through Python's `warnings` (filterable, shown in
Jupyter) instead of written on C stderr:

    import warnings, sdf_lattices as sl
    warnings.simplefilter("ignore", sl.MeshWarning)     # e.g. for open meshes you know about
"""


class SdfWarning(UserWarning):
    """A warning of a computation (e.g. sign="auto" chose the winding number for a mesh)."""


class MeshWarning(SdfWarning):
    """A warning of mesh preparation: open, non-manifold, inconsistently oriented, flipped or
    self-intersecting (the mesh's `warnings`)."""


def warn_at_caller(message, category=SdfWarning):
    """warnings.warn(message, category) attributed to the first frame outside this package:
    the caller's line (a fixed stacklevel pointed at "sys:1" from a top-level call, or into
    the package when the call came through its Python parts, e.g. SDF(path) loading the mesh)."""
    import os
    import sys
    import warnings

    package = os.path.dirname(os.path.abspath(__file__)) + os.sep
    level, frame = 1, sys._getframe(1)
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(package):
        level, frame = level + 1, frame.f_back
    warnings.warn(message, category, stacklevel=level + 1)
