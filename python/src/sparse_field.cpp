// sdf_lattices.SparseField: a narrow band sampled sparsely (core/sampling/sparse_band.h), as
// sample(mesh, ..., band=W) and SDF.sample(..., band=W) return it (the package routes band=
// here, python/sdf_lattices/_sparse.py). No dense array is made unless to_dense() is asked.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>

#include "core/mesh/mesh_provenance.h"
#include "core/reconstruction/sparse_reconstruction.h"
#include "core/sampling/sparse_band.h"
#include "core/sampling/sparse_band_cells.h"
#include "harness/config/json_reader.h"
#include "harness/io/sparse_field_file.h"
#include "harness/io/sparse_nvdb_file.h"
#include "harness/io/sparse_vdb_file.h"
#include "harness/resources/memory_budget.h"
#include "python/src/field.h"
#include "python/src/task.h"

namespace sdf {

namespace {

std::string text_of(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", v);
    return text;
}

class SparseField {
public:
    explicit SparseField(SparseBandField band) : band_(std::make_shared<const SparseBandField>(std::move(band))) {
        // The band's points: channel positions a * 512 + local of the active blocks' points
        // within the band (their mask's bits; padding's are clear), in block order.
        const SparseBandField& b = *band_;
        b.require_channels({false, false}, "SparseField");
        at_.reserve(size_t(b.counts().band_points));
        for (size_t a = 0; a < b.active.size(); ++a)
            for (int local = 0; local < kBandBlockPoints; ++local)
                if (b.in_band(a, local)) at_.push_back(int64_t(a * kBandBlockPoints + size_t(local)));
    }

    const SparseBandField& band() const { return *band_; }
    const Lattice& lattice() const { return band_->lattice; }
    py::ssize_t size() const { return py::ssize_t(at_.size()); }

    py::array_t<double> distance() const {
        return new_array<double>({size()}, [&](double* d) {
            for (size_t i = 0; i < at_.size(); ++i) d[i] = band_->distance[size_t(at_[i])];
        });
    }
    py::object gradient() const {
        if (!band_->channels.gradient) return py::none();
        return new_array<double>({size(), 3}, [&](double* g) {
            for (size_t i = 0; i < at_.size(); ++i) {
                const Vec3d& v = band_->gradient[size_t(at_[i])];
                g[3 * i] = v.x, g[3 * i + 1] = v.y, g[3 * i + 2] = v.z;
            }
        });
    }
    py::object triangle() const {
        if (!band_->channels.closest_triangle) return py::none();
        return new_array<int32_t>({size()}, [&](int32_t* t) {
            for (size_t i = 0; i < at_.size(); ++i) t[i] = band_->closest_triangle[size_t(at_[i])];
        });
    }
    /// Block id and local index of band point i.
    std::pair<int64_t, int> block_of(size_t i) const {
        return {band_->active[size_t(at_[i] / kBandBlockPoints)], int(at_[i] % kBandBlockPoints)};
    }
    py::array_t<double> points() const {
        return new_array<double>({size(), 3}, [&](double* p) {
            for (size_t i = 0; i < at_.size(); ++i) {
                const auto [id, local] = block_of(i);
                const Vec3d x = lattice().position_of_coords(band_->layout().point_coords(id, local));
                p[3 * i] = x.x, p[3 * i + 1] = x.y, p[3 * i + 2] = x.z;
            }
        });
    }
    py::array_t<int64_t> indices() const {
        return new_array<int64_t>({size(), 3}, [&](int64_t* q) {
            for (size_t i = 0; i < at_.size(); ++i) {
                const auto [id, local] = block_of(i);
                const Int3 c = band_->layout().coset_point(id, local);
                q[3 * i] = c.x, q[3 * i + 1] = c.y, q[3 * i + 2] = c.z;
            }
        });
    }
    py::array_t<int8_t> subgrid() const {
        return new_array<int8_t>({size()}, [&](int8_t* s) {
            for (size_t i = 0; i < at_.size(); ++i) s[i] = int8_t(band_->layout().block_coords(block_of(i).first).coset);
        });
    }
    size_t nbytes() const { return band_->memory_bytes() + at_.capacity() * sizeof(int64_t); }
    /// Whether the band holds gradients (a file read without its gradient channel does not).
    bool has_gradient() const { return band_->channels.gradient; }

