/// @file wire_codec.h
/// @brief The bytes of the messages between the ranks (mpi_transport.h carries them):
/// commands, sampler options, meshes, channel files and timings.
///
/// Requests are flat little-endian records (ByteWriter, ByteReader); everything with named
/// fields travels as JSON. Sampler options go through their one codec
/// (harness/config/sampler_spec.h), enums by name, so the wire cannot drift from configs.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh/triangle_mesh.h"
#include "core/sampling/sampler.h"
#include "harness/io/field_file.h"

namespace sdf::mpi {

static_assert(std::is_trivially_copyable_v<Lattice>, "lattices are sent as bytes");
static_assert(sizeof(Vec3d) == 3 * sizeof(double), "gradients are sent as packed doubles");

/// What the root asks of a worker (the first int32 of every kTagCommand message).
/// Mesh: a mesh the root has loaded, sent before it is sampled so that the workers prepare it
/// while the root prepares its own (issue 36: they prepared it after the first Sample request,
/// inside the sampling's time).
enum class Command : int32_t { Sample = 1, Quit = 2, Write = 3, Mesh = 4 };

/// Flat little-endian encoding of a request.
class ByteWriter {
public:
    template <typename T>
    void put(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes_.append(reinterpret_cast<const char*>(&v), sizeof v);
    }
    void put_string(const std::string& s) {
        put(uint64_t(s.size()));
        bytes_.append(s);
    }
    template <typename T>
    void put_vector(const std::vector<T>& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        put(uint64_t(v.size()));
        bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    }
    const std::string& bytes() const { return bytes_; }

private:
    std::string bytes_;
};

/// Reads what ByteWriter wrote; a short or inconsistent record is a "malformed request".
class ByteReader {
public:
    explicit ByteReader(const std::string& bytes) : bytes_(bytes) {}
    template <typename T>
    T get() {
        T v;
        std::memcpy(&v, take(sizeof v), sizeof v);
        return v;
    }
    std::string get_string() {
        const size_t n = size_t(get<uint64_t>());
        return std::string(take(n), n);
    }
    template <typename T>
    std::vector<T> get_vector() {
        const size_t n = size_t(get<uint64_t>());
        if (n > (bytes_.size() - at_) / sizeof(T)) throw std::runtime_error("malformed request: array too long");
        std::vector<T> v(n);
        std::memcpy(v.data(), take(n * sizeof(T)), n * sizeof(T));
        return v;
    }

private:
    const char* take(size_t n) {
        if (n > bytes_.size() - at_) throw std::runtime_error("malformed request: truncated");
        const char* p = bytes_.data() + at_;
        at_ += n;
        return p;
    }
    const std::string& bytes_;
    size_t at_ = 0;
};

/// Sampler options on the wire: sampler_options_to_json, read back by
/// sampler_options_from_json (errors name "the root's request").
void put_options(ByteWriter& out, const SamplerOptions& options);
SamplerOptions get_options(ByteReader& in);

/// A mesh as loaded (before preparation): the workers prepare it as the root did.
void put_mesh(ByteWriter& out, const TriangleMesh& mesh);
TriangleMesh get_mesh(ByteReader& in);

/// The channel files of a parallel write.
nlohmann::json files_to_json(const std::vector<FieldChannelFile>& files);
std::vector<FieldChannelFile> files_from_json(const nlohmann::json& j);

nlohmann::json timings_to_json(const SamplingTimings& t);
SamplingTimings timings_from_json(const nlohmann::json& j);

}  // namespace sdf::mpi
