/// @file vdb_grid_file.h
/// @brief How this project writes OpenVDB files (the dense narrow band's, vdb_file.cpp, and
/// the sparse band's, sparse_vdb_file.cpp): one place for the file's settings. Include only
/// where OpenVDB is found (SDF_HAVE_OPENVDB).
#pragma once

#include <string>

#include <openvdb/openvdb.h>

namespace sdf {

/// Writes `grids` to `path` with the active-mask compression alone. OpenVDB's default adds
/// Blosc, which on level sets of exact float distances saves about 5 % for twice the write
/// time (the dragon's band at 1024^3: 34.3 MB in 0.46-0.55 s with it, 36.1 MB in 0.21-0.27 s
/// without, one thread); and a file without Blosc opens in OpenVDB builds that lack it.
inline void write_vdb_grids(const openvdb::GridPtrVec& grids, const std::string& path) {
    openvdb::io::File file(path);
    file.setCompression(openvdb::io::COMPRESS_ACTIVE_MASK);
    file.write(grids);
    file.close();
}

}  // namespace sdf
