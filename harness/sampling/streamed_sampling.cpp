#include "harness/sampling/streamed_sampling.h"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <future>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>

#include <fcntl.h>
#include <unistd.h>

#include "core/checked_math.h"
#include "core/lattice/lattice_fitting.h"
#include "core/parallel/parallel_for.h"
#include "harness/io/atomic_file.h"
#include "harness/io/field_replacement.h"
#include "harness/io/volume_grids.h"
#include "harness/resources/memory_budget.h"

namespace sdf {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

int64_t checked(std::optional<int64_t> v, const std::string& what) {
    if (!v) throw std::runtime_error(what + ": the size overflows 64 bits");
    return *v;
}

/// Points of one z-plane of the slab layout: a primary plane and, on BCC, a secondary one.
int64_t points_per_plane(const Lattice& l) {
    const int64_t primary = checked(checked_mul(l.resolution.x, l.resolution.y), "z-plane of " + lattice_notation(l));
    if (l.secondary_count() == 0) return primary;
    const Int3 s = l.secondary_resolution();
    return primary + int64_t(s.x) * s.y;
}

std::string errno_text() { return std::strerror(errno); }

/// The channel files being written: temporaries beside their final names, removed unless
/// committed.
class StagedChannels {
public:
    StagedChannels(const std::vector<FieldChannelFile>& channels, int64_t points) : channels_(channels) {
        for (const FieldChannelFile& c : channels_) {
            const std::string tmp = unique_sibling_name(c.path, "tmp");
            const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
            if (fd < 0) throw std::runtime_error(tmp + ": cannot create (" + errno_text() + ")");
            temps_.push_back(tmp);
            fds_.push_back(fd);
            const off_t size = off_t(checked(checked_mul(points, int64_t(c.bytes_per_point())), c.path));
            // Reserve the blocks now, so a full disk fails here rather than after the sampling;
            // file systems without fallocate get a sparse file of the final size.
            if (::fallocate(fd, 0, 0, size) != 0) {
                if (errno == ENOSPC) throw std::runtime_error(c.path + ": no space left for " + format_bytes(uint64_t(size)));
                if (::ftruncate(fd, size) != 0) throw std::runtime_error(tmp + ": cannot size (" + errno_text() + ")");
            }
        }
    }
    ~StagedChannels() {
        close_all();
        for (const std::string& t : temps_)
            if (!t.empty()) ::unlink(t.c_str());
    }
    StagedChannels(const StagedChannels&) = delete;
    StagedChannels& operator=(const StagedChannels&) = delete;

    /// Writes points [first, first + count) of `field` at lattice storage offset `offset`,
    /// chunk by chunk on kStreamWriteThreads threads (pwrite at distinct offsets): the
    /// conversion to the stored type, not the disk, limits one thread behind a fast sampler.
    void write(const SampledField& field, int64_t first, int64_t count, int64_t offset) {
        for (size_t c = 0; c < channels_.size(); ++c) {
            const size_t width = channels_[c].bytes_per_point();
            const int64_t chunks = (count + kStreamWriteChunk - 1) / kStreamWriteChunk;
            parallel_for(chunks, 1, kStreamWriteThreads, [&](int64_t begin, int64_t end) {
                for (int64_t k = begin; k < end; ++k) {
                    const int64_t done = k * kStreamWriteChunk, n = std::min(kStreamWriteChunk, count - done);
                    const std::vector<char> bytes = field_channel_bytes(field, channels_[c], size_t(first + done), size_t(n));
                    write_at(c, bytes.data(), bytes.size(), off_t(size_t(offset + done) * width));
                }
            });
        }
    }

    /// Writes `count` points of channel c, already in its stored bytes (`bytes`: count x the
    /// channel's bytes per point), at lattice storage offset `offset`, chunk by chunk on
    /// kStreamWriteThreads threads: nothing to convert, only pwrite.
    void write_bytes(size_t c, const char* bytes, int64_t count, int64_t offset) {
        const size_t width = channels_[c].bytes_per_point();
        const int64_t chunks = (count + kStreamWriteChunk - 1) / kStreamWriteChunk;
        parallel_for(chunks, 1, kStreamWriteThreads, [&](int64_t begin, int64_t end) {
            for (int64_t k = begin; k < end; ++k) {
                const int64_t done = k * kStreamWriteChunk, n = std::min(kStreamWriteChunk, count - done);
                write_at(c, bytes + size_t(done) * width, size_t(n) * width, off_t(size_t(offset + done) * width));
            }
        });
    }

