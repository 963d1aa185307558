// Open3D peer: t::geometry::RaycastingScene::compute_signed_distance through the Python
// module (python3-open3d), see open3d_peer.py for why and what is timed. The mesh and the
// points go to a temporary folder as raw float32/uint32 arrays; the signed distances come
// back the same way. The timings are Open3D's own calls measured inside Python.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "experiments/peers/peer.h"

#ifndef SDF_PEERS_SCRIPT_DIR
#error "SDF_PEERS_SCRIPT_DIR must name experiments/peers"
#endif

namespace sdf::peers {
namespace {

/// Runs `command` and returns its standard output; throws naming it when it fails.
std::string run_command(const std::string& command) {
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) throw std::runtime_error("open3d peer: cannot run: " + command);
    std::string out;
    char buffer[4096];
    while (size_t n = fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
    const int status = pclose(pipe);
    if (status != 0) throw std::runtime_error("open3d peer: '" + command + "' failed with status " + std::to_string(status));
    return out;
}

template <typename T>
void write_raw(const std::string& path, const std::vector<T>& values) {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(values.data()), std::streamsize(values.size() * sizeof(T)));
    if (!f) throw std::runtime_error("open3d peer: cannot write " + path);
}

/// A Python interpreter that imports open3d: `preferred`, /usr/bin/python3 or python3.
std::string find_python(const std::string& preferred) {
    for (const std::string& py : {preferred, std::string("/usr/bin/python3"), std::string("python3")}) {
        if (py.empty()) continue;
        if (std::system((py + " -c 'import open3d' >/dev/null 2>&1").c_str()) == 0) return py;
    }
    return {};
}

class Open3dPeer final : public PeerAdapter {
public:
    explicit Open3dPeer(std::string python) : python_(std::move(python)) {
        version_ = run_command(python_ + " -c 'import open3d; print(open3d.__version__, end=\"\")' 2>/dev/null");
    }

    std::string version() const override { return version_; }

    PeerResult run(const PeerInput& in) override {
        const PreparedMesh& mesh = *in.mesh;
        const std::vector<Vec3d>& points = *in.points;
        const int threads = in.threads;
        char dir_template[] = "/tmp/sdf-open3d-XXXXXX";
        if (!mkdtemp(dir_template)) throw std::runtime_error("open3d peer: mkdtemp failed");
        const std::string dir = dir_template;
        std::vector<float> v, p;
        std::vector<uint32_t> t;
        for (const Vec3d& x : mesh.vertices()) v.insert(v.end(), {float(x.x), float(x.y), float(x.z)});
        for (const Int3& x : mesh.triangles()) t.insert(t.end(), {uint32_t(x.x), uint32_t(x.y), uint32_t(x.z)});
        for (const Vec3d& x : points) p.insert(p.end(), {float(x.x), float(x.y), float(x.z)});
        write_raw(dir + "/vertices.f32", v);
        write_raw(dir + "/triangles.u32", t);
        write_raw(dir + "/points.f32", p);
        const std::string script = std::string(SDF_PEERS_SCRIPT_DIR) + "/open3d_peer.py";
        const std::string out = run_command(python_ + " " + script + " " + dir + " " + std::to_string(threads));
        const nlohmann::json j = nlohmann::json::parse(out.substr(out.find('{')));
        std::vector<float> signed_distance(points.size());
        std::ifstream f(dir + "/signed.f32", std::ios::binary);
        f.read(reinterpret_cast<char*>(signed_distance.data()), std::streamsize(signed_distance.size() * sizeof(float)));
        if (!f) throw std::runtime_error("open3d peer: cannot read " + dir + "/signed.f32");
        std::filesystem::remove_all(dir);

        PeerResult r;
        r.sign = SignKind::Own;
        r.threads = j["threads"].get<int>();
        r.build_seconds = j["build_seconds"].get<double>();
        r.query_seconds = j["signed_seconds"].get<double>();
        r.distance.assign(signed_distance.begin(), signed_distance.end());
        r.cpu_seconds = j["cpu_seconds"].get<double>();
        r.details = {{"unsigned_query_seconds", j["unsigned_seconds"]},
                     {"cpu_seconds_note", "includes the unsigned compute_distance call as well"},
                     {"sign", "ray intersection count (compute_signed_distance)"},
                     {"precision", "float"},
                     {"interface", "python3-open3d via experiments/peers/open3d_peer.py"}};
        return r;
    }

private:
    std::string python_, version_;
};

}  // namespace

/// Null when no Python with open3d is found; `reason` says so.
std::unique_ptr<PeerAdapter> make_open3d_peer(const std::string& python, std::string& reason) {
    const std::string py = find_python(python);
    if (py.empty()) {
        reason = "no python3 that imports open3d (apt-get install python3-open3d; or set \"python\")";
        return nullptr;
    }
    return std::make_unique<Open3dPeer>(py);
}

}  // namespace sdf::peers
