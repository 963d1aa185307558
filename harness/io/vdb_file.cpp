/// @file vdb_file.cpp
/// @brief OpenVDB export (built when OpenVDB is found, cmake/Dependencies.cmake): the distance
/// as a narrow-band level set, the gradient as a Vec3f grid, each CC grid with a linear
/// transform of voxel size h translated to the grid's origin, so index (i,j,k) is the lattice
/// point at origin + h (i,j,k).
#include <openvdb/openvdb.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <algorithm>
#include <cmath>

#include "harness/io/vdb_grid_file.h"
#include "harness/io/volume_grids.h"

namespace sdf {

namespace {

openvdb::math::Transform::Ptr grid_transform(const VolumeGrid& g) {
    openvdb::math::Transform::Ptr t = openvdb::math::Transform::createLinearTransform(g.spacing);
    t->postTranslate(openvdb::Vec3d(g.origin.x, g.origin.y, g.origin.z));
    return t;
}

void add_metadata(openvdb::GridBase& grid, const SampledField& field, const VolumeGrid& g) {
    grid.insertMeta("sdf_lattice", openvdb::StringMetadata(lattice_type_name(field.lattice.type)));
    if (!g.part.empty()) grid.insertMeta("sdf_subgrid", openvdb::StringMetadata(g.part));
    grid.insertMeta("sdf_units", openvdb::StringMetadata("mesh units; distance negative inside"));
}

}  // namespace

struct VdbNarrowBandBuilder::Grids {
    Lattice lattice;
    std::vector<VolumeGrid> parts;
    std::vector<openvdb::FloatGrid::Ptr> distance;
    std::vector<openvdb::Vec3fGrid::Ptr> normals;
    float band = 0;
    bool gradient = false;
};

VdbNarrowBandBuilder::VdbNarrowBandBuilder(const Lattice& lattice, double band, bool gradient) : grids_(new Grids) {
    openvdb::initialize();
    grids_->lattice = lattice;
    grids_->parts = volume_grids(lattice);
    // The background is the band's half-width in world units (OpenVDB's level set
    // convention): outside the band a voxel reads +band, inside -band.
    grids_->band = float(band);
    grids_->gradient = gradient;
    for (size_t g = 0; g < grids_->parts.size(); ++g) {
        grids_->distance.push_back(openvdb::FloatGrid::create(grids_->band));
        grids_->normals.push_back(openvdb::Vec3fGrid::create(openvdb::Vec3f(0.0f)));
    }
}

VdbNarrowBandBuilder::~VdbNarrowBandBuilder() = default;

void VdbNarrowBandBuilder::add(const SampledField& part, int64_t from, int64_t count, int64_t offset) {
    const bool gradient = grids_->gradient && part.gradient.size() == part.distance.size();
    const float band = grids_->band;
    for (size_t p = 0; p < grids_->parts.size(); ++p) {
        const VolumeGrid& g = grids_->parts[p];
        const int64_t begin = std::max(offset, g.first), end = std::min(offset + count, g.first + g.count());
        if (begin >= end) continue;
        auto d_acc = grids_->distance[p]->getAccessor();
        auto n_acc = grids_->normals[p]->getAccessor();
        for (int64_t at = begin; at < end; ++at) {
            const size_t source = size_t(from + (at - offset));
            const float d = float(part.distance[source]);
            if (!(std::abs(d) < band)) continue;
            const int64_t local = at - g.first;
            const openvdb::Coord c(int(local % g.resolution.x), int((local / g.resolution.x) % g.resolution.y),
                                   int(local / (int64_t(g.resolution.x) * g.resolution.y)));
            d_acc.setValue(c, d);
            ++active_;
            if (gradient) {
                const Vec3d& n = part.gradient[source];
                n_acc.setValue(c, openvdb::Vec3f(float(n.x), float(n.y), float(n.z)));
            }
        }
    }
}

void VdbNarrowBandBuilder::write(const std::string& path) {
    openvdb::GridPtrVec grids;
    SampledField meta;  // add_metadata reads the lattice type only
    meta.lattice = grids_->lattice;
    for (size_t p = 0; p < grids_->parts.size(); ++p) {
        const VolumeGrid& g = grids_->parts[p];
        const std::string suffix = g.part.empty() ? "" : "_" + g.part;
        openvdb::FloatGrid::Ptr distance = grids_->distance[p];
        // Inactive voxels and tiles take the sign of their side (-band inside).
        openvdb::tools::signedFloodFill(distance->tree());
        distance->setTransform(grid_transform(g));
        distance->setGridClass(openvdb::GRID_LEVEL_SET);
        distance->setName("distance" + suffix);
        add_metadata(*distance, meta, g);
        grids.push_back(distance);
        if (grids_->gradient) {
            openvdb::Vec3fGrid::Ptr normals = grids_->normals[p];
            normals->setTransform(grid_transform(g));
            normals->setVectorType(openvdb::VEC_COVARIANT_NORMALIZE);
            normals->setName("gradient" + suffix);
            add_metadata(*normals, meta, g);
            grids.push_back(normals);
        }
    }
    write_vdb_grids(grids, path);
}

void write_vdb_file(const SampledField& field, const std::string& path, double band_in_spacings) {
    VdbNarrowBandBuilder builder(field.lattice, band_in_spacings * field.lattice.spacing,
                                 field.gradient.size() == field.distance.size());
    builder.add(field, 0, field.size(), 0);
    builder.write(path);
}

}  // namespace sdf