    /// fsync and close every file, then rename each to its final name (FieldReplacement).
    void place_all(FieldReplacement& replacement) {
        for (size_t c = 0; c < fds_.size(); ++c)
            if (::fsync(fds_[c]) != 0) throw std::runtime_error(channels_[c].path + ": fsync failed (" + errno_text() + ")");
        close_all();
        for (size_t c = 0; c < temps_.size(); ++c) {
            replacement.place(c, temps_[c]);
            temps_[c].clear();  // renamed: the replacement owns it now
        }
    }

private:
    void write_at(size_t c, const char* bytes, size_t size, off_t at) {
        size_t done = 0;
        while (done < size) {
            const ssize_t n = ::pwrite(fds_[c], bytes + done, size - done, at + off_t(done));
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) throw std::runtime_error(channels_[c].path + ": write failed (" + errno_text() + ")");
            done += size_t(n);
        }
    }
    void close_all() {
        for (int fd : fds_) ::close(fd);
        fds_.clear();
    }

    std::vector<FieldChannelFile> channels_;
    std::vector<std::string> temps_;
    std::vector<int> fds_;
};

/// A file removed when it goes out of scope, unless its path was cleared (renamed into place).
struct TemporaryFile {
    explicit TemporaryFile(std::string p) : path(std::move(p)) {}
    ~TemporaryFile() {
        if (!path.empty()) ::unlink(path.c_str());
    }
    TemporaryFile(const TemporaryFile&) = delete;
    TemporaryFile& operator=(const TemporaryFile&) = delete;
    std::string path;
};

/// The stored bytes the plan's channel files hold, for samplers that produce them
/// (Sampler::sample_slab_stored).
StoredLayout stored_layout_of(const StreamPlan& plan, const StreamOptions& options) {
    StoredLayout layout;
    layout.float32 = options.write.dtype == FieldDtype::Float32;
    layout.gradient = options.gradient;
    layout.closest_triangle = false;
    for (const FieldChannelFile& c : plan.channels) layout.closest_triangle |= c.name == "closest_triangle";
    return layout;
}

/// The bytes of `channel` in a stored slab.
const char* stored_channel(const StoredSlab& slab, const FieldChannelFile& channel) {
    if (channel.name == "distance") return slab.distance;
    if (channel.name == "gradient") return slab.gradient;
    if (channel.name == "closest_triangle") return slab.closest_triangle;
    throw std::logic_error("stored slab: no channel " + channel.name);
}

}  // namespace

uint64_t estimate_fixed_bytes(const PreparedMesh& mesh) {
    return current_resident_bytes() + kStreamBvhBytesPerTriangle * uint64_t(mesh.triangles().size()) +
           (kStreamWriteThreads + 1) * uint64_t(kStreamWriteChunk) * 24;  // a conversion buffer per writing thread, with room
}

std::vector<LatticeSlab> StreamPlan::slab_list() const {
    std::vector<LatticeSlab> slabs;
    for (int z = 0; z < lattice.resolution.z; z += planes_per_slab)
        slabs.push_back({z, std::min(lattice.resolution.z, z + planes_per_slab)});
    return slabs;
}

nlohmann::json StreamPlan::to_json() const {
    nlohmann::json names = nlohmann::json::array();
    for (const FieldChannelFile& c : channels) names.push_back(c.name);
    return {{"points", points},
            {"slabs", slabs},
            {"planes_per_slab", planes_per_slab},
            {"slab_bytes", slab_bytes},
            {"memory_budget_bytes", memory_budget},
            {"fixed_bytes", fixed_bytes},
            {"peak_estimate_bytes", peak_estimate},
            {"bytes_per_point_sampled", bytes_per_point},
            {"output_bytes", output_bytes},
            {"channels", names}};
}

