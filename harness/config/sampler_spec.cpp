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
            {"device", o.device}};
}

}  // namespace sdf
