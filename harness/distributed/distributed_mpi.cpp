// The MPI side of harness/distributed/distributed.h (docs/distributed.md).
//
// Messages, all point to point between the root (rank 0) and one worker, each a size
// (uint64) then the bytes in chunks of at most 1 GiB (MPI counts are ints):
//   root -> worker  kTagCommand  Sample request (options, lattice, slabs, mesh when new) or Quit
//   worker -> root  kTagStatus   JSON: ok or the error, host, timings, the slab's sampler
//   worker -> root  kTagData     (when ok) distance, gradient, closest triangle; each as the
//                                slab's primary part then its secondary part
//   worker -> root  kTagHello    at start: rank, host, local rank, threads, GPU
//   worker -> root  kTagSettings then its command line's settings (JSON); the root answers
//   root -> worker  kTagSettings with "" (the same as rank 0's) or the message every rank raises
//   root -> worker  kTagCommand  Write: the channel files (temporary names) of the field the
//                                ranks sampled last; the worker writes its slab into them with
//                                MPI-IO and answers with a kTagStatus JSON (bytes, seconds, or
//                                the error). Workers keep their last slab until then.
// Collective sampling (the Python module, every rank calling sample_collectively) uses the
// same Sample/status/data messages and then kTagOutcome; see its section below.
// Waiting ranks poll with short sleeps instead of MPI's busy wait, so that an idle worker
// does not take a core from the ranks that compute.
#include "harness/distributed/distributed.h"

#include <fcntl.h>
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <type_traits>

#include "core/lattice/lattice_fitting.h"
#include "core/parallel/parallel_for.h"
#include "core/sampling/sampler_results.h"
#include "harness/build_config.h"
#include "harness/distributed/slab_plan.h"
#include "harness/io/field_replacement.h"
#include "harness/sampling/sampler_table.h"
#if SDF_HAVE_CUDA
#include "cuda/cuda_device.h"
#endif

