/// @file text_cursor.h
/// @brief Whitespace-separated tokens of a text mesh file (ASCII PLY and STL, OFF) with the
/// line number of each, and exact number parsing (std::from_chars: correctly rounded, no
/// locale), so a reader can name the line of every error.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

namespace sdf {

class TextCursor {
public:
    explicit TextCursor(std::string_view text, size_t offset = 0, int line = 1) : text_(text), pos_(offset), line_(line) {}

    /// The next token, or false at the end of the text. `#` comments run to the end of the
    /// line when `hash_comments` is set (OFF).
    bool next(std::string_view& token) {
        skip_space();
        if (pos_ >= text_.size()) return false;
        token_line_ = line_;
        const size_t start = pos_;
        while (pos_ < text_.size() && !is_space(text_[pos_]) && !(hash_comments && text_[pos_] == '#')) ++pos_;
        token = text_.substr(start, pos_ - start);
        return true;
    }

    /// The rest of the current line (without its end), then moves to the next line.
    std::string_view rest_of_line() {
        const size_t start = pos_;
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
        std::string_view rest = text_.substr(start, pos_ - start);
        if (pos_ < text_.size()) { ++pos_; ++line_; }
        token_line_ = line_;
        return rest;
    }

    /// The next token without moving past it, and its line; false at the end of the text.
    bool peek(std::string_view& token, int& line) const {
        TextCursor copy = *this;
        if (!copy.next(token)) return false;
        line = copy.line();
        return true;
    }

    /// Line of the last token returned.
    int line() const { return token_line_; }
    /// Line the cursor stands on.
    int current_line() const { return line_; }
    bool at_end() { skip_space(); return pos_ >= text_.size(); }
    size_t bytes_left() const { return text_.size() - pos_; }

    bool hash_comments = false;

private:
    static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }
    void skip_space() {
        for (; pos_ < text_.size(); ++pos_) {
            const char c = text_[pos_];
            if (c == '\n') ++line_;
            else if (hash_comments && c == '#') { while (pos_ + 1 < text_.size() && text_[pos_ + 1] != '\n') ++pos_; }
            else if (!is_space(c)) break;
        }
    }

    std::string_view text_;
    size_t pos_ = 0;
    int line_ = 1;
    int token_line_ = 1;
};

/// The whole token as a double (a leading '+' allowed); false if it is not a number.
/// Non-finite values parse; callers reject them with their own message.
inline bool parse_double(std::string_view token, double& value) {
    if (token.size() > 1 && token[0] == '+') token.remove_prefix(1);
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    return ec == std::errc() && end == token.data() + token.size();
}

/// The whole token as a decimal integer; false if it is not one or overflows int64.
inline bool parse_int(std::string_view token, int64_t& value) {
    if (token.size() > 1 && token[0] == '+') token.remove_prefix(1);
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    return ec == std::errc() && end == token.data() + token.size();
}

/// A token quoted for a message, cut to 40 characters; bytes other than printable ASCII are
/// written as \xNN, so that binary data neither garbles the terminal nor cuts the message
/// (a NUL would end what() there).
inline std::string quoted(std::string_view token) {
    static const char* const hex = "0123456789abcdef";
    std::string out = "'";
    for (const char c : token.substr(0, 40)) {
        const auto byte = static_cast<unsigned char>(c);
        if (byte >= 0x20 && byte < 0x7f) out += c;
        else out += std::string("\\x") + hex[byte >> 4] + hex[byte & 15];
    }
    return out + (token.size() > 40 ? "...'" : "'");
}

/// ASCII case-insensitive equality of a token and a lower-case keyword.
inline bool equals_keyword(std::string_view token, std::string_view keyword) {
    if (token.size() != keyword.size()) return false;
    for (size_t i = 0; i < token.size(); ++i) {
        const char c = token[i] >= 'A' && token[i] <= 'Z' ? char(token[i] - 'A' + 'a') : token[i];
        if (c != keyword[i]) return false;
    }
    return true;
}

}  // namespace sdf
