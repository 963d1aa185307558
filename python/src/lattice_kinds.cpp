// sdf_lattices.lattice_kinds(): the rows of the one lattice table, for the pure-Python readers
// (.npz, .vti) and for users, so that no lattice kind's name is written twice.
#include "harness/io/volume_grids.h"
#include "kernels/lattice/lattice_kinds.h"
#include "python/src/common.h"

namespace sdf {

void bind_lattice_kinds(py::module_& m) {
    m.def("lattice_kinds", [] {
        py::list kinds;
        for (const LatticeKind& k : kLatticeKinds) {
            Lattice lattice;
            lattice.type = k.type;
            lattice.resolution = {2, 2, 2};
            py::list parts;
            for (const VolumeGrid& g : volume_grids(lattice)) parts.append(g.part);
            py::dict kind;
            kind["name"] = k.name;
            kind["label"] = k.label;
            kind["cosets"] = k.cosets;
            kind["description"] = k.description;
            kind["parts"] = parts;
            kinds.append(kind);
        }
        return kinds;
    }, R"(lattice_kinds() -> list of dict

The lattice kinds, the rows of the one lattice table (kernels/lattice/lattice_kinds.h) in its
order: "name" (what lattice= takes), "label", "cosets" (the CC grids the lattice is made of),
"description", and "parts": the names of those grids in the files Field.write writes (""
for a kind of one grid; "primary" and "secondary" for BCC, whose .npz arrays are
distance_primary, ... and whose .vti files are NAME.primary.vti and NAME.secondary.vti).)");
}

}  // namespace sdf
