#include "harness/sampling/device_selection.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

namespace sdf {

std::string visible_devices_note() {
    const char* v = std::getenv("CUDA_VISIBLE_DEVICES");
    return v ? "CUDA_VISIBLE_DEVICES=\"" + std::string(v) + "\"" : std::string("CUDA_VISIBLE_DEVICES unset");
}

std::vector<int> resolve_devices(const SamplerOptions& options, int visible) {
    const auto visible_text = [&] {
        return std::to_string(visible) + " CUDA device" + (visible == 1 ? " is" : "s are") + " visible (" +
               visible_devices_note() + ")";
    };
    if (options.devices.is_default()) {
        if (options.device < 0 || options.device >= std::max(visible, 1))
            throw std::invalid_argument("sampler.device: device " + std::to_string(options.device) + " is not visible: " +
                                        visible_text());
        return {options.device};
    }
    if (visible <= 0) throw std::invalid_argument("sampler.devices: no CUDA device is visible (" + visible_devices_note() + ")");
    if (options.devices.all) {
        std::vector<int> all(size_t(visible), 0);
        for (int d = 0; d < visible; ++d) all[size_t(d)] = d;
        return all;
    }
    for (int d : options.devices.list)
        if (d < 0 || d >= visible)
            throw std::invalid_argument("sampler.devices: device " + std::to_string(d) + " is not visible: " + visible_text());
    return options.devices.list;
}

SamplerOptions place_rank_on_devices(SamplerOptions o, int local_rank, int local_size, int visible) {
    if (o.backend != "cuda" || visible <= 0) return o;
    local_size = std::max(local_size, 1);
    local_rank = std::clamp(local_rank, 0, local_size - 1);
    if (o.devices.is_default()) {
        o.device = (o.device + local_rank) % visible;
        return o;
    }
    const std::vector<int> all = resolve_devices(o, visible);
    std::vector<int> mine;
    for (size_t i = 0; i < all.size(); ++i)
        if (int(i % size_t(local_size)) == local_rank) mine.push_back(all[i]);
    if (mine.empty()) mine.push_back(all[size_t(local_rank) % all.size()]);
    o.devices = DeviceSelection{};
    if (mine.size() == 1) o.device = mine[0];
    else o.devices.list = mine;
    return o;
}

}  // namespace sdf
