#include "harness/io/volume_formats.h"

#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "harness/io/volume_grids.h"

namespace sdf {
namespace fs = std::filesystem;

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "volume files are written little-endian");

std::vector<VolumeGrid> volume_grids(const Lattice& l) {
    if (l.type == LatticeType::CC) return {{"", l.origin, l.spacing, l.resolution, 0}};
    const double hh = l.half_spacing();
    return {{"primary", l.origin, l.spacing, l.resolution, 0},
            {"secondary", {l.origin.x + hh, l.origin.y + hh, l.origin.z + hh}, l.spacing, l.secondary_resolution(),
             l.primary_count()}};
}

const char* volume_format_name(VolumeFormat format) {
    for (const VolumeFormatInfo& f : kVolumeFormats)
        if (f.format == format) return f.name;
    return "?";
}

std::string volume_format_names() {
    std::string names;
    for (const VolumeFormatInfo& f : kVolumeFormats) names += std::string(names.empty() ? "" : ", ") + f.name;
    return names;
}

VolumeFormat volume_format_from_name(const std::string& name) {
    for (const VolumeFormatInfo& f : kVolumeFormats)
        if (name == f.name) return f.format;
    throw std::invalid_argument("unknown volume format \"" + name + "\"; expected one of " + volume_format_names());
}

bool volume_format_available(VolumeFormat format) { return format != VolumeFormat::Vdb || SDF_HAVE_OPENVDB; }

namespace {

/// `path` without ".<ext>" when it ends with it.
std::string stem_of(const std::string& path, const std::string& ext) {
    const std::string suffix = "." + ext;
    if (path.size() > suffix.size() && path.compare(path.size() - suffix.size(), suffix.size(), suffix) == 0)
        return path.substr(0, path.size() - suffix.size());
    return path;
}

std::string with_part(const std::string& stem, const std::string& part) { return part.empty() ? stem : stem + "." + part; }

bool has_gradient(const SampledField& field) { return field.gradient.size() == field.distance.size(); }

// ---- NumPy .npy (format version 1.0) ----------------------------------------------------

/// One array as .npy bytes: the magic, a header dict padded to 64 bytes, the data.
std::string npy_bytes(FieldDtype dtype, const std::vector<int64_t>& shape, const double* values, size_t count) {
    std::string dict = std::string("{'descr': '") + (dtype == FieldDtype::Float32 ? "<f4" : "<f8") +
                       "', 'fortran_order': False, 'shape': (";
    for (size_t i = 0; i < shape.size(); ++i) dict += std::to_string(shape[i]) + (shape.size() == 1 || i + 1 < shape.size() ? ", " : "");
    dict += "), }";
    const size_t unpadded = 10 + dict.size() + 1;  // magic(6) + version(2) + length(2) + dict + '\n'
    dict += std::string((64 - unpadded % 64) % 64, ' ') + "\n";
    std::string out("\x93NUMPY\x01\x00", 8);
    const uint16_t length = uint16_t(dict.size());
    out.append(reinterpret_cast<const char*>(&length), 2);
    out += dict;
    if (dtype == FieldDtype::Float32) {
        const size_t at = out.size();
        out.resize(at + count * sizeof(float));
        for (size_t i = 0; i < count; ++i) {
            const float v = float(values[i]);
            std::memcpy(&out[at + i * sizeof(float)], &v, sizeof v);
        }
    } else {
        out.append(reinterpret_cast<const char*>(values), count * sizeof(double));
    }
    return out;
}

/// A 0-d or 1-d array of doubles, or a 0-d unicode string, as .npy bytes.
std::string npy_string(const std::string& text) {
    std::string dict = "{'descr': '<U" + std::to_string(text.size()) + "', 'fortran_order': False, 'shape': (), }";
    const size_t unpadded = 10 + dict.size() + 1;
    dict += std::string((64 - unpadded % 64) % 64, ' ') + "\n";
    std::string out("\x93NUMPY\x01\x00", 8);
    const uint16_t length = uint16_t(dict.size());
    out.append(reinterpret_cast<const char*>(&length), 2);
    out += dict;
    for (char c : text) {  // UTF-32LE of ASCII
        const uint32_t code = uint32_t(static_cast<unsigned char>(c));
        out.append(reinterpret_cast<const char*>(&code), 4);
    }
    return out;
}

struct NamedArray {
    std::string name;  ///< file (npy) or archive member (npz) without ".npy"
    std::string bytes;
};

std::vector<int64_t> grid_shape(const VolumeGrid& g, int components) {
    std::vector<int64_t> shape = {g.resolution.z, g.resolution.y, g.resolution.x};
    if (components > 1) shape.push_back(components);
    return shape;
}

/// The arrays of every grid: "distance" and "gradient", with "_<part>" for BCC.
std::vector<NamedArray> grid_arrays(const SampledField& field, FieldDtype dtype, const std::string& separator) {
    std::vector<NamedArray> arrays;
    for (const VolumeGrid& g : volume_grids(field.lattice)) {
        const std::string suffix = g.part.empty() ? "" : separator + g.part;
        arrays.push_back({"distance" + suffix, npy_bytes(dtype, grid_shape(g, 1), field.distance.data() + g.first, size_t(g.count()))});
        if (has_gradient(field))
            arrays.push_back({"gradient" + suffix, npy_bytes(dtype, grid_shape(g, 3), &field.gradient[size_t(g.first)].x,
                                                             3 * size_t(g.count()))});
    }
    return arrays;
}

// ---- NumPy .npz: an uncompressed ZIP of .npy members --------------------------------------

void put16(std::string& s, uint16_t v) { s.append(reinterpret_cast<const char*>(&v), 2); }
void put32(std::string& s, uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }

uint32_t crc32_of(const std::string& bytes) {
    uLong crc = crc32(0L, Z_NULL, 0);
    for (size_t at = 0; at < bytes.size(); at += size_t(1) << 30) {
        const size_t n = std::min(bytes.size() - at, size_t(1) << 30);
        crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data() + at), uInt(n));
    }
    return uint32_t(crc);
}

