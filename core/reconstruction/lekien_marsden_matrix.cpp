#include "core/reconstruction/lekien_marsden_matrix.h"

#include "kernels/reconstruction/cubic_monomials.h"

namespace sdf {

LekienMarsdenMatrix lekien_marsden_constraint_matrix() {
    // Derivative flags (dx, dy, dz) of each datum type, in Lekien-Marsden order
    const int flags[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
    LekienMarsdenMatrix b;
    for (int type = 0; type < 8; ++type)
        for (int corner = 0; corner < 8; ++corner) {
            const double c[3] = {double(corner & 1), double((corner >> 1) & 1), double(corner >> 2)};
            for (int col = 0; col < 64; ++col) {
                const int e[3] = {col % 4, (col / 4) % 4, col / 16};
                double v = 1;
                for (int a = 0; a < 3; ++a) v *= monomial_derivative_1d(c[a], e[a], flags[type][a]);
                b(8 * type + corner, col) = v;
            }
        }
    return b;
}

}  // namespace sdf