    /// The band's reconstruction of `spec`, the last one kept for the next call. Each caller
    /// holds its own reference (the GIL is released while it evaluates); it reads band_,
    /// which lives as long as this object.
    std::shared_ptr<const SparseReconstruction> reconstruction(const ReconstructionSpec& spec) const {
        // Keyed on the exact values (describe() prints sigma2 to 6 digits); threads only
        // change how the derivative arrays are built, not their values.
        const auto same = [](const ReconstructionSpec& a, const ReconstructionSpec& b) {
            return a.interpolator == b.interpolator && a.derivatives == b.derivatives && a.sigma_units == b.sigma_units &&
                   std::memcmp(&a.sigma2, &b.sigma2, sizeof(double)) == 0;
        };
        if (!recon_ || !same(recon_spec_, spec)) {
            recon_ = std::make_shared<const SparseReconstruction>(*band_, spec, has_gradient());
            recon_spec_ = spec;
        }
        return recon_;
    }

    /// The dense field, made once (to_dense()) for reconstruct(). to_dense() releases the GIL,
    /// so another thread may have made it meanwhile: the first one made is kept, and each caller
    /// holds its own reference, so that no field is freed while a reconstruction reads it.
    std::shared_ptr<Field> dense() const {
        if (!dense_) {
            std::shared_ptr<Field> made = std::make_shared<Field>(to_dense());
            if (!dense_) dense_ = std::move(made);
        }
        return dense_;
    }

    /// The band's reconstruction with the band's rule: a point outside the band's cells
    /// (sparse_band_cells.h) is treated as a point outside the lattice's domain (outside=
    /// "nan", "clamp": the dense band field's value there, built from +-W, or "error"). From
    /// the blocks (SparseReconstruction: the dense band field's reconstruction bit for bit,
    /// without it); the interpolating splines, whose prefilter spans the lattice, from
    /// to_dense() (made once, past the memory check).
    py::tuple reconstruct(const py::object& points_in, const std::string& interpolator, const std::string& derivatives,
                          double sigma2, const std::string& sigma_units, int threads, const std::string& outside) {
        choose("outside", outside, {"nan", "clamp", "error"});
        const DoubleArray array = points_argument(points_in);
        const ReconstructionSpec spec =
            reconstruction_spec(lattice().type, has_gradient(), interpolator, derivatives, sigma2, sigma_units, threads);
        py::tuple out;
        std::vector<Vec3d> points;
        if (reconstructs_locally(spec.interpolator)) {
            const std::shared_ptr<const SparseReconstruction> r = reconstruction(spec);
            auto [p, samples] = reconstruct_points(array, [&](const std::vector<Vec3d>& q) { return r->evaluate(q, threads); });
            out = reconstruction_arrays(p, samples, r->domain(), outside);
            points = std::move(p);
        } else {
            const std::shared_ptr<Field> field = dense();
            out = field->reconstruct(points_in, interpolator, derivatives, sigma2, sigma_units, threads, outside);
            points = points_from_array(array, "points");
        }
        if (outside == "clamp") return out;
        auto values = out[0].cast<py::array_t<double>>();
        auto gradients = out[1].cast<py::array_t<double>>();
        auto v = values.mutable_unchecked<1>();
        auto g = gradients.mutable_unchecked<2>();
        const double nan = std::numeric_limits<double>::quiet_NaN();
        for (size_t i = 0; i < points.size(); ++i) {
            if (std::isnan(v(py::ssize_t(i))) || in_band_cells(*band_, points[i])) continue;
            if (outside == "error")
                throw std::invalid_argument("points: row " + std::to_string(i) + " (" + text_of(points[i].x) + ", " +
                                            text_of(points[i].y) + ", " + text_of(points[i].z) +
                                            ") lies outside the band's cells (a corner of its cell holds |d| > W = " +
                                            text_of(band_->width) + "; outside=\"nan\" gives NaN there, \"clamp\" the "
                                            "dense band field's value, built from +-W)");
            v(py::ssize_t(i)) = nan;
            for (int a = 0; a < 3; ++a) g(py::ssize_t(i), a) = nan;
        }
        return py::make_tuple(values, gradients);
    }

    Field to_dense() const {
        const uint64_t bytes = uint64_t(SparseBandField::dense_bytes(lattice(), band_->channels));
        require_host_memory({bytes, "densifying the band of " + lattice_notation(lattice()) + " (" +
                                        std::to_string(lattice().num_points()) + " points)"},
                            "SparseField.to_dense()");
        std::shared_ptr<const SparseBandField> b = band_;
        TaskOptions task;
        task.total = kBackgroundItems;
        task.label = "densifying the band";
        const bool gradient = has_gradient();
        return run_task([&] {
            SampledField f = b->densify();
            if (!gradient) f.gradient.clear();  // read without its gradient channel: none, as read_field of the dense file
            return Field(std::move(f));
        }, task);
    }

