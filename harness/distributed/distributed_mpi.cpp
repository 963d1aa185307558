// The MPI side of harness/distributed/distributed.h (docs/distributed.md).
//
// Messages, all point to point between the root (rank 0) and one worker, each a size
// (uint64) then the bytes in chunks of at most 1 GiB (MPI counts are ints):
//   root -> worker  kTagCommand  Sample request (options, lattice, slabs, mesh when new) or Quit
//   worker -> root  kTagStatus   JSON: ok or the error, host, timings, the slab's sampler
//   worker -> root  kTagData     (when ok) distance, gradient, closest triangle; each as the
//                                slab's primary part then its secondary part
//   worker -> root  kTagHello    at start: rank, host, local rank, threads, GPU
//   root -> worker  kTagCommand  Write: the channel files (temporary names) of the field the
//                                ranks sampled last; the worker writes its slab into them with
//                                MPI-IO and answers with a kTagStatus JSON (bytes, seconds, or
//                                the error). Workers keep their last slab until then.
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
#include <optional>
#include <stdexcept>
#include <thread>
#include <type_traits>

#include "core/lattice/lattice_fitting.h"
#include "core/parallel/parallel_for.h"
#include "core/sampling/sampler_results.h"
#include "harness/build_config.h"
#include "harness/distributed/slab_plan.h"
#include "harness/sampling/sampler_table.h"
#if SDF_HAVE_CUDA
#include "cuda/cuda_device.h"
#endif

namespace sdf {
namespace {

constexpr int kTagCommand = 1, kTagStatus = 2, kTagData = 3, kTagHello = 4, kTagRuns = 5;
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
            {"points_per_thread", o.points_per_thread}};
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
        for (int p = 0; p < 2; ++p) {
            const StorageRange r = slab_storage(lattice, slab, p);
            const size_t first = p == 0 ? 0 : size_t(slab_storage(lattice, slab, 0).count);
            const size_t n = part.size() == 0 ? 0 : size_t(r.count);
            send_bytes(part.distance.data() + first, n * sizeof(double), 0, kTagData);
            send_bytes(part.gradient.data() + first, n * sizeof(Vec3d), 0, kTagData);
            send_bytes(part.closest_triangle.data() + first, n * sizeof(int32_t), 0, kTagData);
        }
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

// ---- The root's sampler -------------------------------------------------------------------

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

        std::vector<std::string> errors;
        nlohmann::json parts = nlohmann::json::array();
        nlohmann::json sampler_json;
        try {
            const auto t0 = std::chrono::steady_clock::now();
            maybe_inject_failure(0);
            const SampledField part = sample_part(*local_, mesh, lattice, plan.slabs[0]);
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            place_part(field, lattice, plan.slabs[0], part);
            parts.push_back(describe_part(part, 0, s.self["host"].get<std::string>(), plan.slabs[0], seconds));
            sampler_json = part.sampler;
        } catch (const std::exception& e) {
            errors.push_back(rank_and_host(0, s.self["host"].get<std::string>()) + ": " + e.what());
        }
        // Every worker answers, failed or not, so the exchange ends in step on every rank.
        for (int r = 1; r < s.size; ++r) {
            const nlohmann::json status = nlohmann::json::parse(receive_string(r, kTagStatus));
            const std::string host = status.value("host", std::string("?"));
            if (!status.value("ok", false)) {
                errors.push_back(rank_and_host(r, host) + ": " + status.value("error", std::string("unknown error")));
                continue;
            }
            receive_part(field, lattice, plan.slabs[size_t(r)], r);
            parts.push_back(status["part"]);
            if (!sampler_json.is_object() && status["sampler"].is_object()) sampler_json = status["sampler"];
        }
        if (!errors.empty()) {
            std::string text = "distributed sampling of " + lattice_notation(lattice) + " failed on " +
                               std::to_string(errors.size()) + " of " + std::to_string(s.size) + " ranks: ";
            for (size_t i = 0; i < errors.size(); ++i) text += (i ? "; " : "") + errors[i];
            throw std::runtime_error(text);
        }
        const auto end = std::chrono::steady_clock::now();
        finish_provenance(field, plan, parts, sampler_json, std::chrono::duration<double>(end - start).count(),
                          std::chrono::duration<double>(end - sampling_start).count());
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