std::string StreamPlan::describe() const {
    std::string names;
    for (const FieldChannelFile& c : channels) names += (names.empty() ? "" : ", ") + c.name;
    std::string text = "lattice: " + lattice_notation(lattice) + " (" + std::to_string(points) + " points)\n";
    text += "slabs: " + std::to_string(slabs) + " of up to " + std::to_string(planes_per_slab) + " z-planes (" +
            format_bytes(slab_bytes) + " each while sampled; two held at a time)\n";
    text += "memory: budget " + format_bytes(memory_budget) + ", fixed part " + format_bytes(fixed_bytes) +
            ", estimated peak " + format_bytes(peak_estimate) + "\n";
    text += "output: " + format_bytes(output_bytes) + " in " + std::to_string(channels.size()) + " channel files (" + names + ")\n";
    return text;
}

StreamPlan plan_streamed_sampling(const Lattice& lattice, const StreamOptions& options) {
    StreamPlan plan;
    plan.lattice = lattice;
    plan.points = checked_lattice_points(lattice.type, lattice.resolution);
    plan.memory_budget = options.memory_budget;
    plan.fixed_bytes = options.fixed_bytes;
    SampledField layout;  // one point: the channel layout of write_field for these options
    layout.lattice = lattice;
    layout.resize(1);
    if (!options.gradient) layout.gradient.clear();
    plan.channels = field_channel_files(options.header_path, layout, options.write);
    for (const FieldChannelFile& c : plan.channels)
        plan.output_bytes += uint64_t(checked(checked_mul(plan.points, int64_t(c.bytes_per_point())), c.path));
    if (options.bytes_per_point == 0 || options.bytes_per_point > 4096)
        throw std::invalid_argument("streamed sampling: bytes per point must be in [1, 4096], got " +
                                    std::to_string(options.bytes_per_point));
    plan.bytes_per_point = options.bytes_per_point;
    const int64_t plane_bytes = checked(checked_mul(points_per_plane(lattice), int64_t(options.bytes_per_point)), "z-plane bytes");
    const uint64_t least = options.fixed_bytes + 2 * uint64_t(plane_bytes);
    if (options.memory_budget < least)
        throw std::runtime_error("memory budget " + format_bytes(options.memory_budget) + " is too small for " +
                                 lattice_notation(lattice) + ": the fixed part (libraries, mesh, BVH) takes " +
                                 format_bytes(options.fixed_bytes) + " and two slabs of one z-plane " +
                                 format_bytes(2 * uint64_t(plane_bytes)) + "; give at least " + format_bytes(least) + " (" + std::to_string(least) + " bytes)");
    const uint64_t planes = (options.memory_budget - options.fixed_bytes) / (2 * uint64_t(plane_bytes));
    plan.planes_per_slab = int(std::min<uint64_t>(planes, uint64_t(lattice.resolution.z)));
    if (options.max_planes_per_slab > 0) plan.planes_per_slab = std::min(plan.planes_per_slab, options.max_planes_per_slab);
    plan.slabs = (lattice.resolution.z + plan.planes_per_slab - 1) / plan.planes_per_slab;
    plan.slab_bytes = uint64_t(plan.planes_per_slab) * uint64_t(plane_bytes);
    plan.peak_estimate = options.fixed_bytes + 2 * plan.slab_bytes;
    return plan;
}

