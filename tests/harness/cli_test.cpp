// The command-line tools as a user runs them: sdf-query against the analytic box distance,
// its input parsing and errors; run-experiment end to end on tiny configs (run directory,
// manifest, metrics, readable fields) and its config errors. Executables come from CMake
// (SDF_QUERY_EXE, RUN_EXPERIMENT_EXE); stdout and stderr are captured into files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh/sha256.h"
#include "harness/build_config.h"
#include "harness/io/field_file.h"
#include "harness/io/npy_file.h"

#ifndef SDF_QUERY_EXE
#error "SDF_QUERY_EXE must be defined by CMake"
#endif
#ifndef RUN_EXPERIMENT_EXE
#error "RUN_EXPERIMENT_EXE must be defined by CMake"
#endif

#include "harness/sampling/sampler_table.h"
#include "harness_test_util.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::Contains;
using test::quote;
using test::read_json;
using test::read_text;
using test::ShellResult;
using test::sorted_entries;

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

int count_files(const fs::path& dir) {
    int n = 0;
    if (!fs::exists(dir)) return 0;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (!e.is_directory()) ++n;
    return n;
}

// ---- the analytic box (half-extent 1, centred at the origin) ------------------------------

double box_sdf(const Vec3d& p) {
    const double q[3] = {std::abs(p.x) - 1, std::abs(p.y) - 1, std::abs(p.z) - 1};
    const double o[3] = {std::max(q[0], 0.0), std::max(q[1], 0.0), std::max(q[2], 0.0)};
    return std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]) + std::min(std::max(q[0], std::max(q[1], q[2])), 0.0);
}

/// Analytic gradient, and whether it is well defined with a margin: not near the surface
/// (|d| > 0.05) and, inside, not near the medial axis (the two largest q differ by > 1e-4).
/// `face` is the axis*2+sign face whose interior is closest, or -1 (edge/corner region).
struct BoxTruth {
    double d;
    Vec3d g;
    bool gradient_reliable;
    int axis = -1;
    bool positive = false;
};

BoxTruth box_truth(const Vec3d& p) {
    BoxTruth t{box_sdf(p), {}, false};
    const double a[3] = {p.x, p.y, p.z};
    double q[3];
    for (int i = 0; i < 3; ++i) q[i] = std::abs(a[i]) - 1;
    int outside = 0;
    for (double v : q) outside += v > 0;
    if (outside > 0) {
        double o[3], len = 0;
        for (int i = 0; i < 3; ++i) {
            o[i] = std::max(q[i], 0.0);
            len += o[i] * o[i];
        }
        len = std::sqrt(len);
        t.g = {std::copysign(o[0] / len, a[0]), std::copysign(o[1] / len, a[1]), std::copysign(o[2] / len, a[2])};
        t.gradient_reliable = t.d > 0.05;
        if (outside == 1) {
            for (int i = 0; i < 3; ++i)
                if (q[i] > 0) t.axis = i;
            bool clear = true;  // the other coordinates well inside the face
            for (int i = 0; i < 3; ++i)
                if (i != t.axis && q[i] > -1e-3) clear = false;
            if (!clear) t.axis = -1;
        }
    } else {
        int m = 0;
        for (int i = 1; i < 3; ++i)
            if (q[i] > q[m]) m = i;
        double second = -1e300;
        for (int i = 0; i < 3; ++i)
            if (i != m) second = std::max(second, q[i]);
        const double s = a[m] < 0 ? -1.0 : 1.0;
        t.g = {m == 0 ? s : 0.0, m == 1 ? s : 0.0, m == 2 ? s : 0.0};
        t.gradient_reliable = t.d < -0.05 && q[m] - second > 1e-4;
        if (q[m] - second > 1e-4) t.axis = m;
    }
    if (t.axis >= 0) t.positive = a[t.axis] > 0;
    return t;
}

/// make_box's face order: -z, +z, -y, +y, -x, +x, two triangles each.
int procedural_box_face(int axis, bool positive) { return 2 * (2 - axis) + (positive ? 1 : 0); }

struct QueryLine {
    double d = 0;
    Vec3d g{};
    int tri = -1;
};

std::vector<QueryLine> parse_query_output(const std::string& out) {
    std::vector<QueryLine> lines;
    std::istringstream in(out);
    for (std::string line; std::getline(in, line);) {
        std::istringstream ss(line);
        QueryLine q;
        std::string extra;
        EXPECT_TRUE(ss >> q.d >> q.g.x >> q.g.y >> q.g.z >> q.tri) << "bad output line: " << line;
        EXPECT_FALSE(ss >> extra) << "extra output: " << line;
        lines.push_back(q);
    }
    return lines;
}

// ---- fixture ------------------------------------------------------------------------------

class Cli : public test::ScratchDirTest {
protected:
    Cli() : ScratchDirTest("sdf_cli_test") {}

    /// Runs `exe args` in the temporary directory with SDF_DATA_PATH set to `data_path`.
    ShellResult run(const std::string& exe, const std::string& args, const std::string& data_path = "") const {
        return test::run_in(dir_, "SDF_DATA_PATH=" + quote(data_path) + " SDF_CACHE_DIR=" + quote(at("cache")) + " " +
                                      quote(exe) + " " + args);
    }
    ShellResult query(const std::string& args, const std::string& data_path = "") const {
        return run(SDF_QUERY_EXE, args, data_path);
    }
    ShellResult experiment(const std::string& args, const std::string& data_path = "") const {
        return run(RUN_EXPERIMENT_EXE, args, data_path);
    }

    /// A config with `overrides` merged over the tiny box config of the brief.
    std::string config(const std::string& rel, const json& overrides = json::object()) const {
        json c = {{"name", "tiny"},
                  {"mesh", {{"shape", "box"}}},
                  {"lattices", {{{"type", "cc"}, {"resolution", {8, 8, 8}}}, {{"type", "bcc"}, {"resolution", {6, 6, 12}}}}},
                  {"sampler", {{"threads", 1}, {"progress", false}}}};
        for (const auto& [k, v] : overrides.items()) {
            if (v.is_null()) c.erase(k);
            else c[k] = v;
        }
        return write(rel, c.dump(2));
    }
};

