/// @file text_file.h
/// @brief Reading every text input the same way (meshes, points files, configs, field
/// headers): only regular files, a size limit checked before allocating, and the encodings
/// editors write (a UTF-8 byte-order mark is skipped; UTF-16 is refused by name; CRLF line
/// ends are whitespace to every reader).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace sdf {

/// "a directory", "a FIFO", "a socket", "a character device", "a block device", "missing",
/// or "a regular file": what `path` is, for messages.
std::string file_kind(const std::string& path);

/// Throws "PATH: cannot read WHAT: it is a directory, not a regular file" (or missing, ...)
/// unless `path` is a regular file (symbolic links followed).
void require_regular_file(const std::string& path, const std::string& what);

/// `text` without a leading UTF-8 byte-order mark (EF BB BF).
inline std::string_view without_utf8_bom(std::string_view text) {
    if (text.size() >= 3 && uint8_t(text[0]) == 0xEF && uint8_t(text[1]) == 0xBB && uint8_t(text[2]) == 0xBF)
        text.remove_prefix(3);
    return text;
}

/// Throws naming `path` if `bytes` start with a UTF-16 or UTF-32 byte-order mark, or look
/// like UTF-16 without one (NUL bytes beside the first characters): such a file would
/// otherwise read as garbage or, worse, as fewer lines than it has.
void reject_wide_encodings(std::string_view bytes, const std::string& path, const std::string& what);

/// The whole text file `path` (a WHAT, for messages) without its UTF-8 byte-order mark; a
/// regular file of at most `max_bytes` bytes, else an error naming the file.
std::string read_text_file(const std::string& path, const std::string& what, uint64_t max_bytes = uint64_t(1) << 30);

}  // namespace sdf
