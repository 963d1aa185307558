#include "harness/io/npy_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "core/checked_math.h"
#include "core/io/text_file.h"

namespace sdf {
namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr size_t kMagicSize = 6;
constexpr int kMaxDimensions = 32;  // NumPy's own limit (NPY_MAXDIMS)

std::string expected_descrs() {
    std::string s;
    for (const NpyDtypeInfo& d : kNpyDtypes) s += (s.empty() ? "'" : ", '") + std::string(d.descr) + "'";
    return s;
}

/// A cursor over the header's Python dictionary literal,
/// "{'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }": every error names the file.
class HeaderParser {
public:
    HeaderParser(const std::string& text, const std::string& name) : s_(text), name_(name) {}

    [[noreturn]] void fail(const std::string& what) const {
        throw std::runtime_error(name_ + ": header: " + what + " (header: " + printable() + ")");
    }

    void skip_space() {
        while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) ++i_;
    }
    bool accept(char c) {
        skip_space();
        if (i_ < s_.size() && s_[i_] == c) {
            ++i_;
            return true;
        }
        return false;
    }
    void expect(char c, const char* where) {
        if (!accept(c)) fail(std::string("expected '") + c + "' " + where);
    }
    bool at_end() {
        skip_space();
        return i_ == s_.size();
    }

    std::string quoted() {
        skip_space();
        if (i_ >= s_.size() || (s_[i_] != '\'' && s_[i_] != '"')) fail("expected a quoted string");
        const char quote = s_[i_++];
        const size_t end = s_.find(quote, i_);
        if (end == std::string::npos) fail("unterminated string");
        std::string value = s_.substr(i_, end - i_);
        i_ = end + 1;
        return value;
    }

    bool boolean() {
        skip_space();
        for (const auto& [word, value] : {std::pair<const char*, bool>{"True", true}, {"False", false}})
            if (s_.compare(i_, std::strlen(word), word) == 0) {
                i_ += std::strlen(word);
                return value;
            }
        fail("'fortran_order' must be True or False");
    }

    std::vector<int64_t> shape() {
        expect('(', "to open 'shape'");
        std::vector<int64_t> dims;
        while (!accept(')')) {
            skip_space();
            const size_t start = i_;
            int64_t v = 0;
            while (i_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[i_]))) {
                const std::optional<int64_t> next = checked_mul(v, 10);
                const std::optional<int64_t> sum = next ? checked_add(*next, s_[i_] - '0') : std::nullopt;
                if (!sum) fail("a dimension of 'shape' does not fit 64 bits");
                v = *sum;
                ++i_;
            }
            if (i_ == start) fail("'shape' must be a tuple of non-negative integers");
            dims.push_back(v);
            if (int(dims.size()) > kMaxDimensions) fail("'shape' has more than 32 dimensions");
            if (!accept(',')) {
                expect(')', "to close 'shape'");
                if (dims.size() == 1) fail("a 1-d 'shape' is written (N,), with a comma");
                break;
            }
        }
        return dims;
    }

private:
    std::string printable() const {
        std::string p;
        for (char c : s_.substr(0, 200)) p += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
        while (!p.empty() && p.back() == ' ') p.pop_back();
        return p;
    }

    const std::string& s_;
    const std::string& name_;
    size_t i_ = 0;
};

NpyDtype dtype_from_descr(const std::string& descr, const HeaderParser& parser) {
    for (const NpyDtypeInfo& d : kNpyDtypes)
        if (descr == d.descr) return d.dtype;
    std::string why;
    if (!descr.empty() && descr[0] == '>') why = " (big-endian)";
    else if (descr == "|O" || descr == "O") why = " (Python objects)";
    parser.fail("'descr' is '" + descr + "'" + why + "; expected one of " + expected_descrs());
}

uint32_t little_endian(const std::string& bytes, size_t at, int size) {
    uint32_t v = 0;
    for (int k = size - 1; k >= 0; --k) v = (v << 8) | uint8_t(bytes[at + size_t(k)]);
    return v;
}

}  // namespace

