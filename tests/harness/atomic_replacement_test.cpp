// Replacing a field is atomic (harness/io/field_replacement.h, issue 26): `sdf-sample
// --overwrite` fails (SDF_FAULT_AT=k) or is killed (SDF_FAULT_MODE=kill, and SIGKILL at
// random instants) at every step of its commit, and the field file it replaces must then read
// back as the old field whole or the new one whole: the same mesh, lattice and values as a
// reference run of either, never the old header over the new channels. Both on the same
// lattice (where a mix would read back without error) and on another one. A failed run leaves
// no file behind; a killed run's leftovers are removed by the next run. Also: every target is
// checked before sampling (a missing --vdb folder), the sparse band's .vdb is old or new whole
// at every step too (write_through_temporary), values float32 cannot hold are refused
// (--band 1e-300), and budgets beyond the machine are refused with both figures. The sparse
// band's field file (--layout sparse) is old or new whole at every step as well.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <csignal>
#include <cstdio>

#include <chrono>
#include <filesystem>
#include <random>
#include <set>

#include "core/mesh/sha256.h"
#include "harness/io/field_file.h"
#include "harness/io/field_replacement.h"
#include "harness/io/sparse_field_file.h"
#include "harness_test_util.h"

#if !defined(SDF_SAMPLE_EXE) || !defined(RUN_EXPERIMENT_EXE)
#error "SDF_SAMPLE_EXE and RUN_EXPERIMENT_EXE must be defined by CMake"
#endif

namespace sdf {
namespace {

namespace fs = std::filesystem;

/// What a field holds: its mesh, lattice and values, or "unreadable: why".
std::string fingerprint(const std::string& header) {
    try {
        const SampledField f = read_field(header);
        std::string bytes = nlohmann::json(f.mesh).dump() + lattice_to_json(f.lattice).dump();
        bytes.append(reinterpret_cast<const char*>(f.distance.data()), f.distance.size() * sizeof(double));
        bytes.append(reinterpret_cast<const char*>(f.gradient.data()), f.gradient.size() * sizeof(Vec3d));
        bytes.append(reinterpret_cast<const char*>(f.closest_triangle.data()), f.closest_triangle.size() * sizeof(int32_t));
        return sha256_hex(bytes.data(), bytes.size());
    } catch (const std::exception& e) {
        return std::string("unreadable: ") + e.what();
    }
}

std::set<std::string> entries(const fs::path& dir) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
    return names;
}

void copy_folder(const fs::path& from, const fs::path& to) {
    fs::remove_all(to);
    fs::create_directories(to);
    for (const auto& e : fs::directory_iterator(from)) fs::copy_file(e.path(), to / e.path().filename());
}

const std::string kExe = test::quote(SDF_SAMPLE_EXE);
const std::string kCommon = " --backend cpu --quiet --memory-budget 256MiB";
const std::string kFourPlanes = " --max-planes-per-slab 4";

/// An old field and a new one (another mesh: another header) to replace it with.
struct Case {
    std::string label, old_args, new_args;
};

class AtomicReplacement : public test::ScratchDirTest {
protected:
    AtomicReplacement() : ScratchDirTest("atomic_replacement") {}

    /// Runs sdf-sample in `dir` with `args` (and environment assignments before it).
    test::ShellResult sample(const fs::path& dir, const std::string& env, const std::string& args) {
        return test::run_in(dir, env + " " + kExe + " " + args + kCommon);
    }

    /// The reference fingerprint of `args` written alone into `name`/f.json.
    std::string reference(const std::string& name, const std::string& args) {
        const fs::path dir = dir_ / (name + "_" + std::to_string(references_++));
        fs::create_directories(dir);
        const test::ShellResult r = sample(dir, "", args + " --out f.json");
        EXPECT_EQ(r.code, 0) << r.err;
        return fingerprint((dir / "f.json").string());
    }