/// Points for the box: random in [-2.5, 2.5]^3 (fixed seed), plus hand-picked ones in every
/// region (inside, face, edge, corner, on the surface).
std::vector<Vec3d> box_points() {
    std::vector<Vec3d> pts = {{0.5, 0.2, 0.1},  {1.5, 0.1, -0.2}, {-0.3, -1.7, 0.4}, {1.5, 1.5, 0.25},
                              {1.5, 1.5, 1.5},  {-2, 1.25, -1.5}, {1.0, 0.3, 0.2},   {0.2, 0.1, -0.95},
                              {0.0, 0.0, 0.6},  {0.9, 0.95, 0.1}};
    std::mt19937 rng(20261121);
    std::uniform_real_distribution<double> u(-2.5, 2.5);
    for (int i = 0; i < 300; ++i) pts.push_back({u(rng), u(rng), u(rng)});
    return pts;
}

std::string points_text(const std::vector<Vec3d>& pts) {
    std::ostringstream s;
    s.precision(17);
    s << "# query points for the box\n\n";
    for (size_t i = 0; i < pts.size(); ++i) {
        if (i % 50 == 7) s << "   # a comment between points\n\n";
        if (i % 40 == 3) s << "\t" << pts[i].x << "\t" << pts[i].y << "  " << pts[i].z << "\r\n";  // tabs, CRLF
        else s << pts[i].x << " " << pts[i].y << " " << pts[i].z << "\n";
    }
    return s.str();
}

void check_box_answers(const std::vector<Vec3d>& pts, const std::string& out, double d_tol, double g_tol) {
    const std::vector<QueryLine> lines = parse_query_output(out);
    ASSERT_EQ(lines.size(), pts.size());
    int gradients_checked = 0, faces_checked = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        const BoxTruth t = box_truth(pts[i]);
        const QueryLine& q = lines[i];
        EXPECT_NEAR(q.d, t.d, d_tol) << "point " << i;
        EXPECT_GE(q.tri, 0) << "point " << i;
        EXPECT_LT(q.tri, 12) << "point " << i;
        if (t.gradient_reliable) {
            EXPECT_NEAR(q.g.x, t.g.x, g_tol) << "point " << i;
            EXPECT_NEAR(q.g.y, t.g.y, g_tol) << "point " << i;
            EXPECT_NEAR(q.g.z, t.g.z, g_tol) << "point " << i;
            ++gradients_checked;
        }
        if (t.axis >= 0 && std::abs(t.d) > 1e-3) {
            EXPECT_EQ(q.tri / 2, procedural_box_face(t.axis, t.positive)) << "point " << i;
            ++faces_checked;
        }
    }
    EXPECT_GT(gradients_checked, 200);
    EXPECT_GT(faces_checked, 50);
}

// ---- sdf-query ----------------------------------------------------------------------------

TEST_F(Cli, QueryBoxFloatMatchesAnalyticSdfInInputOrder) {
    const std::vector<Vec3d> pts = box_points();
    write("points.txt", points_text(pts));
    const ShellResult r = query("shape:box points.txt");
    ASSERT_EQ(r.code, 0) << r.err;
    check_box_answers(pts, r.out, 1e-6, 1e-5);
}

TEST_F(Cli, QueryBoxDoubleMatchesAnalyticSdf) {
    const std::vector<Vec3d> pts = box_points();
    write("points.txt", points_text(pts));
    const ShellResult r = query("shape:box points.txt --precision double --threads 2");
    ASSERT_EQ(r.code, 0) << r.err;
    check_box_answers(pts, r.out, 1e-12, 1e-10);
}

