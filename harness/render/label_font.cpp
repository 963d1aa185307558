#include "harness/render/label_font.h"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace sdf {

std::string find_label_font() {
    std::vector<std::string> tried;
    if (const char* env = std::getenv("SDF_FONT"); env && *env) {
        if (std::filesystem::is_regular_file(env)) return env;
        tried.push_back(std::string(env) + " ($SDF_FONT)");
    }
    for (const char* path : {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                             "/usr/share/fonts/TTF/DejaVuSans.ttf",
                             "/usr/share/fonts/dejavu/DejaVuSans.ttf",
                             "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf"}) {
        if (std::filesystem::is_regular_file(path)) return path;
        tried.push_back(path);
    }
    std::string list;
    for (const std::string& t : tried) list += "\n  " + t;
    throw std::runtime_error("no font for the image labels: install the Debian package fonts-dejavu-core "
                             "(scripts/debian-packages.txt, group build) or set SDF_FONT to a .ttf file; tried:" + list);
}

}  // namespace sdf
