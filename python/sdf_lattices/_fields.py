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


def _lattice_kinds():
    """{name: kind} of the lattice table (kernels/lattice/lattice_kinds.h), in its order; each
    kind's "parts" are the CC grids its files hold, as the writers name them ("" for CC's one
    grid, "primary" and "secondary" for BCC's)."""
    from . import _core

    return {k["name"]: k for k in _core.lattice_kinds()}


def _suffixed(key, part, separator):
    """An array's name for one part: "distance", "distance_primary", ..."""
    return key + separator + part if part else key


def _one_or_tuple(arrays):
    """What Field takes per lattice: one array for a kind of one grid, a tuple otherwise."""
    return arrays[0] if len(arrays) == 1 else tuple(arrays)


def _read_npz(path):
    from . import _core

    if os.path.getsize(path) == 0 or not zipfile.is_zipfile(path):
        raise ValueError(f"{path}: not a .npz file (no zip archive; truncated or not written by Field.write?)")
    kinds = _lattice_kinds()
    with np.load(path, allow_pickle=False) as z:
        lattice = str(z["lattice"]) if "lattice" in z else None
        kind = kinds.get(lattice)
        if kind is not None:
            parts = kind["parts"]
            values = _one_or_tuple([z[_suffixed("distance", part, "_")] for part in parts])
            gradient = None
            if _suffixed("gradient", parts[0], "_") in z:  # then every part's (a missing one is an error)
                gradient = _one_or_tuple([z[_suffixed("gradient", part, "_")] for part in parts])
            origin = tuple(z[_suffixed("origin", parts[0], "_")])
            return _core.Field(values, origin, float(z["spacing"]), lattice, gradient)
    names = [f"'{name}'" for name in kinds]
    known = f"neither {names[0]} nor {names[1]}" if len(names) == 2 else "none of " + ", ".join(names)
    raise ValueError(f"{path}: not an sdf_lattices .npz field (its 'lattice' entry is missing or {known})")


def _check_vti_sizes(path):
    """Checks every raw appended array of a .vti against its extent and the file's size
    before VTK reads it: VTK's reader fills a short array silently (values up to 3.7e19 from
    a file cut inside its gradient array). ValueError naming the array otherwise. Files that
    are not raw appended (inline, base64, compressed) are left to VTK."""
    import re

    bad = f"{path}: not a readable VTK ImageData XML file: "
    size = os.path.getsize(path)
    with open(path, "rb") as f:
        head = f.read(1 << 20)
    marker = re.search(rb"<AppendedData[^>]*>", head)
    if marker is None or b'encoding="raw"' not in marker.group(0):
        return
    xml = head[:marker.start()]
    if b"compressor=" in xml:
        return
    underscore = head.find(b"_", marker.end())
    if underscore < 0:
        raise ValueError(bad + f"the appended data has no '_' start mark (truncated?)")
    data_start = underscore + 1
    header = re.search(rb'header_type="(UInt32|UInt64)"', xml)
    header_bytes = 8 if header is None or header.group(1) == b"UInt64" else 4
    extent = re.search(rb'WholeExtent="([^"]*)"', xml)
    if extent is None:
        raise ValueError(bad + f"no WholeExtent (not a VTK ImageData file written by Field.write)")
    e = [int(t) for t in extent.group(1).split()]
    if len(e) != 6:
        raise ValueError(bad + f"WholeExtent holds {len(e)} numbers; expected 6")
    points = 1
    for k in range(3):
        points *= max(0, e[2 * k + 1] - e[2 * k] + 1)
    item = {b"Float32": 4, b"Float64": 8, b"Int32": 4, b"Int64": 8, b"UInt8": 1, b"Int8": 1, b"UInt16": 2,
            b"Int16": 2, b"UInt32": 4, b"UInt64": 8}
    for array in re.finditer(rb"<DataArray\b[^>]*>", xml):
        a = array.group(0)
        if b'format="appended"' not in a:
            continue
        attr = {k.decode(): v.decode() for k, v in re.findall(rb'(\w+)="([^"]*)"', a)}
        name = attr.get("Name", "?")
        components = int(attr.get("NumberOfComponents", "1"))
        dtype = attr.get("type", "").encode()
        if dtype not in item:
            continue
        expected = points * components * item[dtype]
        at = data_start + int(attr.get("offset", "0"))
        if at + header_bytes > size:
            raise ValueError(bad + f"array '{name}' starts at byte {at}, beyond the file's {size} bytes "
                             "(truncated?)")
        with open(path, "rb") as f:
            f.seek(at)
            declared = int.from_bytes(f.read(header_bytes), "little")
        if declared != expected:
            raise ValueError(bad + f"array '{name}' declares {declared} bytes; its {points} points x {components} "
                             f"component(s) of {dtype.decode()} need {expected}")
        if at + header_bytes + expected > size:
            raise ValueError(bad + f"array '{name}' needs {expected} bytes from byte {at + header_bytes}, but the "
                             f"file ends after {size} bytes (truncated: {at + header_bytes + expected - size} "
                             "bytes missing)")


