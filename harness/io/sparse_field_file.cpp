#include "harness/io/sparse_field_file.h"

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include "core/checked_math.h"
#include "core/lattice/lattice_fitting.h"
#include "core/parallel/parallel_for.h"
#include "harness/config/json_reader.h"
#include "harness/io/field_replacement.h"
#include "harness/resources/memory_budget.h"

namespace sdf {
namespace fs = std::filesystem;

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "field files are little-endian; add byte swapping");

namespace {

constexpr int kSignWords = kBandBlockPoints / 64;  // words of a mixed block's BandSignMask
constexpr int64_t kChunk = int64_t(1) << 20;       // elements converted per read
constexpr int64_t kWriteChunk = int64_t(1) << 22;  // per write: each converted on every core

std::string header_of(const std::string& path) {
    return path.size() > 5 && path.compare(path.size() - 5, 5, ".json") == 0 ? path : path + ".json";
}

/// One channel's layout: its name, stored element type and components per element.
struct SparseChannel {
    const char* name;
    const char* dtype;  ///< "float32", "float64", "int32", "int64", "uint64"
    int components;
};

size_t dtype_bytes(const std::string& dtype) { return dtype == "float32" || dtype == "int32" ? 4 : 8; }

/// Writes `count` elements, each `components` values, to a temporary beside channel i's
/// final path, `fill(first, n, out)` storing elements [first, first + n) as bytes; fsyncs
/// it and places it (field_replacement.h).
template <typename Fill>
void write_channel(FieldReplacement& replacement, size_t i, const SparseChannel& c, int64_t count, Fill fill) {
    const std::string path = replacement.channels()[i].path;
    const std::string tmp = unique_sibling_name(path, "tmp");
    const size_t element = dtype_bytes(c.dtype) * size_t(c.components);
    try {
        {
            std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
            if (!out) throw std::runtime_error(path + ": cannot open " + tmp + " for writing");
            std::vector<char> bytes;
            for (int64_t first = 0; first < count; first += kWriteChunk) {
                const int64_t n = std::min(kWriteChunk, count - first);
                bytes.resize(size_t(n) * element);
                fill(first, n, bytes.data());
                out.write(bytes.data(), std::streamsize(bytes.size()));
                if (!out) throw std::runtime_error(path + ": write failed (disk full?)");
            }
            out.close();
            if (!out) throw std::runtime_error(path + ": write failed on closing");
        }
        sync_file(tmp);
        replacement.place(i, tmp);
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
}

/// Stores doubles as float32 or float64, refusing a finite value beyond float32's range (the
/// first such value, whatever the thread count). Converted on every core: at 8192^3 a band's
/// distances are 4.2G values. Floats (a band held in float32) are stored as they are, in
/// float32 only (the caller refused float64 for them).
template <typename Real>
void store_reals(const Real* values, size_t n, FieldDtype dtype, char* out, const std::string& channel, int64_t first) {
    if (sizeof(Real) == (dtype == FieldDtype::Float32 ? sizeof(float) : sizeof(double))) {
        std::memcpy(out, values, n * sizeof(Real));
        return;
    }
    if constexpr (std::is_same_v<Real, float>) throw std::logic_error(channel + ": float32 values written as float64");
    std::atomic<size_t> beyond{n};  // the first value beyond float32's range
    parallel_for(int64_t(n), 1 << 16, 0, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i) {
            const double v = values[size_t(i)];
            if (std::abs(v) > double(std::numeric_limits<float>::max()) && std::isfinite(v)) {
                for (size_t seen = beyond.load(); size_t(i) < seen && !beyond.compare_exchange_weak(seen, size_t(i));) {
                }
                return;
            }
            const float f = float(v);
            std::memcpy(out + size_t(i) * sizeof(float), &f, sizeof(float));
        }
    });
    if (const size_t i = beyond.load(); i < n) {
        char text[32];
        std::snprintf(text, sizeof text, "%.6g", values[i]);
        throw std::range_error(channel + ": value " + text + " (value " + std::to_string(first + int64_t(i)) +
                               " of the channel) is beyond float32's range (3.40282e+38); write float64");
    }
}

