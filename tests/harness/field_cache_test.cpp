// The content-addressed cache: what the field key holds (and leaves out), exact round trips,
// entries never replaced, damaged entries (checksums) moved aside and repaired, stale staging removed, and the default
// root ($SDF_CACHE_DIR).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "core/mesh/sha256.h"
#include "core/sampling/sampler_sign.h"
#include "harness/cache/content_cache.h"
#include "harness/config/json_reader.h"
#include "harness/config/sampler_spec.h"
#include "harness/cache/field_cache.h"
#include "harness/io/atomic_file.h"
#include "harness_test_util.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::Contains;

Lattice lattice(LatticeType type, Int3 res, double h = 0.1) {
    Lattice l;
    l.type = type;
    l.origin = {-1.0, -0.5, 0.25};
    l.spacing = h;
    l.resolution = res;
    return l;
}

SampledField field(const Lattice& l) {
    SampledField f;
    f.lattice = l;
    f.resize(l.num_points());
    for (int64_t i = 0; i < f.size(); ++i) {
        f.distance[size_t(i)] = 0.1 * double(i) - 1.0 / 3.0;  // not representable in float
        f.gradient[size_t(i)] = {1.0 / 3.0, double(i), -1.0};
        f.closest_triangle[size_t(i)] = int32_t(i % 7);
    }
    f.timings.total = 1.5;
    f.timings.kernel = 1.25;
    f.timings.point_triangle_pairs = 1e6;
    f.sampler.backend = "cpu";
    f.sampler.method = "brute_force";
    f.sampler.kernel = "vectorized";
    f.sampler.precision = "float";
    f.sampler.details["threads"] = 2;
    return f;
}

/// The cache root does not exist beforehand: the cache creates it.
class Cache : public test::ScratchDirTest {
protected:
    Cache() : ScratchDirTest("sdf_field_cache_test", /*create=*/false) {}
};

TEST(FieldCacheKey, BackendAndThreadsAreNotPartOfTheKey) {
    const Lattice l = lattice(LatticeType::BCC, {4, 4, 4});
    SamplerOptions cpu;
    cpu.backend = "cpu";
    cpu.threads = 1;
    SamplerOptions gpu = cpu;
    gpu.backend = "cuda";
    gpu.threads = 0;
    gpu.device = 1;
    gpu.points_per_thread = 4;
    EXPECT_EQ(field_cache_key("abc", l, cpu), field_cache_key("abc", l, gpu));
}

TEST(FieldCacheKey, EverythingThatChangesTheFieldIsPartOfTheKey) {
    const Lattice l = lattice(LatticeType::BCC, {4, 4, 4});
    const SamplerOptions o;
    const json base = field_cache_key("abc", l, o);
    auto differs = [&](const json& other) { return ContentCache::key_hash(other) != ContentCache::key_hash(base); };
    EXPECT_TRUE(differs(field_cache_key("abd", l, o)));
    Lattice moved = l;
    moved.origin.x = std::nextafter(moved.origin.x, 1.0);  // one ulp: a different lattice
    EXPECT_TRUE(differs(field_cache_key("abc", moved, o)));
    Lattice finer = l;
    finer.spacing = 0.05;
    EXPECT_TRUE(differs(field_cache_key("abc", finer, o)));
    EXPECT_TRUE(differs(field_cache_key("abc", lattice(LatticeType::BCC, {4, 4, 5}), o)));
    EXPECT_TRUE(differs(field_cache_key("abc", lattice(LatticeType::CC, {4, 4, 4}), o)));
    SamplerOptions p = o;
    p.precision = Precision::Double;
    EXPECT_TRUE(differs(field_cache_key("abc", l, p)));
    SamplerOptions k = o;
    k.kernel = "eberly";
    EXPECT_TRUE(differs(field_cache_key("abc", l, k)));
    SamplerOptions s = o;
    s.bcc_strategy = BccStrategy::DoubleResolution;
    EXPECT_TRUE(differs(field_cache_key("abc", l, s)));
    for (const SignMode mode : {SignMode::Pseudonormal, SignMode::Winding}) {
        SamplerOptions signed_by = o;  // o asks for auto
        signed_by.sign = mode;
        EXPECT_TRUE(differs(field_cache_key("abc", l, signed_by))) << sign_mode_name(mode);
    }
    EXPECT_EQ(base.at("code_version"), kFieldCodeVersion);
    // The BCC strategy does not matter for a CC lattice.
    const Lattice cc = lattice(LatticeType::CC, {4, 4, 4});
    EXPECT_EQ(field_cache_key("abc", cc, o), field_cache_key("abc", cc, s));
}

