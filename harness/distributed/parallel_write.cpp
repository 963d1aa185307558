// The field files of a distributed field written by the ranks with MPI-IO (parallel_write.h),
// and the root's side of it, write_sampled_field (harness/distributed/distributed.h).
#include "harness/distributed/parallel_write.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "harness/distributed/distributed.h"
#include "harness/distributed/fault_injection.h"
#include "harness/distributed/mpi_session.h"
#include "harness/distributed/mpi_transport.h"
#include "harness/distributed/wire_codec.h"
#include "harness/io/field_replacement.h"

namespace sdf {
namespace mpi {

/// Points converted to the stored dtype at a time by a parallel write (bounds its buffer:
/// 96 MiB for a float64 gradient).
constexpr size_t kWritePoints = size_t(1) << 22;

ChannelFiles::~ChannelFiles() {
    for (MPI_File& h : handles_) MPI_File_close(&h);  // after a failure: the caller is already failing
}

bool ChannelFiles::open(const std::vector<FieldChannelFile>& files, int64_t points, std::string& why) {
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

uint64_t ChannelFiles::write(const SampledField& source, size_t first, size_t count, int64_t offset) {
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

void ChannelFiles::close() {
    for (size_t c = 0; c < handles_.size(); ++c)
        check_mpi(MPI_File_sync(handles_[c]), ("MPI_File_sync " + files_[c].path).c_str());
    while (!handles_.empty()) {
        const std::string path = files_[handles_.size() - 1].path;
        MPI_File h = handles_.back();
        handles_.pop_back();
        check_mpi(MPI_File_close(&h), ("MPI_File_close " + path).c_str());
    }
}

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
           lattice_to_json(field.lattice) == lattice_to_json(h.lattice) && field.sampler.details.contains("distributed") &&
           field.sampler.details.at("distributed") == h.record;
}

}  // namespace
}  // namespace mpi

using namespace mpi;

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

}  // namespace sdf