const char* npy_descr(NpyDtype dtype) {
    for (const NpyDtypeInfo& d : kNpyDtypes)
        if (d.dtype == dtype) return d.descr;
    throw std::invalid_argument("npy_descr: unknown dtype");
}

int npy_item_size(NpyDtype dtype) {
    for (const NpyDtypeInfo& d : kNpyDtypes)
        if (d.dtype == dtype) return d.item_size;
    throw std::invalid_argument("npy_item_size: unknown dtype");
}

int64_t NpyArray::count() const {
    int64_t n = 1;
    for (int64_t d : shape) n *= d;  // checked when the array was read or made
    return n;
}

std::vector<double> NpyArray::to_doubles() const {
    const size_t n = size_t(count());
    std::vector<double> out(n);
    const unsigned char* p = data.data();
    for (size_t i = 0; i < n; ++i) {
        switch (dtype) {
            case NpyDtype::Float32: { float v; std::memcpy(&v, p + 4 * i, 4); out[i] = double(v); break; }
            case NpyDtype::Float64: { double v; std::memcpy(&v, p + 8 * i, 8); out[i] = v; break; }
            case NpyDtype::Int32: { int32_t v; std::memcpy(&v, p + 4 * i, 4); out[i] = double(v); break; }
            case NpyDtype::Int64: { int64_t v; std::memcpy(&v, p + 8 * i, 8); out[i] = double(v); break; }
        }
    }
    return out;
}

std::string NpyArray::shape_text() const {
    std::string s = "(";
    for (size_t k = 0; k < shape.size(); ++k) s += (k ? ", " : "") + std::to_string(shape[k]);
    return s + (shape.size() == 1 ? ",)" : ")");
}

NpyArray parse_npy(const std::string& bytes, const std::string& name) {
    if (bytes.size() < kMagicSize + 4 || bytes.compare(0, kMagicSize, kMagic, kMagicSize) != 0)
        throw std::runtime_error(name + ": not a NumPy .npy file (expected the magic string \\x93NUMPY at its start)");
    const int major = uint8_t(bytes[6]);
    if (major < 1 || major > 3)
        throw std::runtime_error(name + ": .npy format version " + std::to_string(major) + "." +
                                 std::to_string(uint8_t(bytes[7])) + " is not supported; expected 1.0, 2.0 or 3.0");
    const int length_size = major == 1 ? 2 : 4;
    if (bytes.size() < 8 + size_t(length_size)) throw std::runtime_error(name + ": truncated .npy header");
    const uint64_t header_length = little_endian(bytes, 8, length_size);
    const uint64_t data_offset = 8 + uint64_t(length_size) + header_length;
    if (data_offset > bytes.size())
        throw std::runtime_error(name + ": the .npy header claims " + std::to_string(header_length) + " bytes but the file has " +
                                 std::to_string(bytes.size()) + " bytes in all");
    const std::string header = bytes.substr(8 + size_t(length_size), size_t(header_length));
    HeaderParser p(header, name);
    std::optional<std::string> descr;
    std::optional<bool> fortran_order;
    std::optional<std::vector<int64_t>> shape;
    p.expect('{', "at the header's start");
    while (!p.accept('}')) {
        const std::string key = p.quoted();
        p.expect(':', "after a key");
        if (key == "descr" && !descr) descr = p.quoted();
        else if (key == "fortran_order" && !fortran_order) fortran_order = p.boolean();
        else if (key == "shape" && !shape) shape = p.shape();
        else p.fail("unexpected or repeated key '" + key + "'; expected 'descr', 'fortran_order' and 'shape' once each");
        if (!p.accept(',')) {
            p.expect('}', "to close the header");
            break;
        }
    }
    if (!p.at_end()) p.fail("text after the header's closing '}'");
    if (!descr || !fortran_order || !shape) p.fail("expected the keys 'descr', 'fortran_order' and 'shape'");
    NpyArray array;
    array.dtype = dtype_from_descr(*descr, p);
    if (*fortran_order) p.fail("Fortran order is not supported; expected C order ('fortran_order': False)");
    array.shape = *shape;
    int64_t count = 1;
    for (int64_t d : array.shape) {
        const std::optional<int64_t> next = checked_mul(count, d);
        if (!next) p.fail("the product of 'shape' " + array.shape_text() + " does not fit 64 bits");
        count = *next;
    }
    const std::optional<int64_t> data_bytes = checked_mul(count, npy_item_size(array.dtype));
    if (!data_bytes) p.fail("shape " + array.shape_text() + " of '" + *descr + "' items does not fit 64 bits of bytes");
    const uint64_t have = bytes.size() - data_offset;
    if (have != uint64_t(*data_bytes))
        throw std::runtime_error(name + ": shape " + array.shape_text() + " of '" + *descr + "' needs " +
                                 std::to_string(*data_bytes) + " bytes of data; the file has " + std::to_string(have));
    array.data.assign(bytes.begin() + std::ptrdiff_t(data_offset), bytes.end());
    return array;
}