namespace sdf {
namespace {

constexpr int kTagCommand = 1, kTagStatus = 2, kTagData = 3, kTagHello = 4, kTagRuns = 5, kTagOutcome = 6,
              kTagSettings = 7;
enum class Command : int32_t { Sample = 1, Quit = 2, Write = 3 };
constexpr size_t kChunkBytes = size_t(1) << 30;
/// Points converted to the stored dtype at a time by a parallel write (bounds its buffer:
/// 96 MiB for a float64 gradient).
constexpr size_t kWritePoints = size_t(1) << 22;

static_assert(std::is_trivially_copyable_v<Lattice>, "lattices are sent as bytes");
static_assert(sizeof(Vec3d) == 3 * sizeof(double), "gradients are sent as packed doubles");

/// This process's part in the run.
struct Session {
    bool started = false;   ///< MPI_Init was called here
    bool joined = false;    ///< MPI runs and this rank knows the others (join_ranks)
    /// Every rank runs the same code and calls sample_collectively (the Python module), so
    /// there is no workers' loop to end.
    bool collective = false;
    std::string started_by;  ///< collective: "sdf_lattices" or "another library"
    int rank = 0, size = 1;
    nlohmann::json self;    ///< rank, host, local_rank, local_size, threads, device, gpu
    nlohmann::json processes = nlohmann::json::array();  ///< root: every rank's `self`
    nlohmann::json fields = nlohmann::json::array();     ///< root: each distributed field
    std::map<std::string, TriangleMesh> meshes;          ///< root: by content SHA-256
    std::string mesh_sent;  ///< root: SHA-256 of the mesh the workers hold
    bool released = false;  ///< root: workers told to quit
    Distribution distribution = Distribution::LatticeSlabs;
    /// Root: the field the ranks sampled last, whose slabs the workers still hold for the
    /// parallel write (write_sampled_field); invalid once written or when another is sampled.
    struct HeldField {
        bool valid = false;
        Lattice lattice;
        std::vector<LatticeSlab> slabs;
        nlohmann::json record;             ///< the field's sampler.distributed
        const double* distance = nullptr;  ///< the field's storage (moving the field keeps it)
        size_t field_index = 0;            ///< its record in `fields`
    } held;
};

Session& session() {
    static Session s;
    return s;
}

/// Set by mpirun / mpiexec (Open MPI, MPICH's hydra) or srun (PMI, PMIx).
bool launched_by_mpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
        if (std::getenv(v) != nullptr) return true;
    return false;
}

void check_mpi(int code, const char* what) {
    if (code == MPI_SUCCESS) return;
    char text[MPI_MAX_ERROR_STRING];
    int length = 0;
    MPI_Error_string(code, text, &length);
    throw std::runtime_error(std::string("MPI: ") + what + ": " + std::string(text, size_t(length)));
}

/// Waits for `request` without spinning a core.
void wait_politely(MPI_Request& request) {
    auto pause = std::chrono::microseconds(20);
    for (;;) {
        int done = 0;
        check_mpi(MPI_Test(&request, &done, MPI_STATUS_IGNORE), "MPI_Test");
        if (done) return;
        std::this_thread::sleep_for(pause);
        pause = std::min(pause * 2, std::chrono::microseconds(2000));
    }
}

void send_bytes(const void* data, size_t bytes, int dest, int tag) {
    uint64_t size = bytes;
    check_mpi(MPI_Send(&size, 1, MPI_UINT64_T, dest, tag, MPI_COMM_WORLD), "MPI_Send");
    const char* p = static_cast<const char*>(data);
    for (size_t off = 0; off < bytes; off += kChunkBytes)
        check_mpi(MPI_Send(p + off, int(std::min(kChunkBytes, bytes - off)), MPI_BYTE, dest, tag, MPI_COMM_WORLD),
                  "MPI_Send");
}

uint64_t receive_size(int source, int tag) {
    uint64_t size = 0;
    MPI_Request request;
    check_mpi(MPI_Irecv(&size, 1, MPI_UINT64_T, source, tag, MPI_COMM_WORLD, &request), "MPI_Irecv");
    wait_politely(request);
    return size;
}

void receive_chunks(void* data, size_t bytes, int source, int tag) {
    char* p = static_cast<char*>(data);
    for (size_t off = 0; off < bytes; off += kChunkBytes)
        check_mpi(MPI_Recv(p + off, int(std::min(kChunkBytes, bytes - off)), MPI_BYTE, source, tag, MPI_COMM_WORLD,
                           MPI_STATUS_IGNORE),
                  "MPI_Recv");
}

std::string receive_string(int source, int tag) {
    std::string s(size_t(receive_size(source, tag)), '\0');
    receive_chunks(s.data(), s.size(), source, tag);
    return s;
}

void send_string(const std::string& s, int dest, int tag) { send_bytes(s.data(), s.size(), dest, tag); }

/// Receives exactly `bytes` into `data`; a different size is a protocol error.
void receive_into(void* data, size_t bytes, int source, int tag) {
    const uint64_t size = receive_size(source, tag);
    if (size != bytes)
        throw std::runtime_error("rank " + std::to_string(source) + " sent " + std::to_string(size) + " bytes where " +
                                 std::to_string(bytes) + " were expected");
    receive_chunks(data, bytes, source, tag);
}

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

nlohmann::json options_to_json(const SamplerOptions& o) {
    return {{"backend", o.backend},
            {"method", o.method},
            {"kernel", o.kernel},
            {"precision", int(o.precision)},
            {"sign", int(o.sign)},
            {"threads", o.threads},
            {"bcc_strategy", int(o.bcc_strategy)},
            {"device", o.device},
            {"max_points_per_piece", o.max_points_per_piece},
            {"max_triangles_per_chunk", o.max_triangles_per_chunk},
            {"points_per_thread", o.points_per_thread},
            {"band_width", o.band_width},
            {"bvh_build", int(o.bvh_build)}};
}

SamplerOptions options_from_json(const nlohmann::json& j) {
    SamplerOptions o;
    o.backend = j.at("backend").get<std::string>();
    o.method = j.at("method").get<std::string>();
    o.kernel = j.at("kernel").get<std::string>();
    o.precision = Precision(j.at("precision").get<int>());
    o.sign = SignMode(j.at("sign").get<int>());
    o.threads = j.at("threads").get<int>();
    o.bcc_strategy = BccStrategy(j.at("bcc_strategy").get<int>());
    o.device = j.at("device").get<int>();
    o.max_points_per_piece = j.at("max_points_per_piece").get<int64_t>();
    o.max_triangles_per_chunk = j.at("max_triangles_per_chunk").get<int>();
    o.points_per_thread = j.at("points_per_thread").get<int>();
    o.band_width = j.at("band_width").get<double>();
    o.bvh_build = BvhBuildSite(j.at("bvh_build").get<int>());
    return o;
}

int cuda_devices() {
#if SDF_HAVE_CUDA
    return cuda::device_count();
#else
    return 0;
#endif
}

/// This rank's sampler options: its GPU (the local rank modulo the devices, offset by the
/// configured device) and, for "all threads", its share of the host's cores.
SamplerOptions options_for_this_rank(SamplerOptions o) {
    const Session& s = session();
    const int devices = cuda_devices();
    if (o.backend == "cuda" && devices > 0) o.device = (o.device + s.self.value("local_rank", 0)) % devices;
    if (o.threads == 0) o.threads = std::max(1, resolve_thread_count(0) / std::max(1, s.self.value("local_size", 1)));
    if (s.rank != 0) o.progress = false;  // one progress line per run: the root's
    return o;
}

/// Whether the tests ask rank `rank` to fail at `stage` (SDF_MPI_FAIL_RANK, SDF_MPI_FAIL_STAGE:
/// "sample" when unset, "write", or "open": the rank cannot open the files of the parallel
/// write, as on a node without the shared file system).
bool failure_asked(int rank, const std::string& stage) {
    const char* target = std::getenv("SDF_MPI_FAIL_RANK");
    if (target == nullptr || std::atoi(target) != rank) return false;
    const char* wanted = std::getenv("SDF_MPI_FAIL_STAGE");
    return stage == (wanted != nullptr ? wanted : "sample");
}

/// SDF_MPI_FAIL_RANK=r makes rank r fail its slab (tests of the failure path), or with
/// SDF_MPI_FAIL_STAGE=write its part of the parallel write; SDF_MPI_FAIL_MODE=kill makes it
/// die instead, as a crashed or OOM-killed process would.
void maybe_inject_failure(int rank, const std::string& stage = "sample") {
    if (!failure_asked(rank, stage)) return;
    const std::string target = std::getenv("SDF_MPI_FAIL_RANK");
    const char* mode = std::getenv("SDF_MPI_FAIL_MODE");
    if (mode != nullptr && std::string(mode) == "kill") std::raise(SIGKILL);
    if (stage == "sample") throw std::runtime_error("injected failure (SDF_MPI_FAIL_RANK=" + std::string(target) + ")");
    throw std::runtime_error("injected failure at the " + stage + " stage (SDF_MPI_FAIL_RANK=" + std::string(target) + ")");
}

std::string host_name() {
    char name[MPI_MAX_PROCESSOR_NAME];
    int length = 0;
    MPI_Get_processor_name(name, &length);
    return std::string(name, size_t(length));
}

std::string rank_and_host(int rank, const std::string& host) { return "rank " + std::to_string(rank) + " (host " + host + ")"; }

/// Samples `slab` with `sampler` (nothing for an empty slab).
SampledField sample_part(Sampler& sampler, const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& slab) {
    if (slab.z_end <= slab.z_begin) {
        SampledField empty;
        empty.lattice = lattice;
        return empty;
    }
    return sampler.sample_slab(mesh, lattice, slab);
}

/// What a rank reports of its slab.
nlohmann::json describe_part(const SampledField& part, int rank, const std::string& host, const LatticeSlab& slab,
                             double wall_seconds) {
    nlohmann::json j = {{"rank", rank},
                        {"host", host},
                        {"z_planes", {slab.z_begin, slab.z_end}},
                        {"points", part.size()},
                        {"seconds", wall_seconds},
                        {"kernel_seconds", part.timings.kernel},
                        {"upload_seconds", part.timings.upload},
                        {"download_seconds", part.timings.download},
                        {"pairs", part.timings.point_triangle_pairs}};
    if (part.sampler.is_object()) {
        j["points_computed"] = part.sampler.value("points_computed", int64_t(0));
        if (part.sampler.contains("device")) j["device"] = part.sampler["device"];
        if (part.sampler.contains("threads")) j["threads"] = part.sampler["threads"];
    } else {
        j["points_computed"] = 0;
    }
    return j;
}

// ---- Parallel writes of field files -------------------------------------------------------

nlohmann::json files_to_json(const std::vector<FieldChannelFile>& files) {
    nlohmann::json j = nlohmann::json::array();
    for (const FieldChannelFile& f : files)
        j.push_back({{"name", f.name}, {"path", f.path}, {"float32", f.dtype == FieldDtype::Float32}, {"components", f.components}});
    return j;
}

std::vector<FieldChannelFile> files_from_json(const nlohmann::json& j) {
    std::vector<FieldChannelFile> files;
    for (const nlohmann::json& f : j)
        files.push_back({f.at("name").get<std::string>(), f.at("path").get<std::string>(),
                         f.at("float32").get<bool>() ? FieldDtype::Float32 : FieldDtype::Float64, f.at("components").get<int>()});
    return files;
}

/// One rank's handles on the channel files of a parallel write. Each file is opened on
/// MPI_COMM_SELF and written with independent MPI_File_write_at calls: no collective call,
/// so a rank that fails cannot hang the others; its status message to the root, sent after
/// MPI_File_sync and MPI_File_close, is the barrier.
class ChannelFiles {
public:
    ChannelFiles() = default;
    ChannelFiles(const ChannelFiles&) = delete;
    ChannelFiles& operator=(const ChannelFiles&) = delete;
    ~ChannelFiles() {
        for (MPI_File& h : handles_) MPI_File_close(&h);  // after a failure: the caller is already failing
    }

