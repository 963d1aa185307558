#include "harness/io/field_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <type_traits>

#include "core/lattice/lattice_fitting.h"
#include "harness/config/json_reader.h"
#include "harness/io/field_replacement.h"

namespace sdf {
namespace fs = std::filesystem;

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "field files are little-endian; add byte swapping");

namespace {

std::string stem_of_header(const std::string& header_path) {
    const std::string suffix = ".json";
    if (header_path.size() > suffix.size() && header_path.compare(header_path.size() - suffix.size(), suffix.size(), suffix) == 0)
        return header_path.substr(0, header_path.size() - suffix.size());
    return header_path;
}

template <typename Out, typename In>
std::vector<Out> convert_all(const In* in, size_t n) {
    std::vector<Out> out(n);
    for (size_t i = 0; i < n; ++i) out[i] = Out(in[i]);
    return out;
}

std::vector<char> read_bytes(const std::string& path, size_t expected, const std::string& header) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (!fs::exists(st)) throw std::runtime_error(header + ": channel file " + path + " not found");
    if (fs::is_directory(st)) throw std::runtime_error(header + ": channel file " + path + " is a directory, not a regular file");
    if (!fs::is_regular_file(st)) throw std::runtime_error(header + ": channel file " + path + " is not a regular file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(header + ": channel file " + path + " cannot be opened");
    const size_t size = size_t(fs::file_size(path));
    if (size != expected)
        throw std::runtime_error(header + ": channel file " + path + " holds " + std::to_string(size) +
                                 " bytes; the header's lattice and dtype need " + std::to_string(expected));
    std::vector<char> bytes(size);
    in.read(bytes.data(), std::streamsize(size));
    if (!in) throw std::runtime_error(header + ": channel file " + path + ": read failed");
    return bytes;
}

/// Reads a channel as doubles (float32, float64 or int32 on disk).
std::vector<double> read_channel(const std::string& header_path, JsonReader& channels, const std::string& name,
                                 int64_t points, int components) {
    JsonReader ch = channels.object(name);
    const std::string file = ch.required<std::string>("file", "a file name relative to the header");
    const std::string dtype = ch.choice("dtype", {"float32", "float64", "int32"}, "float32");
    const int comps = ch.optional<int>("components", 1, "the number of components (1 or 3)");
    ch.finish({"description", "units"});
    if (comps != components)
        ch.fail("components", "expected " + std::to_string(components) + " for channel '" + name + "', got " +
                                  std::to_string(comps));
    const size_t n = size_t(points) * size_t(components);
    const size_t width = dtype == "float64" ? 8 : 4;
    const fs::path path = fs::path(header_path).parent_path() / file;
    const std::vector<char> bytes = read_bytes(path.string(), n * width, header_path);
    if (dtype == "float32") return convert_all<double>(reinterpret_cast<const float*>(bytes.data()), n);
    if (dtype == "int32") return convert_all<double>(reinterpret_cast<const int32_t*>(bytes.data()), n);
    return convert_all<double>(reinterpret_cast<const double*>(bytes.data()), n);
}

}  // namespace

nlohmann::json lattice_to_json(const Lattice& l) {
    const int z = l.type == LatticeType::BCC ? 2 * l.resolution.z : l.resolution.z;
    return {{"type", lattice_type_name(l.type)},
            {"origin", {l.origin.x, l.origin.y, l.origin.z}},
            {"spacing", l.spacing},
            {"resolution", {l.resolution.x, l.resolution.y, z}},
            {"notation", lattice_notation(l)},
            {"points", l.num_points()}};
}

