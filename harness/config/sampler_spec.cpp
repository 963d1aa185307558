#include "harness/config/sampler_spec.h"

namespace sdf {

SamplerOptions parse_sampler_options(JsonReader& r) {
    SamplerOptions o;
    o.backend = r.choice("backend", {"cpu", "cuda"}, "cpu");
    o.method = r.choice("method", {"brute_force", "bvh"}, "brute_force");
    o.kernel = r.optional<std::string>("kernel", "", "a kernel name (cpu: vectorized, eberly; cuda: thesis, tuned)");
    o.threads = r.optional<int>("threads", 0, "a thread count (0 = all cores)");
    if (o.threads < 0) r.fail("threads", "expected 0 (all cores) or a positive count");
    o.precision = r.choice("precision", {"float", "double"}, "float") == "float" ? Precision::Float : Precision::Double;
    o.bcc_strategy = r.choice("bcc_strategy", {"two_grids", "double_resolution"}, "two_grids") == "two_grids"
                         ? BccStrategy::TwoGrids
                         : BccStrategy::DoubleResolution;
    o.progress = r.optional<bool>("progress", true, "true or false");
    o.device = r.optional<int>("device", 0, "a CUDA device ordinal");
    o.max_points_per_piece = r.optional<int64_t>("max_points_per_piece", 0, "a point count (0 = automatic)");
    o.max_triangles_per_chunk = r.optional<int>("max_triangles_per_chunk", 0, "a triangle count (0 = automatic)");
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
            {"bcc_strategy", bcc_strategy_name(o.bcc_strategy)},
            {"device", o.device},
            {"max_points_per_piece", o.max_points_per_piece},
            {"max_triangles_per_chunk", o.max_triangles_per_chunk},
            {"points_per_thread", o.points_per_thread}};
}

}  // namespace sdf
