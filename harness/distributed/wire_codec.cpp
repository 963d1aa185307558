// The bytes of the messages between the ranks (wire_codec.h).
#include "harness/distributed/wire_codec.h"

#include "harness/config/sampler_spec.h"

namespace sdf::mpi {

void put_options(ByteWriter& out, const SamplerOptions& options) { out.put_string(sampler_options_to_json(options).dump()); }

SamplerOptions get_options(ByteReader& in) {
    return sampler_options_from_json(nlohmann::json::parse(in.get_string()), "the root's request");
}

void put_mesh(ByteWriter& out, const TriangleMesh& m) {
    out.put_string(m.name);
    out.put_string(m.source);
    out.put_string(m.content_sha256);
    out.put_vector(m.vertices);
    out.put_vector(m.triangles);
}

TriangleMesh get_mesh(ByteReader& in) {
    TriangleMesh m;
    m.name = in.get_string();
    m.source = in.get_string();
    m.content_sha256 = in.get_string();
    m.vertices = in.get_vector<Vec3d>();
    m.triangles = in.get_vector<Int3>();
    return m;
}

nlohmann::json files_to_json(const std::vector<FieldChannelFile>& files) {
    nlohmann::json j = nlohmann::json::array();
    for (const FieldChannelFile& f : files)
        j.push_back({{"name", f.name}, {"path", f.path}, {"float32", f.dtype == FieldDtype::Float32}, {"components", f.components}});
    return j;
}

std::vector<FieldChannelFile> files_from_json(const nlohmann::json& j) {
    std::vector<FieldChannelFile> files;
    for (const nlohmann::json& f : j)
        files.push_back({f.at("name").get<std::string>(), f.at("path").get<std::string>(),
                         f.at("float32").get<bool>() ? FieldDtype::Float32 : FieldDtype::Float64, f.at("components").get<int>()});
    return files;
}

nlohmann::json timings_to_json(const SamplingTimings& t) {
    return {{"total", t.total}, {"kernel", t.kernel}, {"upload", t.upload}, {"download", t.download},
            {"point_triangle_pairs", t.point_triangle_pairs}};
}

SamplingTimings timings_from_json(const nlohmann::json& j) {
    SamplingTimings t;
    t.total = j.at("total").get<double>();
    t.kernel = j.at("kernel").get<double>();
    t.upload = j.at("upload").get<double>();
    t.download = j.at("download").get<double>();
    t.point_triangle_pairs = j.at("point_triangle_pairs").get<double>();
    return t;
}


}  // namespace sdf::mpi