    py::list write(const std::string& path, bool overwrite, bool closest_triangle, const std::string& dtype) const {
        choose("dtype", dtype, {"float32", "float64"});
        if (closest_triangle && !band_->channels.closest_triangle)
            throw std::invalid_argument(path + ": closest_triangle=True, but the band holds no closest triangle (sampled with "
                                        "closest_triangle=False, or read from a file without one)");
        const bool json = path.size() > 5 && path.compare(path.size() - 5, 5, ".json") == 0;
        if (!json && dtype != "float32")
            throw std::invalid_argument(path + ": dtype=\"" + dtype + "\": a level set (.vdb, .nvdb) stores float32; "
                                        "float64 is for the sparse band's field file (.json)");
        if (path.size() > 5 && path.compare(path.size() - 5, 5, ".nvdb") == 0) return write_nvdb(path, overwrite, closest_triangle);
        std::shared_ptr<const SparseBandField> b = band_;
        if (json) {
            SparseFieldWriteOptions options;
            options.gradient = b->channels.gradient;
            options.dtype = dtype == "float32" ? FieldDtype::Float32 : FieldDtype::Float64;
            options.overwrite = overwrite ? Overwrite::Allow : Overwrite::Forbid;
            TaskOptions task;
            task.total = kBackgroundItems;
            task.label = "writing " + path;
            run_task([&] { write_sparse_field(path, *b, options); return 0; }, task);
            py::list files;
            files.append(path);
            const nlohmann::json header = read_json_file(path, "field header");
            for (const auto& [name, channel] : header["channels"].items())
                files.append((std::filesystem::path(path).parent_path() / channel["file"].get<std::string>()).string());
            return files;
        }
        if (path.size() < 5 || path.compare(path.size() - 4, 4, ".vdb") != 0)
            throw std::invalid_argument(path + ": a SparseField writes .json (the sparse band's field file), .vdb (an "
                                        "OpenVDB level set) and .nvdb (a NanoVDB level set); to_dense().write(path) writes the dense formats (vti, npy, npz)");
        SparseVdbOptions options;
        options.gradient = b->channels.gradient;
        options.closest_triangle = closest_triangle;
        options.overwrite = overwrite ? Overwrite::Allow : Overwrite::Forbid;
        TaskOptions task;
        task.total = kBackgroundItems;
        task.label = "writing " + path;
        run_task([&] { return write_sparse_band_vdb(*b, path, options); }, task);
        py::list files;
        files.append(path);
        return files;
    }

private:
    /// The NanoVDB level set (harness/io/sparse_nvdb_file.h): distance grids only.
    py::list write_nvdb(const std::string& path, bool overwrite, bool closest_triangle) const {
        if (closest_triangle)
            throw std::invalid_argument(path + ": a .nvdb holds the distance grids only; closest_triangle=True needs a .vdb");
        std::shared_ptr<const SparseBandField> b = band_;
        TaskOptions task;
        task.total = kBackgroundItems;
        task.label = "writing " + path;
        run_task([&] { return write_sparse_band_nvdb(*b, path, overwrite ? Overwrite::Allow : Overwrite::Forbid); }, task);
        py::list files;
        files.append(path);
        return files;
    }