Lattice lattice_from_json(const nlohmann::json& j, const std::string& file, LatticeStorage storage) {
    JsonReader r(j, file, "lattice");
    Lattice l;
    l.type = lattice_type_named(r.choice("type", lattice_type_names(), lattice_type_name(LatticeType::CC)));
    const auto origin = r.required<std::vector<double>>("origin", "an array of 3 numbers");
    l.spacing = r.required<double>("spacing", "a positive number");
    const auto res = r.required<std::vector<int>>("resolution", "an array of 3 positive integers");
    if (origin.size() != 3) r.fail("origin", "expected an array of 3 numbers, got " + r.raw("origin").dump());
    if (res.size() != 3 || *std::min_element(res.begin(), res.end()) < 1)
        r.fail("resolution", "expected an array of 3 positive integers, got " + r.raw("resolution").dump());
    // Not subnormal: positions divide by the spacing, and 1/h must stay finite.
    if (!(l.spacing >= std::numeric_limits<double>::min()) || !std::isfinite(l.spacing))
        r.fail("spacing", "expected a positive number (finite, not subnormal), got " + r.raw("spacing").dump());
    l.origin = {origin[0], origin[1], origin[2]};
    l.resolution = {res[0], res[1], res[2]};
    if (l.type == LatticeType::BCC) {
        if (res[2] % 2 != 0)
            r.fail("resolution", "BCC resolution is [Rx, Ry, 2Rz]; the third entry must be even, got " +
                                     r.raw("resolution").dump());
        l.resolution.z = res[2] / 2;
    }
    // Checked before any channel size is computed from it (points x components x bytes).
    try {
        checked_lattice_points(l.type, l.resolution, storage);
    } catch (const std::invalid_argument& e) {
        r.fail("resolution", e.what());
    }
    for (const Vec3d& corner : {l.domain_min(), l.domain_max()})
        if (!std::isfinite(corner.x) || !std::isfinite(corner.y) || !std::isfinite(corner.z))
            r.fail("origin", "the lattice's far corner (origin + spacing x (resolution - 1)) is not finite: origin " +
                                 r.raw("origin").dump() + ", spacing " + r.raw("spacing").dump());
    r.finish({"notation", "points"});
    return l;
}

namespace {

/// The header of `field`, whose channel files are described by `channels`.
nlohmann::json field_header(const SampledField& field, const nlohmann::json& channels) {
    nlohmann::json header = {{"format", "sdf-lattice-field"},
                             {"version", 1},
                             {"lattice", lattice_to_json(field.lattice)},
                             {"channels", channels},
                             {"value_channel", "distance"},
                             {"units", "mesh units; distance negative inside"},
                             {"precision", precision_name(field.precision)},
                             {"mesh", field.mesh},
                             {"sampler", field.sampler},
                             {"timings_seconds", {{"total", field.timings.total},
                                                  {"kernel", field.timings.kernel},
                                                  {"upload", field.timings.upload},
                                                  {"download", field.timings.download}}},
                             {"point_triangle_pairs", field.timings.point_triangle_pairs}};
    if (channels.contains("gradient")) header["gradient_channel"] = "gradient";
    return header;
}

}  // namespace

size_t FieldChannelFile::bytes_per_point() const {
    const size_t width = name == "closest_triangle" ? sizeof(int32_t) : dtype == FieldDtype::Float32 ? sizeof(float) : sizeof(double);
    return width * size_t(components);
}

std::vector<FieldChannelFile> field_channel_files(const std::string& header_path, const SampledField& field,
                                                  const FieldWriteOptions& options) {
    const std::string stem = stem_of_header(header_path);
    const size_t n = size_t(field.size());
    std::vector<FieldChannelFile> files = {{"distance", stem + ".distance.raw", options.dtype, 1}};
    if (!field.gradient.empty() && field.gradient.size() == n)
        files.push_back({"gradient", stem + ".gradient.raw", options.dtype, 3});
    if (options.closest_triangle && field.closest_triangle.size() == n)
        files.push_back({"closest_triangle", stem + ".closest_triangle.raw", options.dtype, 1});
    return files;
}

std::vector<char> field_channel_bytes(const SampledField& field, const FieldChannelFile& channel, size_t first,
                                      size_t count) {
    std::vector<char> bytes(count * channel.bytes_per_point());
    auto store = [&](const auto* values, auto as) {  // values[first*c .. (first+count)*c) as the stored type
        using Stored = decltype(as);
        const size_t c = size_t(channel.components), at = first * c;
        if constexpr (std::is_same_v<Stored, std::remove_const_t<std::remove_pointer_t<decltype(values)>>>) {
            if (count > 0) std::memcpy(bytes.data(), values + at, count * c * sizeof(Stored));  // stored as held
        } else {
            for (size_t i = 0; i < count * c; ++i) {
                if constexpr (std::is_same_v<Stored, float>)
                    if (std::abs(values[at + i]) > double(std::numeric_limits<float>::max()) && std::isfinite(values[at + i])) {
                        char value[32];  // %.6g: 1e300 as "1e+300", not its 301 digits
                        std::snprintf(value, sizeof value, "%.6g", double(values[at + i]));
                        throw std::range_error(channel.path + ": value " + value + " of point " +
                                               std::to_string((at + i) / c) + " is beyond float32's range (3.40282e+38); "
                                               "write float64");
                    }
                const Stored v = Stored(values[at + i]);
                std::memcpy(bytes.data() + i * sizeof(Stored), &v, sizeof(Stored));
            }
        }
    };
    const double* values = channel.name == "distance" ? field.distance.data()
                           : channel.name == "gradient" ? &field.gradient[0].x : nullptr;
    if (channel.name == "closest_triangle") store(field.closest_triangle.data(), int32_t());
    else if (values == nullptr) throw std::invalid_argument("field_channel_bytes: unknown channel " + channel.name);
    else if (channel.dtype == FieldDtype::Float32) store(values, float());
    else store(values, double());
    return bytes;
}

