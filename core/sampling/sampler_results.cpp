#include "core/sampling/sampler_results.h"

namespace sdf {

const char* bcc_strategy_name(BccStrategy s) {
    return s == BccStrategy::TwoGrids ? "two_grids" : "double_resolution";
}

nlohmann::json sampler_provenance(const std::string& backend, const std::string& method, const std::string& kernel,
                                  const SamplerOptions& options, const Lattice& lattice, int64_t points_computed,
                                  const SamplerSign& sign) {
    nlohmann::json p = {{"backend", backend},
                        {"method", method},
                        {"kernel", kernel},
                        {"precision", precision_name(options.precision)},
                        {"points_computed", points_computed},
                        {"sign", sign.provenance()}};
    if (lattice.type == LatticeType::BCC) p["bcc_strategy"] = bcc_strategy_name(options.bcc_strategy);
    if (options.band_width > 0) p["band_width"] = options.band_width;
    return p;
}

}  // namespace sdf
