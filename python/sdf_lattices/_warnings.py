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
