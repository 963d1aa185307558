#include "core/sampling/certified_search.h"

#include <algorithm>
#include <cmath>

namespace sdf {
FloatSearchBound float_search_bound(const PreparedMesh& mesh) { return mesh.search_bound(); }

CertificateReport certificate_provenance(bool float_search, bool certified, const CertificateCounters& counters) {
    CertificateReport c;
    if (!float_search) {
        c.note = "double search: the reference";
        return c;
    }
    c.certified = certified;
    if (!certified) {
        c.note = "uncertified: the float search's own winner (near-ties may differ from the double search)";
        return c;
    }
    c.counted = true;
    c.points = counters.points.load();
    c.reranked_in_double = counters.reranked.load();
    c.full_double_search = counters.full_double.load();
    return c;
}

}  // namespace sdf
