"""read_field: every format Field.write writes, read back as a Field where the file holds
the lattice, and a ValueError that says why (and what to do) where it does not."""
import errno
import os
import zipfile

import numpy as np

_FORMATS = ".json (field file), .npz, .vti, .npy, .vdb"


def _missing(path):
    return FileNotFoundError(errno.ENOENT, "no such field file", path)


def _named(path, read):
    """read(), with any error of a bad file (not a zip, a missing or misshapen entry, a
    lattice the Field refuses) raised as a ValueError that names the file."""
    try:
        return read()
    except (ValueError, TypeError, KeyError, IndexError, EOFError, OSError, zipfile.BadZipFile) as e:
        if isinstance(e, FileNotFoundError) or str(e).startswith(path):
            raise
        raise ValueError(f"{path}: {str(e).strip(chr(39)) or type(e).__name__}") from e


def _read_npz(path):
    from . import _core

    if os.path.getsize(path) == 0 or not zipfile.is_zipfile(path):
        raise ValueError(f"{path}: not a .npz file (no zip archive; truncated or not written by Field.write?)")
    with np.load(path, allow_pickle=False) as z:
        lattice = str(z["lattice"]) if "lattice" in z else None
        if lattice == "cc":
            gradient = z["gradient"] if "gradient" in z else None
            return _core.Field(z["distance"], tuple(z["origin"]), float(z["spacing"]), "cc", gradient)
        if lattice == "bcc":
            values = (z["distance_primary"], z["distance_secondary"])
            gradient = (z["gradient_primary"], z["gradient_secondary"]) if "gradient_primary" in z else None
            return _core.Field(values, tuple(z["origin_primary"]), float(z["spacing"]), "bcc", gradient)
    raise ValueError(f"{path}: not an sdf_lattices .npz field (its 'lattice' entry is missing or neither 'cc' nor 'bcc')")


def _read_vti_grid(path):
    """(distance [nz, ny, nx], gradient [nz, ny, nx, 3] or None, origin, spacing) of one .vti."""
    try:
        import vtk
        from vtk.util.numpy_support import vtk_to_numpy
    except ImportError:
        raise ValueError(f"{path}: reading .vti needs VTK's Python module (Debian python3-vtk9), which is not "
                         "installed; the field file (.json) or .npz hold the same field") from None
    reader = vtk.vtkXMLImageDataReader()
    errors = []
    reader.AddObserver("ErrorEvent", lambda obj, event: errors.append(event))
    reader.SetFileName(path)
    reader.Update()
    if errors or reader.GetErrorCode() != 0:
        raise ValueError(f"{path}: not a readable VTK ImageData XML file (truncated or corrupt?); VTK: "
                         f"{reader.GetErrorCode() and vtk.vtkErrorCode.GetStringFromErrorCode(reader.GetErrorCode()) or 'parse error'}")
    image = reader.GetOutput()
    data = image.GetPointData()
    if image.GetNumberOfPoints() == 0 or data.GetArray("distance") is None:
        raise ValueError(f"{path}: no 'distance' point data (not a VTK ImageData file written by Field.write)")
    nx, ny, nz = image.GetDimensions()
    spacing = image.GetSpacing()
    if not (spacing[0] == spacing[1] == spacing[2]):
        raise ValueError(f"{path}: spacing {spacing} is not isotropic (a CC lattice has one spacing)")
    distance = vtk_to_numpy(data.GetArray("distance")).astype(np.float64).reshape(nz, ny, nx)
    g = data.GetArray("gradient")
    gradient = None if g is None else vtk_to_numpy(g).astype(np.float64).reshape(nz, ny, nx, 3)
    return distance, gradient, tuple(image.GetOrigin()), float(spacing[0])


def _read_vti(path):
    from . import _core

    stem = path[:-len(".vti")]
    primary, secondary = stem + ".primary.vti", stem + ".secondary.vti"
    if os.path.exists(path):
        d, g, origin, h = _read_vti_grid(path)
        return _core.Field(d, origin, h, "cc", g)
    if os.path.exists(primary) and os.path.exists(secondary):  # a BCC field: its two CC sub-grids
        d0, g0, origin, h = _read_vti_grid(primary)
        d1, g1, _, _ = _read_vti_grid(secondary)
        gradient = (g0, g1) if g0 is not None and g1 is not None else None
        return _core.Field((d0, d1), origin, h, "bcc", gradient)
    raise _missing(path)


def read_field(path):
    """read_field(path) -> Field

    Reads a field in any format Field.write writes, by the path's extension: ".json" (the
    field file, docs/field-format.md: lossless, with closest triangles and provenance),
    ".npz" and ".vti" (values and gradients on their lattice; BCC .vti as NAME.primary.vti
    and NAME.secondary.vti beside the NAME.vti given). ".npy" holds values without their
    lattice and ".vdb" only a narrow band of them: both raise ValueError saying how to read
    them instead. A missing file raises FileNotFoundError.
    """
    from . import _core

    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".json":
        if not os.path.exists(path):
            raise _missing(path)
        return _core.read_field_file(path)
    if ext == ".npz":
        if not os.path.exists(path):
            raise _missing(path)
        return _named(path, lambda: _read_npz(path))
    if ext == ".vti":
        return _named(path, lambda: _read_vti(path))
    if ext == ".npy":
        raise ValueError(f"{path}: a .npy file holds the values without their lattice (origin, spacing), so it cannot "
                         "be read back as a Field: use numpy.load and sdf_lattices.Field(values, origin, spacing), or "
                         "write .npz or .json, which keep the lattice")
    if ext == ".vdb":
        raise ValueError(f"{path}: a .vdb file holds the field only in a narrow band (every other voxel is the "
                         "background value), so it cannot be read back as the sampled Field: open it with pyopenvdb, "
                         "or write .json or .npz for a lossless copy")
    raise ValueError(f"{path}: unknown field file extension '{ext}'; read_field reads {_FORMATS}")
