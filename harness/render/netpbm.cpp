#include "harness/render/netpbm.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace sdf {
namespace {

std::vector<unsigned char> with_header(const std::string& header, size_t payload) {
    std::vector<unsigned char> bytes(header.begin(), header.end());
    bytes.reserve(header.size() + payload);
    return bytes;
}

void append_float(std::vector<unsigned char>& bytes, float v) {
    unsigned char b[4];
    std::memcpy(b, &v, 4);  // little-endian hosts only (x86-64, aarch64): the PFM scale is -1
    bytes.insert(bytes.end(), b, b + 4);
}

}  // namespace

std::vector<unsigned char> encode_ppm(const ImageRgb& image) {
    std::vector<unsigned char> bytes =
        with_header("P6\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n255\n",
                    image.data.size());
    for (float v : image.data) bytes.push_back(static_cast<unsigned char>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)));
    return bytes;
}

std::vector<unsigned char> encode_pfm(const ImageRgb& image) {
    std::vector<unsigned char> bytes =
        with_header("PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1.0\n",
                    image.data.size() * 4);
    for (int y = image.height - 1; y >= 0; --y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 3; ++c) append_float(bytes, image.at(x, y)[c]);
    return bytes;
}

std::vector<unsigned char> encode_pfm_grey(const std::vector<float>& values, int width, int height) {
    std::vector<unsigned char> bytes =
        with_header("Pf\n" + std::to_string(width) + " " + std::to_string(height) + "\n-1.0\n", values.size() * 4);
    for (int y = height - 1; y >= 0; --y)
        for (int x = 0; x < width; ++x) append_float(bytes, values[size_t(y) * size_t(width) + size_t(x)]);
    return bytes;
}

ImageRgb read_netpbm(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path + ": cannot open image");
    std::string magic;
    int width = 0, height = 0;
    double scale = 0;
    in >> magic >> width >> height >> scale;
    in.get();  // the single whitespace before the data
    if (!in || width < 1 || height < 1)
        throw std::runtime_error(path + ": not a PPM/PFM image (bad header, magic '" + magic + "')");
    ImageRgb image(width, height);
    if (magic == "P6") {
        if (scale != 255) throw std::runtime_error(path + ": PPM maxval " + std::to_string(scale) + ", expected 255");
        std::vector<unsigned char> raw(image.data.size());
        in.read(reinterpret_cast<char*>(raw.data()), std::streamsize(raw.size()));
        if (!in) throw std::runtime_error(path + ": PPM data truncated");
        for (size_t i = 0; i < raw.size(); ++i) image.data[i] = float(raw[i]) / 255.0f;
        return image;
    }
    const int channels = magic == "PF" ? 3 : (magic == "Pf" ? 1 : 0);
    if (channels == 0) throw std::runtime_error(path + ": magic '" + magic + "', expected P6, PF or Pf");
    if (scale >= 0) throw std::runtime_error(path + ": big-endian PFM is not supported");
    std::vector<float> raw(size_t(width) * size_t(height) * size_t(channels));
    in.read(reinterpret_cast<char*>(raw.data()), std::streamsize(raw.size() * 4));
    if (!in) throw std::runtime_error(path + ": PFM data truncated");
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const float* p = &raw[(size_t(height - 1 - y) * size_t(width) + size_t(x)) * size_t(channels)];
            image.set(x, y, p[0], p[channels > 1 ? 1 : 0], p[channels > 1 ? 2 : 0]);
        }
    return image;
}

}  // namespace sdf
