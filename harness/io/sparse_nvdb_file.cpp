/// @file sparse_nvdb_file.cpp
/// @brief The sparse band's NanoVDB writer (sparse_nvdb_file.h): the grids of
/// sparse_nvdb_grids.h streamed to a temporary, which is then synced and placed
/// (write_through_temporary).
#include "harness/io/sparse_nvdb_file.h"

#if SDF_HAVE_NANOVDB
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <future>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/io/IO.h>

#include "core/host_memory.h"
#include "core/parallel/parallel_for.h"
#include "harness/io/sparse_nvdb_grids.h"
#endif

namespace sdf {

#if SDF_HAVE_NANOVDB
namespace {

using Leaf = nanovdb::NanoLeaf<float>;
using Lower = nanovdb::NanoLower<float>;

void write_at(int fd, const char* data, uint64_t bytes, uint64_t at, const std::string& target) {
    while (bytes > 0) {
        const ssize_t n = ::pwrite(fd, data, size_t(std::min<uint64_t>(bytes, uint64_t(1) << 30)), off_t(at));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0)
            throw std::runtime_error(target + ": writing the NanoVDB grids failed (" + (n < 0 ? std::strerror(errno) : "no progress") + ")");
        data += n;
        bytes -= uint64_t(n);
        at += uint64_t(n);
    }
}

/// Leaves a window holds: 32Ki (67 MiB), two windows, one filling while the other is written.
constexpr uint64_t kWindowLeaves = uint64_t(1) << 15;
constexpr uint64_t kLeavesOfALower = uint64_t(1) << (3 * Lower::LOG2DIM);  // a window holds at least one lower node's

// path: the temporary written; target: the name the messages give. The file io::writeGrids
// writes (one segment per grid: its header, metadata and name, then the grid), streamed: the
// leaves, a window of lower nodes' at a time, are filled on every core while the previous
// window is written; each grid's top part and segment header last, at their places, once its
// statistics are known. Host memory: the band, the tops and the two windows.
void write_grids(const SparseBandField& band, const std::string& path, const std::string& target, uint64_t window_capacity,
                 SparseNvdbCounts& counts) {
    const SparseNanoPlan plan(band, target);
    // A fresh temporary (write_through_temporary's unique name): never one a link points at.
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error(target + ": cannot open a file beside it for writing (" + std::strerror(errno) + ")");
    struct Closer {
        int fd;
        ~Closer() {
            if (fd >= 0) ::close(fd);
        }
    } closer{fd};
    uint64_t file_at = 0;
    for (int c = 0; c < plan.grids(); ++c) {
        const SparseNanoPlan::GridPlan& g = plan.grid(c);
        const uint64_t prefix = sizeof(nanovdb::io::FileHeader) + sizeof(nanovdb::io::FileMetaData) + g.name.size() + 1;
        const uint64_t window_leaves = std::min<uint64_t>(g.leaves(), std::max(window_capacity, kLeavesOfALower));
        require_host_bytes(g.leaf_at + 2 * window_leaves * Leaf::DataType::memUsage(),
                           target + ": the NanoVDB grid's nodes and two windows of its " + std::to_string(g.leaves()) + " leaves");
        nanovdb::HostBuffer top_buffer = nanovdb::HostBuffer::create(g.leaf_at);
        char* top = static_cast<char*>(top_buffer.data());
        // The futures after the windows: on an exception their destructors, first, wait for
        // the writes still reading the windows.
        nanovdb::HostBuffer windows[2];
        std::future<void> written[2];
        for (nanovdb::HostBuffer& w : windows) {
            w = nanovdb::HostBuffer::create(std::max<uint64_t>(window_leaves, 1) * Leaf::DataType::memUsage());
            advise_huge_pages(w.data(), w.size());
        }
        std::vector<NanoNodeStats> lower_stats(g.lowers());
        std::atomic<int64_t> voxels{0}, inside_tiles{0};
        int window = 0;
        for (size_t n0 = 0; n0 < g.lowers();) {
            // The next lower nodes whose leaves fit the window (a lower node holds at most 4096).
            const size_t first_leaf = plan.leaves_of_lower(c, n0).first;
            size_t n1 = n0 + 1;
            while (n1 < g.lowers() && plan.leaves_of_lower(c, n1).second - first_leaf <= window_leaves) ++n1;
            if (written[window].valid()) written[window].get();  // its previous write is done
            Leaf* leaves = static_cast<Leaf*>(windows[window].data());
            parallel_for(int64_t(n1 - n0), 1, 0, [&](int64_t k0, int64_t k1) {
                int64_t on = 0, inside = 0;
                for (int64_t k = k0; k < k1; ++k) {
                    const size_t n = n0 + size_t(k);
                    lower_stats[n] = plan.build_lower(c, n, top, leaves + (plan.leaves_of_lower(c, n).first - first_leaf), on, inside);
                }
                voxels += on;
                inside_tiles += inside;
            });
            const size_t last_leaf = plan.leaves_of_lower(c, n1 - 1).second;
            const uint64_t bytes = (last_leaf - first_leaf) * Leaf::DataType::memUsage();
            const uint64_t at = file_at + prefix + g.leaf_at + first_leaf * Leaf::DataType::memUsage();
            written[window] = std::async(std::launch::async, [=, &target] {
                write_at(fd, reinterpret_cast<const char*>(leaves), bytes, at, target);
            });
            window ^= 1;
            n0 = n1;
        }
        for (std::future<void>& f : written)
            if (f.valid()) f.get();
        plan.finish(c, top, lower_stats, voxels.load());

        // The segment's header and metadata, as io::writeGrid writes them for this grid.
        const auto& grid_data = *reinterpret_cast<const nanovdb::GridData*>(top);
        nanovdb::io::Segment segment(nanovdb::io::Codec::NONE);
        segment.header.gridCount = 1;
        segment.meta.emplace_back(g.size, nanovdb::io::Codec::NONE, grid_data);
        segment.meta.back().fileSize = g.size;  // uncompressed
        std::ostringstream head;
        segment.write(head);
        const std::string bytes = head.str();
        if (bytes.size() != prefix) throw std::logic_error(target + ": unexpected NanoVDB segment header size");
        write_at(fd, bytes.data(), bytes.size(), file_at, target);
        write_at(fd, top, g.leaf_at, file_at + prefix, target);
        file_at += prefix + g.size;

        counts.leaves += int64_t(g.leaves());
        counts.active_voxels += voxels.load();
        counts.inside_tiles += inside_tiles.load();
        counts.bytes += int64_t(g.size);
    }
    if (::close(closer.fd) != 0) {
        closer.fd = -1;
        throw std::runtime_error(target + ": writing the NanoVDB grids failed (" + std::strerror(errno) + ")");
    }
    closer.fd = -1;
}

}  // namespace

bool nanovdb_available() { return true; }

SparseNvdbCounts write_sparse_band_nvdb(const SparseBandField& band, const std::string& path, Overwrite overwrite) {
    return write_sparse_band_nvdb_windows(band, path, overwrite, kWindowLeaves);
}

SparseNvdbCounts write_sparse_band_nvdb_windows(const SparseBandField& band, const std::string& path, Overwrite overwrite,
                                                uint64_t window_leaves) {
    check_band_for_nanovdb(band, path);  // before a temporary is made
    SparseNvdbCounts counts;
    write_through_temporary(path, overwrite,
                            [&](const std::string& temporary) { write_grids(band, temporary, path, window_leaves, counts); });
    return counts;
}

#else

bool nanovdb_available() { return false; }

SparseNvdbCounts write_sparse_band_nvdb(const SparseBandField&, const std::string& path, Overwrite) {
    throw std::runtime_error(path + ": this build has no NanoVDB support (its headers were not found at configure time: "
                                    "set SDF_NANOVDB_DIR to the folder holding nanovdb/NanoVDB.h)");
}

#endif

}  // namespace sdf