    static void place_part(SampledField& field, const Lattice& lattice, const LatticeSlab& slab, const SampledField& part) {
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

    static void receive_part(SampledField& field, const Lattice& lattice, const LatticeSlab& slab, int rank) {
        for (int p = 0; p < 2; ++p) {
            const StorageRange r = slab_storage(lattice, slab, p);
            const size_t n = size_t(r.count), at = size_t(r.offset);
            receive_into(field.distance.data() + at, n * sizeof(double), rank, kTagData);
            receive_into(field.gradient.data() + at, n * sizeof(Vec3d), rank, kTagData);
            receive_into(field.closest_triangle.data() + at, n * sizeof(int32_t), rank, kTagData);
        }
    }

    /// The field's provenance: the root's slab sampler (when its slab was empty, the first
    /// worker's) with the whole run's counts, and "distributed".
    void finish_provenance(SampledField& field, const SlabPlan& plan, nlohmann::json parts,
                           nlohmann::json sampler_json, double total_seconds, double sampling_seconds) {
        Session& s = session();
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
            sampler_json = {{"backend", options_.backend}, {"method", options_.method},
                            {"kernel", options_.kernel}, {"precision", precision_name(options_.precision)}};
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
        if (field.lattice.type == LatticeType::BCC && options_.bcc_strategy == BccStrategy::DoubleResolution)
            d["slab_bcc_strategy"] = "two_grids";  // lattice_slab.h: the same positions, the same samples
        sampler_json["distributed"] = d;
        field.sampler = sampler_json;
        field.timings.total = total_seconds;
        field.timings.kernel = sampling_seconds;
        field.timings.upload = upload;
        field.timings.download = download;
        field.timings.point_triangle_pairs = pairs;
        s.fields.push_back(d);
    }

    SamplerOptions options_;
    std::unique_ptr<Sampler> local_;
};

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

}  // namespace

DistributedScope::DistributedScope(int& argc, char**& argv) {
    if (!launched_by_mpi()) return;
    Session& s = session();
    int provided = 0;
    check_mpi(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
    s.started = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &s.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &s.size);
    s.self = describe_this_process(s.rank);
    if (s.rank != 0) {
        send_string(s.self.dump(), 0, kTagHello);
        return;
    }
    s.processes.push_back(s.self);
    for (int r = 1; r < s.size; ++r) s.processes.push_back(nlohmann::json::parse(receive_string(r, kTagHello)));
}

DistributedScope::~DistributedScope() {
    Session& s = session();
    if (!s.started) return;
    if (s.rank == 0 && !s.released && s.distribution == Distribution::LatticeSlabs) {
        const int32_t quit = int32_t(Command::Quit);
        for (int r = 1; r < s.size; ++r) send_bytes(&quit, sizeof quit, r, kTagCommand);
        s.released = true;
    }
    MPI_Finalize();
}

bool distributed_active() { return session().started && session().size > 1; }
int distributed_rank() { return session().rank; }
int distributed_size() { return session().size; }
bool distributed_build() { return true; }

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

    /// Moves file i to `final_path` (refused if it exists, unless overwriting is allowed).
    void move_into_place(size_t i, const std::string& final_path, Overwrite overwrite) {
        if (overwrite == Overwrite::Forbid) {
            if (!rename_no_replace(temps_[i].path, final_path))
                throw std::runtime_error(final_path + ": already exists; refusing to overwrite a field");
        } else {
            std::filesystem::rename(temps_[i].path, final_path);
        }
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
    const std::vector<FieldChannelFile> files = field_channel_files(header_path, field, options);
    std::vector<std::string> targets = {header_path};
    for (const FieldChannelFile& f : files) targets.push_back(f.path);
    if (options.overwrite == Overwrite::Forbid)
        for (const std::string& t : targets)
            if (std::filesystem::exists(t)) throw std::runtime_error(t + ": already exists; refusing to overwrite a field");
    const std::filesystem::path parent = std::filesystem::path(header_path).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
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
    std::vector<std::string> moved;
    try {
        for (size_t i = 0; i < files.size(); ++i) {
            staged.move_into_place(i, files[i].path, options.overwrite);
            moved.push_back(files[i].path);
        }
        write_field_header(header_path, field, files, options.overwrite);
    } catch (...) {
        if (options.overwrite == Overwrite::Forbid)
            for (const std::string& m : moved) ::unlink(m.c_str());  // all new: leave none behind
        throw;
    }

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
void fail_here_if_asked() { maybe_inject_failure(session().rank); }

}  // namespace sdf