    /// Opens the root's files; false, saying why, when this rank cannot (no shared file
    /// system) or sees another file of that name (its size is not the root's preallocation).
    bool open(const std::vector<FieldChannelFile>& files, int64_t points, std::string& why) {
        files_ = files;
        for (const FieldChannelFile& f : files) {
            MPI_File h;
            int code = MPI_File_open(MPI_COMM_SELF, f.path.c_str(), MPI_MODE_WRONLY, MPI_INFO_NULL, &h);
            if (code != MPI_SUCCESS) {
                char text[MPI_MAX_ERROR_STRING];
                int length = 0;
                MPI_Error_string(code, text, &length);
                why = f.path + ": cannot open: " + std::string(text, size_t(length));
                return false;
            }
            handles_.push_back(h);
            MPI_Offset size = 0;
            check_mpi(MPI_File_get_size(h, &size), "MPI_File_get_size");
            if (uint64_t(size) != uint64_t(points) * f.bytes_per_point()) {
                why = f.path + ": holds " + std::to_string(size) + " bytes, not the root's " +
                      std::to_string(uint64_t(points) * f.bytes_per_point());
                return false;
            }
        }
        return true;
    }

    /// Writes points [first, first + count) of `source` at lattice storage offset `offset`
    /// of every channel; returns the bytes written.
    uint64_t write(const SampledField& source, size_t first, size_t count, int64_t offset) {
        uint64_t total = 0;
        for (size_t c = 0; c < files_.size(); ++c) {
            const size_t width = files_[c].bytes_per_point();
            for (size_t done = 0; done < count; done += kWritePoints) {
                const size_t n = std::min(kWritePoints, count - done);
                const std::vector<char> bytes = field_channel_bytes(source, files_[c], first + done, n);
                MPI_Status status;
                check_mpi(MPI_File_write_at(handles_[c], MPI_Offset((size_t(offset) + done) * width), bytes.data(),
                                            int(bytes.size()), MPI_BYTE, &status),
                          ("MPI_File_write_at " + files_[c].path).c_str());
                int written = 0;
                MPI_Get_count(&status, MPI_BYTE, &written);
                if (size_t(written) != bytes.size())
                    throw std::runtime_error(files_[c].path + ": wrote " + std::to_string(written) + " of " +
                                             std::to_string(bytes.size()) + " bytes");
                total += bytes.size();
            }
        }
        return total;
    }

    /// Flushes every file to storage and closes it.
    void close() {
        for (size_t c = 0; c < handles_.size(); ++c)
            check_mpi(MPI_File_sync(handles_[c]), ("MPI_File_sync " + files_[c].path).c_str());
        while (!handles_.empty()) {
            const std::string path = files_[handles_.size() - 1].path;
            MPI_File h = handles_.back();
            handles_.pop_back();
            check_mpi(MPI_File_close(&h), ("MPI_File_close " + path).c_str());
        }
    }

private:
    std::vector<FieldChannelFile> files_;
    std::vector<MPI_File> handles_;
};

/// Writes `slab` of `source` (the whole field, or a rank's part: its primary points, then
/// its secondary ones) at its storage offsets; returns the bytes written.
uint64_t write_slab(ChannelFiles& files, const SampledField& source, bool source_is_whole, const Lattice& lattice,
                    const LatticeSlab& slab) {
    if (slab.z_end <= slab.z_begin) return 0;
    uint64_t bytes = 0;
    int64_t from = 0;
    for (int p = 0; p < 2; ++p) {
        const StorageRange r = slab_storage(lattice, slab, p);
        bytes += files.write(source, size_t(source_is_whole ? r.offset : from), size_t(r.count), r.offset);
        from += r.count;
    }
    return bytes;
}

// ---- Workers ------------------------------------------------------------------------------

void send_part(const SampledField& part, const Lattice& lattice, const LatticeSlab& slab);

class Worker {
public:
    /// Handles one Sample request; the answer goes to the root whatever happens.
    void sample(const std::string& request) {
        const Session& s = session();
        nlohmann::json status = {{"ok", true}, {"rank", s.rank}, {"host", s.self["host"]}};
        release();  // a new field: the last one's slab is no longer wanted
        SampledField& part = part_;
        LatticeSlab& slab = slab_;
        Lattice& lattice = lattice_;
        try {
            ByteReader in(request);
            in.get<int32_t>();  // the command
            const SamplerOptions options = options_for_this_rank(options_from_json(nlohmann::json::parse(in.get_string())));
            lattice = in.get<Lattice>();
            const std::vector<LatticeSlab> slabs = in.get_vector<LatticeSlab>();
            const std::string sha = in.get_string();
            if (in.get<uint8_t>() != 0) {
                TriangleMesh m;
                m.name = in.get_string();
                m.source = in.get_string();
                m.content_sha256 = in.get_string();
                m.vertices = in.get_vector<Vec3d>();
                m.triangles = in.get_vector<Int3>();
                mesh_.reset();
                mesh_.emplace(prepare_mesh(m));  // as the root's load_prepared_mesh()
            }
            if (!mesh_ || mesh_->content_sha256() != sha)
                throw std::runtime_error("has no prepared mesh " + sha.substr(0, 12) + " (protocol error)");
            if (slabs.size() != size_t(s.size)) throw std::runtime_error("the request holds no slab for this rank");
            slab = slabs[size_t(s.rank)];
            const std::string key = options_to_json(options).dump();
            if (!sampler_ || key != sampler_key_) {
                sampler_ = make_sampler(options);
                sampler_key_ = key;
            }
            const auto start = std::chrono::steady_clock::now();
            maybe_inject_failure(s.rank);
            part = sample_part(*sampler_, *mesh_, lattice, slab);
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            status["part"] = describe_part(part, s.rank, s.self["host"].get<std::string>(), slab, seconds);
            status["sampler"] = part.sampler;
        } catch (const std::exception& e) {
            status["ok"] = false;
            status["error"] = e.what();
        }
        send_string(status.dump(), 0, kTagStatus);
        if (!status["ok"].get<bool>()) return release();
        holds_part_ = true;  // for the parallel write of its files
        send_part(part, lattice, slab);
    }