NpyArray read_npy(const std::string& path) {
    require_regular_file(path, ".npy file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path + ": cannot open the .npy file");
    std::string bytes(size_t(std::filesystem::file_size(path)), '\0');
    if (!in.read(bytes.data(), std::streamsize(bytes.size())))
        throw std::runtime_error(path + ": cannot read the .npy file");
    return parse_npy(bytes, path);
}

std::string npy_bytes(NpyDtype dtype, const std::vector<int64_t>& shape, const void* data) {
    std::string shape_text = "(";
    int64_t count = 1;
    for (size_t k = 0; k < shape.size(); ++k) {
        if (shape[k] < 0) throw std::invalid_argument("npy_bytes: negative dimension " + std::to_string(shape[k]));
        const std::optional<int64_t> next = checked_mul(count, shape[k]);
        if (!next) throw std::invalid_argument("npy_bytes: the shape's product does not fit 64 bits");
        count = *next;
        shape_text += (k ? ", " : "") + std::to_string(shape[k]);
    }
    shape_text += shape.size() == 1 ? ",)" : ")";
    std::string header = std::string("{'descr': '") + npy_descr(dtype) + "', 'fortran_order': False, 'shape': " +
                         shape_text + ", }";
    // Version 1.0 unless the header needs more than 16 bits; the data starts 64-byte aligned.
    const int major = header.size() + 1 + 10 < 65536 ? 1 : 2;
    const size_t prefix = major == 1 ? 10 : 12;
    header.append((64 - (prefix + header.size() + 1) % 64) % 64, ' ');
    header += '\n';
    std::string out(kMagic, kMagicSize);
    out += char(major);
    out += char(0);
    const uint64_t length = header.size();
    for (size_t k = 0; k < prefix - 8; ++k) out += char((length >> (8 * k)) & 0xFF);
    out += header;
    out.append(static_cast<const char*>(data), size_t(count) * size_t(npy_item_size(dtype)));
    return out;
}

void write_npy(const std::string& path, NpyDtype dtype, const std::vector<int64_t>& shape, const void* data,
               Overwrite overwrite) {
    const std::string bytes = npy_bytes(dtype, shape, data);
    write_file_atomically(path, bytes.data(), bytes.size(), overwrite);
}

std::vector<Vec3d> read_npy_points(const std::string& path) {
    const NpyArray a = read_npy(path);
    if (a.shape.size() != 2 || a.shape[1] != 3)
        throw std::runtime_error(path + ": expected an array of shape (N, 3) (x, y, z per row), got shape " + a.shape_text());
    const std::vector<double> v = a.to_doubles();
    std::vector<Vec3d> points(size_t(a.shape[0]));
    for (size_t i = 0; i < points.size(); ++i) {
        points[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
        if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y) || !std::isfinite(points[i].z))
            throw std::runtime_error(path + ": row " + std::to_string(i) + " is not three finite numbers");
    }
    return points;
}

bool is_npy_path(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".npy";
}

}  // namespace sdf