TEST_F(Cli, QueryReadsAndWritesNpyFilesAndNeverOverwrites) {
    const std::vector<Vec3d> pts = box_points();
    std::vector<double> flat;
    for (const Vec3d& p : pts) flat.insert(flat.end(), {p.x, p.y, p.z});
    write_npy(at("p.npy"), flat, {int64_t(pts.size()), 3});
    ASSERT_EQ(query("shape:box p.npy --precision double --out r.npy").code, 0);
    const NpyArray rows = read_npy(at("r.npy"));
    ASSERT_EQ(rows.shape, (std::vector<int64_t>{int64_t(pts.size()), 5}));
    const std::vector<double> r = rows.to_doubles();
    for (size_t i = 0; i < pts.size(); ++i) EXPECT_NEAR(r[5 * i], box_sdf(pts[i]), 1e-12) << i;
    // Brute force on request: the same distances, to the last bit.
    ASSERT_EQ(query("shape:box p.npy --precision double --method brute_force --out brute.npy").code, 0);
    const NpyArray brute = read_npy(at("brute.npy"));
    for (size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(brute.to_doubles()[5 * i], r[5 * i]) << i;
    // Text to a file is what stdout gets; an existing --out file is kept unless --overwrite.
    const ShellResult out = query("shape:box p.npy --out r.txt");
    ASSERT_EQ(out.code, 0) << out.err;
    EXPECT_EQ(read_text(at("r.txt")), query("shape:box p.npy").out);
    const ShellResult again = query("shape:box p.npy --out r.npy");
    EXPECT_EQ(again.code, 1);
    EXPECT_TRUE(Contains(again.err, "r.npy")) << again.err;
    EXPECT_EQ(query("shape:box p.npy --out r.npy --overwrite").code, 0);
}

TEST_F(Cli, QueryReadsStdin) {
    const std::vector<Vec3d> pts = {{2, 0, 0}, {0, 0, 0.5}, {3, 4, 1}};
    write("p.txt", points_text(pts));
    const ShellResult r = query("shape:box - < p.txt --precision double");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<QueryLine> lines = parse_query_output(r.out);
    ASSERT_EQ(lines.size(), 3u);
    EXPECT_NEAR(lines[0].d, 1.0, 1e-15);
    EXPECT_NEAR(lines[1].d, -0.5, 1e-15);
    EXPECT_NEAR(lines[2].d, std::sqrt(4.0 + 9.0), 1e-14);
}

// A query of no points is most often the wrong file or a failed step before it: refused,
// naming the input and what it should hold, in every format, and no --out file is written.
TEST_F(Cli, QueryRefusesInputWithoutPointsNamingIt) {
    write("empty.txt", "");
    write("comments.txt", "# nothing\r\n\n   \n");
    write_npy(at("none.npy"), std::vector<double>{}, {0, 3});
    const struct {
        std::string args, message;
    } cases[] = {
        {"empty.txt", "empty.txt: no points: expected \"x y z\" per line (blank lines and '#' comment lines are "
                      "skipped), but the file is empty"},
        {"comments.txt", "comments.txt: no points: expected \"x y z\" per line (blank lines and '#' comment lines are "
                         "skipped), but the file has only blank or comment lines (3)"},
        {"- < empty.txt", "-: no points: expected \"x y z\" per line (blank lines and '#' comment lines are skipped), "
                          "but standard input is empty"},
        {"none.npy", "none.npy: no points: the array has shape (0, 3); expected (N, 3) with N >= 1"},
    };
    for (const auto& c : cases) {
        const ShellResult r = query("shape:box " + c.args);
        EXPECT_EQ(r.code, 1) << c.args;
        EXPECT_TRUE(Contains(r.err, "sdf-query: error: ")) << r.err;
        EXPECT_TRUE(Contains(r.err, c.message)) << r.err;
        EXPECT_EQ(r.out, "") << c.args;
        for (const char* out : {"r.npy", "r.txt"}) {
            EXPECT_EQ(query("shape:box " + c.args + " --out " + out).code, 1) << c.args;
            EXPECT_FALSE(fs::exists(at(out))) << c.args << " wrote " << out;
        }
    }
}

TEST_F(Cli, QueryMalformedLineNamesFileAndLine) {
    // Line 1 comment, 2 blank, 3 good, 4 bad.
    for (const std::string bad : {"1.0 2.0 x", "1 2", "1 2 3 4", "nan 0 0", "1e999 0 0", "1,2,3"}) {
        write("bad.txt", "# header\n\n0 0 0\n" + bad + "\n1 1 1\n");
        const ShellResult r = query("shape:box bad.txt");
        EXPECT_NE(r.code, 0) << bad;
        EXPECT_TRUE(Contains(r.err, "bad.txt:4")) << bad;
        EXPECT_TRUE(Contains(r.err, "x y z")) << bad;
    }
}

TEST_F(Cli, QueryErrorsAreClear) {
    write("p.txt", "0 0 0\n");
    const ShellResult missing_points = query("shape:box nope.txt");
    EXPECT_NE(missing_points.code, 0);
    EXPECT_TRUE(Contains(missing_points.err, "nope.txt"));
    const ShellResult shape = query("shape:bxo p.txt");
    EXPECT_NE(shape.code, 0);
    EXPECT_TRUE(Contains(shape.err, "did you mean 'box'?"));
    const ShellResult mesh = query("no_such_mesh.obj p.txt", at("env_meshes"));
    EXPECT_NE(mesh.code, 0);
    EXPECT_TRUE(Contains(mesh.err, "no_such_mesh.obj"));
    EXPECT_TRUE(Contains(mesh.err, at("env_meshes")));
    EXPECT_TRUE(Contains(mesh.err, "scripts/fetch-meshes"));
    const ShellResult precision = query("shape:box p.txt --precision half");
    EXPECT_NE(precision.code, 0);
    EXPECT_TRUE(Contains(precision.err, "half"));
    // Number options say what they expect, without printing DBL_MAX's 309 digits, and refuse nan.
    const ShellResult threads = query("shape:box p.txt --threads -1");
    EXPECT_EQ(threads.code, 2);
    EXPECT_TRUE(Contains(threads.err, "threads")) << threads.err;  // through the options codec: key, value, what it expects
    EXPECT_TRUE(Contains(threads.err, "0 or a positive number, got -1")) << threads.err;
    EXPECT_FALSE(std::regex_search(threads.err, std::regex("[0-9]{20}"))) << threads.err;
    const ShellResult nan = query("shape:box p.txt --threads nan");
    EXPECT_EQ(nan.code, 2);
    EXPECT_TRUE(Contains(nan.err, "nan")) << nan.err;
}

TEST_F(Cli, QueryCudaBackendWithoutGpuFailsClearly) {
    if (cuda_backend_available()) GTEST_SKIP() << "a GPU is present: nothing to fail";
    write("p.txt", "0 0 0\n");
    const ShellResult r = query("shape:box p.txt --backend cuda");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(lower(r.err), "cuda")) << r.err;
    EXPECT_EQ(r.out, "");
}

/// The box as an OBJ file with the faces in a different order than make_box:
/// +x, -y, +z, -x, +y, -z (quads, outward, counter-clockwise). `skip` drops one face.
std::string box_obj(int skip = -1) {
    std::ostringstream s;
    for (int c = 0; c < 8; ++c)
        s << "v " << ((c & 1) ? 1 : -1) << " " << ((c & 2) ? 1 : -1) << " " << ((c & 4) ? 1 : -1) << "\n";
    const int quads[6][4] = {{1, 3, 7, 5}, {0, 1, 5, 4}, {4, 5, 7, 6}, {0, 4, 6, 2}, {2, 6, 7, 3}, {0, 2, 3, 1}};
    for (int f = 0; f < 6; ++f) {
        if (f == skip) continue;
        s << "f";
        for (int k = 0; k < 4; ++k) s << " " << quads[f][k] + 1;
        s << "\n";
    }
    return s.str();
}

