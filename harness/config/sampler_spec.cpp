#include "harness/config/sampler_spec.h"

#include <algorithm>

#include "harness/sampling/sampler_table.h"

namespace sdf {

std::string sampler_kernels_help() {
    std::string help;
    for (const SamplerKind& k : sampler_table()) {
        help += (help.empty() ? "" : "; ") + std::string(k.backend) + " " + k.method + ": ";
        for (size_t i = 0; i < k.kernels.size(); ++i) help += (i ? ", " : "") + k.kernels[i];
    }
    return help;
}

SamplerOptions parse_sampler_options(JsonReader& r) {
    SamplerOptions o;
    std::vector<std::string> backends = sampler_backends();
    backends.emplace_back("auto");
    const std::string backend = r.choice("backend", backends, "cpu");
    o.backend = backend == "auto" ? (cuda_backend_available() ? "cuda" : "cpu") : backend;
    o.method = r.choice("method", sampler_methods(), "brute_force");
    o.kernel = r.optional<std::string>("kernel", "", "a kernel name (" + sampler_kernels_help() + ")");
    const std::vector<std::string> kernels = sampler_kind(o.backend, o.method).kernels;
    if (backend == "auto" && !o.kernel.empty())
        r.fail("kernel", "\"backend\": \"auto\" takes no kernel (each backend uses its default); got \"" + o.kernel +
                             "\": name the backend to choose a kernel");
    if (!o.kernel.empty() && std::find(kernels.begin(), kernels.end(), o.kernel) == kernels.end()) {
        std::string list;
        for (const auto& k : kernels) list += (list.empty() ? "\"" : ", \"") + k + "\"";
        const std::string near = nearest_match(o.kernel, kernels);
        r.fail("kernel", "unknown " + o.backend + (o.method == "bvh" ? " bvh" : "") + " kernel \"" + o.kernel + "\"; expected one of " + list +
                             (near.empty() ? "" : " (did you mean \"" + near + "\"?)"));
    }
    o.threads = r.optional<int>("threads", 0, "a thread count (0 = all cores)");
    if (o.threads < 0) r.fail("threads", "expected 0 (all cores) or a positive count, got " + std::to_string(o.threads));
    o.precision = r.choice("precision", {"float", "double"}, "float") == "float" ? Precision::Float : Precision::Double;
    o.sign = sign_mode_from_name(r.choice("sign", sign_mode_names(), sign_mode_name(kSignModes[0].mode)), "sampler.sign");
    o.bcc_strategy = r.choice("bcc_strategy", {"two_grids", "double_resolution"}, "two_grids") == "two_grids"
                         ? BccStrategy::TwoGrids
                         : BccStrategy::DoubleResolution;
    o.progress = r.optional<bool>("progress", true, "true or false");
    o.device = r.optional<int>("device", 0, "a CUDA device ordinal");
    if (o.device < 0) r.fail("device", "expected a CUDA device ordinal >= 0, got " + std::to_string(o.device));
    o.max_points_per_piece = r.optional<int64_t>("max_points_per_piece", 0, "a point count (0 = automatic)");
    if (o.max_points_per_piece < 0)
        r.fail("max_points_per_piece", "expected 0 (automatic) or a positive count, got " + std::to_string(o.max_points_per_piece));
    o.max_triangles_per_chunk = r.optional<int>("max_triangles_per_chunk", 0, "a triangle count (0 = automatic)");
    if (o.max_triangles_per_chunk < 0)
        r.fail("max_triangles_per_chunk",
               "expected 0 (automatic) or a positive count, got " + std::to_string(o.max_triangles_per_chunk));
    o.points_per_thread = r.optional<int>("points_per_thread", 0, "1, 2, 4 or 8 (0 = automatic)");
    if (o.points_per_thread != 0 && o.points_per_thread != 1 && o.points_per_thread != 2 && o.points_per_thread != 4 &&
        o.points_per_thread != 8)
        r.fail("points_per_thread", "expected 0, 1, 2, 4 or 8, got " + std::to_string(o.points_per_thread));
    r.finish();
    return o;
}

nlohmann::json sampler_options_to_json(const SamplerOptions& o) {
    return {{"backend", o.backend},
            {"method", o.method},
            {"kernel", o.kernel},
            {"threads", o.threads},
            {"precision", precision_name(o.precision)},
            {"sign", sign_mode_name(o.sign)},
            {"bcc_strategy", bcc_strategy_name(o.bcc_strategy)},
            {"device", o.device},
            {"max_points_per_piece", o.max_points_per_piece},
            {"max_triangles_per_chunk", o.max_triangles_per_chunk},
            {"points_per_thread", o.points_per_thread}};
}

}  // namespace sdf
