// Provenance: the source commit of a tree without .git (a copy sent to a GPU machine) is the
// one passed in as SDF_SOURCE_COMMIT, with "-dirty" read as git describe writes it; a commit
// passed in wins over a (possibly stale) .git. The build record names the ISA level the CPU
// kernels ran at, and the machine identity of speedup checks includes it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>

#include "cpu_reference/dispatch/cpu_kernels.h"
#include "harness/provenance/provenance.h"
#include "harness_test_util.h"

namespace sdf {
namespace {

class SourceCommit : public test::ScratchDirTest {
protected:
    SourceCommit() : ScratchDirTest("sdf_provenance_test") {}
    void TearDown() override {
        unsetenv("SDF_SOURCE_COMMIT");
        ScratchDirTest::TearDown();
    }
};

TEST_F(SourceCommit, ATreeWithoutGitRecordsTheCommitPassedIn) {
    ASSERT_EQ(setenv("SDF_SOURCE_COMMIT", "0123abcd", 1), 0);
    GitState g = git_state_of(dir_.string());
    EXPECT_EQ(g.commit, "0123abcd");
    EXPECT_FALSE(g.dirty);
    EXPECT_EQ(g.source, "SDF_SOURCE_COMMIT");

    ASSERT_EQ(setenv("SDF_SOURCE_COMMIT", "0123abcd-dirty", 1), 0);
    g = git_state_of(dir_.string());
    EXPECT_EQ(g.commit, "0123abcd");
    EXPECT_TRUE(g.dirty);
}

TEST_F(SourceCommit, ACommitPassedInWinsOverAStaleGitDirectory) {
    // The GPU machines' copies of the tree held a .git whose HEAD was an older commit, and the
    // runs recorded that one as their source.
    const std::string init = "cd '" + dir_.string() + "' && git init -q && git -c user.name=t -c user.email=t@t " +
                             "commit -q --allow-empty -m stale";
    ASSERT_EQ(std::system(init.c_str()), 0);
    unsetenv("SDF_SOURCE_COMMIT");
    const GitState from_git = git_state_of(dir_.string());
    if (from_git.source == "SDF_SOURCE_COMMIT") GTEST_SKIP() << "this build was configured with -DSDF_SOURCE_COMMIT";
    EXPECT_EQ(from_git.source, "git");
    ASSERT_EQ(setenv("SDF_SOURCE_COMMIT", "0123abcd", 1), 0);
    const GitState passed = git_state_of(dir_.string());
    EXPECT_EQ(passed.commit, "0123abcd");
    EXPECT_EQ(passed.source, "SDF_SOURCE_COMMIT");
}

TEST_F(SourceCommit, WithNothingPassedInTheCommitIsUnknownAndCountsAsDirty) {
    unsetenv("SDF_SOURCE_COMMIT");
    const GitState g = git_state_of(dir_.string());
    if (g.source == "SDF_SOURCE_COMMIT") GTEST_SKIP() << "this build was configured with -DSDF_SOURCE_COMMIT";
    EXPECT_EQ(g.commit, "unknown");
    EXPECT_TRUE(g.dirty);
    EXPECT_EQ(g.source, "none");
}

TEST(Provenance, TheBuildRecordNamesTheKernelsThatRan) {
    const nlohmann::json build = build_info();
    ASSERT_TRUE(build.contains("cpu_kernels")) << build.dump();
    const nlohmann::json& k = build["cpu_kernels"];
    EXPECT_EQ(k.at("isa").get<std::string>(), active_cpu_kernels().isa);
    const std::vector<std::string> built = k.at("built").get<std::vector<std::string>>();
    EXPECT_NE(std::find(built.begin(), built.end(), k.at("isa").get<std::string>()), built.end()) << k.dump();
    const nlohmann::json kind = machine_kind(machine_and_build());
    EXPECT_EQ(kind.at("cpu_kernels"), k.at("isa"));
    // A manifest written before dispatch has no record: its identity has no such key.
    nlohmann::json old = machine_and_build();
    old["build"].erase("cpu_kernels");
    EXPECT_FALSE(machine_kind(old).contains("cpu_kernels"));
}

}  // namespace
}  // namespace sdf
