"""Arguments checked before they reach the extension, where pybind11 would answer a wrong
keyword or a wrong type with a dump of the C++ signature: SDF.sample() given a sampler
keyword (those bind the sampler, in SDF(mesh, ...)), render() given a path instead of a Field."""
import functools

# SDF.sample's own keywords; the sampler's belong to SDF(mesh, **sampler).
_SDF_SAMPLE = ("lattice", "resolution", "samples", "margin", "bounds", "spacing", "origin", "progress")


def install(core):
    """Wraps core.SDF.sample and core.render with the checks; returns the new render."""
    sdf_sample, core_render = core.SDF.sample, core.render

    @functools.wraps(sdf_sample)
    def sample(self, *args, **kwargs):
        for key in kwargs:
            if key not in _SDF_SAMPLE:
                raise TypeError(f"SDF.sample(): unexpected keyword {key!r}; it takes {', '.join(_SDF_SAMPLE)}. "
                                f"Sampler keywords ({key}=... among them, if it is one) bind the sampler: give them to "
                                f"SDF(mesh, {key}=...), or call sdf_lattices.sample(mesh, ..., {key}=...)")
        return sdf_sample(self, *args, **kwargs)

    @functools.wraps(core_render)
    def render(*args, **kwargs):
        field = args[0] if args else kwargs.get("field")
        if not isinstance(field, core.Field):
            what = type(field).__name__ if field is not None else "nothing"
            hint = (": read it first, render(sdf_lattices.read_field(path)), or run the sdf-render tool on a mesh file"
                    if isinstance(field, (str, bytes)) or hasattr(field, "__fspath__") else "")
            raise TypeError(f"render(): field: expected an sdf_lattices.Field (from sample() or read_field()), "
                            f"got {what}{hint}")
        return core_render(*args, **kwargs)

    core.SDF.sample = sample
    return render


__all__ = ["install"]