TEST_F(Cli, QueryObjTriangleIndicesFollowTheFileFaceOrder) {
    write("box.obj", box_obj());
    // Points nearest to the interiors of +x, -y, +z, -x, +y, -z: quads 0..5 -> triangles 2k, 2k+1.
    const std::vector<Vec3d> pts = {{1.5, 0.1, 0.2}, {0.2, -1.5, 0.1}, {0.1, 0.2, 1.5},
                                    {-1.5, 0.2, 0.1}, {0.1, 1.5, -0.2}, {0.2, 0.1, -1.5}};
    write("p.txt", points_text(pts));
    const ShellResult r = query(quote(at("box.obj")) + " p.txt --precision double");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err, "");  // closed and consistently oriented: no warnings
    const std::vector<QueryLine> lines = parse_query_output(r.out);
    ASSERT_EQ(lines.size(), 6u);
    for (int k = 0; k < 6; ++k) {
        EXPECT_NEAR(lines[size_t(k)].d, 0.5, 1e-14) << k;
        EXPECT_EQ(lines[size_t(k)].tri / 2, k) << "point " << k << " got triangle " << lines[size_t(k)].tri;
    }
}

TEST_F(Cli, QueryOpenMeshWarns) {
    write("open.obj", box_obj(/*skip=*/2));  // no +z face
    write("p.txt", "0 0 3\n");
    const ShellResult r = query("open.obj p.txt", dir_.string());
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(Contains(r.err, "open"));
}

TEST_F(Cli, QuerySignModes) {
    // Two overlapping closed boxes, [-1,1]^3 and [0,2]x[-1,1]^2 (two shells). (-0.1, 0, 0) is
    // inside the first, 0.1 from the second's -x face seen from outside it: the pseudonormal
    // sign says outside, the winding number (1) inside.
    std::string two_boxes = box_obj();
    std::istringstream first(box_obj());
    std::string line;
    std::ostringstream second;
    for (int c = 0; c < 8; ++c)
        second << "v " << ((c & 1) ? 2 : 0) << " " << ((c & 2) ? 1 : -1) << " " << ((c & 4) ? 1 : -1) << "\n";
    while (std::getline(first, line)) {
        if (line.rfind("f ", 0) != 0) continue;
        std::istringstream f(line.substr(2));
        second << "f";
        for (int v; f >> v;) second << " " << v + 8;
        second << "\n";
    }
    write("two_boxes.obj", two_boxes + second.str());
    write("p.txt", "-0.1 0 0\n");
    const std::string mesh = quote(at("two_boxes.obj")) + " p.txt --precision double";

    const ShellResult pseudonormal = query(mesh + " --sign pseudonormal");
    ASSERT_EQ(pseudonormal.code, 0) << pseudonormal.err;
    ASSERT_EQ(parse_query_output(pseudonormal.out).size(), 1u);
    EXPECT_NEAR(parse_query_output(pseudonormal.out)[0].d, 0.1, 1e-15);
    EXPECT_FALSE(Contains(pseudonormal.err, "sign auto")) << pseudonormal.err;

    const ShellResult automatic = query(mesh);  // auto is the default
    ASSERT_EQ(automatic.code, 0) << automatic.err;
    EXPECT_NEAR(parse_query_output(automatic.out)[0].d, -0.1, 1e-15);
    EXPECT_TRUE(Contains(automatic.err, "warning: sign auto")) << automatic.err;
    EXPECT_TRUE(Contains(automatic.err, "2 shells")) << automatic.err;

    const ShellResult winding = query(mesh + " --sign winding");
    ASSERT_EQ(winding.code, 0) << winding.err;
    EXPECT_NEAR(parse_query_output(winding.out)[0].d, -0.1, 1e-15);
    EXPECT_FALSE(Contains(winding.err, "sign auto")) << winding.err;

    const ShellResult bad = query(mesh + " --sign parity");
    EXPECT_NE(bad.code, 0);
    EXPECT_TRUE(Contains(bad.err, "--sign")) << bad.err;
    EXPECT_TRUE(Contains(bad.err, "parity")) << bad.err;
}

// ---- run-experiment: a successful run ---------------------------------------------------