    int references_ = 0;
};

TEST_F(AtomicReplacement, FailureOrKillAtEveryStepLeavesTheOldFieldOrTheNewOneWhole) {
    const std::vector<Case> cases = {
        {"same lattice", "shape:sphere --resolution 16" + kFourPlanes, "shape:torus --resolution 16" + kFourPlanes},
        {"another lattice", "shape:sphere --resolution 16" + kFourPlanes, "shape:torus --lattice bcc --resolution 10" + kFourPlanes},
    };
    for (const Case& c : cases) {
        const std::string old_fp = reference("old", c.old_args), new_fp = reference("new", c.new_args);
        ASSERT_NE(old_fp, new_fp);
        ASSERT_EQ(old_fp.rfind("unreadable", 0), std::string::npos) << old_fp;
        // The old field as a first write left it (plain names), and as a replacement left it
        // (names with a writer's tag): both must be replaced atomically.
        for (int generation : {1, 2}) {
            if (generation == 2 && c.label != "same lattice") continue;  // the tagged layout once: it does not depend on the lattice
            const fs::path seed = dir_ / ("seed_" + std::to_string(references_) + "_" + std::to_string(generation));
            fs::create_directories(seed);
            if (generation == 2) {
                ASSERT_EQ(sample(seed, "", c.new_args + " --out f.json --vdb f.vdb").code, 0);
            }
            ASSERT_EQ(sample(seed, "", c.old_args + " --out f.json --vdb f.vdb" + (generation == 2 ? " --overwrite" : "")).code, 0);
            ASSERT_EQ(fingerprint((seed / "f.json").string()), old_fp);
            const std::set<std::string> old_files = entries(seed);
            for (const char* mode : {"fail", "kill"}) {
                int completed_at = 0;
                for (int k = 1; k <= 40 && completed_at == 0; ++k) {
                    const std::string what = c.label + ", generation " + std::to_string(generation) + ", " + mode +
                                             " at step " + std::to_string(k);
                    const fs::path work = dir_ / "work";
                    copy_folder(seed, work);
                    const std::string env = "SDF_FAULT_AT=" + std::to_string(k) + (std::string(mode) == "kill" ? " SDF_FAULT_MODE=kill" : "");
                    const test::ShellResult r = sample(work, env, c.new_args + " --out f.json --vdb f.vdb --overwrite");
                    const std::string now = fingerprint((work / "f.json").string());
                    if (r.code == 0) {  // past the last step: the run completed
                        completed_at = k;
                        EXPECT_EQ(now, new_fp) << what;
                        continue;
                    }
                    EXPECT_TRUE(now == old_fp || now == new_fp) << what << ": " << now << "\n" << r.err;
                    if (std::string(mode) == "fail") {
                        EXPECT_EQ(r.code, 1) << what;
                        EXPECT_TRUE(test::Contains(r.err, "injected failure at step " + std::to_string(k))) << what;
                        // Nothing left behind: the old field's files, or the new one's.
                        if (now == old_fp) {
                            EXPECT_EQ(entries(work), old_files) << what;
                        }
                    } else {
                        EXPECT_TRUE(r.code == -1 || r.code == 128 + SIGKILL) << what << ": not killed (" << r.code << ")\n" << r.err;
                        // The next run removes what the killed one left and replaces the field.
                        ASSERT_EQ(sample(work, "", c.new_args + " --out f.json --vdb f.vdb --overwrite").code, 0) << what;
                        EXPECT_EQ(fingerprint((work / "f.json").string()), new_fp) << what;
                        EXPECT_EQ(entries(work).size(), 5u) << what << ": header, 3 channels, .vdb";
                    }
                }
                // Every step was tried: sampling (4 slabs), the channels, their renames, the
                // header, the old files' removal, the .vdb.
                EXPECT_GE(completed_at, 10) << c.label << " " << mode;
            }
        }
    }
}

TEST_F(AtomicReplacement, SigkillAtRandomInstantsLeavesAWholeField) {
    const std::string old_args = "shape:sphere --resolution 28", new_args = "shape:torus --resolution 28";
    const std::string old_fp = reference("old", old_args), new_fp = reference("new", new_args);
    const fs::path work = dir_ / "work";
    fs::create_directories(work);
    ASSERT_EQ(sample(work, "", old_args + " --out f.json --max-planes-per-slab 2").code, 0);
    // How long a replacing run takes here: the kills fall within it.
    const auto start = std::chrono::steady_clock::now();
    ASSERT_EQ(sample(work, "", new_args + " --out f.json --overwrite --max-planes-per-slab 2").code, 0);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::mt19937 random(26);  // a fixed seed: the same instants every run
    std::uniform_real_distribution<double> instant(0.0, 1.2 * seconds);
    int killed = 0, old_seen = 0, new_seen = 0;
    for (int i = 0; i < 16; ++i) {
        const std::string next = i % 2 == 0 ? old_args : new_args;  // alternate: each run replaces the other
        char t[32];
        std::snprintf(t, sizeof t, "%.3f", std::max(0.001, instant(random)));
        const test::ShellResult r =
            test::run_in(work, "timeout -s KILL " + std::string(t) + " " + kExe + " " + next + kCommon +
                                   " --max-planes-per-slab 2 --out f.json --overwrite");
        killed += r.code != 0;
        const std::string now = fingerprint((work / "f.json").string());
        EXPECT_TRUE(now == old_fp || now == new_fp) << "kill after " << t << " s: " << now;
        old_seen += now == old_fp;
        new_seen += now == new_fp;
    }
    EXPECT_GT(killed, 0);
    std::cout << "SIGKILL at 16 random instants within " << 1.2 * seconds << " s: " << killed << " killed; the field read back "
              << old_seen << " times as the sphere's, " << new_seen << " as the torus's\n";
    ASSERT_EQ(sample(work, "", new_args + " --out f.json --overwrite --max-planes-per-slab 2").code, 0);
    EXPECT_EQ(fingerprint((work / "f.json").string()), new_fp);
    EXPECT_EQ(entries(work).size(), 4u) << "header and 3 channels; leftovers of the killed runs removed";
}

// The sparse band's .vdb (write_sparse_band_vdb) is written through a temporary, synced and
// placed by write_through_temporary (atomic_file.h), whose rename is a fault point: failed or
// killed at every step of a replacing run, the .vdb is the old file byte for byte or a whole
// new one (as large as the reference run's: OpenVDB's bytes differ only in the file's UUID),
// the field is old or new whole, and a failed run leaves no temporary behind.
TEST_F(AtomicReplacement, SparseBandVdbIsOldOrNewWholeAtEveryStep) {
    const std::string old_args = "shape:sphere --resolution 12 --band 0.3 --sparse" + kFourPlanes,
                      new_args = "shape:torus --resolution 12 --band 0.3 --sparse" + kFourPlanes;
    const std::string old_fp = reference("sparse_old", old_args), new_fp = reference("sparse_new", new_args);
    const fs::path seed = dir_ / "sparse_seed", fresh = dir_ / "sparse_fresh";
    fs::create_directories(seed);
    fs::create_directories(fresh);
    ASSERT_EQ(sample(seed, "", old_args + " --out f.json --vdb f.vdb").code, 0);
    ASSERT_EQ(sample(fresh, "", new_args + " --out f.json --vdb f.vdb").code, 0);
    const std::string old_vdb = test::read_text(seed / "f.vdb");
    const size_t new_vdb_size = fs::file_size(fresh / "f.vdb");
    ASSERT_NE(old_vdb.size(), new_vdb_size);
    const std::set<std::string> old_files = entries(seed);
    for (const char* mode : {"fail", "kill"}) {
        int completed_at = 0, vdb_kept_at_last_step = 0;
        for (int k = 1; k <= 40 && completed_at == 0; ++k) {
            const std::string what = std::string(mode) + " at step " + std::to_string(k);
            const fs::path work = dir_ / "sparse_work";
            copy_folder(seed, work);
            const std::string env = "SDF_FAULT_AT=" + std::to_string(k) + (std::string(mode) == "kill" ? " SDF_FAULT_MODE=kill" : "");
            const test::ShellResult r = sample(work, env, new_args + " --out f.json --vdb f.vdb --overwrite");
            const std::string now = fingerprint((work / "f.json").string());
            const std::string vdb = test::read_text(work / "f.vdb");
            EXPECT_TRUE(vdb == old_vdb || vdb.size() == new_vdb_size) << what << ": a .vdb of " << vdb.size() << " bytes";
            if (r.code == 0) {
                completed_at = k;
                EXPECT_EQ(now, new_fp) << what;
                EXPECT_EQ(vdb.size(), new_vdb_size) << what;
                continue;
            }
            EXPECT_TRUE(now == old_fp || now == new_fp) << what << ": " << now << "\n" << r.err;
            if (now == new_fp && vdb == old_vdb) vdb_kept_at_last_step = k;  // the field committed, the .vdb not yet
            if (std::string(mode) == "fail") {
                EXPECT_TRUE(test::Contains(r.err, "injected failure at step " + std::to_string(k))) << what;
                if (now == old_fp) {
                    EXPECT_EQ(entries(work), old_files) << what;
                }
                for (const std::string& name : entries(work))
                    EXPECT_EQ(name.find(".tmp."), std::string::npos) << what << ": " << name << " left behind";
            }
        }
        EXPECT_GE(completed_at, 8) << mode;
        // The last step before completion is the .vdb's rename: the field is new, the .vdb still old.
        EXPECT_EQ(vdb_kept_at_last_step, completed_at - 1) << mode;
    }
}

/// What a sparse band's field file holds: its mesh, lattice, band and every array, or
/// "unreadable: why".
std::string sparse_fingerprint(const std::string& header) {
    try {
        const SparseBandField b = read_sparse_field(header);
        std::string bytes = nlohmann::json(b.mesh).dump() + lattice_to_json(b.lattice).dump() + std::to_string(b.width);
        const auto add = [&](const auto& v) {
            bytes.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(v[0]));
        };
        add(b.active), add(b.distance), add(b.gradient), add(b.closest_triangle), add(b.inside_tiles), add(b.mixed),
            add(b.mixed_inside);
        return sha256_hex(bytes.data(), bytes.size());
    } catch (const std::exception& e) {
        return std::string("unreadable: ") + e.what();
    }
}

