// load_obj(): small OBJ files written here (triangulation order, 1-based indices, the errors
// and their messages), then the real bunny meshes when the data directory is present.
//
// tinyobjloader (2.0.0rc10) turns a token it cannot read, such as "nan" or "inf", into 0
// without a word, so load_obj() checks the `v` lines itself; both "nan" and an overflowing
// "1e999" are tested.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/mesh/load_obj.h"
#include "core/mesh/prepared_mesh.h"
#include "tests/test_util/scratch_dir.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;

/// OBJ files written to a fresh scratch directory per test.
class LoadObj : public test::ScratchDirTest {
protected:
    LoadObj() : ScratchDirTest("sdf_load_obj_test") {}

    /// Runs load_obj and returns the message it throws (fails the test if it does not throw).
    static std::string error_of(const std::string& path) {
        try {
            load_obj(path);
        } catch (const std::runtime_error& e) {
            return e.what();
        }
        ADD_FAILURE() << "load_obj(" << path << ") did not throw";
        return {};
    }
};

const char* kSquareVertices =
    "v 0 0 0\n"
    "v 1 0 0\n"
    "v 1 1 0\n"
    "v 0 1 0\n";

TEST_F(LoadObj, ReadsOneBasedIndicesAndExactCoordinates) {
    const std::string path = write("tri.obj", "# one triangle\nv 0.5 -1.25 3\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const TriangleMesh mesh = load_obj(path);
    ASSERT_EQ(mesh.vertices.size(), 3u);
    ASSERT_EQ(mesh.triangles.size(), 1u);
    EXPECT_EQ(mesh.triangles[0], (Int3{0, 1, 2}));
    EXPECT_EQ(mesh.vertices[0], (Vec3d{0.5, -1.25, 3.0}));
    EXPECT_EQ(mesh.name, "tri");
    EXPECT_EQ(mesh.source, path);
    EXPECT_EQ(mesh.content_sha256.size(), 64u);
}

// A quad is split along its shorter diagonal (polygon_triangulation.h); with the 0-2
// diagonal shorter that is the fan (0 1 2) (0 2 3). Faces keep their file order.
TEST_F(LoadObj, QuadBecomesTwoTrianglesInFileOrder) {
    const std::string path = write("kite.obj",
                                   "v 0 0 0\n"
                                   "v 1 -3 0\n"
                                   "v 2 0 0\n"
                                   "v 1 3 0\n"
                                   "v 5 5 5\n"
                                   "f 1 2 5\n"
                                   "f 1 2 3 4\n"
                                   "f 2 3 5\n");
    const TriangleMesh mesh = load_obj(path);
    ASSERT_EQ(mesh.triangles.size(), 4u);
    EXPECT_EQ(mesh.triangles[0], (Int3{0, 1, 4}));
    EXPECT_EQ(mesh.triangles[1], (Int3{0, 1, 2}));
    EXPECT_EQ(mesh.triangles[2], (Int3{0, 2, 3}));
    EXPECT_EQ(mesh.triangles[3], (Int3{1, 2, 4}));
}

// With the 1-3 diagonal shorter the quad is cut along it: (1 2 3) (0 1 3), both still
// counter-clockwise like the quad (polygon_triangulation.h: the ear at corner 2 first).
TEST_F(LoadObj, QuadIsCutAlongItsShorterDiagonal) {
    const std::string path = write("flat.obj", "v 0 0 0\nv 2 -0.5 0\nv 4 0 0\nv 2 0.5 0\nf 1 2 3 4\n");
    const TriangleMesh mesh = load_obj(path);
    ASSERT_EQ(mesh.triangles.size(), 2u);
    EXPECT_EQ(mesh.triangles[0], (Int3{1, 2, 3}));
    EXPECT_EQ(mesh.triangles[1], (Int3{0, 1, 3}));
}

TEST_F(LoadObj, MissingFileThrowsWithItsPath) {
    const std::string path = (dir_ / "does-not-exist.obj").string();
    EXPECT_NE(error_of(path).find(path), std::string::npos);
}

TEST_F(LoadObj, FileWithoutFacesThrows) {
    const std::string path = write("points.obj", kSquareVertices);
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find("no triangles"), std::string::npos) << error;
}

TEST_F(LoadObj, NonFiniteCoordinateThrowsWithFileAndLine) {
    const std::string path = write("inf.obj",
                                   "# a comment\n"
                                   "v 0 0 0\n"
                                   "v 1 0 0\n"
                                   "v 1e999 1 0\n"
                                   "v 0 1 0\n"
                                   "f 1 2 3\n");
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path + ":4:"), std::string::npos) << error;
    EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
}

// tinyobjloader alone would read "nan" as 0; load_obj() checks every `v` line itself.
TEST_F(LoadObj, NanCoordinateThrowsWithFileAndLine) {
    const std::string path = write("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path + ":3:"), std::string::npos) << error;
}

TEST_F(LoadObj, FaceIndexOutOfRangeThrows) {
    const std::string path = write("bad-index.obj", std::string(kSquareVertices) + "f 1 2 3\nf 1 3 9\n");
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find("vertex 9"), std::string::npos) << error;
}

// tinyobjloader alone would drop such a quad with a warning; load_obj() makes it an error.
TEST_F(LoadObj, QuadIndexOutOfRangeThrows) {
    const std::string path = write("bad-quad.obj", std::string(kSquareVertices) + "f 1 2 3\nf 1 2 3 9\n");
    error_of(path);
}

/// The first directory of the colon-separated SDF_DATA_PATH (set by ctest) holding `file`.
std::string find_data_file(const std::string& file) {
    const char* env = std::getenv("SDF_DATA_PATH");
    std::stringstream dirs(env ? env : "");
    for (std::string dir; std::getline(dirs, dir, ':');)
        if (!dir.empty() && fs::is_regular_file(fs::path(dir) / file)) return (fs::path(dir) / file).string();
    return {};
}

TEST(LoadObjData, BunnyIsClosedAndTheOpenBunnyHas223BoundaryEdges) {
    const std::string bunny = find_data_file("bunny.obj"), open = find_data_file("bunny-open.obj");
    if (bunny.empty() || open.empty()) GTEST_SKIP() << "bunny.obj / bunny-open.obj not on SDF_DATA_PATH";

    const TriangleMesh closed_mesh = load_obj(bunny);
    EXPECT_EQ(closed_mesh.vertices.size(), 34834u);
    EXPECT_EQ(closed_mesh.triangles.size(), 69664u);
    const PreparedMesh closed = prepare_mesh(closed_mesh);
    EXPECT_TRUE(closed.report().sign_reliable());
    EXPECT_EQ(closed.report().components, 1);
    EXPECT_FALSE(closed.report().flipped);
    EXPECT_NEAR(closed.report().signed_volume, 0.000754759, 1e-9);  // meshes/README.md

    const PreparedMesh open_mesh = prepare_mesh(load_obj(open));
    EXPECT_EQ(open_mesh.report().input_triangles, 69451);
    EXPECT_EQ(open_mesh.report().boundary_edges, 223);
    EXPECT_EQ(open_mesh.report().nonmanifold_edges, 0);
    EXPECT_TRUE(open_mesh.report().consistently_oriented());
    bool warned = false;
    for (const std::string& w : open_mesh.warnings()) warned |= w.find("open") != std::string::npos;
    EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace sdf
