"""band=W: a narrow band sampled sparsely (sdf_lattices.SparseField, python/src/sparse_field.cpp).

sample(mesh, ..., band=W) and SDF.sample(..., band=W) sample only the blocks of 8^3 lattice
points within W of a triangle and return a SparseField; without band= they return the dense
Field as before (band_width=W, a sampler keyword, keeps its dense meaning). With band=W,
gradient=False samples the band without its gradient channel (12 bytes a point instead of 36;
SparseField.gradient is None, distances and triangles the same bytes), closest_triangle=False
without its closest triangles (4 bytes a point less; SparseField.triangle is None, the band's
points the same, marked by a bit each): both False, 8.125 bytes a point."""
import functools
import os
import tempfile

# sample()'s lattice arguments, passed on to the native _sample_band (as SDF.sample takes them).
_LATTICE = ("lattice", "resolution", "samples", "margin", "bounds", "spacing", "origin", "progress")


def _channel(name, value):
    """band=W's gradient= and closest_triangle= keywords: True (the default) or False (a band without
    that channel)."""
    if value is None:
        return True
    if not isinstance(value, bool):
        raise TypeError(f"sample(): {name}= expects True or False, got {value!r}")
    return value


def _channels(gradient, closest_triangle):
    return {"gradient": _channel("gradient", gradient), "closest_triangle": _channel("closest_triangle", closest_triangle)}


def _no_channel_keywords(gradient, closest_triangle):
    for name, value in (("gradient", gradient), ("closest_triangle", closest_triangle)):
        if value is not None:
            raise TypeError(f"sample(): {name}= goes with band=W (a sparse band without the {name} channel); "
                            f"the dense Field always holds its {name}")


def install(core):
    """Wraps core.sample and core.SDF.sample with band=; adds SparseField.to_openvdb; returns the new sample."""
    core_sample, sdf_sample = core.sample, core.SDF.sample

    @functools.wraps(core_sample)
    def sample(mesh, *args, band=None, gradient=None, closest_triangle=None, **kwargs):
        if band is None:
            _no_channel_keywords(gradient, closest_triangle)
            return core_sample(mesh, *args, **kwargs)
        if kwargs.get("band_width"):
            raise ValueError("sample(): band=W samples a sparse band; band_width=W (the dense band) is not given with it")
        kwargs.pop("band_width", None)
        kwargs.pop("distributed", None)  # a sparse band is sampled on this process
        if len(args) > len(_LATTICE) - 1:
            raise TypeError(f"sample(): at most {len(_LATTICE) - 1} positional arguments after mesh")
        lattice = dict(zip(_LATTICE, args))
        for key in _LATTICE:
            if key in kwargs:
                lattice[key] = kwargs.pop(key)
        return core._sample_band(core.SDF(mesh, **kwargs), band, **lattice, **_channels(gradient, closest_triangle))

    @functools.wraps(sdf_sample)
    def sdf_sample_band(self, *args, band=None, gradient=None, closest_triangle=None, **kwargs):
        if band is None:
            _no_channel_keywords(gradient, closest_triangle)
            return sdf_sample(self, *args, **kwargs)
        for key in kwargs:
            if key not in _LATTICE:
                return sdf_sample(self, *args, **kwargs)  # raises its TypeError naming the keyword
        return core._sample_band(self, band, *args, **kwargs, **_channels(gradient, closest_triangle))

    def to_openvdb(self):
        """The band as pyopenvdb grids, {name: grid} (as write(path) writes them: "distance", "gradient",
        "closest_triangle", with "_primary" / "_secondary" for BCC); needs pyopenvdb (Debian python3-openvdb)."""
        try:
            import pyopenvdb
        except ImportError as e:
            raise ImportError(f"SparseField.to_openvdb(): {e} (install the Debian package python3-openvdb)") from e
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "band.vdb")
            self.write(path)
            grids, _ = pyopenvdb.readAll(path)
        return {grid.name: grid for grid in grids}

    core.SDF.sample = sdf_sample_band
    core.SparseField.to_openvdb = to_openvdb
    return sample


__all__ = ["install"]
