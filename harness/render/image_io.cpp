#include "harness/render/image_io.h"

#include <atomic>
#include <cstdio>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "harness/render/netpbm.h"

#if SDF_HAVE_OIIO
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#endif

namespace sdf {
namespace {

namespace fs = std::filesystem;

std::string lower_extension(const std::string& path) {
    std::string e = fs::path(path).extension().string();
    for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

void write_bytes(const std::string& path, const std::vector<unsigned char>& bytes, Overwrite overwrite) {
    write_file_atomically(path, bytes.data(), bytes.size(), overwrite);
}

void write_sidecar(const std::string& path, const nlohmann::json& attributes, Overwrite overwrite) {
    write_text_atomically(path + ".json", attributes.dump(2) + "\n", overwrite);
}

#if !SDF_HAVE_OIIO
/// Says once per process that PNG/EXR became PPM/PFM.
void note_fallback(const std::string& asked, const std::string& written) {
    static std::atomic<bool> said{false};
    if (said.exchange(true)) return;
    std::fprintf(stderr,
                 "note: built without OpenImageIO: .png files are written as .ppm and .exr as .pfm, attributes in "
                 ".json sidecars (first: %s written as %s)\n",
                 asked.c_str(), written.c_str());
}
#endif

#if SDF_HAVE_OIIO
namespace oiio = OIIO;

/// A hidden name beside `path` with its extension (OpenImageIO picks the format by it).
std::string temporary_name(const std::string& path) {
    static std::atomic<int> counter{0};
    const fs::path p(path);
    return (p.parent_path() / ("." + p.stem().string() + ".oiio." + std::to_string(getpid()) + "." +
                               std::to_string(counter++) + p.extension().string()))
        .string();
}

void add_attributes(oiio::ImageSpec& spec, const nlohmann::json& attributes) {
    for (auto it = attributes.begin(); it != attributes.end(); ++it) {
        const std::string key = "sdf:" + it.key();
        const nlohmann::json& v = it.value();
        if (v.is_string()) spec.attribute(key, v.get<std::string>());
        else if (v.is_number_integer() && v.get<int64_t>() == int64_t(int(v.get<int64_t>()))) spec.attribute(key, int(v.get<int64_t>()));
        else if (v.is_number()) spec.attribute(key, v.get<float>());
        else if (v.is_boolean()) spec.attribute(key, v.get<bool>() ? 1 : 0);
        else spec.attribute(key, v.dump());
    }
}

/// Encodes `pixels` (float, spec.nchannels per pixel) in the format of `path`'s extension
/// into memory, through an IOProxy when the format supports one, else through a
/// temporary file beside `path`.
std::vector<unsigned char> encode_with_oiio(const std::string& path, const oiio::ImageSpec& spec, const float* pixels) {
    std::vector<unsigned char> bytes;
    oiio::Filesystem::IOVecOutput proxy(bytes);
    auto out = oiio::ImageOutput::create(path, &proxy);
    if (!out) throw std::runtime_error(path + ": OpenImageIO cannot write this format: " + oiio::geterror());
    const bool in_memory = out->supports("ioproxy");
    const std::string target = in_memory ? path : temporary_name(path);
    if (!in_memory) out = oiio::ImageOutput::create(target);
    if (!out->open(target, spec) || !out->write_image(oiio::TypeDesc::FLOAT, pixels) || !out->close())
        throw std::runtime_error(path + ": OpenImageIO failed to write: " + out->geterror());
    if (!in_memory) {
        std::ifstream in(target, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        fs::remove(target);
    }
    return bytes;
}
#endif

}  // namespace

bool have_openimageio() { return SDF_HAVE_OIIO != 0; }

std::string replace_extension(const std::string& path, const std::string& extension) {
    return fs::path(path).replace_extension(extension).string();
}

std::string write_image(const std::string& path, const ImageRgb& image, const nlohmann::json& attributes,
                        Overwrite overwrite) {
    const std::string ext = lower_extension(path);
    if (ext == ".ppm" || ext == ".pfm") {
        write_bytes(path, ext == ".ppm" ? encode_ppm(image) : encode_pfm(image), overwrite);
        if (!attributes.empty()) write_sidecar(path, attributes, overwrite);
        return path;
    }
#if SDF_HAVE_OIIO
    oiio::ImageSpec spec(image.width, image.height, 3, ext == ".png" ? oiio::TypeDesc::UINT8 : oiio::TypeDesc::FLOAT);
    add_attributes(spec, attributes);
    write_bytes(path, encode_with_oiio(path, spec, image.data.data()), overwrite);
    return path;
#else
    const std::string fallback = replace_extension(path, ext == ".exr" ? ".pfm" : ".ppm");
    note_fallback(path, fallback);
    return write_image(fallback, image, attributes, overwrite);
#endif
}

std::string write_render_exr(const std::string& path, const RenderedImage& image, const nlohmann::json& attributes,
                             Overwrite overwrite) {
    const size_t n = image.pixels.size();
#if SDF_HAVE_OIIO
    constexpr int kChannels = 8;
    std::vector<float> pixels(n * kChannels);
    for (size_t i = 0; i < n; ++i) {
        const PixelRecord& p = image.pixels[i];
        const float values[kChannels] = {p.shade, p.shade, p.shade, p.depth, p.normal.x, p.normal.y, p.normal.z,
                                         float(static_cast<int>(p.hit))};
        std::copy(values, values + kChannels, &pixels[i * kChannels]);
    }
    oiio::ImageSpec spec(image.width, image.height, kChannels, oiio::TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", "Z", "N.X", "N.Y", "N.Z", "hit"};
    spec.z_channel = 3;
    spec.attribute("compression", "zip");
    add_attributes(spec, attributes);
    write_bytes(path, encode_with_oiio(path, spec, pixels.data()), overwrite);
    return path;
#else
    const std::string base = replace_extension(path, "");
    std::vector<float> depth(n), normal_rgb(n * 3);
    for (size_t i = 0; i < n; ++i) {
        depth[i] = image.pixels[i].depth;
        normal_rgb[i * 3] = image.pixels[i].normal.x;
        normal_rgb[i * 3 + 1] = image.pixels[i].normal.y;
        normal_rgb[i * 3 + 2] = image.pixels[i].normal.z;
    }
    ImageRgb normals(image.width, image.height);
    normals.data = normal_rgb;
    write_bytes(base + ".depth.pfm", encode_pfm_grey(depth, image.width, image.height), overwrite);
    write_bytes(base + ".normal.pfm", encode_pfm(normals), overwrite);
    note_fallback(path, base + ".pfm");
    return write_image(base + ".pfm", shaded_image(image), attributes, overwrite);
#endif
}

ImageRgb read_image_rgb(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext == ".ppm" || ext == ".pfm") return read_netpbm(path);
#if SDF_HAVE_OIIO
    auto in = oiio::ImageInput::open(path);
    if (!in) throw std::runtime_error(path + ": cannot read image: " + oiio::geterror());
    const oiio::ImageSpec& spec = in->spec();
    std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, oiio::TypeDesc::FLOAT, all.data()))
        throw std::runtime_error(path + ": cannot read pixels: " + in->geterror());
    ImageRgb image(spec.width, spec.height);
    for (size_t i = 0; i < size_t(spec.width) * size_t(spec.height); ++i)
        for (int c = 0; c < 3; ++c) image.data[i * 3 + size_t(c)] = all[i * size_t(spec.nchannels) + size_t(std::min(c, spec.nchannels - 1))];
    return image;
#else
    throw std::runtime_error(path + ": reading " + ext + " needs OpenImageIO (this build has none); PPM/PFM only");
#endif
}

std::string read_image_attribute(const std::string& path, const std::string& name) {
#if SDF_HAVE_OIIO
    auto in = oiio::ImageInput::open(path);
    if (!in) throw std::runtime_error(path + ": cannot read image: " + oiio::geterror());
    return in->spec().get_string_attribute(name);
#else
    (void)name;
    throw std::runtime_error(path + ": reading attributes needs OpenImageIO (this build has none)");
#endif
}

}  // namespace sdf