/// `v` changed to another value of its type (an enum: its next enumerator).
template <class T>
void change(T& v) {
    if constexpr (std::is_same_v<T, std::string>) v += "_changed";
    else if constexpr (std::is_same_v<T, bool>) v = !v;
    else if constexpr (std::is_enum_v<T>) v = T(int(v) + 1);
    else if constexpr (std::is_same_v<T, DeviceSelection>) v.all = !v.all;
    else v = T(v + 1);
}

// Every field of the options' table: one of role Result changes the key (on a BCC lattice,
// where every one matters), one of role Execution does not; and the Execution fields are
// exactly those that must not key a field. A new option is keyed once it has its row (the
// codec does not compile while the struct has a field without one).
TEST(FieldCacheKey, EveryResultOptionChangesTheKeyAndNoOtherDoes) {
    const Lattice l = lattice(LatticeType::BCC, {4, 4, 4});
    const SamplerOptions base;
    const json key = field_cache_key("abc", l, base);
    std::vector<std::string> execution;
    size_t visited = 0;
    for_each_sampler_option(base, [&](const OptionField& f, const auto& member) {
        ++visited;
        SamplerOptions changed = base;
        for_each_sampler_option(changed, [&](const OptionField& g, auto& m) {
            if constexpr (std::is_same_v<std::decay_t<decltype(m)>, std::decay_t<decltype(member)>>)
                if (std::string(g.name) == f.name) change(m);
        });
        ASSERT_NE(sampler_options_to_json(changed), sampler_options_to_json(base)) << f.name << " was not changed";
        const bool keyed = field_cache_key("abc", l, changed) != key;
        EXPECT_EQ(keyed, f.role == OptionRole::Result) << f.name;
        if (f.role == OptionRole::Execution) execution.push_back(f.name);
    });
    EXPECT_EQ(visited, kSamplerOptionFields);
    const std::vector<std::string> must_not_key = {"backend", "threads", "progress", "device", "devices", "max_points_per_piece",
                                                   "max_triangles_per_chunk", "points_per_thread", "bvh_build",
                                                   "min_points_per_device"};
    EXPECT_EQ(execution, must_not_key);
}

// Issue 25: the narrow band was missing from the key, so a banded field could be served for
// a full one.
TEST(FieldCacheKey, TheNarrowBandIsPartOfTheKey) {
    const Lattice l = lattice(LatticeType::CC, {4, 4, 4});
    SamplerOptions banded;
    banded.band_width = 0.25;
    EXPECT_NE(field_cache_key("abc", l, SamplerOptions{}), field_cache_key("abc", l, banded));
}

// The uncertified winding sign (SDF_WINDING_UNCERTIFIED=1, a measurement switch) gives other
// signs: its fields never pass for the certified ones, nor the other way round.
TEST(FieldCacheKey, TheUncertifiedWindingSignIsPartOfTheKey) {
    const Lattice l = lattice(LatticeType::CC, {4, 4, 4});
    const json certified = field_cache_key("abc", l, SamplerOptions{});
    setenv("SDF_WINDING_UNCERTIFIED", "1", 1);
    const json uncertified = field_cache_key("abc", l, SamplerOptions{});
    const bool certify = SamplerSign::winding_options().certify;
    unsetenv("SDF_WINDING_UNCERTIFIED");
    EXPECT_FALSE(certify);
    EXPECT_TRUE(SamplerSign::winding_options().certify);
    EXPECT_NE(certified, uncertified);
    EXPECT_EQ(certified, field_cache_key("abc", l, SamplerOptions{}));
}

