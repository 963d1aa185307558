#include "core/sampling/certified_search.h"

#include <algorithm>
#include <cmath>

namespace sdf {
FloatSearchBound float_search_bound(const PreparedMesh& mesh) {
    const MeshBuffers<double>& d = mesh.buffers<double>();
    return float_search_bound(d.vertices, d.triangles, d.packed, mesh.buffers<float>().packed);
}

nlohmann::json certificate_provenance(bool float_search, bool certified, const CertificateCounters& counters) {
    nlohmann::json j;
    if (!float_search) {
        j["certified"] = true;
        j["note"] = "double search: the reference";
        return j;
    }
    j["certified"] = certified;
    if (!certified) {
        j["note"] = "uncertified: the float search's own winner (near-ties may differ from the double search)";
        return j;
    }
    const int64_t n = counters.points.load();
    j["points"] = n;
    j["reranked_in_double"] = counters.reranked.load();
    j["full_double_search"] = counters.full_double.load();
    j["reranked_fraction"] = n > 0 ? double(counters.reranked.load()) / double(n) : 0.0;
    return j;
}

}  // namespace sdf
