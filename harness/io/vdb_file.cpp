/// @file vdb_file.cpp
/// @brief OpenVDB export (built when OpenVDB is found, cmake/Dependencies.cmake): the distance
/// as a narrow-band level set, the gradient as a Vec3f grid, each CC grid with a linear
/// transform of voxel size h translated to the grid's origin, so index (i,j,k) is the lattice
/// point at origin + h (i,j,k).
#include <openvdb/openvdb.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <cmath>

#include "harness/io/volume_grids.h"

namespace sdf {

namespace {

openvdb::math::Transform::Ptr grid_transform(const VolumeGrid& g) {
    openvdb::math::Transform::Ptr t = openvdb::math::Transform::createLinearTransform(g.spacing);
    t->postTranslate(openvdb::Vec3d(g.origin.x, g.origin.y, g.origin.z));
    return t;
}

void add_metadata(openvdb::GridBase& grid, const SampledField& field, const VolumeGrid& g) {
    grid.insertMeta("sdf_lattice", openvdb::StringMetadata(field.lattice.type == LatticeType::CC ? "cc" : "bcc"));
    if (!g.part.empty()) grid.insertMeta("sdf_subgrid", openvdb::StringMetadata(g.part));
    grid.insertMeta("sdf_units", openvdb::StringMetadata("mesh units; distance negative inside"));
}

}  // namespace

void write_vdb_file(const SampledField& field, const std::string& path, double band_in_spacings) {
    openvdb::initialize();
    openvdb::GridPtrVec grids;
    const bool gradient = field.gradient.size() == field.distance.size();
    for (const VolumeGrid& g : volume_grids(field.lattice)) {
        const std::string suffix = g.part.empty() ? "" : "_" + g.part;
        // The background is the band's half-width in world units (OpenVDB's level set
        // convention): outside the band a voxel reads +band, inside -band.
        const float band = float(band_in_spacings * g.spacing);
        openvdb::FloatGrid::Ptr distance = openvdb::FloatGrid::create(band);
        openvdb::Vec3fGrid::Ptr normals = openvdb::Vec3fGrid::create(openvdb::Vec3f(0.0f));
        auto d_acc = distance->getAccessor();
        auto n_acc = normals->getAccessor();
        for (int k = 0; k < g.resolution.z; ++k)
            for (int j = 0; j < g.resolution.y; ++j)
                for (int i = 0; i < g.resolution.x; ++i) {
                    const size_t at = size_t(g.first + (int64_t(k) * g.resolution.y + j) * g.resolution.x + i);
                    const float d = float(field.distance[at]);
                    if (!(std::abs(d) < band)) continue;
                    d_acc.setValue(openvdb::Coord(i, j, k), d);
                    if (gradient) {
                        const Vec3d& n = field.gradient[at];
                        n_acc.setValue(openvdb::Coord(i, j, k), openvdb::Vec3f(float(n.x), float(n.y), float(n.z)));
                    }
                }
        // Inactive voxels and tiles take the sign of their side (-band inside).
        openvdb::tools::signedFloodFill(distance->tree());
        distance->setTransform(grid_transform(g));
        distance->setGridClass(openvdb::GRID_LEVEL_SET);
        distance->setName("distance" + suffix);
        add_metadata(*distance, field, g);
        grids.push_back(distance);
        if (gradient) {
            normals->setTransform(grid_transform(g));
            normals->setVectorType(openvdb::VEC_COVARIANT_NORMALIZE);
            normals->setName("gradient" + suffix);
            add_metadata(*normals, field, g);
            grids.push_back(normals);
        }
    }
    openvdb::io::File file(path);
    file.write(grids);
    file.close();
}

}  // namespace sdf