// The sparse band's field file (write_sparse_field: its channels placed by FieldReplacement,
// the header last) replaced by `sdf-sample --layout sparse --overwrite` that fails or is
// killed at every step: it reads back as the old band whole or the new one whole; a failed
// run leaves the old files and no temporary; the next run after a kill replaces it cleanly.
TEST_F(AtomicReplacement, SparseFieldFileIsOldOrNewWholeAtEveryStep) {
    const std::string old_args = "shape:sphere --resolution 12 --band 0.3 --sparse --layout sparse",
                      new_args = "shape:torus --resolution 14 --band 0.3 --sparse --layout sparse";
    const fs::path seed = dir_ / "sparse_file_seed", fresh = dir_ / "sparse_file_fresh";
    fs::create_directories(seed);
    fs::create_directories(fresh);
    ASSERT_EQ(sample(seed, "", old_args + " --out f.json").code, 0);
    ASSERT_EQ(sample(fresh, "", new_args + " --out f.json").code, 0);
    const std::string old_fp = sparse_fingerprint((seed / "f.json").string()), new_fp = sparse_fingerprint((fresh / "f.json").string());
    ASSERT_EQ(old_fp.rfind("unreadable", 0), std::string::npos) << old_fp;
    ASSERT_NE(old_fp, new_fp);
    const std::set<std::string> old_files = entries(seed), new_files = entries(fresh);
    ASSERT_EQ(old_files.size(), 8u) << "header and 7 channels";
    for (const char* mode : {"fail", "kill"}) {
        int completed_at = 0;
        for (int k = 1; k <= 40 && completed_at == 0; ++k) {
            const std::string what = std::string(mode) + " at step " + std::to_string(k);
            const fs::path work = dir_ / "sparse_file_work";
            copy_folder(seed, work);
            const std::string env = "SDF_FAULT_AT=" + std::to_string(k) + (std::string(mode) == "kill" ? " SDF_FAULT_MODE=kill" : "");
            const test::ShellResult r = sample(work, env, new_args + " --out f.json --overwrite");
            const std::string now = sparse_fingerprint((work / "f.json").string());
            if (r.code == 0) {
                completed_at = k;
                EXPECT_EQ(now, new_fp) << what;
                EXPECT_EQ(entries(work).size(), 8u) << what;
                continue;
            }
            EXPECT_TRUE(now == old_fp || now == new_fp) << what << ": " << now << "\n" << r.err;
            if (std::string(mode) == "fail") {
                EXPECT_EQ(r.code, 1) << what;
                EXPECT_TRUE(test::Contains(r.err, "injected failure at step " + std::to_string(k))) << what;
                if (now == old_fp) {
                    EXPECT_EQ(entries(work), old_files) << what;
                }
                for (const std::string& name : entries(work))
                    EXPECT_EQ(name.find(".tmp"), std::string::npos) << what << ": " << name << " left behind";
            } else {
                EXPECT_TRUE(r.code == -1 || r.code == 128 + SIGKILL) << what << ": not killed (" << r.code << ")\n" << r.err;
                ASSERT_EQ(sample(work, "", new_args + " --out f.json --overwrite").code, 0) << what;
                EXPECT_EQ(sparse_fingerprint((work / "f.json").string()), new_fp) << what;
                EXPECT_EQ(entries(work).size(), 8u) << what << ": header and 7 channels";
            }
        }
        // Every step was tried: the 7 channels' renames, the header, the old files' removal.
        EXPECT_GE(completed_at, 9) << mode;
    }
}