/// ZIP "stored" entries (no compression, no ZIP64): what numpy.load reads as an .npz.
std::string zip_stored(const std::string& path, const std::vector<NamedArray>& members) {
    std::string out, directory;
    const uint16_t dos_time = 0, dos_date = (1 << 5) | 1;  // 1980-01-01 00:00: reproducible bytes
    for (const NamedArray& m : members) {
        const std::string name = m.name + ".npy";
        if (m.bytes.size() >= 0xFFFFFFFFu || out.size() + m.bytes.size() >= 0xFFFFFFFFu)
            throw std::runtime_error(path + ": an .npz is limited to 4 GiB here (no ZIP64); write \"npy\" instead");
        const uint32_t crc = crc32_of(m.bytes), size = uint32_t(m.bytes.size()), offset = uint32_t(out.size());
        auto common = [&](std::string& s) {
            put16(s, 20), put16(s, 0), put16(s, 0), put16(s, dos_time), put16(s, dos_date);
            put32(s, crc), put32(s, size), put32(s, size), put16(s, uint16_t(name.size())), put16(s, 0);
        };
        put32(out, 0x04034b50);
        common(out);
        out += name;
        out += m.bytes;
        put32(directory, 0x02014b50);
        put16(directory, 20);
        common(directory);
        put16(directory, 0), put16(directory, 0), put16(directory, 0), put32(directory, 0), put32(directory, offset);
        directory += name;
    }
    const uint32_t directory_at = uint32_t(out.size());
    out += directory;
    put32(out, 0x06054b50);
    put16(out, 0), put16(out, 0), put16(out, uint16_t(members.size())), put16(out, uint16_t(members.size()));
    put32(out, uint32_t(directory.size())), put32(out, directory_at), put16(out, 0);
    return out;
}