    std::shared_ptr<const SparseBandField> band_;
    std::vector<int64_t> at_;
    mutable std::shared_ptr<Field> dense_;
    mutable std::shared_ptr<const SparseReconstruction> recon_;
    mutable ReconstructionSpec recon_spec_;
};

/// read_field of a sparse band's field file (sdf_lattices._fields routes .json files here).
SparseField read_sparse_field_file(const std::string& path) {
    TaskOptions task;
    task.total = kBackgroundItems;
    task.label = "reading " + path;
    return SparseField(run_task([&] { return read_sparse_field(path); }, task));
}

SparseField sample_band(const MeshSdf& sdf, double band, const std::string& lattice, const py::object& resolution,
                        const py::object& samples, const py::object& margin, const py::object& bounds,
                        const py::object& spacing, const py::object& origin, const py::object& progress, bool gradient,
                        bool closest_triangle) {
    if (!(band > 0) || !std::isfinite(band))
        throw std::invalid_argument("band: expected a positive width in mesh units, got " + std::to_string(band));
    if (!(float(band) > 0) || !std::isfinite(float(band)))
        throw std::invalid_argument("band: " + std::to_string(band) + " is not representable in float32 (a .vdb's values)");
    const Lattice l = frame_lattice({lattice, resolution, samples, margin, bounds, spacing, origin, LatticeStorage::SparseBand},
                                    sdf.mesh().bounds());
    TaskOptions task;
    task.total = kBackgroundItems;
    task.label = "sampling the band of '" + sdf.mesh().name() + "'";
    task.progress = progress;
    BandChannels channels;
    channels.gradient = gradient;
    channels.closest_triangle = closest_triangle;
    SparseBandField field = run_task([&] {
        try {
            return sdf.sample_band(l, band, channels);
        } catch (const std::bad_alloc&) {
            throw std::runtime_error(out_of_memory_message("sample(band=) of " + sdf.mesh().name() + " on " + lattice_notation(l), 0));
        }
    }, task);
    field.mesh = describe_prepared_mesh(sdf.mesh());
    return SparseField(std::move(field));
}

}  // namespace

void bind_sparse_field(py::module_& m) {
    py::class_<SparseField>(m, "SparseField", R"(A narrow band of width W sampled sparsely: sample(mesh, ..., band=W) and
SDF.sample(..., band=W) return it. The lattice is cut into blocks of 8^3 points (OpenVDB's
leaves); only the blocks within W of a triangle are sampled, so its memory grows with the band,
not with the lattice. Its arrays hold the band's points (|d| <= W), in block order: distance,
gradient (None when sampled with gradient=False or read without one), triangle (None when
sampled with closest_triangle=False or read without one), their world positions (points) and
lattice indices (indices, subgrid).
Every other lattice point stands for +W or -W by its side: to_dense() is the dense field of
sample(mesh, ..., band_width=W), bit for bit. write(path) writes an OpenVDB level set (.vdb).)")
        .def_property_readonly("distance", &SparseField::distance, "Exact signed distance of the band's points, float64 (N,).")
        .def_property_readonly("gradient", &SparseField::gradient,
                               "Exact gradient of the band's points, float64 (N, 3); None when the band holds none (sampled "
                               "with gradient=False, or read from a file without the channel).")
        .def_property_readonly("triangle", &SparseField::triangle,
                               "Closest triangle of the band's points, int32 (N,), 0-based; None when the band holds none "
                               "(sampled with closest_triangle=False, or read from a file without the channel).")
        .def_property_readonly("points", &SparseField::points, "World positions of the band's points, float64 (N, 3).")
        .def_property_readonly("indices", &SparseField::indices,
                               "Lattice indices (i, j, k) of the band's points, int64 (N, 3), x first, in their sub-grid "
                               "(subgrid): the point is to_dense().values[k, j, i] (CC) or values[subgrid][k, j, i] (BCC).")
        .def_property_readonly("subgrid", &SparseField::subgrid,
                               "Sub-grid of each band point, int8 (N,): 0 (CC, or BCC's primary grid) or 1 (BCC's secondary).")
        .def_property_readonly("width", [](const SparseField& f) { return f.band().width; }, "The band's width W, mesh units.")
        .def_property_readonly("lattice", [](const SparseField& f) { return lattice_type_name(f.lattice().type); }, "'cc' or 'bcc'.")
        .def_property_readonly("resolution", [](const SparseField& f) {
            const Int3 r = f.lattice().resolution;
            return py::make_tuple(r.x, r.y, f.lattice().type == LatticeType::BCC ? 2 * r.z : r.z);
        }, "(nx, ny, nz) for CC; (Rx, Ry, 2Rz) for BCC, as Field.resolution.")
        .def_property_readonly("origin", [](const SparseField& f) {
            const Vec3d o = f.lattice().origin;
            return py::make_tuple(o.x, o.y, o.z);
        }, "World position (x, y, z) of the first (primary) lattice point.")
        .def_property_readonly("spacing", [](const SparseField& f) { return f.lattice().spacing; }, "h, as Field.spacing.")
        .def_property_readonly("num_points", [](const SparseField& f) { return f.lattice().num_points(); },
                               "Lattice points in all (the dense field's).")
        .def_property_readonly("active_blocks", [](const SparseField& f) { return f.band().active.size(); },
                               "Blocks of 8^3 points that were sampled.")
        .def_property_readonly("counts", [](const SparseField& f) {
            const SparseBandCounts c = f.band().counts();
            py::dict d;
            d["blocks"] = c.blocks, d["active_blocks"] = c.active_blocks, d["mixed_blocks"] = c.mixed_blocks;
            d["tiles"] = c.tiles, d["inside_tiles"] = c.inside_tiles, d["active_points"] = c.active_points;
            d["band_points"] = c.band_points;
            return d;
        }, "The band's blocks and points counted (dict).")
        .def_property_readonly("nbytes", &SparseField::nbytes, "Bytes the band holds (its arrays' capacity).")
        .def_property_readonly("precision", [](const SparseField& f) { return precision_name(f.band().precision); },
                               "The search precision it was sampled with.")
        .def_property_readonly("mesh", [](const SparseField& f) { return json_to_python(nlohmann::json(f.band().mesh)); },
                               "The mesh it was sampled from (dict).")
        .def("to_dense", &SparseField::to_dense,
             "to_dense() -> Field: the dense banded field (every lattice point; +-W outside the band), refused (RuntimeError, naming "
             "the size) when it exceeds the memory available, as sample() is.")
        .def("write", &SparseField::write, py::arg("path"), py::arg("overwrite") = false, py::arg("closest_triangle") = false,
             py::arg("dtype") = "float32",
             "write(path, overwrite=False, closest_triangle=False, dtype=\"float32\") -> list of files: by the extension, "
             ".json: the sparse band's field file (docs/field-format.md; its blocks, tiles and signs, values as dtype, "
             "the closest triangles where held, else the band points' bit mask), read back by read_field, sdf-eval and sdf-render; .vdb: an OpenVDB level set "
             "(harness/io/sparse_vdb_file.h) with its gradient grid where the band holds gradients, closest_triangle=True adding an Int32Grid of the "
             "closest triangles (which Debian's pyopenvdb 10 cannot read); .nvdb: the NanoVDB level set of the distance "
             "(harness/io/sparse_nvdb_file.h; builds with NanoVDB only). Written atomically. Other formats are refused "
             "(to_dense().write(path) writes them).")
        .def("reconstruct", &SparseField::reconstruct, py::arg("points"), py::arg("interpolator") = "",
             py::arg("derivatives") = "", py::arg("sigma2") = 0.5, py::arg("sigma_units") = "lattice", py::arg("threads") = 0,
             py::arg("outside") = "nan",
             "reconstruct(points, interpolator=\"\", derivatives=\"\", sigma2=0.5, sigma_units=\"lattice\", threads=0, "
             "outside=\"nan\") -> (values, gradients): to_dense().reconstruct(...) bit for bit, computed from the band's "
             "blocks without the dense field (its memory grows with the band; cc_bspline3 and bcc_box_quintic, whose "
             "prefilter spans the lattice, use to_dense(), made once and refused past the memory check). A point outside the band's cells (a corner of its lattice "
             "cell, in either BCC sub-grid, holds |d| > W) is treated as a point outside the lattice: outside=\"nan\" "
             "gives NaN, \"clamp\" the dense band field's reconstruction there (built from +-W), \"error\" raises.")
        .def("__len__", &SparseField::size)
        .def("__repr__", [](const SparseField& f) {
            return "<sdf_lattices.SparseField " + std::string(lattice_type_name(f.lattice().type)) + " " +
                   lattice_notation(f.lattice()) + ", band " + std::to_string(f.band().width) + ": " + std::to_string(f.size()) +
                   " points in " + std::to_string(f.band().active.size()) + " blocks>";
        });
    m.def("_read_sparse_field_file", &read_sparse_field_file, py::arg("path"),
          "read_field's native part for a sparse band's field file (sdf_lattices._fields).");
    m.def("_is_sparse_field_file", &is_sparse_field_file, py::arg("path"),
          "Whether the field header at path is a sparse band's (\"layout\": \"sparse_band\").");
    m.def("_sample_band", &sample_band, py::arg("sdf"), py::arg("band"), py::arg("lattice") = lattice_type_name(LatticeType::CC),
          py::arg("resolution") = py::none(), py::arg("samples") = py::none(), py::arg("margin") = py::none(),
          py::arg("bounds") = py::none(), py::arg("spacing") = py::none(), py::arg("origin") = py::none(),
          py::arg("progress") = py::none(), py::arg("gradient") = true, py::arg("closest_triangle") = true,
          "SDF.sample(band=W)'s native part (sdf_lattices._sparse); gradient=False (closest_triangle=False): a band "
          "without that channel.");
}

}  // namespace sdf