TEST_F(Cli, RunTinyConfigEndToEnd) {
    config("c.json");
    const ShellResult r = experiment("c.json --output-root out");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(Contains(r.out, "results in"));
    // Exactly one run directory, nothing hidden (no staging leftovers).
    EXPECT_EQ(sorted_entries(dir_ / "out"), (std::vector<std::string>{"tiny"}));
    const std::vector<std::string> runs = sorted_entries(dir_ / "out/tiny");
    ASSERT_EQ(runs.size(), 1u);
    const fs::path run = dir_ / "out/tiny" / runs[0];
    EXPECT_NE(runs[0][0], '.');
    EXPECT_EQ(sorted_entries(run), (std::vector<std::string>{"fields", "manifest.json", "metrics.json"}));

    const json manifest = read_json(run / "manifest.json");
    EXPECT_EQ(manifest.at("run_id"), runs[0]);
    const std::string sha = manifest.at("config").at("sha256");
    EXPECT_TRUE(std::regex_match(sha, std::regex("[0-9a-f]{64}"))) << sha;
    EXPECT_TRUE(Contains(runs[0], sha.substr(0, 8)));
    EXPECT_FALSE(manifest.at("provenance").at("git").at("commit").get<std::string>().empty());
    EXPECT_TRUE(manifest.at("provenance").at("git").contains("dirty"));
    EXPECT_TRUE(manifest.at("provenance").at("build").is_object());
    EXPECT_TRUE(manifest.at("provenance").at("build").contains("build_type"));
    const std::string started = manifest.at("started"), finished = manifest.at("finished");
    EXPECT_TRUE(std::regex_match(started, std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)"))) << started;
    EXPECT_LE(started, finished);
    EXPECT_EQ(manifest.at("name"), "tiny");
    EXPECT_EQ(manifest.at("kind"), "sampling");
    EXPECT_EQ(manifest.at("inputs").at("mesh").at("name"), "box");

    const json metrics = read_json(run / "metrics.json");
    ASSERT_EQ(metrics.at("fields").size(), 2u);
    for (const json& f : metrics.at("fields")) {
        EXPECT_TRUE(f.at("pairs_per_second").is_number()) << f.dump();
        EXPECT_GT(f.value("pairs_per_second", 0.0), 0.0) << f.dump();
    }

    // The fields read back, with the right point counts and the box's distances.
    const std::vector<std::string> files = sorted_entries(run / "fields");
    std::vector<std::string> headers;
    for (const auto& f : files)
        if (fs::path(f).extension() == ".json") headers.push_back(f);
    EXPECT_EQ(headers, (std::vector<std::string>{"box-bcc-6x6x12.json", "box-cc-8x8x8.json"}));
    for (const std::string& h : headers) {
        const SampledField field = read_field((run / "fields" / h).string());
        const bool bcc = field.lattice.type == LatticeType::BCC;
        EXPECT_EQ(field.size(), bcc ? 6 * 6 * 6 + 5 * 5 * 5 : 8 * 8 * 8) << h;
        EXPECT_EQ(field.gradient.size(), size_t(field.size()));
        EXPECT_EQ(field.closest_triangle.size(), size_t(field.size()));
        for (int64_t i = 0; i < field.size(); ++i)
            EXPECT_NEAR(field.distance[size_t(i)], box_sdf(field.lattice.position(i)), 1e-6) << h << " point " << i;
        // Domain: the box plus the default 10 % margin (0.2) on every side.
        EXPECT_NEAR(field.lattice.origin.x, -1.2, 1e-12);
        EXPECT_NEAR(field.lattice.domain_max().z, 1.2, 1e-12);
    }
}

TEST_F(Cli, RunDataPathRelativeToConfigAndOpenMeshWarning) {
    write("cfg/meshes/openbox.obj", box_obj(/*skip=*/2));
    config("cfg/c.json", {{"name", "open"},
                          {"mesh", "openbox.obj"},
                          {"data_path", {"meshes"}},
                          {"lattices", {{{"type", "cc"}, {"resolution", {4, 4, 4}}}}}});
    // Run from another directory: data_path is relative to the config, not the cwd.
    const ShellResult r = experiment("cfg/c.json --output-root out");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(Contains(r.err, "open")) << r.err;
    EXPECT_TRUE(Contains(r.err, "openbox"));
    EXPECT_EQ(sorted_entries(dir_ / "out/open").size(), 1u);
}

TEST_F(Cli, DryRunPrintsPlanAndCreatesNothing) {
    config("c.json");
    const ShellResult r = experiment("c.json --output-root out --dry-run");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(Contains(r.out, "plan"));
    EXPECT_TRUE(Contains(r.out, "cc 8x8x8"));
    EXPECT_TRUE(Contains(r.out, "bcc 6x6x12"));
    EXPECT_TRUE(Contains(r.out, "box"));
    EXPECT_FALSE(fs::exists(dir_ / "out"));
    EXPECT_EQ(sorted_entries(dir_), (std::vector<std::string>{"c.json"}));
}

TEST_F(Cli, SamplesLatticeAndOutputOptions) {
    config("c.json", {{"lattices", {{{"type", "bcc"}, {"samples", 100}}, {{"type", "cc"}, {"resolution", {3, 3, 3}}}}},
                      {"output", {{"dtype", "float64"}, {"nrrd", true}, {"uint8", true}}}});
    const ShellResult r = experiment("c.json --output-root out");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<std::string> runs = sorted_entries(dir_ / "out/tiny");
    ASSERT_EQ(runs.size(), 1u);
    const fs::path fields = dir_ / "out/tiny" / runs[0] / "fields";
    // 100 samples: BCC r = 4 (4^3 + 3^3 = 91; r = 5 gives 189).
    const SampledField b = read_field((fields / "box-bcc-4x4x8.json").string());
    EXPECT_EQ(b.size(), 91);
    EXPECT_EQ(read_json(fields / "box-bcc-4x4x8.json").at("channels").at("distance").at("dtype"), "float64");
    EXPECT_TRUE(fs::exists(fields / "box-cc-3x3x3.nrrd"));
    EXPECT_FALSE(fs::exists(fields / "box-bcc-4x4x8.nrrd"));  // NRRD is CC only
    EXPECT_EQ(fs::file_size(fields / "box-cc-3x3x3.u8.raw"), 27u);
    EXPECT_EQ(fs::file_size(fields / "box-bcc-4x4x8.u8.raw"), 91u);
}

// ---- run-experiment: config errors ----------------------------------------------------------

TEST_F(Cli, TypoInOptionalKeyNamesItAndSuggests) {
    json c = read_json(config("c.json"));
    c["sampeler"] = c["sampler"];
    c.erase("sampler");
    write("c.json", c.dump());
    const ShellResult r = experiment("c.json --output-root out");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(r.err, "c.json"));
    EXPECT_TRUE(Contains(r.err, "'sampeler'"));
    EXPECT_TRUE(Contains(r.err, "did you mean 'sampler'?"));
    EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(Cli, TypoInNestedKeyNamesThePath) {
    config("c.json", {{"sampler", {{"threads", 1}, {"precison", "double"}}}});
    const ShellResult r = experiment("c.json --output-root out --dry-run");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(r.err, "'sampler.precison'"));
    EXPECT_TRUE(Contains(r.err, "did you mean 'precision'?"));
}

// "latices" for the required "lattices": the message names the typo and suggests the key.
TEST_F(Cli, TypoInRequiredKeyNamesItAndSuggests) {
    json c = read_json(config("c.json"));
    c["latices"] = c["lattices"];
    c.erase("lattices");
    write("c.json", c.dump());
    const ShellResult r = experiment("c.json --output-root out --dry-run");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(r.err, "c.json"));
    EXPECT_TRUE(Contains(r.err, "'lattices': missing"));
    EXPECT_TRUE(Contains(r.err, "'latices'"));
    EXPECT_TRUE(Contains(r.err, "did you mean 'lattices'?"));
}