void write_field_header(const std::string& header_path, const SampledField& field,
                        const std::vector<FieldChannelFile>& files, Overwrite overwrite) {
    nlohmann::json channels = nlohmann::json::object();
    for (const FieldChannelFile& f : files) {
        const std::string dtype = f.name == "closest_triangle" ? "int32" : f.dtype == FieldDtype::Float32 ? "float32" : "float64";
        channels[f.name] = {{"file", fs::path(f.path).filename().string()}, {"dtype", dtype}, {"components", f.components}};
    }
    write_text_atomically(stem_of_header(header_path) + ".json", field_header(field, channels).dump(2) + "\n", overwrite);
}

void write_field(const std::string& header_path, const SampledField& field, const FieldWriteOptions& options) {
    const std::string header = stem_of_header(header_path) + ".json";
    const fs::path parent = fs::path(header).parent_path();
    if (!parent.empty()) fs::create_directories(parent);
    // Every target is checked, and the channels' names chosen, before anything is written
    // (field_replacement.h): the header is written last, over the old one in one step.
    require_storable(field, options, header);
    FieldReplacement replacement(header, field_channel_files(header_path, field, options), options.overwrite);
    for (size_t i = 0; i < replacement.channels().size(); ++i) {
        const FieldChannelFile& f = replacement.channels()[i];
        const size_t bytes = size_t(field.size()) * f.bytes_per_point();
        // Channels stored as held (float64, int32) are written from the field's arrays,
        // without a copy: the same bytes as field_channel_bytes. The names are new: no replace.
        if (f.name == "closest_triangle") {
            write_file_atomically(f.path, field.closest_triangle.data(), bytes, Overwrite::Forbid);
        } else if (f.dtype == FieldDtype::Float64) {
            const double* values = f.name == "distance" ? field.distance.data() : &field.gradient[0].x;
            write_file_atomically(f.path, values, bytes, Overwrite::Forbid);
        } else {
            const std::vector<char> converted = field_channel_bytes(field, f, 0, size_t(field.size()));
            write_file_atomically(f.path, converted.data(), converted.size(), Overwrite::Forbid);
        }
        replacement.placed(i);
    }
    replacement.commit(field);
}

void require_representable_band(double w, FieldDtype dtype, const std::string& what) {
    if (w == 0) return;
    const bool f32 = dtype == FieldDtype::Float32;
    const double least = f32 ? double(std::numeric_limits<float>::min()) : std::numeric_limits<double>::min();
    const double most = f32 ? double(std::numeric_limits<float>::max()) : std::numeric_limits<double>::max();
    if (w >= least && w <= most) return;
    char text[160];
    std::snprintf(text, sizeof text, "%.6g cannot be stored in %s (its positive normal values are %.6g to %.6g)", w,
                  f32 ? "float32" : "float64", least, most);
    throw std::invalid_argument(what + ": " + text + (f32 ? "; choose a band in that range, or float64 output" : ""));
}

void require_storable(const SampledField& field, const FieldWriteOptions& options, const std::string& header_path) {
    if (field.sampler.band)
        require_representable_band(field.sampler.band->width, options.dtype, header_path + ": the narrow band width");
}

