#include "core/sampling/sampler_results.h"

namespace sdf {

const char* bcc_strategy_name(BccStrategy s) {
    return s == BccStrategy::TwoGrids ? "two_grids" : "double_resolution";
}

SamplerReport sampler_provenance(const std::string& backend, const std::string& method, const std::string& kernel,
                                 const SamplerOptions& options, const Lattice& lattice, int64_t points_computed,
                                 const SamplerSign& sign) {
    SamplerReport r;
    r.backend = backend;
    r.method = method;
    r.kernel = kernel;
    r.precision = precision_name(options.precision);
    r.points_computed = points_computed;
    r.details["sign"] = sign.provenance();
    if (sign.winding()) {
        const WindingSignCounts c = sign.counts();
        r.winding_sign = WindingSignReport{c.fast, c.refined, c.direct, c.ties};
    }
    if (lattice_kind(lattice.type).cosets > 1) r.details["bcc_strategy"] = bcc_strategy_name(options.bcc_strategy);
    if (options.band_width > 0) r.details["band_width"] = options.band_width;
    return r;
}

}  // namespace sdf
