#include "core/io/text_file.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace sdf {
namespace fs = std::filesystem;

std::string file_kind(const std::string& path) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    switch (st.type()) {
        case fs::file_type::regular: return "a regular file";
        case fs::file_type::directory: return "a directory";
        case fs::file_type::fifo: return "a FIFO";
        case fs::file_type::socket: return "a socket";
        case fs::file_type::character: return "a character device";
        case fs::file_type::block: return "a block device";
        case fs::file_type::not_found: return "missing";
        default: return ec ? "unreadable (" + ec.message() + ")" : "not a regular file";
    }
}

void require_regular_file(const std::string& path, const std::string& what) {
    const std::string kind = file_kind(path);
    if (kind == "a regular file") return;
    if (kind == "missing") throw std::runtime_error(path + ": " + what + " not found");
    throw std::runtime_error(path + ": cannot read " + what + ": it is " + kind + ", not a regular file");
}

void reject_wide_encodings(std::string_view bytes, const std::string& path, const std::string& what) {
    const auto starts = [&](std::initializer_list<uint8_t> mark) {
        if (bytes.size() < mark.size()) return false;
        size_t i = 0;
        for (uint8_t m : mark)
            if (uint8_t(bytes[i++]) != m) return false;
        return true;
    };
    // UTF-32 LE begins like UTF-16 LE, so test it first.
    const char* encoding = starts({0xFF, 0xFE, 0x00, 0x00})   ? "UTF-32LE"
                           : starts({0x00, 0x00, 0xFE, 0xFF}) ? "UTF-32BE"
                           : starts({0xFF, 0xFE})             ? "UTF-16LE"
                           : starts({0xFE, 0xFF})             ? "UTF-16BE"
                                                              : nullptr;
    if (encoding)
        throw std::runtime_error(path + ": " + what + " is encoded as " + encoding +
                                 " (byte-order mark); expected ASCII or UTF-8 text");
    // Without a mark, UTF-16 text of ASCII characters has a NUL byte beside every character.
    const auto nul_beside = [&](size_t first_nul) {
        if (bytes.size() < 4) return false;
        for (size_t i = 0; i < std::min<size_t>(bytes.size() & ~size_t(1), 16); i += 2)
            if (bytes[i + first_nul] != '\0' || bytes[i + 1 - first_nul] == '\0') return false;
        return true;
    };
    const char* unmarked = nul_beside(1) ? "UTF-16LE" : nul_beside(0) ? "UTF-16BE" : nullptr;
    if (unmarked)
        throw std::runtime_error(path + ": " + what + " looks like " + unmarked +
                                 " text without a byte-order mark (a NUL byte beside every character); expected ASCII "
                                 "or UTF-8 text");
}

std::string read_text_file(const std::string& path, const std::string& what, uint64_t max_bytes) {
    require_regular_file(path, what);
    std::error_code ec;
    const uint64_t size = fs::file_size(path, ec);
    if (ec) throw std::runtime_error(path + ": cannot read " + what + " (" + ec.message() + ")");
    if (size > max_bytes)
        throw std::runtime_error(path + ": " + what + " has " + std::to_string(size) + " bytes, more than the " +
                                 std::to_string(max_bytes) + " read");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path + ": cannot open " + what);
    std::string bytes(size_t(size), '\0');
    if (size > 0 && !in.read(bytes.data(), std::streamsize(size)))
        throw std::runtime_error(path + ": cannot read " + what + " (" + std::to_string(size) + " bytes)");
    reject_wide_encodings(bytes, path, what);
    const std::string_view text = without_utf8_bom(bytes);
    if (text.size() != bytes.size()) bytes.erase(0, bytes.size() - text.size());
    return bytes;
}

}  // namespace sdf