TEST_F(Cli, MalformedJsonNamesFileLineColumn) {
    write("bad.json", "{\n  \"name\": \"tiny\",\n  \"mesh\": {\"shape\": \"box\"}\n  \"lattices\": []\n}\n");
    const ShellResult r = experiment("bad.json --output-root out");
    EXPECT_NE(r.code, 0);
    // Line 4 `  "lattices": []`: the unexpected string literal ends at column 12.
    EXPECT_TRUE(Contains(r.err, "bad.json:4:12:")) << r.err;
    EXPECT_TRUE(Contains(r.err, "malformed JSON"));
    EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(Cli, WrongTypesAndValuesNameTheKey) {
    struct Case {
        json overrides;
        std::string key;
    };
    const std::vector<Case> cases = {
        {{{"sampler", {{"threads", "2"}}}}, "'sampler.threads'"},
        {{{"lattices", {{{"type", "cc"}, {"resolution", {8, 8, 8}}}, {{"type", "bcc"}, {"resolution", {6, 6, 13}}}}}},
         "'lattices[1].resolution'"},
        {{{"lattices", {{{"type", "cc"}, {"resolution", {8, 8, 8}}, {"samples", 512}}}}}, "'lattices[0].samples'"},
        {{{"domain", {{"margin", -0.1}}}}, "'domain.margin'"},
        {{{"name", "a b"}}, "'name'"},
        {{{"kind", "samplin"}}, "'kind'"},
        {{{"mesh", 3}}, "'mesh'"},
        {{{"mesh", nullptr}}, "'mesh'"},
        {{{"data_path", "meshes"}}, "'data_path'"},
        {{{"output", {{"dtype", "float16"}}}}, "'output.dtype'"},
    };
    for (const Case& c : cases) {
        config("c.json", c.overrides);
        const ShellResult r = experiment("c.json --output-root out --dry-run");
        EXPECT_NE(r.code, 0) << c.overrides.dump();
        EXPECT_TRUE(Contains(r.err, "c.json")) << c.overrides.dump();
        EXPECT_TRUE(Contains(r.err, c.key)) << c.overrides.dump();
    }
    EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(Cli, MissingMeshNamesSearchPathAndFetchScript) {
    config("cfg/c.json", {{"mesh", "no_such_mesh.obj"}, {"data_path", {"meshes"}}});
    const ShellResult r = experiment("cfg/c.json --output-root out", at("envdir"));
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(r.err, "no_such_mesh.obj"));
    EXPECT_TRUE(Contains(r.err, (fs::path("cfg") / "meshes").string()));  // the config's data_path entry
    EXPECT_TRUE(Contains(r.err, at("envdir")));                           // $SDF_DATA_PATH
    EXPECT_TRUE(Contains(r.err, "scripts/fetch-meshes"));
    EXPECT_EQ(count_files(dir_ / "out"), 0);
}

TEST_F(Cli, BadMeshFilesNameFileAndLine) {
    write("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n");
    write("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n");
    config("nan.json", {{"mesh", "nan.obj"}});
    config("lines.json", {{"mesh", "lines.obj"}});
    const ShellResult nan = experiment("nan.json --output-root out", dir_.string());
    EXPECT_NE(nan.code, 0);
    EXPECT_TRUE(Contains(nan.err, "nan.obj:3")) << nan.err;
    const ShellResult lines = experiment("lines.json --output-root out", dir_.string());
    EXPECT_NE(lines.code, 0);
    EXPECT_TRUE(Contains(lines.err, "lines.obj"));
    EXPECT_TRUE(Contains(lines.err, "no triangles"));
    EXPECT_EQ(count_files(dir_ / "out"), 0);
}

TEST_F(Cli, MissingConfigFileAndCommandLineErrors) {
    const ShellResult none = experiment("nope.json");
    EXPECT_NE(none.code, 0);
    EXPECT_TRUE(Contains(none.err, "nope.json"));
    const ShellResult no_args = experiment("");
    EXPECT_NE(no_args.code, 0);
    EXPECT_TRUE(Contains(lower(no_args.err), "config"));
}

// ---- run-experiment: runs that fail, repeat, collide, or try to escape -------------------------

// Failed runs leave nothing behind: neither the staged run nor the directories created on
// the way to it.
TEST_F(Cli, FailedRunLeavesNoDirectories) {
    // Configure-time failure: nothing is created at all.
    config("missing.json", {{"mesh", "no_such_mesh.obj"}});
    const ShellResult r = experiment("missing.json --output-root out", dir_.string());
    EXPECT_NE(r.code, 0);
    EXPECT_FALSE(fs::exists(dir_ / "out"));
    // Run-time failure (the file is found when the config is read, its line 3 is bad when it
    // is loaded): out/ and out/tiny/ were created by the run and are removed with it.
    write("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n");
    config("late.json", {{"mesh", "nan.obj"}, {"lattices", {{{"type", "cc"}, {"resolution", {3, 3, 3}}}}}});
    ASSERT_EQ(experiment("late.json --output-root out --dry-run").code, 1);  // the plan loads the mesh too
    const ShellResult late = experiment("late.json --output-root out/deeper");
    EXPECT_NE(late.code, 0);
    EXPECT_TRUE(Contains(late.err, "nan.obj:3")) << late.err;
    EXPECT_TRUE(Contains(late.err, "late.json: key 'mesh'")) << late.err;  // run-time errors name the config too
    EXPECT_FALSE(fs::exists(dir_ / "out")) << count_files(dir_ / "out");
    // An output root that existed before is kept.
    fs::create_directories(dir_ / "kept");
    EXPECT_NE(experiment("late.json --output-root kept").code, 0);
    EXPECT_TRUE(fs::is_directory(dir_ / "kept"));
    EXPECT_TRUE(fs::is_empty(dir_ / "kept"));
}

// Two runs of the same config within a second get distinct ids (milliseconds, then a suffix).
TEST_F(Cli, TwoRunsOfTheSameConfigBothSucceed) {
    config("c.json", {{"lattices", {{{"type", "cc"}, {"resolution", {3, 3, 3}}}}}});
    const ShellResult first = experiment("c.json --output-root out");
    ASSERT_EQ(first.code, 0) << first.err;
    const ShellResult second = experiment("c.json --output-root out");
    EXPECT_EQ(second.code, 0) << second.err;
    const std::vector<std::string> runs = sorted_entries(dir_ / "out/tiny");
    ASSERT_EQ(runs.size(), 2u);
    EXPECT_NE(runs[0], runs[1]);
    for (const std::string& id : runs) {
        EXPECT_TRUE(std::regex_match(id, std::regex(R"(\d{8}T\d{6}\.\d{3}Z-[0-9a-f]{8}(-\d+)?)"))) << id;
        EXPECT_EQ(read_json(dir_ / "out/tiny" / id / "manifest.json").at("run_id"), id);
    }
}

// "name" must start with a letter or digit: ".." cannot escape --output-root.
TEST_F(Cli, RunNameCannotEscapeTheOutputRoot) {
    for (const std::string name : {"..", ".", ".hidden", "-x", "_x"}) {
        config("c.json", {{"name", name}, {"lattices", {{{"type", "cc"}, {"resolution", {3, 3, 3}}}}}});
        const ShellResult r = experiment("c.json --output-root out/root");
        EXPECT_NE(r.code, 0) << name;
        EXPECT_TRUE(Contains(r.err, "'name'")) << name;
        EXPECT_TRUE(Contains(r.err, "starting with a letter or digit")) << name;
        EXPECT_FALSE(fs::exists(dir_ / "out")) << name;
    }
}

// Two lattices with the same type and resolution: distinct field names, both written.
TEST_F(Cli, TwoLatticesWithTheSameResolution) {
    config("c.json", {{"lattices", {{{"type", "cc"}, {"resolution", {4, 4, 4}}},
                                    {{"type", "cc"}, {"resolution", {4, 4, 4}}, {"margin", 0.5}}}}});
    const ShellResult dry = experiment("c.json --output-root out --dry-run");
    EXPECT_EQ(dry.code, 0) << dry.err;
    EXPECT_TRUE(Contains(dry.out, "fields/box-cc-4x4x4.json"));
    EXPECT_TRUE(Contains(dry.out, "fields/box-cc-4x4x4-1.json"));
    const ShellResult r = experiment("c.json --output-root out");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<std::string> runs = sorted_entries(dir_ / "out/tiny");
    ASSERT_EQ(runs.size(), 1u);
    std::vector<std::string> headers;
    for (const auto& f : sorted_entries(dir_ / "out/tiny" / runs[0] / "fields"))
        if (fs::path(f).extension() == ".json") headers.push_back(f);
    EXPECT_EQ(headers, (std::vector<std::string>{"box-cc-4x4x4-1.json", "box-cc-4x4x4.json"}));
    // Given names that collide are rejected before anything runs.
    config("n.json", {{"lattices", {{{"type", "cc"}, {"resolution", {4, 4, 4}}, {"name", "a"}},
                                    {{"type", "cc"}, {"resolution", {5, 5, 5}}, {"name", "a"}}}}});
    const ShellResult named = experiment("n.json --output-root out2 --dry-run");
    EXPECT_NE(named.code, 0);
    EXPECT_TRUE(Contains(named.err, "'lattices[1].name'")) << named.err;
}

// --dry-run finds what the run would: a missing mesh file, an unknown shape, a misspelt or
// out-of-range shape parameter.
TEST_F(Cli, DryRunValidatesTheMesh) {
    struct Case {
        json mesh;
        std::string expect;
    };
    for (const Case& c : std::vector<Case>{{json("no_such_mesh.obj"), "no_such_mesh.obj"},
                                           {json("shape:bxo"), "did you mean 'box'?"},
                                           {json("shape:"), "needs a shape name"},
                                           {json{{"shape", "box"}, {"half_extnt", {1, 1, 1}}}, "'mesh.half_extnt'"},
                                           {json{{"shape", "torus"}, {"minor_radius", 2.0}}, "'mesh.minor_radius'"},
                                           {json{{"file", "x.obj"}, {"shape", "box"}}, "not both"}}) {
        config("c.json", {{"mesh", c.mesh}});
        const ShellResult r = experiment("c.json --output-root out --dry-run", dir_.string());
        EXPECT_NE(r.code, 0) << c.mesh.dump();
        EXPECT_TRUE(Contains(r.err, "c.json")) << c.mesh.dump();
        EXPECT_TRUE(Contains(r.err, "'mesh")) << c.mesh.dump();
        EXPECT_TRUE(Contains(r.err, c.expect)) << c.mesh.dump();
    }
}

// Kernel names per backend and method, and a CUDA backend on a machine without
// one are all found by the dry run, naming the file and key.
TEST_F(Cli, DryRunValidatesTheSampler) {
    struct Case {
        json sampler;
        std::string key;
    };
    for (const Case& c : std::vector<Case>{{{{"threads", 1}, {"kernel", "nosuch"}}, "'sampler.kernel'"},
                                           {{{"threads", 1}, {"kernel", "tuned"}}, "'sampler.kernel'"},
                                           {{{"backend", "cuda"}, {"kernel", "eberly"}}, "'sampler.kernel'"},
                                           {{{"backend", "auto"}, {"kernel", "eberly"}}, "'sampler.kernel'"},
                                           {{{"threads", 1}, {"method", "bvh"}, {"kernel", "vectorized"}}, "'sampler.kernel'"},
                                           {{{"threads", 1}, {"method", "octree"}}, "'sampler.method'"}}) {
        config("c.json", {{"sampler", c.sampler}});
        const ShellResult r = experiment("c.json --output-root out --dry-run");
        EXPECT_NE(r.code, 0) << c.sampler.dump();
        EXPECT_TRUE(Contains(r.err, "c.json")) << r.err;
        EXPECT_TRUE(Contains(r.err, c.key)) << r.err;
    }
    // A kernel belongs to a backend: it needs the backend named (the default, auto, takes none).
    config("c.json", {{"sampler", {{"threads", 1}, {"backend", "cpu"}, {"method", "brute_force"}, {"kernel", "eberly"}}}});
    EXPECT_EQ(experiment("c.json --output-root out --dry-run").code, 0);
    config("c.json", {{"sampler", {{"threads", 1}, {"backend", "cpu"}, {"method", "bvh"}, {"kernel", "brick"}}}});
    EXPECT_EQ(experiment("c.json --output-root out --dry-run").code, 0);
    config("c.json", {{"sampler", {{"backend", "auto"}, {"threads", 1}}}});
    EXPECT_EQ(experiment("c.json --output-root out --dry-run").code, 0);
#if !SDF_HAVE_CUDA
    config("c.json", {{"sampler", {{"backend", "cuda"}}}});
    const ShellResult cuda = experiment("c.json --output-root out --dry-run");
    EXPECT_NE(cuda.code, 0);
    EXPECT_TRUE(Contains(cuda.err, "'sampler.backend'")) << cuda.err;
    EXPECT_TRUE(Contains(cuda.err, "not available")) << cuda.err;
#endif
}

TEST_F(Cli, QueryRejectsNegativeThreadCountAndUnknownKernel) {
    write("p.txt", "0 0 0\n");
    const ShellResult r = query("shape:box p.txt --threads -5");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(r.err, "threads"));
    for (const std::string backend : {"", " --backend cpu"}) {
        const ShellResult k = query("shape:box p.txt --kernel tuned" + backend);
        EXPECT_NE(k.code, 0);
        EXPECT_TRUE(Contains(k.err, "tuned")) << k.err;
    }
    // A kernel belongs to one backend and method: "auto" takes none (as in configs).
    const ShellResult auto_kernel = query("shape:box p.txt --kernel seeded");
    EXPECT_EQ(auto_kernel.code, 2);  // a command-line error
    EXPECT_TRUE(Contains(auto_kernel.err, "a kernel needs the backend cpu or cuda")) << auto_kernel.err;
    EXPECT_EQ(query("shape:box p.txt --backend cpu --kernel seeded").code, 0);
    EXPECT_EQ(query("shape:box p.txt --backend cpu --method brute_force --kernel eberly").code, 0);
    EXPECT_NE(query("shape:box p.txt --backend cpu --kernel eberly").code, 0);  // a brute-force kernel, bvh method
}

