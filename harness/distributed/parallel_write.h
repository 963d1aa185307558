/// @file parallel_write.h
/// @brief The field files of a distributed field written by every rank, each its own slab's
/// bytes, with MPI-IO (write_sampled_field in distributed.h is the root's side; the
/// workers' side is Worker::write). MPI-only part of sdf_distributed.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/sampling/sampler.h"
#include "harness/io/field_file.h"

namespace sdf::mpi {

/// One rank's handles on the channel files of a parallel write. Each file is opened on
/// MPI_COMM_SELF and written with independent MPI_File_write_at calls: no collective call,
/// so a rank that fails cannot hang the others; its status message to the root, sent after
/// MPI_File_sync and MPI_File_close, is the barrier.
class ChannelFiles {
public:
    ChannelFiles() = default;
    ChannelFiles(const ChannelFiles&) = delete;
    ChannelFiles& operator=(const ChannelFiles&) = delete;
    ~ChannelFiles();

    /// Opens the root's files; false, saying why, when this rank cannot (no shared file
    /// system) or sees another file of that name (its size is not the root's preallocation).
    bool open(const std::vector<FieldChannelFile>& files, int64_t points, std::string& why);

    /// Writes points [first, first + count) of `source` at lattice storage offset `offset`
    /// of every channel; returns the bytes written.
    uint64_t write(const SampledField& source, size_t first, size_t count, int64_t offset);

    /// Flushes every file to storage and closes it.
    void close();

private:
    std::vector<FieldChannelFile> files_;
    std::vector<MPI_File> handles_;
};

/// Writes `slab` of `source` (the whole field, or a rank's part: its primary points, then

/// Writes `slab` of `source` (the whole field, or a rank's part: its primary points, then
/// its secondary ones) at its storage offsets; returns the bytes written.
uint64_t write_slab(ChannelFiles& files, const SampledField& source, bool source_is_whole, const Lattice& lattice,
                    const LatticeSlab& slab);

}  // namespace sdf::mpi