nlohmann::json sparse_header(const SparseBandField& band, const nlohmann::json& channels) {
    const SparseBandCounts c = band.counts();
    nlohmann::json header = {{"format", "sdf-lattice-field"},
                             {"version", 1},
                             {"layout", kSparseBandLayout},
                             {"lattice", lattice_to_json(band.lattice)},
                             {"band", {{"width", band.width},
                                       {"block_points", {kBandBlockDim, kBandBlockDim, kBandBlockDim}},
                                       {"blocks", c.blocks},
                                       {"active_blocks", c.active_blocks},
                                       {"mixed_blocks", c.mixed_blocks},
                                       {"tiles", c.tiles},
                                       {"inside_tiles", c.inside_tiles},
                                       {"active_points", c.active_points},
                                       {"band_points", c.band_points}}},
                             {"channels", channels},
                             {"value_channel", "distance"},
                             {"units", "mesh units; distance negative inside"},
                             {"precision", precision_name(band.precision)},
                             {"mesh", band.mesh},
                             {"sampler", band.sampler},
                             {"timings_seconds", {{"total", band.timings.total},
                                                  {"kernel", band.timings.kernel},
                                                  {"upload", band.timings.upload},
                                                  {"download", band.timings.download}}}};
    if (channels.contains("gradient")) header["gradient_channel"] = "gradient";
    return header;
}

}  // namespace

void write_sparse_field(const std::string& header_path, const SparseBandField& band, const SparseFieldWriteOptions& options) {
    const std::string header = header_of(header_path);
    const std::string stem = header.substr(0, header.size() - 5);
    const fs::path parent = fs::path(header).parent_path();
    if (!parent.empty()) fs::create_directories(parent);
    require_representable_band(band.width, options.dtype, header + ": the narrow band width");
    const int64_t points = int64_t(band.active.size()) * kBandBlockPoints;
    const bool gradient = options.gradient;
    // A band held in float32 is written in float32 only: float64 would claim digits it lacks.
    band.require_channels({gradient, false, options.dtype == FieldDtype::Float32 ? BandDistanceType::Float32 : BandDistanceType::Float64},
                          header + ": the gradient channel and the distances' dtype");
    if (band.mixed_inside.size() != band.mixed.size() ||
        band.inside_tiles.size() != size_t((band.layout().block_count() + 63) / 64))
        throw std::invalid_argument(header + ": the sparse band's arrays do not match its " + std::to_string(band.active.size()) +
                                    " active and " + std::to_string(band.mixed.size()) + " mixed blocks");
    const char* real = options.dtype == FieldDtype::Float32 ? "float32" : "float64";
    std::vector<SparseChannel> layout = {{"active_blocks", "int64", 1}, {"distance", real, 1}};
    if (gradient) layout.push_back({"gradient", real, 3});
    // The band's points: its closest triangles where held (kOutsideBandTriangle off the
    // band), else its mask (sparse_band.h's band_mask).
    if (band.channels.closest_triangle) layout.push_back({"closest_triangle", "int32", 1});
    else layout.push_back({"band_points", "uint64", kSignWords});
    layout.push_back({"tile_signs", "uint64", 1});
    layout.push_back({"mixed_blocks", "int64", 1});
    layout.push_back({"mixed_signs", "uint64", kSignWords});
    std::vector<FieldChannelFile> files;
    for (const SparseChannel& c : layout) files.push_back({c.name, stem + "." + c.name + ".raw", options.dtype, c.components});
    FieldReplacement replacement(header, files, options.overwrite);
    for (size_t i = 0; i < layout.size(); ++i) {
        const SparseChannel& c = layout[i];
        const std::string name = c.name;
        const std::string& path = replacement.channels()[i].path;
        if (name == "active_blocks" || name == "mixed_blocks") {
            const std::vector<int64_t>& ids = name == "active_blocks" ? band.active : band.mixed;
            write_channel(replacement, i, c, int64_t(ids.size()), [&](int64_t first, int64_t n, char* out) {
                std::memcpy(out, ids.data() + first, size_t(n) * sizeof(int64_t));
            });
        } else if (name == "distance") {
            write_channel(replacement, i, c, points, [&](int64_t first, int64_t n, char* out) {
                band.distance.visit([&](const auto* d) { store_reals(d + first, size_t(n), options.dtype, out, path, first); });
            });
        } else if (name == "gradient") {
            write_channel(replacement, i, c, points, [&](int64_t first, int64_t n, char* out) {
                store_reals(&band.gradient[size_t(first)].x, 3 * size_t(n), options.dtype, out, path, 3 * first);
            });
        } else if (name == "closest_triangle") {
            write_channel(replacement, i, c, points, [&](int64_t first, int64_t n, char* out) {
                std::memcpy(out, band.closest_triangle.data() + first, size_t(n) * sizeof(int32_t));
            });
        } else if (name == "band_points") {
            write_channel(replacement, i, c, int64_t(band.band_mask.size()), [&](int64_t first, int64_t n, char* out) {
                std::memcpy(out, band.band_mask.data() + first, size_t(n) * sizeof(BandPointMask));
            });
        } else if (name == "tile_signs") {
            // Only tiles' bits mean something (sparse_band.h): active and mixed blocks' are cleared.
            std::vector<uint64_t> words = band.inside_tiles;
            for (const std::vector<int64_t>* ids : {&band.active, &band.mixed})
                for (int64_t id : *ids) words[size_t(id >> 6)] &= ~(uint64_t(1) << (id & 63));
            write_channel(replacement, i, c, int64_t(words.size()), [&](int64_t first, int64_t n, char* out) {
                std::memcpy(out, words.data() + first, size_t(n) * sizeof(uint64_t));
            });
        } else {  // mixed_signs
            write_channel(replacement, i, c, int64_t(band.mixed_inside.size()), [&](int64_t first, int64_t n, char* out) {
                std::memcpy(out, band.mixed_inside.data() + first, size_t(n) * sizeof(BandSignMask));
            });
        }
    }
    replacement.commit_with([&](const std::vector<FieldChannelFile>& placed) {
        nlohmann::json channels = nlohmann::json::object();
        for (size_t i = 0; i < placed.size(); ++i) {
            nlohmann::json ch = {{"file", fs::path(placed[i].path).filename().string()}, {"dtype", layout[i].dtype}};
            if (layout[i].components != 1) ch["components"] = layout[i].components;
            channels[layout[i].name] = ch;
        }
        write_text_atomically(header, sparse_header(band, channels).dump(2) + "\n", options.overwrite);
    });
}