// Relative mesh names: the config's own directory, then its data_path, then $SDF_DATA_PATH;
// never the working directory. The recorded source is the absolute path used.
TEST_F(Cli, WorkingDirectoryDoesNotShadowTheDataPath) {
    write("cfg/meshes/shadow.obj", box_obj());  // 12 triangles: the one the config means
    write("shadow.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    config("cfg/c.json", {{"mesh", "shadow.obj"}, {"data_path", {"meshes"}},
                          {"lattices", {{{"type", "cc"}, {"resolution", {3, 3, 3}}}}}});
    const ShellResult r = experiment("cfg/c.json --output-root out");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<std::string> runs = sorted_entries(dir_ / "out/tiny");
    ASSERT_EQ(runs.size(), 1u);
    const json manifest = read_json(dir_ / "out/tiny" / runs[0] / "manifest.json");
    EXPECT_EQ(manifest.at("inputs").at("mesh").at("triangles"), 12);
    EXPECT_EQ(fs::path(manifest.at("inputs").at("mesh").at("source").get<std::string>()),
              fs::weakly_canonical(dir_ / "cfg/meshes/shadow.obj"));
    // Beside the config wins over data_path.
    write("cfg/shadow.obj", read_text(dir_ / "shadow.obj"));
    ASSERT_EQ(experiment("cfg/c.json --output-root out2").code, 0);
    const std::string run2 = sorted_entries(dir_ / "out2/tiny").at(0);
    EXPECT_EQ(read_json(dir_ / "out2/tiny" / run2 / "manifest.json").at("inputs").at("mesh").at("triangles"), 4);
    // sdf-query (no config) looks in the working directory first.
    write("p.txt", "0 0 3\n");
    const ShellResult q = query("shadow.obj p.txt --precision double", at("cfg/meshes"));
    ASSERT_EQ(q.code, 0) << q.err;
    EXPECT_LT(parse_query_output(q.out).at(0).tri, 4);
}