def _read_vti_grid(path):
    """(distance [nz, ny, nx], gradient [nz, ny, nx, 3] or None, origin, spacing) of one .vti."""
    _check_vti_sizes(path)
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
    """A field's .vti files: NAME.vti for a kind of one grid, NAME.<part>.vti for each of a
    kind's parts (BCC: NAME.primary.vti and NAME.secondary.vti), the first kind whose files
    are all there."""
    from . import _core

    stem = path[:-len(".vti")]
    for name, kind in _lattice_kinds().items():
        files = [_suffixed(stem, part, ".") + ".vti" for part in kind["parts"]]
        if all(os.path.exists(f) for f in files):
            grids = [_read_vti_grid(f) for f in files]
            values = _one_or_tuple([distance for distance, _, _, _ in grids])
            gradients = [gradient for _, gradient, _, _ in grids]
            gradient = None if any(g is None for g in gradients) else _one_or_tuple(gradients)
            _, _, origin, spacing = grids[0]
            return _core.Field(values, origin, spacing, name, gradient)
    raise _missing(path)


def read_field(path):
    """read_field(path) -> Field

    Reads a field in any format Field.write writes, by the path's extension: ".json" (the
    field file, docs/field-format.md: every point at the dtype it was written with, float32
    by default, float64 with write(..., dtype="float64"), with closest triangles and provenance),
    ".npz" and ".vti" (values and gradients on their lattice; BCC .vti as NAME.primary.vti
    and NAME.secondary.vti beside the NAME.vti given). A sparse band's field file (".json"
    with "layout": "sparse_band", SparseField.write) comes back as the SparseField. ".vdb"
    holds a narrow band: where pyopenvdb is importable it comes back as its grids, {name: grid}
    (as SparseField.to_openvdb() gives them), else (or missing) ValueError says how to read it. ".npy" holds
    values without their lattice: ValueError. A missing file raises FileNotFoundError.
    """
    from . import _core

    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".json":
        if not os.path.exists(path):
            raise _missing(path)
        if _core._is_sparse_field_file(path):  # "layout": "sparse_band": the band back, never densified
            return _core._read_sparse_field_file(path)
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
        try:
            import pyopenvdb
        except ImportError:
            pyopenvdb = None
        if pyopenvdb is not None and os.path.exists(path):  # its grids, as SparseField.to_openvdb() gives them
            return _named(path, lambda: {grid.name: grid for grid in pyopenvdb.readAll(path)[0]})
        raise ValueError(f"{path}: a .vdb file holds the field only in a narrow band (every other voxel is the "
                         "background value), so it cannot be read back as the sampled Field: open it with pyopenvdb, "
                         "or write .json or .npz, which keep every point of the lattice (float32 by default; "
                         "write(..., dtype=\"float64\") keeps every bit)")
    raise ValueError(f"{path}: unknown field file extension '{ext}'; read_field reads {_FORMATS}")