// The issue's case: a missing --vdb folder was found after the sampling, with the new channels
// renamed over the old ones. Now it is refused before anything is sampled or written.
TEST_F(AtomicReplacement, EveryTargetIsCheckedBeforeSampling) {
    ASSERT_EQ(sample(dir_, "", "shape:sphere --resolution 12 --out f.json").code, 0);
    const std::string before = fingerprint(at("f.json"));
    const std::set<std::string> files = entries(dir_);
    const test::ShellResult r = sample(dir_, "", "shape:torus --resolution 12 --out f.json --vdb nodir/x.vdb --overwrite");
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(test::Contains(r.err, "nodir/x.vdb")) << r.err;
    EXPECT_TRUE(test::Contains(r.err, "does not exist")) << r.err;
    EXPECT_EQ(fingerprint(at("f.json")), before);
    EXPECT_EQ(entries(dir_), files);
    const test::ShellResult missing = sample(dir_, "", "shape:torus --resolution 12 --out nodir/f.json");
    EXPECT_EQ(missing.code, 1);
    EXPECT_TRUE(test::Contains(missing.err, "does not exist")) << missing.err;
}

TEST_F(AtomicReplacement, ChannelNamesOfAFieldAreRecognised) {
    EXPECT_TRUE(is_field_channel_name("a/f.json", "f.distance.raw"));
    EXPECT_TRUE(is_field_channel_name("a/f.json", "f.closest_triangle.w123-4.raw"));
    EXPECT_FALSE(is_field_channel_name("a/f.json", "f.normals.raw"));
    EXPECT_FALSE(is_field_channel_name("a/f.json", "g.distance.raw"));
    EXPECT_FALSE(is_field_channel_name("a/f.json", "f.distance.mine.raw"));
    EXPECT_FALSE(is_field_channel_name("a/f.json", "f.distance.w12.raw"));
}

