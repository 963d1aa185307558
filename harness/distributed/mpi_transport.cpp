// Point-to-point messages between the ranks (mpi_transport.h).
#include "harness/distributed/mpi_transport.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <thread>

namespace sdf::mpi {

namespace {

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

}  // namespace

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


void broadcast_bytes(void* data, size_t bytes) {
    char* p = static_cast<char*>(data);
    for (size_t off = 0; off < bytes; off += kChunkBytes)
        check_mpi(MPI_Bcast(p + off, int(std::min(kChunkBytes, bytes - off)), MPI_BYTE, 0, MPI_COMM_WORLD), "MPI_Bcast");
}

std::string host_name() {
    char name[MPI_MAX_PROCESSOR_NAME];
    int length = 0;
    MPI_Get_processor_name(name, &length);
    return std::string(name, size_t(length));
}

std::string rank_and_host(int rank, const std::string& host) { return "rank " + std::to_string(rank) + " (host " + host + ")"; }

}  // namespace sdf::mpi
