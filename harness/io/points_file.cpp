#include "harness/io/points_file.h"

#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "core/io/text_file.h"
#include "core/mesh/text_cursor.h"
#include "harness/io/npy_file.h"

namespace sdf {
namespace {

bool is_blank_or_comment(const std::string& line) {
    const size_t first = line.find_first_not_of(" \t\r");
    return first == std::string::npos || line[first] == '#';
}

/// The point on `line` (line `number` of `name`), or a message naming both.
Vec3d parse_point(const std::string& line, const std::string& name, int number) {
    std::istringstream ss(line);
    Vec3d p;
    std::string extra;
    if (!(ss >> p.x >> p.y >> p.z) || (ss >> extra) || !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw std::runtime_error(name + ":" + std::to_string(number) + ": expected three finite numbers \"x y z\", got " +
                                 quoted(line));
    return p;
}

/// The points of `text`; `name` names it in messages, `file` says what it is ("the file",
/// "standard input") where no point is found.
std::vector<Vec3d> read_points(const std::string& text, const std::string& name, const std::string& file) {
    std::istringstream in(text);
    std::vector<Vec3d> points;
    std::string line;
    int lines = 0;
    for (int number = 1; std::getline(in, line); ++number, ++lines)
        if (!is_blank_or_comment(line)) points.push_back(parse_point(line, name, number));
    if (points.empty())
        throw std::runtime_error(name + ": no points: expected \"x y z\" per line (blank lines and '#' comment lines are "
                                        "skipped), but " + file + " " +
                                 (lines == 0 ? std::string("is empty")
                                             : "has only blank or comment lines (" + std::to_string(lines) + ")"));
    return points;
}

}  // namespace

std::vector<Vec3d> read_points_file(const std::string& path) {
    if (is_npy_path(path)) {
        std::vector<Vec3d> points = read_npy_points(path);
        if (points.empty())
            throw std::runtime_error(path + ": no points: the array has shape (0, 3); expected (N, 3) with N >= 1");
        return points;
    }
    if (path != "-") return read_points(read_text_file(path, "points file"), path, "the file");
    std::stringstream all;
    all << std::cin.rdbuf();
    const std::string bytes = all.str();
    reject_wide_encodings(bytes, path, "points file");
    return read_points(std::string(without_utf8_bom(bytes)), path, "standard input");
}

}  // namespace sdf