TEST_F(Cache, StoreThenLoadIsExactAndNeverReplaces) {
    const FieldCache cache(dir_.string());
    const Lattice l = lattice(LatticeType::BCC, {3, 4, 5});
    const SampledField f = field(l);
    const json key = field_cache_key("mesh-hash", l, SamplerOptions{});
    EXPECT_FALSE(cache.contains(key));
    EXPECT_FALSE(cache.load(key).has_value());
    ASSERT_TRUE(cache.store(key, f));
    EXPECT_TRUE(cache.contains(key));
    const std::optional<SampledField> back = cache.load(key);
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(back->distance, f.distance);  // float64 on disk: bit for bit
    EXPECT_EQ(back->gradient, f.gradient);
    EXPECT_EQ(back->closest_triangle, f.closest_triangle);
    EXPECT_EQ(back->lattice.origin, l.origin);
    EXPECT_EQ(back->lattice.spacing, l.spacing);
    EXPECT_EQ(back->lattice.resolution, l.resolution);
    EXPECT_EQ(back->timings.total, 1.5);
    EXPECT_EQ(back->timings.kernel, 1.25);
    // The entry says who filled it.
    const json entry = ContentCache(dir_.string()).entry_record("fields", key);
    EXPECT_EQ(entry.at("key"), key);
    EXPECT_EQ(entry.at("info").at("filled_by").at("backend"), "cpu");
    // A second store of the same key keeps the first entry.
    SampledField other = f;
    other.distance[0] = 42;
    EXPECT_FALSE(cache.store(key, other));
    EXPECT_EQ(cache.load(key)->distance[0], f.distance[0]);
    // Nothing but the entry: no staging leftovers.
    int entries = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir_)) entries += e.is_directory() && e.path().filename().string()[0] == '.';
    EXPECT_EQ(entries, 0);
}

/// Damages the stored entry of `key` with `damage`, then checks that load() refuses it with
/// a warning naming the entry and `why`, moves it aside, and that the next store/load repairs it.
void expect_repaired(const FieldCache& cache, const json& key, const SampledField& f,
                     const std::function<void(const fs::path&)>& damage, const std::string& why) {
    if (!cache.contains(key)) {
        ASSERT_TRUE(cache.store(key, f));
    }  // else the previous case repaired it
    ASSERT_TRUE(cache.load(key).has_value());
    const fs::path dir = cache.entry_path(key);
    damage(dir);
    testing::internal::CaptureStderr();
    EXPECT_FALSE(cache.load(key).has_value()) << why;
    const std::string warning = testing::internal::GetCapturedStderr();
    EXPECT_TRUE(Contains(warning, dir.string())) << warning;
    EXPECT_TRUE(Contains(warning, why)) << warning;
    EXPECT_TRUE(Contains(warning, "moved to")) << warning;
    EXPECT_FALSE(fs::exists(dir));  // moved aside, so the entry can be filled again
    int aside = 0;
    for (const auto& e : fs::directory_iterator(dir.parent_path()))
        aside += e.path().filename().string().rfind(dir.filename().string() + ".damaged-", 0) == 0;
    EXPECT_GE(aside, 1);
    ASSERT_TRUE(cache.store(key, f));
    const std::optional<SampledField> back = cache.load(key);
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(back->distance, f.distance);
}

TEST_F(Cache, DamagedEntriesAreMovedAsideNamedAndRepaired) {
    const FieldCache cache(dir_.string());
    const Lattice l = lattice(LatticeType::CC, {2, 2, 3});
    const SampledField f = field(l);
    const json key = field_cache_key("m", l, SamplerOptions{});
    auto flip_a_byte = [](const fs::path& file) {  // same size, one bit different
        std::fstream io(file, std::ios::in | std::ios::out | std::ios::binary);
        io.seekg(5);
        const char c = char(io.get());
        io.seekp(5);
        io.put(char(c ^ 0x10));
    };
    expect_repaired(cache, key, f, [&](const fs::path& d) { flip_a_byte(d / "field.distance.raw"); },
                    "field.distance.raw has SHA-256");
    // NaN written over a gradient value: the bytes change, the size does not.
    expect_repaired(cache, key, f, [&](const fs::path& d) {
        std::fstream io(d / "field.gradient.raw", std::ios::in | std::ios::out | std::ios::binary);
        const double nan = std::nan("");
        io.write(reinterpret_cast<const char*>(&nan), sizeof nan);
    }, "field.gradient.raw has SHA-256");
    expect_repaired(cache, key, f, [](const fs::path& d) { fs::resize_file(d / "field.distance.raw", 3); },
                    "field.distance.raw has 3 bytes");
    expect_repaired(cache, key, f, [](const fs::path& d) { fs::remove(d / "field.json"); }, "field.json is missing");
    // A missing entry.json: before, the directory blocked every store and the field was
    // sampled again on every run; now it is repaired once.
    expect_repaired(cache, key, f, [](const fs::path& d) { fs::remove(d / "entry.json"); }, "entry.json is missing");
    expect_repaired(cache, key, f, [](const fs::path& d) { write_text_atomically((d / "entry.json").string(), "{", Overwrite::Allow); },
                    "entry.json is unreadable");
    // An entry of an older version, without checksums, cannot be verified.
    expect_repaired(cache, key, f, [](const fs::path& d) {
        json record = read_json_file((d / "entry.json").string());
        record.erase("files");
        write_text_atomically((d / "entry.json").string(), record.dump(), Overwrite::Allow);
    }, "no file checksums");
    expect_repaired(cache, key, f, [](const fs::path& d) { write_text_atomically((d / "extra.raw").string(), "x"); },
                    "extra.raw is not part of the entry");
}