SampledField small_field(double value) {
    SampledField f;
    f.lattice.type = LatticeType::CC;
    f.lattice.resolution = {2, 2, 2};
    f.lattice.spacing = 1;
    f.resize(8);
    for (double& d : f.distance) d = value;
    return f;
}

// write_field replaces a field the same way: the old channel files go once the new header is
// in place; a header written by hand keeps the files it names that are not this field's.
TEST_F(AtomicReplacement, WriteFieldReplacesInOneStepAndRemovesOnlyTheOldFieldsFiles) {
    FieldWriteOptions allow;
    allow.overwrite = Overwrite::Allow;
    write_field(at("f.json"), small_field(1), allow);
    write_field(at("f.json"), small_field(2), allow);  // the old header names the plain names
    EXPECT_EQ(read_field(at("f.json")).distance[0], 2);
    EXPECT_EQ(entries(dir_).size(), 4u);  // header and 3 channels, now tagged
    EXPECT_FALSE(fs::exists(at("f.distance.raw")));
    write_field(at("f.json"), small_field(3), allow);  // back to the plain names
    EXPECT_EQ(entries(dir_), (std::set<std::string>{"f.closest_triangle.raw", "f.distance.raw", "f.gradient.raw", "f.json"}));
    EXPECT_EQ(read_field(at("f.json")).distance[0], 3);
    // A user's header naming a file of another pattern: replaced, the file kept.
    write("u.mine.raw", std::string(32, '\0'));
    write("u.json", R"({"format": "sdf-lattice-field", "version": 1,
        "lattice": {"type": "cc", "origin": [0, 0, 0], "spacing": 1, "resolution": [2, 2, 2]},
        "channels": {"value": {"file": "u.mine.raw"}}})");
    write_field(at("u.json"), small_field(4), allow);
    EXPECT_EQ(read_field(at("u.json")).distance[0], 4);
    EXPECT_TRUE(fs::exists(at("u.mine.raw")));
}