namespace {

/// A channel of a sparse header, opened: its file checked to hold exactly `count` elements
/// of `components` values of its dtype (one of `dtypes`) before anything is allocated.
struct OpenChannel {
    std::string path, dtype;
    std::ifstream in;
};

OpenChannel open_channel(const std::string& header, JsonReader& channels, const std::string& name, int64_t count,
                         int components, const std::vector<std::string>& dtypes) {
    JsonReader ch = channels.object(name);
    OpenChannel c;
    const std::string file = ch.required<std::string>("file", "a file name relative to the header");
    c.dtype = ch.choice("dtype", dtypes, dtypes.front());
    const int comps = ch.optional<int>("components", 1, "the number of components");
    ch.finish({"description", "units"});
    if (comps != components)
        ch.fail("components", "expected " + std::to_string(components) + " for channel '" + name + "', got " + std::to_string(comps));
    c.path = (fs::path(header).parent_path() / file).string();
    std::error_code ec;
    const fs::file_status st = fs::status(c.path, ec);
    if (!fs::exists(st)) throw std::runtime_error(header + ": channel '" + name + "': file " + c.path + " not found");
    if (!fs::is_regular_file(st)) throw std::runtime_error(header + ": channel '" + name + "': " + c.path + " is not a regular file");
    const uint64_t size = fs::file_size(c.path, ec);
    if (ec) throw std::runtime_error(header + ": channel '" + name + "': cannot read the size of " + c.path + ": " + ec.message());
    const std::optional<int64_t> expected = checked_mul(count, int64_t(components), int64_t(dtype_bytes(c.dtype)));
    if (!expected || size != uint64_t(*expected))
        throw std::runtime_error(header + ": channel '" + name + "': " + c.path + " holds " + std::to_string(size) +
                                 " bytes; the header's band needs " + std::to_string(count) + " x " + std::to_string(components) +
                                 " " + c.dtype + " = " + (expected ? std::to_string(*expected) : "too many") + " bytes");
    c.in.open(c.path, std::ios::binary);
    if (!c.in) throw std::runtime_error(header + ": channel '" + name + "': " + c.path + " cannot be opened");
    return c;
}

/// Reads n values of the channel's dtype into `out` (as Held), in chunks.
template <typename Held>
void read_values(OpenChannel& c, Held* out, int64_t n, const std::string& header) {
    const size_t width = dtype_bytes(c.dtype);
    std::vector<char> bytes;
    for (int64_t first = 0; first < n; first += kChunk) {
        const int64_t m = std::min(kChunk, n - first);
        bytes.resize(size_t(m) * width);
        c.in.read(bytes.data(), std::streamsize(bytes.size()));
        if (!c.in) throw std::runtime_error(header + ": " + c.path + ": read failed");
        // The dtype is decided once per chunk, not per value (a 2048^3 band holds 10^8 values).
        const auto convert = [&](auto stored) {
            using Stored = decltype(stored);
            for (int64_t i = 0; i < m; ++i) {
                std::memcpy(&stored, bytes.data() + size_t(i) * sizeof(Stored), sizeof(Stored));
                out[first + i] = Held(stored);
            }
        };
        if (c.dtype == "float32") convert(float{});
        else if (c.dtype == "float64") convert(double{});
        else if (c.dtype == "int32") convert(int32_t{});
        else if (c.dtype == "int64") convert(int64_t{});
        else convert(uint64_t{});
    }
}

/// Block ids strictly ascending within [0, blocks).
void require_block_ids(const std::vector<int64_t>& ids, int64_t blocks, const std::string& header, const std::string& name) {
    for (size_t i = 0; i < ids.size(); ++i) {
        if (ids[i] < 0 || ids[i] >= blocks)
            throw std::runtime_error(header + ": channel '" + name + "': block id " + std::to_string(ids[i]) + " (entry " +
                                     std::to_string(i) + ") is not a block of the lattice's " + std::to_string(blocks));
        if (i > 0 && !(ids[i] > ids[i - 1]))
            throw std::runtime_error(header + ": channel '" + name + "': block ids must ascend; entry " + std::to_string(i) +
                                     " (" + std::to_string(ids[i]) + ") follows " + std::to_string(ids[i - 1]));
    }
}

}  // namespace