StreamResult sample_streamed(const BoundSampler& sampler, const SamplerOptions& sampler_options, const Lattice& lattice,
                             const StreamOptions& options, const MeshProvenance& mesh_provenance) {
    const auto start = Clock::now();
    const double w = sampler_options.band_width;
    require_band_width(w, "band width");
    StreamResult result;
    result.plan = plan_streamed_sampling(lattice, options);
    const StreamPlan& plan = result.plan;
    // Every target is checked before sampling: the field's header and channels (whose
    // final names are chosen now: field_replacement.h) and the .vdb.
    require_representable_band(w, options.write.dtype, "band width");
    FieldReplacement replacement(options.header_path, plan.channels, options.write.overwrite);
    std::unique_ptr<VdbNarrowBandBuilder> vdb;
    if (!options.vdb_path.empty()) {
        require_writable_target(options.vdb_path, options.write.overwrite);
        if (!(options.vdb_band > 0) || !std::isfinite(options.vdb_band))
            throw std::invalid_argument(options.vdb_path + ": the OpenVDB band must be a positive width, got " +
                                        std::to_string(options.vdb_band));
        require_representable_band(options.vdb_band, FieldDtype::Float32, options.vdb_path + ": the OpenVDB band");
        vdb = std::make_unique<VdbNarrowBandBuilder>(lattice, options.vdb_band, options.gradient);
    }
    StagedChannels files(replacement.channels(), plan.points);

    SampledField& header = result.header;
    header.lattice = lattice;
    header.precision = sampler_options.precision;
    header.mesh = mesh_provenance;
    std::future<void> writing;  // the previous slab's write, overlapping this slab's sampling
    const std::vector<LatticeSlab> slabs = plan.slab_list();
    // Without a .vdb (whose builder reads the values), a sampler that stores the slab in the
    // files' bytes where it computes (the CUDA BVH sampler) leaves the host only the writes.
    const std::optional<StoredLayout> stored_layout =
        vdb ? std::nullopt : std::optional<StoredLayout>(stored_layout_of(plan, options));
    auto account = [&](const SampledField& info) {
        header.sampler.merge(info.sampler);  // the counters of every slab
        header.timings.kernel += info.timings.kernel;
        header.timings.upload += info.timings.upload;
        header.timings.download += info.timings.download;
        header.timings.point_triangle_pairs += info.timings.point_triangle_pairs;
    };
    auto wait_for_writer = [&] {
        const auto wait_start = Clock::now();
        if (writing.valid()) writing.get();  // rethrows the writer's error; frees its slab
        result.write_wait_seconds += seconds_since(wait_start);
    };
    // A slab whose allocation fails: named with its planes, points and bytes.
    auto slab_out_of_memory = [&](const LatticeSlab& slab) {
        return out_of_memory_message("sampling z-planes " + std::to_string(slab.z_begin) + "-" + std::to_string(slab.z_end - 1) +
                                         " of " + lattice_notation(lattice) + " (" +
                                         std::to_string(slab_point_count(lattice, slab)) + " points) for " + options.header_path,
                                     uint64_t(slab_point_count(lattice, slab)) * plan.bytes_per_point);
    };
    for (size_t s = 0; s < slabs.size(); ++s) {
        const LatticeSlab slab = slabs[s];
        const auto slab_start = Clock::now();
        std::optional<StoredSlab> stored;
        try {
            if (stored_layout) stored = sampler.sample_slab_stored(lattice, slab, *stored_layout);
        } catch (const std::bad_alloc&) {
            throw std::runtime_error(slab_out_of_memory(slab));
        }
        if (stored) {
            if (stored->points != slab_point_count(lattice, slab))
                throw std::logic_error("sampler stored " + std::to_string(stored->points) + " points for a slab of " +
                                       std::to_string(slab_point_count(lattice, slab)));
            if (w > 0) {
                result.band.in_band += stored->band.in_band;
                result.band.outside += stored->band.outside;
            }
            fault_point("sampled slab " + std::to_string(s + 1) + " of " + std::to_string(slabs.size()));
            account(stored->info);
            const double sampled = seconds_since(slab_start);
            wait_for_writer();
            auto bytes = std::make_shared<StoredSlab>(std::move(*stored));
            writing = std::async(std::launch::async, [&files, &plan, &lattice, slab, bytes] {
                const StorageRange primary = slab_storage(lattice, slab, 0), secondary = slab_storage(lattice, slab, 1);
                for (size_t c = 0; c < plan.channels.size(); ++c) {
                    const char* data = stored_channel(*bytes, plan.channels[c]);
                    files.write_bytes(c, data, primary.count, primary.offset);
                    files.write_bytes(c, data + size_t(primary.count) * plan.channels[c].bytes_per_point(), secondary.count,
                                      secondary.offset);
                }
            });
            if (options.progress)
                std::cerr << "sdf-sample: slab " << s + 1 << "/" << slabs.size() << " (z-planes " << slab.z_begin << "-"
                          << slab.z_end - 1 << "): sampled in " << sampled << " s (stored on the device)\n";
            continue;
        }
        std::shared_ptr<SampledField> field;
        try {
            field = std::make_shared<SampledField>(sampler.sample_slab(lattice, slab));
        } catch (const std::bad_alloc&) {
            throw std::runtime_error(slab_out_of_memory(slab));
        }
        if (field->size() != slab_point_count(lattice, slab))
            throw std::logic_error("sampler returned " + std::to_string(field->size()) + " points for a slab of " +
                                   std::to_string(slab_point_count(lattice, slab)));
        if (w > 0 && field->closest_triangle.empty() && field->sampler.band) {
            // A sparse band's slab held without triangles (SparseBandSlabs): banded already,
            // counted from the band's mask.
            result.band.in_band += field->sampler.band->points_in_band;
            result.band.outside += field->sampler.band->points_outside;
        } else if (w > 0) {
            const NarrowBandCounts c = apply_narrow_band(*field, w);
            result.band.in_band += c.in_band;
            result.band.outside += c.outside;
            if (!field->sampler.band) field->sampler.band = narrow_band_provenance(w, c, "post-processed by sdf-sample");
        }
        fault_point("sampled slab " + std::to_string(s + 1) + " of " + std::to_string(slabs.size()));
        account(*field);
        const double sampled = seconds_since(slab_start);
        wait_for_writer();
        writing = std::async(std::launch::async, [&files, &vdb, &lattice, slab, field] {
            const StorageRange primary = slab_storage(lattice, slab, 0), secondary = slab_storage(lattice, slab, 1);
            files.write(*field, 0, primary.count, primary.offset);
            files.write(*field, primary.count, secondary.count, secondary.offset);
            if (vdb) {
                vdb->add(*field, 0, primary.count, primary.offset);
                vdb->add(*field, primary.count, secondary.count, secondary.offset);
            }
        });
        if (options.progress)
            std::cerr << "sdf-sample: slab " << s + 1 << "/" << slabs.size() << " (z-planes " << slab.z_begin << "-"
                      << slab.z_end - 1 << "): sampled in " << sampled << " s\n";
    }
    wait_for_writer();
    fault_point("wrote the channels of " + options.header_path);
    files.place_all(replacement);
    // The .vdb is written whole under a temporary name before the field's commit, and renamed
    // over the old one right after it: each file is old or new whole at every instant.
    TemporaryFile vdb_file(vdb ? unique_sibling_name(options.vdb_path, "tmp") : std::string());
    if (vdb) {
        vdb->write(vdb_file.path);
        sync_file(vdb_file.path);
        result.vdb_active_points = vdb->active_points();
    }
    result.seconds = seconds_since(start);
    result.peak_resident_bytes = peak_resident_bytes();
    header.timings.total = result.seconds;
    nlohmann::json streaming = plan.to_json();
    streaming["seconds"] = result.seconds;
    streaming["write_wait_seconds"] = result.write_wait_seconds;
    streaming["peak_resident_bytes"] = result.peak_resident_bytes;
    if (vdb)
        streaming["vdb"] = {{"file", fs::path(options.vdb_path).filename().string()},
                            {"band", options.vdb_band},
                            {"active_points", result.vdb_active_points}};
    header.sampler.details["streaming"] = streaming;
    replacement.commit(header);  // the commit point: the header names the new channels
    if (vdb) {
        fault_point("rename " + vdb_file.path + " to " + options.vdb_path);
        if (options.write.overwrite == Overwrite::Allow) fs::rename(vdb_file.path, options.vdb_path);
        else if (!rename_no_replace(vdb_file.path, options.vdb_path))
            throw std::runtime_error(options.vdb_path + ": appeared while sampling; refusing to overwrite it (the field " +
                                     options.header_path + " was written)");
        vdb_file.path.clear();
    }
    return result;
}

}  // namespace sdf