std::string npz_bytes(const SampledField& field, const std::string& path, FieldDtype dtype) {
    std::vector<NamedArray> members = grid_arrays(field, dtype, "_");
    for (const VolumeGrid& g : volume_grids(field.lattice)) {
        const double origin[3] = {g.origin.x, g.origin.y, g.origin.z};
        members.push_back({g.part.empty() ? "origin" : "origin_" + g.part, npy_bytes(FieldDtype::Float64, {3}, origin, 3)});
    }
    members.push_back({"spacing", npy_bytes(FieldDtype::Float64, {}, &field.lattice.spacing, 1)});
    members.push_back({"lattice", npy_string(lattice_type_name(field.lattice.type))});
    return zip_stored(path, members);
}

// ---- VTK ImageData XML (.vti), raw appended data ----------------------------------------

std::string number_text(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

/// One appended block: a UInt64 byte count, then the values.
void append_block(std::string& out, FieldDtype dtype, const double* values, size_t count) {
    const uint64_t bytes = count * (dtype == FieldDtype::Float32 ? sizeof(float) : sizeof(double));
    out.append(reinterpret_cast<const char*>(&bytes), sizeof bytes);
    if (dtype == FieldDtype::Float64) {
        out.append(reinterpret_cast<const char*>(values), bytes);
        return;
    }
    for (size_t i = 0; i < count; ++i) {
        const float v = float(values[i]);
        out.append(reinterpret_cast<const char*>(&v), sizeof v);
    }
}

std::string vti_bytes(const SampledField& field, const VolumeGrid& g, FieldDtype dtype) {
    const std::string type = dtype == FieldDtype::Float32 ? "Float32" : "Float64";
    const std::string extent = "0 " + std::to_string(g.resolution.x - 1) + " 0 " + std::to_string(g.resolution.y - 1) +
                               " 0 " + std::to_string(g.resolution.z - 1);
    const std::string h = number_text(g.spacing);
    const size_t n = size_t(g.count());
    const bool gradient = has_gradient(field);
    std::string data = "_";
    append_block(data, dtype, field.distance.data() + g.first, n);
    const size_t gradient_offset = data.size() - 1;
    if (gradient) append_block(data, dtype, &field.gradient[size_t(g.first)].x, 3 * n);

    std::ostringstream x;
    x << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <ImageData WholeExtent=\"" << extent << "\" Origin=\"" << number_text(g.origin.x) << " "
      << number_text(g.origin.y) << " " << number_text(g.origin.z) << "\" Spacing=\"" << h << " " << h << " " << h
      << "\" Direction=\"1 0 0 0 1 0 0 0 1\">\n"
      << "    <Piece Extent=\"" << extent << "\">\n"
      << "      <PointData Scalars=\"distance\"" << (gradient ? " Vectors=\"gradient\"" : "") << ">\n"
      << "        <DataArray type=\"" << type << "\" Name=\"distance\" NumberOfComponents=\"1\" format=\"appended\" offset=\"0\"/>\n";
    if (gradient)
        x << "        <DataArray type=\"" << type << "\" Name=\"gradient\" NumberOfComponents=\"3\" format=\"appended\" offset=\""
          << gradient_offset << "\"/>\n";
    x << "      </PointData>\n      <CellData/>\n    </Piece>\n  </ImageData>\n"
      << "  <AppendedData encoding=\"raw\">\n   ";
    std::string out = x.str();
    out += data;
    out += "\n  </AppendedData>\n</VTKFile>\n";
    return out;
}

// ---- writing --------------------------------------------------------------------------

void check_field(const SampledField& field, const std::string& path) {
    const int64_t points = field.lattice.num_points();
    if (field.size() != points)
        throw std::invalid_argument(path + ": the field holds " + std::to_string(field.size()) +
                                    " distances but its lattice has " + std::to_string(points) + " points");
    if (!field.gradient.empty() && !has_gradient(field))
        throw std::invalid_argument(path + ": the field holds " + std::to_string(field.gradient.size()) +
                                    " gradients but " + std::to_string(points) + " distances");
}

void refuse_existing(const std::vector<std::string>& targets) {
    for (const std::string& t : targets)
        if (fs::exists(t)) throw std::runtime_error(t + ": already exists; refusing to overwrite a field");
}

void write_vdb_atomically(const SampledField& field, const std::string& path, const VolumeWriteOptions& options) {
    if (!(options.vdb_band > 0) || !std::isfinite(options.vdb_band))
        throw std::invalid_argument(path + ": the OpenVDB band must be a positive number of spacings, got " +
                                    number_text(options.vdb_band));
    write_through_temporary(path, options.overwrite,
                            [&](const std::string& temporary) { write_vdb_file(field, temporary, options.vdb_band); });
}

}  // namespace