bool is_sparse_field_header(const nlohmann::json& j) {
    return j.is_object() && j.contains("layout") && j["layout"] == kSparseBandLayout;  // else read_field's messages
}

bool is_sparse_field_file(const std::string& header_path) {
    return is_sparse_field_header(read_json_file(header_path, "field header"));
}

SparseBandField read_sparse_field(const std::string& header_path) {
    return read_sparse_field(header_path, read_json_file(header_path, "field header"));
}

SparseBandField read_sparse_field(const std::string& header_path, const nlohmann::json& j) {
    const std::string& header = header_path;
    JsonReader r(j, header);
    const std::string format = r.required<std::string>("format", "\"sdf-lattice-field\"");
    if (format != "sdf-lattice-field") r.fail("format", "expected \"sdf-lattice-field\", got \"" + format + "\"");
    const int version = r.required<int>("version", "the format version 1");
    if (version != 1) r.fail("version", "only version 1 is known, got " + std::to_string(version));
    const std::string layout = r.required<std::string>("layout", "\"" + std::string(kSparseBandLayout) + "\"");
    if (layout != kSparseBandLayout)
        r.fail("layout", "expected \"" + std::string(kSparseBandLayout) + "\" (a sparse band's file), got \"" + layout + "\"");
    const Lattice lattice = lattice_from_json(r.raw("lattice"), header, LatticeStorage::SparseBand);
    JsonReader b = r.object("band");
    const double width = b.required<double>("width", "the band's width W > 0, mesh units");
    if (!(width > 0) || !std::isfinite(width)) b.fail("width", "expected a finite band width > 0, got " + b.raw("width").dump());
    const std::vector<int> block_points = b.optional<std::vector<int>>("block_points", {8, 8, 8}, "[8, 8, 8]");
    if (block_points != std::vector<int>{kBandBlockDim, kBandBlockDim, kBandBlockDim})
        b.fail("block_points", "only blocks of [8, 8, 8] points are known, got " + b.raw("block_points").dump());
    Precision precision = Precision::Float;
    if (r.has("precision")) {
        const std::string p = r.choice("precision", {"float", "double"}, "float");
        precision = p == "double" ? Precision::Double : Precision::Float;
    }
    try {
        require_band_width(width, "sparse band width");
    } catch (const std::invalid_argument& e) {
        b.fail("width", e.what());
    }
    const int64_t blocks = BandLayout(lattice).block_count();  // nothing allocated before the files are checked
    const int64_t stated = b.required<int64_t>("blocks", "the lattice's number of blocks");
    if (stated != blocks)
        b.fail("blocks", "expected " + std::to_string(blocks) + " (blocks of 8^3 points of " + lattice_notation(lattice) +
                             "), got " + std::to_string(stated));
    const int64_t active = b.required<int64_t>("active_blocks", "the number of active blocks");
    if (active < 0 || active > blocks)
        b.fail("active_blocks", "expected 0 to " + std::to_string(blocks) + " blocks, got " + std::to_string(active));
    const int64_t mixed = b.required<int64_t>("mixed_blocks", "the number of mixed blocks");
    if (mixed < 0 || mixed > blocks - active)
        b.fail("mixed_blocks", "expected 0 to " + std::to_string(blocks - active) + " blocks (those not active), got " +
                                   std::to_string(mixed));
    b.finish({"tiles", "inside_tiles", "active_points", "band_points"});  // counts for people, recomputed
    const int64_t points = active * kBandBlockPoints;

    JsonReader channels = r.object("channels");
    const std::string value = r.optional<std::string>("value_channel", "distance", "\"distance\"");
    if (value != "distance") r.fail("value_channel", "a sparse band's values are its channel \"distance\", got \"" + value + "\"");
    const bool has_gradient = r.has("gradient_channel");
    if (has_gradient) {
        const std::string g = r.required<std::string>("gradient_channel", "\"gradient\"");
        if (g != "gradient") r.fail("gradient_channel", "a sparse band's gradient is its channel \"gradient\", got \"" + g + "\"");
    }
    // Every channel's size is checked before any is read.
    OpenChannel ids = open_channel(header, channels, "active_blocks", active, 1, {"int64"});
    OpenChannel dist = open_channel(header, channels, "distance", points, 1, {"float32", "float64"});
    // A float32 file's +-W must be a float32 W (neither 0 nor infinite), as its writers required.
    if (dist.dtype == "float32") require_representable_band(width, FieldDtype::Float32, header + ": key 'band.width'");
    std::optional<OpenChannel> grad;
    if (has_gradient) grad = open_channel(header, channels, "gradient", points, 3, {"float32", "float64"});
    // The band's points: by their closest triangles, or by their mask (a band without triangles).
    const bool has_triangle = channels.has("closest_triangle");
    if (has_triangle == channels.has("band_points"))
        throw std::runtime_error(header + ": key 'channels': expected exactly one of the channels 'closest_triangle' (int32, 512 "
                                          "per active block) and 'band_points' (uint64, 8 per active block), which mark the "
                                          "band's points; " + (has_triangle ? "both are given" : "neither is given"));
    std::optional<OpenChannel> tri, marks;
    if (has_triangle) tri = open_channel(header, channels, "closest_triangle", points, 1, {"int32"});
    else marks = open_channel(header, channels, "band_points", active, kSignWords, {"uint64"});
    OpenChannel tiles = open_channel(header, channels, "tile_signs", (blocks + 63) / 64, 1, {"uint64"});
    OpenChannel mixed_ids = open_channel(header, channels, "mixed_blocks", mixed, 1, {"int64"});
    OpenChannel signs = open_channel(header, channels, "mixed_signs", mixed, kSignWords, {"uint64"});

    BandChannels held;
    held.gradient = has_gradient;
    held.closest_triangle = has_triangle;
    SparseBandField band(lattice, width, precision, held);
    band.active.resize(size_t(active));
    read_values(ids, band.active.data(), active, header);
    require_block_ids(band.active, blocks, header, "active_blocks");
    band.mixed.resize(size_t(mixed));
    read_values(mixed_ids, band.mixed.data(), mixed, header);
    require_block_ids(band.mixed, blocks, header, "mixed_blocks");
    for (int64_t id : band.mixed)
        if (band.find_active(id) >= 0)
            throw std::runtime_error(header + ": channel 'mixed_blocks': block " + std::to_string(id) +
                                     " is also active; a block is active, mixed or a tile");
    read_values(tiles, band.inside_tiles.data(), int64_t(band.inside_tiles.size()), header);
    if (blocks % 64 != 0 && (band.inside_tiles.back() >> (blocks % 64)) != 0)
        throw std::runtime_error(header + ": channel 'tile_signs': bits set beyond the lattice's " + std::to_string(blocks) +
                                 " blocks");
    band.mixed_inside.resize(size_t(mixed));
    read_values(signs, band.mixed_inside.empty() ? nullptr : band.mixed_inside[0].data(), mixed * kSignWords, header);
    band.distance.resize(size_t(points));
    read_values(dist, band.distance.values<double>(), points, header);
    // A float32 file holds +-float(W) where its active blocks leave the band; its tiles and
    // mixed blocks read as the same value, so the band densifies to the dense float32 file.
    if (dist.dtype == "float32") band.width = double(float(width));
    if (tri) {
        band.closest_triangle.resize(size_t(points));
        read_values(*tri, band.closest_triangle.data(), points, header);
        band.mask_from_triangles();
    } else {
        band.band_mask.resize(size_t(active));
        read_values(*marks, band.band_mask.empty() ? nullptr : band.band_mask[0].data(), active * kSignWords, header);
        for (size_t a = 0; a < band.active.size(); ++a)  // padding is never a band point (counts rely on it)
            for (int local = 0; local < kBandBlockPoints; ++local)
                if (band.in_band(a, local) && band.layout().storage_index(band.active[a], local) < 0)
                    throw std::runtime_error(header + ": channel 'band_points': block " + std::to_string(band.active[a]) +
                                             " marks its point " + std::to_string(local) +
                                             " as a band point, but it lies beyond the lattice (padding)");
    }
    // The values agree with the marks (a writer's invariant, which the level-set writers and
    // the band's cells rely on): a band point has |d| <= W, any other point +-W (padding +W).
    for (size_t a = 0; a < band.active.size(); ++a)
        for (int local = 0; local < kBandBlockPoints; ++local) {
            const double d = band.distance[a * kBandBlockPoints + size_t(local)];
            const bool padding = band.layout().storage_index(band.active[a], local) < 0;
            const bool in_band = band.in_band(a, local);
            const bool fits = in_band ? std::abs(d) <= band.width : padding ? d == band.width : std::abs(d) == band.width;
            if (!fits)
                throw std::runtime_error(header + ": channel 'distance': block " + std::to_string(band.active[a]) + " point " +
                                         std::to_string(local) + " holds " + std::to_string(d) + ", expected " +
                                         (in_band ? "|d| <= W (a band point)" : padding ? "+W (padding)" : "+-W (outside the band)") +
                                         " with W = " + std::to_string(band.width));
        }
    if (grad) {
        band.gradient.resize(size_t(points));
        read_values(*grad, band.gradient.empty() ? nullptr : &band.gradient[0].x, 3 * points, header);
    }
    if (r.has("timings_seconds")) r.accept("timings_seconds");
    try {  // the typed records (mesh_provenance.h, sampler_report.h)
        if (r.has("mesh")) band.mesh = r.raw("mesh").get<MeshProvenance>();
        if (r.has("sampler")) band.sampler = r.raw("sampler").get<SamplerReport>();
    } catch (const std::runtime_error& e) {
        throw std::runtime_error(header + ": " + e.what());
    }
    return band;
}

SampledField densify_within_memory(const SparseBandField& band, bool gradient, const std::string& what,
                                   const std::string& where) {
    const Lattice& l = band.lattice;
    require_host_memory({uint64_t(SparseBandField::dense_bytes(l, band.channels)),
                         "densifying the sparse band of " + what + " (" + lattice_notation(l) + ", " +
                             std::to_string(l.num_points()) + " points)"},
                        where);
    SampledField field = band.densify();
    if (!gradient) field.gradient.clear();  // no gradient channel: none to reconstruct with, as read_field
    return field;
}

SampledField read_field_densified(const std::string& header_path, const std::string& where) {
    const nlohmann::json header = read_json_file(header_path, "field header");
    if (!is_sparse_field_header(header)) return read_field(header_path);
    return densify_within_memory(read_sparse_field(header_path, header), header.contains("gradient_channel"), header_path, where);
}

}  // namespace sdf