TEST_F(Cache, EntryRecordListsEveryFileWithItsChecksum) {
    const FieldCache cache(dir_.string());
    const Lattice l = lattice(LatticeType::BCC, {2, 2, 4});
    const json key = field_cache_key("m", l, SamplerOptions{});
    ASSERT_TRUE(cache.store(key, field(l)));
    const json files = ContentCache(dir_.string()).entry_record("fields", key).at("files");
    for (const auto& e : fs::directory_iterator(cache.entry_path(key))) {
        const std::string name = e.path().filename().string();
        if (name == "entry.json") continue;
        ASSERT_TRUE(files.contains(name)) << name;
        EXPECT_EQ(files[name].at("bytes"), e.file_size());
        EXPECT_EQ(files[name].at("sha256"), sha256_of_file(e.path().string()));
    }
    EXPECT_EQ(ContentCache::verification_failure(cache.entry_path(key), key), "");
    EXPECT_EQ(ContentCache::verification_failure(cache.entry_path(key), json{{"other", 1}}),
              "entry.json does not hold the key of this entry");
}

TEST_F(Cache, ContentCacheStoreRemovesStaleStagingAndWritesEntryRecord) {
    const ContentCache cache(dir_.string());
    const json key = {{"what", "test"}, {"n", 1}};
    const fs::path parent = fs::path(cache.entry_path("things", key)).parent_path();
    // A staging directory left by a process that no longer exists (pid 2^22 + 1 is above
    // Linux's default pid_max), and one of this process, which is kept.
    fs::create_directories(parent / ".x.partial.4194305.0");
    fs::create_directories(parent / (".y.partial." + std::to_string(::getpid()) + ".99"));
    EXPECT_TRUE(cache.store("things", key, {{"note", "hi"}}, [](const std::string& d) {
        write_text_atomically(d + "/payload.txt", "data");
    }));
    EXPECT_FALSE(fs::exists(parent / ".x.partial.4194305.0"));
    EXPECT_TRUE(fs::exists(parent / (".y.partial." + std::to_string(::getpid()) + ".99")));
    const auto found = cache.find("things", key);
    ASSERT_TRUE(found.has_value());
    EXPECT_TRUE(fs::exists(*found + "/payload.txt"));
    EXPECT_EQ(cache.entry_record("things", key).at("info").at("note"), "hi");
    EXPECT_FALSE(cache.find("things", {{"what", "test"}, {"n", 2}}).has_value());
    // A writer that throws leaves no entry.
    const json other = {{"what", "test"}, {"n", 3}};
    EXPECT_ANY_THROW(cache.store("things", other, {}, [](const std::string&) { throw std::runtime_error("x"); }));
    EXPECT_FALSE(cache.find("things", other).has_value());
    EXPECT_FALSE(fs::exists(cache.entry_path("things", other)));
}

TEST(ContentCacheRoot, EnvironmentThenRepository) {
    const char* saved = std::getenv("SDF_CACHE_DIR");
    const std::string keep = saved ? saved : "";
    ::setenv("SDF_CACHE_DIR", "/tmp/some/cache", 1);
    EXPECT_EQ(ContentCache::default_root(), "/tmp/some/cache");
    ::setenv("SDF_CACHE_DIR", "", 1);
    EXPECT_EQ(fs::path(ContentCache::default_root()).filename(), "cache");
    if (saved) ::setenv("SDF_CACHE_DIR", keep.c_str(), 1);
    else ::unsetenv("SDF_CACHE_DIR");
}

}  // namespace
}  // namespace sdf
