/// @file mpi_transport.h
/// @brief Point-to-point messages between the ranks of a distributed run (MPI-only part of
/// sdf_distributed; MPI's headers stay private to the library).
///
/// Every message is a size (uint64) then the bytes in chunks of at most 1 GiB (MPI counts
/// are ints). Waiting ranks poll with short sleeps instead of MPI's busy wait, so that an
/// idle rank does not take a core from the ranks that compute. The tags name the
/// conversations (docs/distributed.md):
///   root -> worker  kTagCommand  a Command (wire_codec.h) and its arguments
///   worker -> root  kTagStatus   JSON: ok or the error, host, timings, the slab's sampler
///   worker -> root  kTagData     (when ok) distance, gradient, closest triangle; each as the
///                                slab's primary part then its secondary part
///   worker -> root  kTagHello    at start: rank, host, local rank, threads, GPU
///   both ways       kTagSettings every rank's command-line settings, then the root's verdict
///   both ways       kTagRuns     runs mode: the staging directory, then each rank's share
///   root -> worker  kTagOutcome  collective sampling: the field's provenance or the error
#pragma once

#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace sdf::mpi {

constexpr int kTagCommand = 1, kTagStatus = 2, kTagData = 3, kTagHello = 4, kTagRuns = 5, kTagOutcome = 6,
              kTagSettings = 7;
constexpr size_t kChunkBytes = size_t(1) << 30;

/// Throws "MPI: <what>: <MPI's text>" unless `code` is MPI_SUCCESS.
void check_mpi(int code, const char* what);

/// Waits for `request` without spinning a core.
void wait_politely(MPI_Request& request);

void send_bytes(const void* data, size_t bytes, int dest, int tag);
void send_string(const std::string& s, int dest, int tag);
std::string receive_string(int source, int tag);
/// Receives exactly `bytes` into `data`; a different size is a protocol error.
void receive_into(void* data, size_t bytes, int source, int tag);
/// Rank 0's `bytes` at `data` on every rank (collective), in chunks of at most 1 GiB.
void broadcast_bytes(void* data, size_t bytes);

/// MPI's name of this processor (the host).
std::string host_name();
/// "rank 2 (host node7)", for messages.
std::string rank_and_host(int rank, const std::string& host);

}  // namespace sdf::mpi