// The manifest records the config as written and as resolved (defaults filled in), and the
// hash of the resolved one.
TEST_F(Cli, ManifestRecordsTheResolvedConfig) {
    config("c.json", {{"sampler", nullptr}, {"lattices", {{{"type", "cc"}, {"resolution", {3, 3, 3}}}}}});
    const ShellResult r = experiment("c.json --output-root out");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<std::string> runs = sorted_entries(dir_ / "out/tiny");
    ASSERT_EQ(runs.size(), 1u);
    const json cfg = read_json(dir_ / "out/tiny" / runs[0] / "manifest.json").at("config");
    const json resolved = cfg.at("resolved");
    EXPECT_EQ(resolved.at("sampler").at("precision"), "float");
    // The defaults (issue 23): the BVH on "auto", recorded as the backend that ran.
    EXPECT_EQ(resolved.at("sampler").at("backend"), cuda_backend_available() ? "cuda" : "cpu");
    EXPECT_EQ(resolved.at("sampler").at("method"), "bvh");
    EXPECT_EQ(resolved.at("domain").at("margin"), 0.1);
    EXPECT_EQ(resolved.at("kind"), "sampling");
    EXPECT_EQ(resolved.at("mesh").at("half_extent"), json({1.0, 1.0, 1.0}));
    EXPECT_FALSE(cfg.at("as_written").contains("sampler"));
    EXPECT_EQ(cfg.at("as_written").at("name"), "tiny");
    const std::string text = resolved.dump();
    EXPECT_EQ(cfg.at("sha256"), sha256_hex(text.data(), text.size()));
}

// Errors in procedural shape parameters name the config file and the key.
TEST_F(Cli, ShapeParameterErrorNamesTheConfigFile) {
    config("c.json", {{"mesh", {{"shape", "box"}, {"half_extnt", {1, 1, 1}}}}});
    const ShellResult r = experiment("c.json --output-root out");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(r.err, "c.json: unknown key 'mesh.half_extnt'"));
    EXPECT_TRUE(Contains(r.err, "did you mean 'half_extent'?"));
    config("c.json", {{"mesh", {{"shape", "sphere"}, {"radius", -2}}}});
    EXPECT_TRUE(Contains(experiment("c.json --output-root out").err, "c.json: key 'mesh.radius'"));
}

TEST_F(Cli, EmptyLatticeListRejected) {
    config("c.json", {{"lattices", json::array()}});
    const ShellResult r = experiment("c.json --output-root out --dry-run");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(r.err, "'lattices'"));
    EXPECT_TRUE(Contains(r.err, "at least one"));
}

}  // namespace
}  // namespace sdf
