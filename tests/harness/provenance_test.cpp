// Provenance: the source commit of a tree without .git (a copy sent to a GPU machine) is the
// one passed in as SDF_SOURCE_COMMIT, with "-dirty" read as git describe writes it.
#include <gtest/gtest.h>

#include <cstdlib>

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

TEST_F(SourceCommit, WithNothingPassedInTheCommitIsUnknownAndCountsAsDirty) {
    unsetenv("SDF_SOURCE_COMMIT");
    const GitState g = git_state_of(dir_.string());
    if (g.source == "SDF_SOURCE_COMMIT") GTEST_SKIP() << "this build was configured with -DSDF_SOURCE_COMMIT";
    EXPECT_EQ(g.commit, "unknown");
    EXPECT_TRUE(g.dirty);
    EXPECT_EQ(g.source, "none");
}

}  // namespace
}  // namespace sdf