    /// Handles one Write request: writes the slab it holds into the root's channel files.
    void write(const std::string& request) {
        const Session& s = session();
        nlohmann::json status = {{"ok", true}, {"rank", s.rank}, {"host", s.self["host"]}};
        try {
            if (!holds_part_) throw std::runtime_error("holds no sampled slab to write (protocol error)");
            ByteReader in(request);
            in.get<int32_t>();  // the command
            const std::vector<FieldChannelFile> files = files_from_json(nlohmann::json::parse(in.get_string()));
            const auto start = std::chrono::steady_clock::now();
            ChannelFiles out;
            std::string why;
            if (failure_asked(s.rank, "open")) {
                status["written"] = false;
                status["why"] = "injected: cannot open the files (SDF_MPI_FAIL_STAGE=open)";
            } else if (!out.open(files, lattice_.num_points(), why)) {
                status["written"] = false;  // the root writes this slab
                status["why"] = why;
            } else {
                maybe_inject_failure(s.rank, "write");
                status["write_bytes"] = write_slab(out, part_, false, lattice_, slab_);
                out.close();
                status["written"] = true;
                status["write_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            }
        } catch (const std::exception& e) {
            status["ok"] = false;
            status["error"] = e.what();
        }
        release();
        send_string(status.dump(), 0, kTagStatus);
    }

private:
    void release() {
        holds_part_ = false;
        part_ = SampledField();
    }

    SampledField part_;  ///< the last slab sampled, kept until its field is written
    LatticeSlab slab_;
    Lattice lattice_;
    bool holds_part_ = false;
    std::optional<PreparedMesh> mesh_;
    std::unique_ptr<Sampler> sampler_;
    std::string sampler_key_;
};

// ---- The root's side of a distributed field ----------------------------------------------

/// Copies a rank's part (its slab's primary points, then its secondary ones) to its offsets.
void place_part(SampledField& field, const Lattice& lattice, const LatticeSlab& slab, const SampledField& part) {
    if (part.size() == 0) return;
    int64_t from = 0;
    for (int p = 0; p < 2; ++p) {
        const StorageRange r = slab_storage(lattice, slab, p);
        std::copy_n(part.distance.begin() + from, r.count, field.distance.begin() + r.offset);
        std::copy_n(part.gradient.begin() + from, r.count, field.gradient.begin() + r.offset);
        std::copy_n(part.closest_triangle.begin() + from, r.count, field.closest_triangle.begin() + r.offset);
        from += r.count;
    }
}

/// Root: rank `rank`'s part (as send_part sends it) at its offsets.
void receive_part(SampledField& field, const Lattice& lattice, const LatticeSlab& slab, int rank) {
    for (int p = 0; p < 2; ++p) {
        const StorageRange r = slab_storage(lattice, slab, p);
        const size_t n = size_t(r.count), at = size_t(r.offset);
        receive_into(field.distance.data() + at, n * sizeof(double), rank, kTagData);
        receive_into(field.gradient.data() + at, n * sizeof(Vec3d), rank, kTagData);
        receive_into(field.closest_triangle.data() + at, n * sizeof(int32_t), rank, kTagData);
    }
}

/// Worker: its part to the root, per channel its primary points, then its secondary ones.
void send_part(const SampledField& part, const Lattice& lattice, const LatticeSlab& slab) {
    for (int p = 0; p < 2; ++p) {
        const StorageRange r = slab_storage(lattice, slab, p);
        const size_t first = p == 0 ? 0 : size_t(slab_storage(lattice, slab, 0).count);
        const size_t n = part.size() == 0 ? 0 : size_t(r.count);
        send_bytes(part.distance.data() + first, n * sizeof(double), 0, kTagData);
        send_bytes(part.gradient.data() + first, n * sizeof(Vec3d), 0, kTagData);
        send_bytes(part.closest_triangle.data() + first, n * sizeof(int32_t), 0, kTagData);
    }
}

struct RankFailure {
    int rank;
    std::string host, error;
    bool setup = false;  ///< before sampling: the caller's arguments (collective sampling)
};

/// What the root gathers of one field: every rank's slab, described; the sampler's
/// provenance (the root's slab's, or the first worker's when the root's slab is empty); and
/// the ranks that failed.
struct Gathered {
    nlohmann::json parts = nlohmann::json::array();
    nlohmann::json sampler;
    std::vector<RankFailure> failures;
};

/// Root: every worker's answer, its status and, when it sampled its slab, the slab into
/// `field`. Every worker answers, failed or not, so the exchange ends in step on every rank.
void receive_answers(Gathered& g, SampledField* field, const Lattice& lattice, const std::vector<LatticeSlab>& slabs) {
    for (int r = 1; r < session().size; ++r) {
        const nlohmann::json status = nlohmann::json::parse(receive_string(r, kTagStatus));
        const std::string host = status.value("host", std::string("?"));
        if (!status.value("ok", false)) {
            g.failures.push_back({r, host, status.value("error", std::string("unknown error")), status.value("setup", false)});
            continue;
        }
        if (!status.contains("part") || field == nullptr) continue;  // nothing sampled: the root had failed first
        receive_part(*field, lattice, slabs[size_t(r)], r);
        g.parts.push_back(status["part"]);
        if (!g.sampler.is_object() && status["sampler"].is_object()) g.sampler = status["sampler"];
    }
}

/// Root: samples slab 0 (`sample_mine`) into `field` while the workers sample theirs, then
/// gathers their answers.
Gathered sample_and_gather(const std::function<SampledField(const LatticeSlab&)>& sample_mine, const Lattice& lattice,
                           const SlabPlan& plan, SampledField& field) {
    const std::string host = session().self["host"].get<std::string>();
    Gathered g;
    try {
        const auto t0 = std::chrono::steady_clock::now();
        maybe_inject_failure(0);
        const SampledField part = sample_mine(plan.slabs[0]);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        place_part(field, lattice, plan.slabs[0], part);
        g.parts.push_back(describe_part(part, 0, host, plan.slabs[0], seconds));
        g.sampler = part.sampler;
    } catch (const std::exception& e) {
        g.failures.push_back({0, host, e.what()});
    }
    receive_answers(g, &field, lattice, plan.slabs);
    return g;
}

/// "distributed sampling of 11x9x13 failed on 1 of 2 ranks: rank 1 (host vm): ..."
std::string failure_message(const std::string& lattice, const std::vector<RankFailure>& failures) {
    std::string text = "distributed sampling" + (lattice.empty() ? std::string() : " of " + lattice) + " failed on " +
                       std::to_string(failures.size()) + " of " + std::to_string(session().size) + " ranks: ";
    for (size_t i = 0; i < failures.size(); ++i)
        text += (i ? "; " : "") + rank_and_host(failures[i].rank, failures[i].host) + ": " + failures[i].error;
    return text;
}

/// The field's provenance: the gathered sampler with the whole run's counts, and
/// "distributed" (the slabs, per-rank seconds, the load balance), which it returns.
nlohmann::json finish_provenance(SampledField& field, const SamplerOptions& options, const SlabPlan& plan,
                                 const Gathered& gathered, double total_seconds, double sampling_seconds) {
    const Session& s = session();
    nlohmann::json parts = gathered.parts, sampler_json = gathered.sampler;
    std::sort(parts.begin(), parts.end(), [](const nlohmann::json& a, const nlohmann::json& b) { return a["rank"] < b["rank"]; });
    int64_t computed = 0;
    double pairs = 0, max_seconds = 0, sum_seconds = 0, upload = 0, download = 0;
    for (size_t r = 0; r < parts.size(); ++r) {
        nlohmann::json& p = parts[r];
        p["estimated_cost"] = plan.slab_cost(int(r));
        computed += p["points_computed"].get<int64_t>();
        pairs += p["pairs"].get<double>();
        max_seconds = std::max(max_seconds, p["seconds"].get<double>());
        sum_seconds += p["seconds"].get<double>();
        upload = std::max(upload, p["upload_seconds"].get<double>());
        download = std::max(download, p["download_seconds"].get<double>());
    }
    if (!sampler_json.is_object() || sampler_json.empty())
        sampler_json = {{"backend", options.backend}, {"method", options.method},
                        {"kernel", options.kernel}, {"precision", precision_name(options.precision)}};
    sampler_json["points_computed"] = computed;
    const double mean = sum_seconds / double(std::max<size_t>(1, parts.size()));
    nlohmann::json d = {{"ranks", s.size},
                        {"lattice", lattice_notation(field.lattice)},
                        {"cost_estimate", plan.estimate},
                        {"estimate_seconds", plan.estimate_seconds},
                        {"slabs", parts},
                        {"load_balance", {{"seconds_max_over_mean", mean > 0 ? max_seconds / mean : 1.0},
                                          {"estimate_max_over_mean", plan.estimated_max_over_mean()}}},
                        {"seconds", total_seconds}};
    if (field.lattice.type == LatticeType::BCC && options.bcc_strategy == BccStrategy::DoubleResolution)
        d["slab_bcc_strategy"] = "two_grids";  // lattice_slab.h: the same positions, the same samples
    sampler_json["distributed"] = d;
    field.sampler = sampler_json;
    field.timings.total = total_seconds;
    field.timings.kernel = sampling_seconds;
    field.timings.upload = upload;
    field.timings.download = download;
    field.timings.point_triangle_pairs = pairs;
    return d;
}

// ---- The root's sampler (run-experiment: the workers serve) --------------------------------

class DistributedSampler final : public Sampler {
public:
    explicit DistributedSampler(const SamplerOptions& options)
        : options_(options), local_(make_sampler(options_for_this_rank(options))) {}

    std::string name() const override {
        return local_->name() + " on " + std::to_string(session().size) + " MPI ranks";
    }

    std::vector<PointSample> query(const PreparedMesh& mesh, const std::vector<Vec3d>& points) override {
        return local_->query(mesh, points);
    }

    SampledField sample_slab(const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& slab) override {
        if (!is_whole_lattice(lattice, slab)) return local_->sample_slab(mesh, lattice, slab);
        Session& s = session();
        s.held.valid = false;  // the workers drop the last field's slabs on this request
        const auto start = std::chrono::steady_clock::now();
        // Before any worker is asked: a mesh or lattice out of the search's range is refused here.
        SampledField field = unfilled_field(mesh, lattice, whole_lattice_slab(lattice), options_.precision);
        const SlabPlan plan = plan_slabs(mesh, lattice, options_, s.size);
        send_requests(mesh, lattice, plan);
        const auto sampling_start = std::chrono::steady_clock::now();
        const Gathered gathered = sample_and_gather(
            [&](const LatticeSlab& mine) { return sample_part(*local_, mesh, lattice, mine); }, lattice, plan, field);
        if (!gathered.failures.empty()) throw std::runtime_error(failure_message(lattice_notation(lattice), gathered.failures));
        const auto end = std::chrono::steady_clock::now();
        s.fields.push_back(finish_provenance(field, options_, plan, gathered, std::chrono::duration<double>(end - start).count(),
                                             std::chrono::duration<double>(end - sampling_start).count()));
        s.held = {true, lattice, plan.slabs, field.sampler["distributed"], field.distance.data(), s.fields.size() - 1};
        return field;
    }

private:
    void send_requests(const PreparedMesh& mesh, const Lattice& lattice, const SlabPlan& plan) {
        Session& s = session();
        ByteWriter out;
        out.put(int32_t(Command::Sample));
        out.put_string(options_to_json(options_).dump());
        out.put(lattice);
        out.put_vector(plan.slabs);
        out.put_string(mesh.content_sha256());
        const bool new_mesh = s.mesh_sent != mesh.content_sha256();
        out.put(uint8_t(new_mesh));
        if (new_mesh) {
            const auto it = s.meshes.find(mesh.content_sha256());
            if (it == s.meshes.end())
                throw std::logic_error("distributed sampling: mesh " + mesh.name() +
                                       " was not shared with the workers (share_mesh_with_workers)");
            const TriangleMesh& m = it->second;
            out.put_string(m.name);
            out.put_string(m.source);
            out.put_string(m.content_sha256);
            out.put_vector(m.vertices);
            out.put_vector(m.triangles);
        }
        for (int r = 1; r < s.size; ++r) send_bytes(out.bytes().data(), out.bytes().size(), r, kTagCommand);
        s.mesh_sent = mesh.content_sha256();
    }

    SamplerOptions options_;
    std::unique_ptr<Sampler> local_;
};

// ---- Collective sampling (the Python module: every rank calls sample_collectively) ---------
//
//   root -> worker  kTagCommand  Sample: the root's setup error (empty when it is ready), then
//                                its sampler options, lattice, slabs and mesh fingerprint
//   worker -> root  kTagStatus   as a worker's answer above (plus "setup": its own arguments
//                                failed), then kTagData with its slab when it sampled one
//   root -> worker  kTagOutcome  JSON: ok and the field's provenance, or the error every rank
//                                raises; when ok, the field's points follow by MPI_Bcast
// The Sample request and the outcome are waited for politely; the broadcast comes when every
// rank has answered, so no rank spins in it while others compute.

/// What every rank's mesh must share with the root's.
std::string mesh_fingerprint(const PreparedMesh& mesh) {
    return "sha256 " + mesh.content_sha256() + ", " + std::to_string(mesh.vertices().size()) + " vertices and " +
           std::to_string(mesh.triangles().size()) + " triangles prepared";
}

void require_same(const std::string& what, const std::string& mine, const std::string& roots) {
    if (mine != roots)
        throw std::runtime_error("called with another " + what + " than rank 0 (every rank must pass the same arguments): " +
                                 mine + " here, " + roots + " on rank 0");
}

/// The same for a JSON object (a lattice, sampler options), naming the keys that differ.
void require_same_keys(const std::string& what, const nlohmann::json& mine, const std::string& roots_text) {
    const nlohmann::json roots = nlohmann::json::parse(roots_text);
    if (mine == roots) return;
    std::string mine_keys, roots_keys;
    for (const auto& [key, value] : mine.items()) {
        const nlohmann::json theirs = roots.contains(key) ? roots[key] : nlohmann::json(nullptr);
        if (value == theirs) continue;
        mine_keys += (mine_keys.empty() ? "" : ", ") + key + " " + value.dump();
        roots_keys += (roots_keys.empty() ? "" : ", ") + key + " " + theirs.dump();
    }
    require_same(what, mine_keys, roots_keys);
}

/// Every rank: the root's points of `field` (sized alike on every rank), in chunks of at
/// most 1 GiB.
void broadcast_field(SampledField& field) {
    const auto broadcast = [](void* data, size_t bytes) {
        char* p = static_cast<char*>(data);
        for (size_t off = 0; off < bytes; off += kChunkBytes)
            check_mpi(MPI_Bcast(p + off, int(std::min(kChunkBytes, bytes - off)), MPI_BYTE, 0, MPI_COMM_WORLD), "MPI_Bcast");
    };
    broadcast(field.distance.data(), field.distance.size() * sizeof(double));
    broadcast(field.gradient.data(), field.gradient.size() * sizeof(Vec3d));
    broadcast(field.closest_triangle.data(), field.closest_triangle.size() * sizeof(int32_t));
}

nlohmann::json timings_to_json(const SamplingTimings& t) {
    return {{"total", t.total}, {"kernel", t.kernel}, {"upload", t.upload}, {"download", t.download},
            {"point_triangle_pairs", t.point_triangle_pairs}};
}

SamplingTimings timings_from_json(const nlohmann::json& j) {
    SamplingTimings t;
    t.total = j.at("total").get<double>();
    t.kernel = j.at("kernel").get<double>();
    t.upload = j.at("upload").get<double>();
    t.download = j.at("download").get<double>();
    t.point_triangle_pairs = j.at("point_triangle_pairs").get<double>();
    return t;
}

/// After a failed exchange, on every rank: where every rank failed in its setup with the same
/// message (the same bad argument everywhere), its own exception, as one process would raise
/// it; otherwise the message naming every failed rank.
[[noreturn]] void raise_outcome(const nlohmann::json& outcome, const std::exception_ptr& setup_error) {
    if (outcome.value("same", false) && setup_error) std::rethrow_exception(setup_error);
    throw std::runtime_error(outcome.at("error").get<std::string>());
}

SampledField collective_root(const PreparedMesh& mesh, const std::function<SamplingRequest()>& setup) {
    Session& s = session();
    s.held.valid = false;
    const std::string host = s.self["host"].get<std::string>();
    const auto start = std::chrono::steady_clock::now();
    SamplingRequest mine;
    SampledField field;
    SlabPlan plan;
    std::exception_ptr setup_error;
    std::string setup_message;
    try {
        mine = setup();
        // The lattice's range check runs on every rank, so a bad one fails everywhere alike.
        field = unfilled_field(mesh, mine.lattice, whole_lattice_slab(mine.lattice), mine.options.precision);
        plan = plan_slabs(mesh, mine.lattice, mine.options, s.size);
    } catch (const std::exception& e) {
        setup_error = std::current_exception();
        setup_message = e.what();
    }
    ByteWriter request;
    request.put(int32_t(Command::Sample));
    request.put_string(setup_message);
    if (!setup_error) {
        request.put_string(options_to_json(mine.options).dump());
        request.put_string(lattice_to_json(mine.lattice).dump());
        request.put_vector(plan.slabs);
        request.put_string(mesh_fingerprint(mesh));
    }
    for (int r = 1; r < s.size; ++r) send_bytes(request.bytes().data(), request.bytes().size(), r, kTagCommand);

    const auto sampling_start = std::chrono::steady_clock::now();
    Gathered gathered;
    if (setup_error) {
        gathered.failures.push_back({0, host, setup_message, true});
        receive_answers(gathered, nullptr, mine.lattice, {});
    } else {
        gathered = sample_and_gather(
            [&](const LatticeSlab& slab) {
                const std::unique_ptr<Sampler> sampler = make_sampler(options_for_this_rank(mine.options));
                return sample_part(*sampler, mesh, mine.lattice, slab);
            },
            mine.lattice, plan, field);
    }

    nlohmann::json outcome = {{"ok", gathered.failures.empty()}};
    if (!gathered.failures.empty()) {
        bool same = int(gathered.failures.size()) == s.size;
        for (const RankFailure& f : gathered.failures) same = same && f.setup && f.error == gathered.failures[0].error;
        std::sort(gathered.failures.begin(), gathered.failures.end(),
                  [](const RankFailure& a, const RankFailure& b) { return a.rank < b.rank; });
        outcome["same"] = same;
        outcome["error"] = same ? gathered.failures[0].error
                                : failure_message(setup_error ? "" : lattice_notation(mine.lattice), gathered.failures);
    } else {
        const auto end = std::chrono::steady_clock::now();
        finish_provenance(field, mine.options, plan, gathered, std::chrono::duration<double>(end - start).count(),
                          std::chrono::duration<double>(end - sampling_start).count());
        field.sampler["distributed"]["collective"] = true;  // every rank called sample and holds the field
        outcome["sampler"] = field.sampler;
        outcome["timings"] = timings_to_json(field.timings);
    }
    for (int r = 1; r < s.size; ++r) send_string(outcome.dump(), r, kTagOutcome);
    if (!outcome["ok"].get<bool>()) raise_outcome(outcome, setup_error);
    broadcast_field(field);
    return field;
}

SampledField collective_worker(const PreparedMesh& mesh, const std::function<SamplingRequest()>& setup) {
    const Session& s = session();
    const std::string host = s.self["host"].get<std::string>();
    nlohmann::json status = {{"ok", true}, {"rank", s.rank}, {"host", host}};
    SamplingRequest mine;
    std::exception_ptr setup_error;
    try {
        mine = setup();
        require_search_range(mesh, mine.lattice, mine.options.precision);  // as the root's unfilled_field
    } catch (const std::exception& e) {
        setup_error = std::current_exception();
        status = {{"ok", false}, {"rank", s.rank}, {"host", host}, {"error", e.what()}, {"setup", true}};
    }
    const std::string request = receive_string(0, kTagCommand);
    SampledField part;
    LatticeSlab slab;
    if (!setup_error) {
        try {
            ByteReader in(request);
            in.get<int32_t>();  // the command
            if (in.get_string().empty()) {  // the root is ready: sample this rank's slab
                const std::string options = in.get_string(), lattice = in.get_string();
                const std::vector<LatticeSlab> slabs = in.get_vector<LatticeSlab>();
                require_same("mesh", mesh_fingerprint(mesh), in.get_string());
                require_same_keys("lattice", lattice_to_json(mine.lattice), lattice);
                require_same_keys("sampler", options_to_json(mine.options), options);
                if (slabs.size() != size_t(s.size)) throw std::runtime_error("the request holds no slab for this rank");
                slab = slabs[size_t(s.rank)];
                const std::unique_ptr<Sampler> sampler = make_sampler(options_for_this_rank(mine.options));
                const auto t0 = std::chrono::steady_clock::now();
                maybe_inject_failure(s.rank);
                part = sample_part(*sampler, mesh, mine.lattice, slab);
                const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                status["part"] = describe_part(part, s.rank, host, slab, seconds);
                status["sampler"] = part.sampler;
            }
        } catch (const std::exception& e) {
            status = {{"ok", false}, {"rank", s.rank}, {"host", host}, {"error", e.what()}};
        }
    }
    send_string(status.dump(), 0, kTagStatus);
    if (status.contains("part")) send_part(part, mine.lattice, slab);
    part = SampledField();

    // The whole field's memory, while the root still gathers (its first touch is not free).
    SampledField field;
    if (status.contains("part")) {
        field.lattice = mine.lattice;
        field.precision = mine.options.precision;
        field.resize(mine.lattice.num_points());
    }
    const nlohmann::json outcome = nlohmann::json::parse(receive_string(0, kTagOutcome));
    if (!outcome.at("ok").get<bool>()) raise_outcome(outcome, setup_error);
    broadcast_field(field);
    field.sampler = outcome.at("sampler");
    field.timings = timings_from_json(outcome.at("timings"));
    return field;
}

nlohmann::json describe_this_process(int rank) {
    nlohmann::json self = {{"rank", rank}, {"host", host_name()}};
    MPI_Comm local;
    check_mpi(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &local), "MPI_Comm_split_type");
    int local_rank = 0, local_size = 1;
    MPI_Comm_rank(local, &local_rank);
    MPI_Comm_size(local, &local_size);
    MPI_Comm_free(&local);
    self["local_rank"] = local_rank;
    self["local_size"] = local_size;
    self["threads"] = std::max(1, resolve_thread_count(0) / std::max(1, local_size));
    const int devices = cuda_devices();
    self["gpus_on_host"] = devices;
    self["gpu"] = nullptr;
#if SDF_HAVE_CUDA
    if (devices > 0) {
        const int device = local_rank % devices;
        self["gpu"] = {{"device", device}, {"name", cuda::describe_device(device).value("name", std::string("?"))}};
    }
#endif
    return self;
}

/// This rank's place among the ranks of a running MPI; the root collects every rank's
/// description (kTagHello). Collective.
void join_ranks() {
    Session& s = session();
    MPI_Comm_rank(MPI_COMM_WORLD, &s.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &s.size);
    s.self = describe_this_process(s.rank);
    s.joined = true;
    if (s.rank != 0) {
        send_string(s.self.dump(), 0, kTagHello);
        return;
    }
    s.processes.push_back(s.self);
    for (int r = 1; r < s.size; ++r) s.processes.push_back(nlohmann::json::parse(receive_string(r, kTagHello)));
}

}  // namespace

DistributedScope::DistributedScope(int& argc, char**& argv) {
    if (!launched_by_mpi()) return;
    Session& s = session();
    int provided = 0;
    check_mpi(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
    s.started = true;
    join_ranks();
}

DistributedScope::~DistributedScope() {
    Session& s = session();
    if (!s.started) return;
    if (s.rank == 0 && !s.released && !s.collective && s.distribution == Distribution::LatticeSlabs) {
        const int32_t quit = int32_t(Command::Quit);
        for (int r = 1; r < s.size; ++r) send_bytes(&quit, sizeof quit, r, kTagCommand);
        s.released = true;
    }
    MPI_Finalize();
}

bool distributed_active() { return session().joined && session().size > 1; }
int distributed_rank() { return session().rank; }
int distributed_size() { return session().size; }
bool distributed_build() { return true; }

namespace {

/// Rank 0: what differs between every rank's settings (in rank order) and its own, one
/// clause per key: "--distribute: rank 0 has \"slabs\", rank 1 has \"runs\"". Empty when
/// every rank agrees.
std::string settings_differences(const std::vector<nlohmann::json>& settings) {
    const nlohmann::json& root = settings[0];
    std::vector<std::string> keys;
    for (const nlohmann::json& s : settings)
        for (const auto& [key, value] : s.items())
            if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
    std::string text;
    for (const std::string& key : keys) {
        const auto value_of = [&](const nlohmann::json& s) { return s.contains(key) ? s[key].dump() : std::string("nothing"); };
        std::map<std::string, std::vector<int>> others;  // value -> ranks
        for (size_t r = 1; r < settings.size(); ++r)
            if (value_of(settings[r]) != value_of(root)) others[value_of(settings[r])].push_back(int(r));
        if (others.empty()) continue;
        std::string clause = key + ": rank 0 has " + value_of(root);
        for (const auto& [value, ranks] : others) {
            std::string list;
            for (int r : ranks) list += (list.empty() ? "" : ", ") + std::to_string(r);
            clause += ", rank" + std::string(ranks.size() > 1 ? "s " : " ") + list + " ha" + (ranks.size() > 1 ? "ve " : "s ") + value;
        }
        text += (text.empty() ? "" : "; ") + clause;
    }
    return text;
}

}  // namespace

void require_same_settings_on_every_rank(const nlohmann::json& settings) {
    Session& s = session();
    if (!distributed_active()) return;
    std::string verdict;
    if (s.rank != 0) {
        send_string(settings.dump(), 0, kTagSettings);
        verdict = receive_string(0, kTagSettings);
    } else {
        std::vector<nlohmann::json> all = {settings};
        for (int r = 1; r < s.size; ++r) all.push_back(nlohmann::json::parse(receive_string(r, kTagSettings), nullptr, false));
        const std::string differences = settings_differences(all);
        if (!differences.empty())
            verdict = "the ranks were started with different options (every rank must get the same command line and "
                      "environment); nothing was run: " + differences;
        for (int r = 1; r < s.size; ++r) send_string(verdict, r, kTagSettings);
    }
    if (verdict.empty()) return;
    s.released = true;  // no worker waits for a command: each stops here
    throw std::runtime_error(verdict);
}

int serve_distributed_requests() {
    Worker worker;
    for (;;) {
        const std::string request = receive_string(0, kTagCommand);
        if (request.size() < sizeof(int32_t)) return 1;
        int32_t command = 0;
        std::memcpy(&command, request.data(), sizeof command);
        if (Command(command) == Command::Quit) return 0;
        if (Command(command) == Command::Write) worker.write(request);
        else worker.sample(request);
    }
}

std::unique_ptr<Sampler> make_field_sampler(const SamplerOptions& options) {
    if (!distributed_active()) return make_sampler(options);
    if (session().distribution == Distribution::Runs) return make_sampler(options_for_this_rank(options));
    return std::make_unique<DistributedSampler>(options);
}

void share_mesh_with_workers(const TriangleMesh& mesh) {
    if (!distributed_active()) return;
    session().meshes.emplace(mesh.content_sha256, mesh);
}

namespace {

/// The root's temporary channel files of a parallel write, at their final size; removed
/// unless moved into place.
class PreallocatedFiles {
public:
    PreallocatedFiles(const std::vector<FieldChannelFile>& files, int64_t points) {
        for (const FieldChannelFile& f : files) {
            FieldChannelFile t = f;
            t.path = unique_sibling_name(f.path, "tmp");
            const int fd = ::open(t.path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
            if (fd < 0) throw std::runtime_error(t.path + ": cannot create: " + std::strerror(errno));
            temps_.push_back(t);
            const off_t size = off_t(uint64_t(points) * f.bytes_per_point());
            const int e = ::ftruncate(fd, size) == 0 ? 0 : errno;
            ::close(fd);
            if (e != 0) throw std::runtime_error(t.path + ": cannot size it to " + std::to_string(size) + " bytes: " + std::strerror(e));
        }
    }
    ~PreallocatedFiles() {
        for (const FieldChannelFile& t : temps_)
            if (!t.path.empty()) ::unlink(t.path.c_str());
    }
    PreallocatedFiles(const PreallocatedFiles&) = delete;
    PreallocatedFiles& operator=(const PreallocatedFiles&) = delete;

    const std::vector<FieldChannelFile>& files() const { return temps_; }

    /// Renames file i to its final name (FieldReplacement::place).
    void place(FieldReplacement& replacement, size_t i) {
        replacement.place(i, temps_[i].path);
        temps_[i].path.clear();
    }

private:
    std::vector<FieldChannelFile> temps_;
};

/// Whether `field` is the one the ranks sampled last and still hold.
bool held_by_the_ranks(const SampledField& field) {
    const Session& s = session();
    const Session::HeldField& h = s.held;
    return distributed_active() && s.rank == 0 && s.distribution == Distribution::LatticeSlabs && h.valid &&
           field.distance.data() == h.distance && field.size() == h.lattice.num_points() &&
           lattice_to_json(field.lattice) == lattice_to_json(h.lattice) && field.sampler.is_object() &&
           field.sampler.contains("distributed") && field.sampler["distributed"] == h.record;
}

}  // namespace

std::string write_sampled_field(const std::string& header_path, const SampledField& field,
                                const FieldWriteOptions& options) {
    if (!held_by_the_ranks(field)) {
        write_field(header_path, field, options);
        return "root";
    }
    Session& s = session();
    const Session::HeldField held = s.held;
    s.held.valid = false;  // the workers release their slabs with this write, whatever happens
    const auto start = std::chrono::steady_clock::now();
    const std::filesystem::path parent = std::filesystem::path(header_path).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    require_storable(field, options, header_path);
    // Every target checked and the channels' final names chosen (field_replacement.h).
    FieldReplacement replacement(header_path, field_channel_files(header_path, field, options), options.overwrite);
    const std::vector<FieldChannelFile>& files = replacement.channels();
    PreallocatedFiles staged(files, field.size());

    ByteWriter request;
    request.put(int32_t(Command::Write));
    request.put_string(files_to_json(staged.files()).dump());
    for (int r = 1; r < s.size; ++r) send_bytes(request.bytes().data(), request.bytes().size(), r, kTagCommand);

    // Rank 0 writes its slab; a rank that cannot open the files (no shared file system)
    // leaves its slab to rank 0, which holds the whole field.
    std::vector<std::string> errors;
    nlohmann::json writes = nlohmann::json::array();
    ChannelFiles mine;
    bool mine_open = false;
    const std::string root_host = s.self["host"].get<std::string>();
    try {
        const auto t0 = std::chrono::steady_clock::now();
        std::string why;
        if (!mine.open(staged.files(), field.size(), why)) throw std::runtime_error(why);
        mine_open = true;
        maybe_inject_failure(0, "write");
        const uint64_t bytes = write_slab(mine, field, true, held.lattice, held.slabs[0]);
        writes.push_back({{"rank", 0}, {"written_by", 0}, {"write_bytes", bytes},
                          {"write_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}});
    } catch (const std::exception& e) {
        errors.push_back(rank_and_host(0, root_host) + ": " + e.what());
    }
    for (int r = 1; r < s.size; ++r) {
        const nlohmann::json status = nlohmann::json::parse(receive_string(r, kTagStatus));
        const std::string host = status.value("host", std::string("?"));
        if (!status.value("ok", false)) {
            errors.push_back(rank_and_host(r, host) + ": " + status.value("error", std::string("unknown error")));
        } else if (status.value("written", false)) {
            writes.push_back({{"rank", r}, {"written_by", r}, {"write_bytes", status["write_bytes"]},
                              {"write_seconds", status["write_seconds"]}});
        } else if (mine_open) {
            try {
                const auto t0 = std::chrono::steady_clock::now();
                const uint64_t bytes = write_slab(mine, field, true, held.lattice, held.slabs[size_t(r)]);
                writes.push_back({{"rank", r}, {"written_by", 0}, {"write_bytes", bytes},
                                  {"write_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()},
                                  {"why", status.value("why", std::string())}});
            } catch (const std::exception& e) {
                errors.push_back(rank_and_host(0, root_host) + ", writing the slab of rank " + std::to_string(r) + ": " + e.what());
            }
        }
    }
    try {
        mine.close();
    } catch (const std::exception& e) {
        errors.push_back(rank_and_host(0, root_host) + ": " + e.what());
    }
    if (!errors.empty()) {
        const std::filesystem::path named(header_path);  // not the staging directory's name
        std::string text = "parallel write of field " + (named.parent_path().filename() / named.filename()).string() + " failed on " + std::to_string(errors.size()) + " of " +
                           std::to_string(s.size) + " ranks: ";
        for (size_t i = 0; i < errors.size(); ++i) text += (i ? "; " : "") + errors[i];
        throw std::runtime_error(text);
    }
    for (size_t i = 0; i < files.size(); ++i) staged.place(replacement, i);
    replacement.commit(field);  // the header: the commit point

    // The manifest's record of the field: how its files were written, by whom.
    nlohmann::json& record = s.fields[held.field_index];
    record["write"] = "mpi-io";
    record["write_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    uint64_t total = 0;
    for (nlohmann::json& slab : record["slabs"])
        for (const nlohmann::json& w : writes)
            if (w["rank"] == slab["rank"]) {
                for (const char* key : {"written_by", "write_bytes", "write_seconds", "why"})
                    if (w.contains(key)) slab[key] = w[key];
                total += w["write_bytes"].get<uint64_t>();
            }
    record["write_bytes"] = total;
    return "mpi-io";
}

nlohmann::json distributed_description() {
    if (!distributed_active()) return nullptr;
    const Session& s = session();
    return {{"ranks", s.size},
            {"mode", s.distribution == Distribution::Runs ? "runs" : "lattice_slabs"},
            {"processes", s.processes},
            {"fields", s.fields}};
}

void set_distribution(Distribution d) { session().distribution = d; }
Distribution distribution() { return session().distribution; }

std::string broadcast_from_root(const std::string& text) {
    const Session& s = session();
    if (!distributed_active()) return text;
    if (s.rank != 0) return receive_string(0, kTagRuns);
    for (int r = 1; r < s.size; ++r) send_string(text, r, kTagRuns);
    return text;
}

nlohmann::json gather_to_root(const nlohmann::json& mine) {
    const Session& s = session();
    if (!distributed_active()) return nlohmann::json::array({mine});
    if (s.rank != 0) {
        send_string(mine.dump(), 0, kTagRuns);
        return nlohmann::json::array();
    }
    nlohmann::json all = nlohmann::json::array({mine});
    for (int r = 1; r < s.size; ++r) all.push_back(nlohmann::json::parse(receive_string(r, kTagRuns)));
    return all;
}

nlohmann::json this_process() { return session().self; }

std::string start_collective_distribution() {
    Session& s = session();
    if (s.joined) return s.started_by;
    int initialized = 0, finalized = 0;
    check_mpi(MPI_Initialized(&initialized), "MPI_Initialized");
    check_mpi(MPI_Finalized(&finalized), "MPI_Finalized");
    if (finalized) return "";
    if (initialized) {
        s.started_by = "another library";  // mpi4py, say: it ends MPI too
    } else if (launched_by_mpi()) {
        // Serialized: sample() releases the GIL, so any Python thread may call it (one at a time).
        int provided = 0;
        check_mpi(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided), "MPI_Init_thread");
        s.started = true;
        s.started_by = "sdf_lattices";
    } else {
        return "";
    }
    s.collective = true;
    join_ranks();
    return s.started_by;
}

void finish_collective_distribution() {
    Session& s = session();
    if (!s.started || !s.collective) return;
    s.started = false;
    s.joined = false;
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
}

SampledField sample_collectively(const PreparedMesh& mesh, const std::function<SamplingRequest()>& setup) {
    if (!distributed_active() || !session().collective) {
        const SamplingRequest request = setup();
        return make_sampler(request.options)->sample(mesh, request.lattice);
    }
    // One exchange at a time (MPI_THREAD_SERIALIZED; the messages of two would interleave).
    static std::mutex one_at_a_time;
    const std::lock_guard<std::mutex> lock(one_at_a_time);
    return session().rank == 0 ? collective_root(mesh, setup) : collective_worker(mesh, setup);
}

void abort_distributed(int code) {
    if (distributed_active()) MPI_Abort(MPI_COMM_WORLD, code);
}

nlohmann::json distributed_info() {
    const Session& s = session();
    nlohmann::json info = {{"mpi", true},
                           {"started_by", s.started_by.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.started_by)},
                           {"rank", s.rank},
                           {"size", s.size}};
    if (s.joined) {
        for (const auto& [key, value] : s.self.items()) info[key] = value;
        if (s.rank == 0 && s.size > 1) info["processes"] = s.processes;
    } else {
        char host[256] = {};
        if (::gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
        info["host"] = std::string(host);
    }
    return info;
}
void fail_here_if_asked() { maybe_inject_failure(session().rank); }

}  // namespace sdf
