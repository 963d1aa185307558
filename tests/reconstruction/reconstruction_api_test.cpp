// The host Reconstruction factory: names, rejected combinations with their messages, a
// user-written field file (values only, as docs/field-format.md describes), and sdf-eval.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "harness/io/field_file.h"
#include "reconstruction_test_util.h"
#include "tests/test_util/shell.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;

const Lattice kCc = test::make_lattice(LatticeType::CC, {6, 6, 6}, 0.2);
const Lattice kBcc = test::make_lattice(LatticeType::BCC, {6, 6, 6}, 0.2);

SampledField values_only(const Lattice& l) {
    SampledField f = sample_analytic_field(l, TrigFunction<double>{});
    f.gradient.clear();
    return f;
}

/// The message of the invalid_argument that building `spec` on `field` throws.
std::string rejection(const SampledField& field, const ReconstructionSpec& spec) {
    try {
        Reconstruction r(field, spec);
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "(accepted)";
}

TEST(ReconstructionApi, NamesRoundTrip) {
    EXPECT_EQ(interpolator_names(),
              (std::vector<std::string>{"trilinear", "catmull_rom", "tricubic_lm", "cc_bspline3", "bcc_linear", "bcc_cubic",
                                        "bcc_cubic_c0", "bcc_box_linear", "bcc_box_quintic", "bcc_box_quintic_qi",
                                        "bcc_box_quintic_approx"}));
    for (const std::string& n : interpolator_names()) EXPECT_EQ(interpolator_name(parse_interpolator(n)), n);
    for (const char* s : {"true", "fd", "fd_weighted"}) EXPECT_STREQ(derivative_source_name(parse_derivative_source(s)), s);
    EXPECT_THROW(parse_interpolator("tricubic"), std::invalid_argument);
    EXPECT_THROW(parse_derivative_source("exact"), std::invalid_argument);
}

TEST(ReconstructionApi, RejectsMeaninglessCombinationsWithClearMessages) {
    const SampledField cc = sample_analytic_field(kCc, TrigFunction<double>{});
    const SampledField bcc = sample_analytic_field(kBcc, TrigFunction<double>{});
    using S = DerivativeSource;
    const std::string wrong_lattice = rejection(bcc, {kind_of<CatmullRom>(), S::FiniteDifferences});
    EXPECT_NE(wrong_lattice.find("needs a CC field; this field is BCC"), std::string::npos) << wrong_lattice;
    EXPECT_NE(rejection(cc, {kind_of<BccCubic>(), S::True}).find("needs a BCC field"), std::string::npos);
    const std::string no_gradient = rejection(values_only(kBcc), {kind_of<BccCubic>(), S::True});
    EXPECT_NE(no_gradient.find("need the field's gradient channel"), std::string::npos) << no_gradient;
    const std::string weighted_cc = rejection(cc, {kind_of<TricubicLekienMarsden>(), S::FiniteDifferencesWeighted});
    EXPECT_NE(weighted_cc.find("does not accept derivatives 'fd_weighted'"), std::string::npos) << weighted_cc;
    EXPECT_NE(rejection(cc, {kind_of<Trilinear>(), S::True}).find("reads no derivative data"), std::string::npos);
    EXPECT_NE(rejection(bcc, {kind_of<BccLinear>(), S::FiniteDifferencesWeighted}).find("expected fd"), std::string::npos);
    const SampledField tiny = sample_analytic_field(test::make_lattice(LatticeType::BCC, {3, 5, 5}, 0.2), TrigFunction<double>{});
    EXPECT_NE(rejection(tiny, {kind_of<BccCubic>(), S::FiniteDifferences}).find("at least 4"), std::string::npos);
    EXPECT_EQ(rejection(tiny, {kind_of<BccLinear>(), S::FiniteDifferences}), "(accepted)");
}

TEST(ReconstructionApi, DefaultDerivativeSource) {
    const SampledField bcc = sample_analytic_field(kBcc, TrigFunction<double>{});
    EXPECT_EQ(Reconstruction(bcc, "bcc_cubic", "").spec().derivatives, DerivativeSource::True);
    EXPECT_EQ(Reconstruction(values_only(kBcc), "bcc_cubic", "").spec().derivatives, DerivativeSource::FiniteDifferences);
    EXPECT_EQ(Reconstruction(bcc, "bcc_linear", "").spec().derivatives, DerivativeSource::FiniteDifferences);
}

/// Writes a values-only field the way docs/field-format.md tells a user to (float64 raw).
std::string write_user_field(const fs::path& dir, const SampledField& f) {
    const fs::path raw = dir / "volume.value.raw";
    std::ofstream(raw, std::ios::binary).write(reinterpret_cast<const char*>(f.distance.data()),
                                               std::streamsize(f.distance.size() * sizeof(double)));
    const Lattice& l = f.lattice;
    const int z = l.type == LatticeType::BCC ? 2 * l.resolution.z : l.resolution.z;
    const nlohmann::json header = {
        {"format", "sdf-lattice-field"},
        {"version", 1},
        {"lattice", {{"type", l.type == LatticeType::BCC ? "bcc" : "cc"},
                     {"origin", {l.origin.x, l.origin.y, l.origin.z}},
                     {"spacing", l.spacing},
                     {"resolution", {l.resolution.x, l.resolution.y, z}}}},
        {"channels", {{"value", {{"file", "volume.value.raw"}, {"dtype", "float64"}}}}},
        {"value_channel", "value"}};
    const fs::path json = dir / "volume.json";
    std::ofstream(json) << header.dump(2);
    return json.string();
}

TEST(ReconstructionApi, UserWrittenFieldFileReconstructsLikeTheInMemoryField) {
    const test::ScratchDir dir("sdf_recon");
    const SampledField field = values_only(kBcc);
    const SampledField read = read_field(write_user_field(dir.path(), field));
    ASSERT_TRUE(read.gradient.empty());
    const Reconstruction a(field, "bcc_cubic", "fd"), b(read, "bcc_cubic", "fd");
    std::mt19937 rng(61);
    for (const Vec3d& p : test::random_points(rng, a.domain(), 100)) EXPECT_EQ(a.evaluate(p).value, b.evaluate(p).value);
}

TEST(ReconstructionApi, SdfEvalPrintsValueAndGradientPerPointInInputOrder) {
    const test::ScratchDir dir("sdf_recon");
    const SampledField field = values_only(kBcc);
    const std::string header = write_user_field(dir.path(), field);
    const Reconstruction recon(field, "bcc_cubic", "fd");
    std::mt19937 rng(62);
    std::vector<Vec3d> points = test::random_points(rng, recon.domain(), 50);
    points.push_back({100.0, 0.0, 0.0});  // outside: clamped, with a warning
    {
        std::ofstream pts(dir.path() / "points.txt");
        pts << "# x y z\n";
        pts.precision(17);
        for (const Vec3d& p : points) pts << p.x << " " << p.y << " " << p.z << "\n";
    }
    const std::string eval = test::quote(SDF_EVAL_PATH) + " " + test::quote(header) + " points.txt --interpolator bcc_cubic";
    const test::ShellResult r = test::run_in(dir.path(), eval + " --derivatives fd");
    ASSERT_EQ(r.code, 0) << r.err;
    std::istringstream out(r.out);
    for (const Vec3d& p : points) {
        const ReconstructedSample<double> want = recon.evaluate(p);
        double f, gx, gy, gz;
        ASSERT_TRUE(out >> f >> gx >> gy >> gz);
        EXPECT_NEAR(f, want.value, 1e-8 * (1 + std::abs(want.value)));
        EXPECT_NEAR(gx, want.gradient.x, 1e-8 * (1 + length(want.gradient)));
        EXPECT_NEAR(gz, want.gradient.z, 1e-8 * (1 + length(want.gradient)));
    }
    EXPECT_NE(r.err.find("1 of 51 points lie outside"), std::string::npos) << r.err;
    // A meaningless combination fails with a message
    EXPECT_NE(test::run_in(dir.path(), eval + " --derivatives true").code, 0);
}

}  // namespace
}  // namespace sdf
