// One process, several GPUs (multi_device_sampler.h): a bound sampler per device, one host
// thread per device per call, the parts placed where one device would have put them.
#include "harness/sampling/multi_device_sampler.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <exception>
#include <future>
#include <stdexcept>
#include <thread>

#include "core/parallel/task_monitor.h"
#include "core/sampling/sampler_results.h"
#include "harness/sampling/slab_plan.h"

namespace sdf {

DeviceSplit plan_device_split(int64_t points, int planes, int devices, int64_t min_points_per_device) {
    DeviceSplit d;
    d.requested = std::max(devices, 1);
    d.points = points;
    d.min_points_per_device = min_points_per_device;
    const int64_t least = std::max<int64_t>(min_points_per_device, 1);
    const std::string requested = std::to_string(d.requested) + " devices requested, ";
    if (d.requested == 1) return d;
    const int64_t by_size = points / least;
    if (by_size < 2) {
        d.why = requested + "1 used: " + std::to_string(points) + " points, fewer than 2 x " + std::to_string(least) +
                " (min_points_per_device: the fewest points a device is given)";
        return d;
    }
    d.used = int(std::min<int64_t>(d.requested, by_size));
    if (d.used < d.requested)
        d.why = requested + std::to_string(d.used) + " used: " + std::to_string(points) + " points, " +
                std::to_string(least) + " or more a device (min_points_per_device)";
    if (planes >= 0 && planes < d.used) {
        d.used = std::max(planes, 1);
        d.why = requested + std::to_string(d.used) + " used: " + std::to_string(planes) + " z-plane" +
                (planes == 1 ? "" : "s") + ", one or more a device";
    }
    return d;
}

nlohmann::json DeviceSplit::to_json() const {
    nlohmann::json j = {{"count", requested}, {"used", used}, {"split", split()}, {"min_points_per_device", min_points_per_device}};
    if (!why.empty()) j[split() ? "why_fewer" : "why_not"] = why;
    return j;
}

std::vector<LatticeSlab> split_slab(const std::vector<double>& plane_cost, const LatticeSlab& slab, int parts) {
    const int planes = slab.z_end - slab.z_begin;
    parts = std::max(1, std::min(parts, planes));
    const std::vector<double> mine(plane_cost.begin() + slab.z_begin, plane_cost.begin() + slab.z_end);
    std::vector<LatticeSlab> out = balanced_slabs(mine, parts);
    for (LatticeSlab& s : out) s = {s.z_begin + slab.z_begin, s.z_end + slab.z_begin};
    return out;
}

std::vector<PointRange> split_points(int64_t n, int parts) {
    parts = int(std::max<int64_t>(1, std::min<int64_t>(parts, std::max<int64_t>(n, 1))));
    std::vector<PointRange> out(static_cast<size_t>(parts));
    int64_t begin = 0;
    for (int i = 0; i < parts; ++i) {
        const int64_t count = n / parts + (i < n % parts ? 1 : 0);
        out[size_t(i)] = {begin, count};
        begin += count;
    }
    return out;
}

StorageRange sub_slab_storage(const Lattice& lattice, const LatticeSlab& slab, const LatticeSlab& sub, int part) {
    const StorageRange whole = slab_storage(lattice, slab, part), mine = slab_storage(lattice, sub, part);
    const int64_t base = part == 0 ? 0 : slab_storage(lattice, slab, 0).count;
    return {base + (mine.offset - whole.offset), mine.count};
}

namespace {

/// Runs job(i) for i in [0, n) on n host threads (i = 0 on the caller's), the caller's task
/// monitor on each (Python's stop request and warnings); rethrows the first failure, its
/// device named.
void on_each_device(const std::vector<int>& devices, size_t n, const std::function<void(size_t)>& job) {
    std::vector<std::exception_ptr> errors(n);
    TaskMonitor* monitor = current_task_monitor();
    auto run = [&](size_t i) {
        const ScopedTaskMonitor scope(monitor);
        try {
            job(i);
        } catch (...) {
            errors[i] = std::current_exception();
        }
    };
    std::vector<std::thread> threads;
    for (size_t i = 1; i < n; ++i) threads.emplace_back(run, i);
    run(0);
    for (std::thread& t : threads) t.join();
    for (size_t i = 0; i < n; ++i) {
        if (!errors[i]) continue;
        try {
            std::rethrow_exception(errors[i]);
        } catch (const std::invalid_argument&) {
            throw;  // the caller's mistake (a point out of range): the same message as one device
        } catch (const std::exception& e) {
            throw std::runtime_error("CUDA device " + std::to_string(devices[i]) + ": " + e.what());
        }
    }
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The parts' timings as one call's: the devices ran at once.
void add_part_timings(SamplingTimings& into, const SamplingTimings& part) {
    into.kernel = std::max(into.kernel, part.kernel);
    into.upload = std::max(into.upload, part.upload);
    into.download = std::max(into.download, part.download);
    into.point_triangle_pairs += part.point_triangle_pairs;
    into.certified_points += part.certified_points;
    into.reranked_points += part.reranked_points;
    into.full_double_points += part.full_double_points;
}

nlohmann::json part_record(const nlohmann::json& device, const SamplingTimings& t, double seconds, int64_t points) {
    return {{"device", device},
            {"points", points},
            {"seconds", seconds},
            {"kernel_seconds", t.kernel},
            {"upload_seconds", t.upload},
            {"download_seconds", t.download}};
}

class BoundMultiDevice final : public BoundSampler {
public:
    BoundMultiDevice(std::shared_ptr<const PreparedMesh> mesh, const std::vector<std::unique_ptr<Sampler>>& samplers,
                     std::vector<int> devices, SamplerOptions options, DeviceDescriber describe)
        : BoundSampler(mesh), devices_(std::move(devices)), options_(std::move(options)), describe_(std::move(describe)),
          bound_(samplers.size()) {
        // Each device's tree and uploads are made on its own thread, at once.
        on_each_device(devices_, samplers.size(), [&](size_t i) { bound_[i] = samplers[i]->bind(mesh); });
    }

    std::string name() const override { return bound_[0]->name() + " on " + std::to_string(bound_.size()) + " devices"; }
    const SignModeChoice& sign() const override { return bound_[0]->sign(); }

    SampledField sample_slab(const Lattice& lattice, const LatticeSlab& slab) const override {
        const auto t0 = std::chrono::steady_clock::now();
        const DeviceSplit split = lattice_split(lattice, slab);
        if (!split.split()) {
            SampledField field = bound_[0]->sample_slab(lattice, slab);
            field.sampler.details["devices"] = record(
                split, {with_planes(part_record(describe_(devices_[0]), field.timings, seconds_since(t0), field.size()), slab)});
            return field;
        }
        std::string estimate;
        const std::vector<double> cost = plane_costs(mesh(), lattice, options_, estimate, slab);
        const std::vector<LatticeSlab> subs = split_slab(cost, slab, split.used);
        // The field's arrays (36 bytes a point, each page mapped at its first write) are made
        // on another thread while the devices compute, as one device's sampler does.
        require_search_range(mesh(), lattice, options_.precision);
        SampledField field;
        const std::shared_future<void> made = std::async(std::launch::async, [&] {
            field = unfilled_field(mesh(), lattice, slab, options_.precision);
        }).share();
        std::vector<SamplerReport> reports(subs.size());
        std::vector<SamplingTimings> timings(subs.size());
        std::vector<nlohmann::json> records(subs.size());
        MeshProvenance provenance;
        on_each_device(devices_, subs.size(), [&](size_t i) {
            const auto start = std::chrono::steady_clock::now();
            SampledField part = bound_[i]->sample_slab(lattice, subs[i]);
            made.get();
            int64_t from = 0;
            for (int p = 0; p < 2; ++p) {  // its primary, then its secondary points
                const StorageRange r = sub_slab_storage(lattice, slab, subs[i], p);
                std::copy_n(part.distance.begin() + from, r.count, field.distance.begin() + r.offset);
                std::copy_n(part.gradient.begin() + from, r.count, field.gradient.begin() + r.offset);
                std::copy_n(part.closest_triangle.begin() + from, r.count, field.closest_triangle.begin() + r.offset);
                from += r.count;
            }
            reports[i] = std::move(part.sampler);
            timings[i] = part.timings;
            records[i] = with_planes(part_record(describe_(devices_[i]), part.timings, seconds_since(start), part.size()), subs[i]);
            if (i == 0) provenance = part.mesh;
        });
        made.get();  // rethrows a failed allocation (also when every device failed first)
        SamplerReport merged;
        for (const SamplerReport& r : reports) merged.merge(r);  // in slab order: the details are the first part's
        merged.details["devices"] = record(split, records, estimate);
        field.sampler = std::move(merged);
        field.mesh = provenance;
        for (const SamplingTimings& t : timings) add_part_timings(field.timings, t);
        field.timings.total = seconds_since(t0);
        return field;
    }

    /// sdf-sample's path: each device's stored bytes (where its sampler makes them) copied to
    /// their places in one buffer; nullopt where the samplers store nothing (then sample_slab).
    std::optional<StoredSlab> sample_slab_stored(const Lattice& lattice, const LatticeSlab& slab,
                                                 const StoredLayout& layout) const override {
        const auto t0 = std::chrono::steady_clock::now();
        const DeviceSplit split = lattice_split(lattice, slab);
        if (!split.split()) {
            std::optional<StoredSlab> one = bound_[0]->sample_slab_stored(lattice, slab, layout);
            if (one)
                one->info.sampler.details["devices"] = record(
                    split, {with_planes(part_record(describe_(devices_[0]), one->info.timings, seconds_since(t0), one->points), slab)});
            return one;
        }
        std::string estimate;
        const std::vector<double> cost = plane_costs(mesh(), lattice, options_, estimate, slab);
        const std::vector<LatticeSlab> subs = split_slab(cost, slab, split.used);
        const int64_t points = slab_point_count(lattice, slab);
        const size_t vb = layout.value_bytes();
        auto bytes = std::make_shared<std::vector<char>>(size_t(points) * layout.bytes_per_point());
        char* distance = bytes->data();
        char* gradient = layout.gradient ? distance + size_t(points) * vb : nullptr;
        char* triangle = layout.closest_triangle ? distance + size_t(points) * vb * (layout.gradient ? 4 : 1) : nullptr;
        std::vector<std::optional<StoredSlab>> got(subs.size());
        std::vector<nlohmann::json> records(subs.size());
        on_each_device(devices_, subs.size(), [&](size_t i) {
            const auto start = std::chrono::steady_clock::now();
            got[i] = bound_[i]->sample_slab_stored(lattice, subs[i], layout);
            if (!got[i]) return;
            const StoredSlab& part = *got[i];
            int64_t from = 0;
            for (int p = 0; p < 2; ++p) {
                const StorageRange r = sub_slab_storage(lattice, slab, subs[i], p);
                const size_t n = size_t(r.count), at = size_t(r.offset), f = size_t(from);
                std::memcpy(distance + at * vb, part.distance + f * vb, n * vb);
                if (gradient) std::memcpy(gradient + 3 * at * vb, part.gradient + 3 * f * vb, 3 * n * vb);
                if (triangle) std::memcpy(triangle + at * 4, part.closest_triangle + f * 4, n * 4);
                from += r.count;
            }
            records[i] = with_planes(part_record(describe_(devices_[i]), part.info.timings, seconds_since(start), part.points), subs[i]);
            got[i]->storage.reset();  // the device's pinned bytes go back to its sampler now
        });
        for (const auto& g : got)
            if (!g) return std::nullopt;  // these samplers store nothing: sample_slab() then
        StoredSlab out;
        SamplerReport merged;
        SamplingTimings timings;
        for (const auto& g : got) {  // in slab order: the details are the first part's
            merged.merge(g->info.sampler);
            add_part_timings(timings, g->info.timings);
            out.band.in_band += g->band.in_band;
            out.band.outside += g->band.outside;
        }
        out.info = std::move(got[0]->info);  // lattice, precision, mesh
        out.info.sampler = std::move(merged);
        out.info.timings = timings;
        out.info.sampler.details["devices"] = record(split, records, estimate);
        out.info.timings.total = seconds_since(t0);
        out.points = points;
        out.distance = distance;
        out.gradient = gradient;
        out.closest_triangle = triangle;
        out.storage = bytes;
        return out;
    }

    std::vector<PointSample> query(const std::vector<Vec3d>& points, SamplingTimings* timings) const override {
        const DeviceSplit split = points_split(int64_t(points.size()));
        if (!split.split()) return bound_[0]->query(points, timings);
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<PointRange> ranges = split_points(int64_t(points.size()), split.used);
        std::vector<PointSample> out(points.size());
        std::vector<SamplingTimings> t(ranges.size());
        on_each_device(devices_, ranges.size(), [&](size_t i) {
            const PointRange r = ranges[i];
            const std::vector<Vec3d> mine(points.begin() + r.begin, points.begin() + r.begin + r.count);
            const std::vector<PointSample> got = bound_[i]->query(mine, &t[i]);
            std::copy(got.begin(), got.end(), out.begin() + r.begin);
        });
        if (timings) {
            *timings = {};
            for (const SamplingTimings& p : t) add_part_timings(*timings, p);
            timings->total = seconds_since(t0);
        }
        return out;
    }

    void query_host(const HostPoints& points, const HostQueryResults& results, SamplingTimings* timings) const override {
        const DeviceSplit split = points_split(points.count);
        if (!split.split()) return bound_[0]->query_host(points, results, timings);
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<PointRange> ranges = split_points(points.count, split.used);
        std::vector<SamplingTimings> t(ranges.size());
        on_each_device(devices_, ranges.size(), [&](size_t i) {
            const PointRange r = ranges[i];
            HostPoints mine = points;
            const size_t element = points.float32 ? sizeof(float) : sizeof(double);
            mine.xyz = static_cast<const char*>(points.xyz) + size_t(r.begin * points.row_stride) * element;
            mine.count = r.count;
            HostQueryResults into;
            if (results.distance) into.distance = results.distance + r.begin;
            if (results.gradient) into.gradient = results.gradient + 3 * r.begin;
            if (results.triangle) into.triangle = results.triangle + r.begin;
            bound_[i]->query_host(mine, into, &t[i]);
        });
        if (timings) {
            *timings = {};
            for (const SamplingTimings& p : t) add_part_timings(*timings, p);
            timings->total = seconds_since(t0);
        }
    }

    /// Points already in one GPU's memory are searched by that GPU's sampler.
    bool query_device(const DevicePoints& points, const DeviceQueryResults& results, SamplingTimings* timings) const override {
        for (size_t i = 0; i < devices_.size(); ++i)
            if (devices_[i] == points.device) return bound_[i]->query_device(points, results, timings);
        std::string list;
        for (int d : devices_) list += (list.empty() ? "" : ", ") + std::to_string(d);
        throw std::invalid_argument("the points are on CUDA device " + std::to_string(points.device) +
                                    ", which this sampler does not use (devices " + list + ")");
    }

private:
    static nlohmann::json with_planes(nlohmann::json record, const LatticeSlab& slab) {
        record["z_planes"] = {slab.z_begin, slab.z_end};
        return record;
    }

    DeviceSplit lattice_split(const Lattice& lattice, const LatticeSlab& slab) const {
        return plan_device_split(slab_point_count(lattice, slab), slab.z_end - slab.z_begin, int(bound_.size()),
                                 options_.min_points_per_device);
    }
    DeviceSplit points_split(int64_t points) const {
        return plan_device_split(points, -1, int(bound_.size()), options_.min_points_per_device);
    }

    /// The report's "devices": the decision, the parts, and how the planes were costed.
    static nlohmann::json record(const DeviceSplit& split, nlohmann::json parts, const std::string& estimate = "") {
        nlohmann::json j = split.to_json();
        if (!estimate.empty()) j["cost_estimate"] = estimate;
        j["parts"] = std::move(parts);
        return j;
    }

    std::vector<int> devices_;
    SamplerOptions options_;
    DeviceDescriber describe_;
    std::vector<std::unique_ptr<BoundSampler>> bound_;  ///< one per device, in devices_' order
};

class MultiDeviceSampler final : public Sampler {
public:
    MultiDeviceSampler(const SamplerOptions& options, std::vector<int> devices, const DeviceSamplerFactory& make_one,
                       DeviceDescriber describe)
        : options_(options), devices_(std::move(devices)), describe_(std::move(describe)) {
        if (devices_.empty()) throw std::invalid_argument("sampler.devices: no device to sample on");
        for (int d : devices_) {
            SamplerOptions one = options;
            one.device = d;
            one.devices = DeviceSelection{};
            one.progress = options.progress && samplers_.empty();  // one progress line: the first device's
            samplers_.push_back(make_one(one));
        }
    }

    std::string name() const override { return samplers_[0]->name() + " on " + std::to_string(devices_.size()) + " devices"; }

    std::unique_ptr<BoundSampler> bind(std::shared_ptr<const PreparedMesh> mesh) const override {
        if (!mesh) throw std::invalid_argument("bind: no mesh");
        return std::make_unique<BoundMultiDevice>(std::move(mesh), samplers_, devices_, options_, describe_);
    }

private:
    SamplerOptions options_;
    std::vector<int> devices_;
    DeviceDescriber describe_;
    std::vector<std::unique_ptr<Sampler>> samplers_;
};

}  // namespace

std::unique_ptr<Sampler> make_multi_device_sampler(const SamplerOptions& options, std::vector<int> devices,
                                                   DeviceSamplerFactory make_one, DeviceDescriber describe) {
    return std::make_unique<MultiDeviceSampler>(options, std::move(devices), make_one, std::move(describe));
}

}  // namespace sdf