// A finite value beyond float32's range would be stored as inf: refused, naming the file,
// and nothing is left behind.
TEST_F(AtomicReplacement, ValuesBeyondFloat32AreRefused) {
    const std::string msg = test::error_of([&] { write_field(at("big.json"), small_field(1e39)); });
    EXPECT_TRUE(test::Contains(msg, "big.distance.raw")) << msg;
    EXPECT_TRUE(test::Contains(msg, "beyond float32's range")) << msg;
    EXPECT_TRUE(entries(dir_).empty());
    FieldWriteOptions f64;
    f64.dtype = FieldDtype::Float64;
    write_field(at("big.json"), small_field(1e39), f64);
    EXPECT_EQ(read_field(at("big.json")).distance[0], 1e39);
}

// Values the output cannot hold: a band below float32's smallest normal value would be stored
// as +-0 (a field of zeros), one beyond its largest as +-inf.
TEST_F(AtomicReplacement, BandsTheOutputCannotHoldAreRefused) {
    for (const std::string& args : {std::string("--band 1e-300"), std::string("--band 1e39"),
                                    std::string("--band 1e-300 --dtype float64 --vdb f.vdb")}) {
        const test::ShellResult r = sample(dir_, "", "shape:sphere --resolution 8 --out f.json " + args);
        EXPECT_EQ(r.code, 2) << args << ": " << r.err;
        EXPECT_TRUE(test::Contains(r.err, "--band")) << r.err;
        EXPECT_TRUE(test::Contains(r.err, "cannot be stored in float32")) << r.err;
        EXPECT_FALSE(fs::exists(at("f.json")));
    }
    const test::ShellResult ok = sample(dir_, "", "shape:sphere --resolution 8 --out f.json --band 1e-300 --dtype float64");
    EXPECT_EQ(ok.code, 0) << ok.err;
    const SampledField f = read_field(at("f.json"));
    for (double d : f.distance) EXPECT_TRUE(d == 1e-300 || d == -1e-300 || std::abs(d) <= 1e-300) << d;
    EXPECT_THROW(require_representable_band(1e-39, FieldDtype::Float32, "w"), std::invalid_argument);
    EXPECT_NO_THROW(require_representable_band(1.2e-38, FieldDtype::Float32, "w"));
    EXPECT_THROW(require_representable_band(1e-310, FieldDtype::Float64, "w"), std::invalid_argument);
}

