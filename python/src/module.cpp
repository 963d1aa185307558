// The extension sdf_lattices._core (pybind11): meshes, exact point queries, sampled CC/BCC
// fields, their reconstruction and ray-cast images, with NumPy arrays in and out. The
// package sdf_lattices (python/sdf_lattices/__init__.py) re-exports it, beside its
// pure-Python parts.
//
// Every call goes through the harness's own code paths, so the module computes what the
// tools compute, bit for bit: load_mesh + prepare_mesh as sdf-query, query_points
// (harness/sampling/point_query.h) as sdf-query, the config's lattice and sampler parsers
// (harness/config/lattice_spec.h, sampler_spec.h) and the sampler table as run-experiment,
// read_field / write_field_file (harness/io) as the tools' files, Reconstruction as sdf-eval,
// render_reconstruction as sdf-render. Work on arrays runs with the GIL released; no Python
// code is called per point. C++ errors arrive as Python exceptions with the tools' messages:
// std::invalid_argument and ConfigError (sample()'s arguments, read by the config parser) as
// ValueError, every other std::exception (a file that cannot be read, a backend this machine
// lacks) as RuntimeError. One file per job: mesh.cpp, query.cpp, field.cpp, sparse_field.cpp, lattice_kinds.cpp,
// render.cpp, distributed.cpp.
#include "harness/config/json_reader.h"
#include "harness/provenance/version.h"
#include "python/src/common.h"

namespace sdf {
void bind_sparse_field(py::module_& m);  // sparse_field.cpp
void bind_lattice_kinds(py::module_& m);  // lattice_kinds.cpp
}

PYBIND11_MODULE(_core, m) {
    using namespace sdf;
    m.doc() = R"(Exact signed distance fields of triangle meshes on CC and BCC lattices.

Meshes (load_mesh, Mesh), exact queries of arbitrary points (query), sampled fields
(sample, read_field, Field), their reconstruction (Field.reconstruct) and ray-cast images
(render), all with NumPy arrays. The same code as the command-line tools: query() equals
sdf-query, sample() equals a run-experiment field, bit for bit. Signed distance is negative
inside; gradients are unit vectors; triangles are 0-based in the input's face order.
Errors raise ValueError (a bad argument) or RuntimeError (a bad file, a missing backend)
with the tools' messages.)";
    // sample()'s arguments are read by the config parser: its ConfigError is a bad argument here.
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const ConfigError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        }
    });
    m.attr("__version__") = project_version();
    m.attr("build_commit") = build_commit();
    bind_distributed(m);
    bind_mesh(m);
    bind_query(m);
    bind_field(m);
    bind_sparse_field(m);
    bind_lattice_kinds(m);
    bind_render(m);
}