SampledField read_field(const std::string& header_path) {
    const nlohmann::json j = read_json_file(header_path, "field header");
    JsonReader r(j, header_path);
    const std::string format = r.required<std::string>("format", "\"sdf-lattice-field\"");
    if (format != "sdf-lattice-field") r.fail("format", "expected \"sdf-lattice-field\", got \"" + format + "\"");
    const int version = r.required<int>("version", "the format version 1");
    if (version != 1) r.fail("version", "only version 1 is known, got " + std::to_string(version));
    if (r.has("layout") && r.choice("layout", {"dense", "sparse_band"}, "dense") != "dense")
        r.fail("layout", "this is a sparse band's file (\"sparse_band\", docs/field-format.md): read_sparse_field "
                         "(harness/io/sparse_field_file.h) reads it; sdf-eval, sdf-render and Python's read_field read both");
    SampledField field;
    field.lattice = lattice_from_json(r.raw("lattice"), header_path);
    const int64_t points = field.lattice.num_points();
    JsonReader channels = r.object("channels");
    const std::string value = r.optional<std::string>("value_channel", "value", "the name of the scalar channel");
    if (!channels.has(value)) r.fail("value_channel", "names channel '" + value + "', which 'channels' lacks");
    field.distance = read_channel(header_path, channels, value, points, 1);
    if (r.has("gradient_channel")) {
        const std::string g = r.required<std::string>("gradient_channel", "the name of a 3-component channel");
        const std::vector<double> grad = read_channel(header_path, channels, g, points, 3);
        field.gradient.resize(size_t(points));
        for (size_t i = 0; i < field.gradient.size(); ++i)
            field.gradient[i] = {grad[3 * i], grad[3 * i + 1], grad[3 * i + 2]};
    }
    if (channels.has("closest_triangle")) {
        const std::vector<double> tri = read_channel(header_path, channels, "closest_triangle", points, 1);
        field.closest_triangle = convert_all<int32_t>(tri.data(), tri.size());
    }
    if (r.has("precision")) field.precision = r.raw("precision") == "double" ? Precision::Double : Precision::Float;
    try {  // the typed records (mesh_provenance.h, sampler_report.h)
        if (r.has("mesh")) field.mesh = r.raw("mesh").get<MeshProvenance>();
        if (r.has("sampler")) field.sampler = r.raw("sampler").get<SamplerReport>();
    } catch (const std::runtime_error& e) {
        throw std::runtime_error(header_path + ": " + e.what());
    }
    // Other provenance keys are free-form; other channels are allowed and ignored.
    return field;
}

void export_nrrd(const std::string& path, const SampledField& field, bool with_gradient, Overwrite overwrite) {
    const Lattice& l = field.lattice;
    if (l.type != LatticeType::CC)
        throw std::invalid_argument(path + ": NRRD export needs a CC lattice (BCC has no NRRD layout)");
    auto write_volume = [&](const std::string& file, const std::vector<float>& data, int components) {
        std::ostringstream h;
        h << "NRRD0004\n# exported by sdf_lattices\ntype: float\n";
        h << "dimension: " << (components == 1 ? 3 : 4) << "\nspace: 3D-right-handed\nsizes: ";
        if (components > 1) h << components << " ";
        h << l.resolution.x << " " << l.resolution.y << " " << l.resolution.z << "\n";
        h.precision(17);
        h << "space directions: " << (components > 1 ? "none " : "") << "(" << l.spacing << ",0,0) (0," << l.spacing
          << ",0) (0,0," << l.spacing << ")\n";
        if (components > 1) h << "kinds: vector domain domain domain\n";
        h << "space origin: (" << l.origin.x << "," << l.origin.y << "," << l.origin.z << ")\n";
        h << "endian: little\nencoding: raw\n\n";
        std::string bytes = h.str();
        bytes.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(float));
        write_file_atomically(file, bytes.data(), bytes.size(), overwrite);
    };
    write_volume(path, convert_all<float>(field.distance.data(), field.distance.size()), 1);
    if (with_gradient && !field.gradient.empty()) {
        const std::string stem = path.size() > 5 && path.substr(path.size() - 5) == ".nrrd" ? path.substr(0, path.size() - 5) : path;
        write_volume(stem + ".gradient.nrrd", convert_all<float>(&field.gradient[0].x, 3 * field.gradient.size()), 3);
    }
}

double export_uint8(const std::string& path, const SampledField& field, Overwrite overwrite) {
    double max_abs = 0;
    for (double d : field.distance) max_abs = std::max(max_abs, std::abs(d));
    const double scale = max_abs > 0 ? 127.0 / max_abs : 1.0;
    std::vector<uint8_t> bytes(field.distance.size());
    for (size_t i = 0; i < bytes.size(); ++i)
        bytes[i] = uint8_t(std::clamp(std::lround(127.0 - field.distance[i] * scale), 0L, 255L));
    write_file_atomically(path, bytes.data(), bytes.size(), overwrite);
    return scale;
}

}  // namespace sdf