// A budget beyond the machine is not trusted: the plan's peak is compared with the memory
// available (here set with SDF_MEMORY_AVAILABLE, as a smaller machine would have).
TEST_F(AtomicReplacement, BudgetsBeyondTheMachineAreRefused) {
    const test::ShellResult r = test::run_in(
        dir_, "SDF_MEMORY_AVAILABLE=1000000000 " + kExe + " shape:sphere --resolution 300 --out f.json --memory-budget 1TiB --quiet");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(test::Contains(r.err, "--memory-budget")) << r.err;
    EXPECT_TRUE(test::Contains(r.err, "exceeds the 954 MiB of memory available")) << r.err;
    EXPECT_TRUE(test::Contains(r.err, "budget 1 TiB")) << r.err;
    EXPECT_FALSE(fs::exists(at("f.json")));
}

// Under a memory limit the plan sees the limit (ulimit -v); where an allocation fails anyway
// (the plan's figure overridden), the message names the input and the size, not a bare
// std::bad_alloc.
TEST_F(AtomicReplacement, OutOfMemoryNamesTheInputAndTheSize) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space: ulimit -v cannot be used";
#endif
    const std::string run = kExe + " shape:sphere --backend cpu --threads 1 --resolution 400 --out f.json --quiet";
    const test::ShellResult planned = test::run_in(dir_, "ulimit -v 2000000 && " + run + " --memory-budget 60GiB");
    EXPECT_EQ(planned.code, 1) << planned.err;
    EXPECT_TRUE(test::Contains(planned.err, "memory available to this process")) << planned.err;
    const test::ShellResult failed =
        test::run_in(dir_, "ulimit -v 2000000 && SDF_MEMORY_AVAILABLE=100000000000 " + run + " --memory-budget 60GiB");
    EXPECT_EQ(failed.code, 1) << failed.err;
    EXPECT_TRUE(test::Contains(failed.err, "out of memory while sampling")) << failed.err;
    EXPECT_TRUE(test::Contains(failed.err, "400x400x400")) << failed.err;
    EXPECT_FALSE(test::Contains(failed.err, "std::bad_alloc")) << failed.err;
    EXPECT_FALSE(fs::exists(at("f.json")));
    // run-experiment: its plan refuses the lattice under the limit; past the plan, the
    // sampling's allocation names the mesh, the lattice and the size.
    write("c.json", R"({"name": "oom", "kind": "sampling", "mesh": {"shape": "sphere"},
        "lattices": [{"type": "cc", "resolution": [400, 400, 400]}],
        "sampler": {"backend": "cpu", "method": "bvh", "threads": 1, "progress": false}})");
    const std::string experiment = test::quote(RUN_EXPERIMENT_EXE) + " c.json --no-cache --quiet --output-root out";
    const test::ShellResult refused = test::run_in(dir_, "ulimit -v 2000000 && " + experiment);
    EXPECT_EQ(refused.code, 1) << refused.err;
    EXPECT_TRUE(test::Contains(refused.err, "needs about 4.31 GiB of host memory")) << refused.err;
    const test::ShellResult oom =
        test::run_in(dir_, "ulimit -v 2000000 && SDF_MEMORY_AVAILABLE=100000000000 " + experiment);
    EXPECT_EQ(oom.code, 1) << oom.err;
    EXPECT_TRUE(test::Contains(oom.err, "out of memory while sampling sphere on 400x400x400 (64000000 points)")) << oom.err;
    EXPECT_TRUE(test::Contains(oom.err, "(about 4.31 GiB)")) << oom.err;
}

}  // namespace
}  // namespace sdf
