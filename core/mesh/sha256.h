/// @file sha256.h
/// @brief SHA-256 digests (OpenSSL) of files and byte buffers, as lowercase hex.
#pragma once

#include <cstddef>
#include <string>

namespace sdf {

std::string sha256_hex(const void* data, size_t size);
/// Throws std::runtime_error naming the file if it cannot be read.
std::string sha256_of_file(const std::string& path);

}  // namespace sdf