std::vector<std::string> volume_files(const SampledField& field, const std::string& path, VolumeFormat format) {
    const std::string ext = volume_format_name(format);
    const std::string stem = stem_of(path, ext);
    std::vector<std::string> files;
    switch (format) {
    case VolumeFormat::Vdb:
    case VolumeFormat::Npz:
        files.push_back(stem + "." + ext);
        break;
    case VolumeFormat::Vti:
        for (const VolumeGrid& g : volume_grids(field.lattice)) files.push_back(with_part(stem, g.part) + ".vti");
        break;
    case VolumeFormat::Npy:
        for (const VolumeGrid& g : volume_grids(field.lattice)) {
            files.push_back(with_part(stem, g.part) + ".npy");
            if (has_gradient(field)) files.push_back(with_part(stem, g.part) + ".gradient.npy");
        }
        break;
    }
    return files;
}

std::vector<std::string> write_field_as(const SampledField& field, const std::string& path, VolumeFormat format,
                                        const VolumeWriteOptions& options) {
    check_field(field, path);
    if (!volume_format_available(format))
        throw std::runtime_error(path + ": this build cannot write \"" + volume_format_name(format) +
                                 "\": it was built without OpenVDB (install libopenvdb-dev, scripts/install-deps, "
                                 "and configure again)");
    const std::vector<std::string> files = volume_files(field, path, format);
    if (options.overwrite == Overwrite::Forbid) refuse_existing(files);
    std::vector<std::string> written;
    try {
        switch (format) {
        case VolumeFormat::Vdb:
            write_vdb_atomically(field, files[0], options);
            written.push_back(files[0]);
            break;
        case VolumeFormat::Npz: {
            const std::string bytes = npz_bytes(field, files[0], options.dtype);
            write_file_atomically(files[0], bytes.data(), bytes.size(), options.overwrite);
            written.push_back(files[0]);
            break;
        }
        case VolumeFormat::Vti: {
            const std::vector<VolumeGrid> grids = volume_grids(field.lattice);
            for (size_t i = 0; i < grids.size(); ++i) {
                const std::string bytes = vti_bytes(field, grids[i], options.dtype);
                write_file_atomically(files[i], bytes.data(), bytes.size(), options.overwrite);
                written.push_back(files[i]);
            }
            break;
        }
        case VolumeFormat::Npy: {
            // grid_arrays lists each grid's distance, then its gradient: the order of files.
            const std::vector<NamedArray> arrays = grid_arrays(field, options.dtype, ".");
            for (size_t i = 0; i < arrays.size(); ++i) {
                write_file_atomically(files[i], arrays[i].bytes.data(), arrays[i].bytes.size(), options.overwrite);
                written.push_back(files[i]);
            }
            break;
        }
        }
    } catch (...) {
        if (options.overwrite == Overwrite::Forbid)  // all new: leave none behind
            for (const std::string& f : written) {
                std::error_code ec;
                fs::remove(f, ec);
            }
        throw;
    }
    return written;
}

#if !SDF_HAVE_OPENVDB
void write_vdb_file(const SampledField&, const std::string& path, double) {
    throw std::runtime_error(path + ": this build has no OpenVDB support (libopenvdb-dev)");
}

struct VdbNarrowBandBuilder::Grids {};
VdbNarrowBandBuilder::VdbNarrowBandBuilder(const Lattice&, double, bool) {
    throw std::runtime_error(".vdb output: this build has no OpenVDB support (libopenvdb-dev)");
}
VdbNarrowBandBuilder::~VdbNarrowBandBuilder() = default;
void VdbNarrowBandBuilder::add(const SampledField&, int64_t, int64_t, int64_t) {}
void VdbNarrowBandBuilder::write(const std::string&) {}
#endif

}  // namespace sdf
