#include "harness/config/sampler_spec.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>
#include <utility>

#include "core/sampling/kernel_table.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {

namespace {

// ---- the table covers the struct --------------------------------------------------------

/// Converts to any member type: brace-initializing an aggregate with n of these compiles
/// exactly when it has at least n fields.
struct AnyField {
    template <class T>
    operator T() const;
};

template <class T, class... A>
constexpr auto braces_accept(int) -> decltype(void(T{std::declval<A>()...}), true) {
    return true;
}
template <class T, class... A>
constexpr bool braces_accept(...) {
    return false;
}

template <class T, class... A>
constexpr std::size_t aggregate_field_count() {
    if constexpr (braces_accept<T, A..., AnyField>(0))
        return aggregate_field_count<T, A..., AnyField>();
    else
        return sizeof...(A);
}

static_assert(aggregate_field_count<SamplerOptions>() == kSamplerOptionFields,
              "SamplerOptions has a field for_each_sampler_option does not visit (or kSamplerOptionFields is stale): "
              "add its row in core/sampling/sampler_options.h so configs, the wire and the cache key know it");

// ---- enums by name ----------------------------------------------------------------------

std::vector<std::string> names_of(Precision) {
    std::vector<std::string> n;
    for (const auto& p : kPrecisions) n.emplace_back(p.name);
    return n;
}
std::vector<std::string> names_of(BccStrategy) {
    std::vector<std::string> n;
    for (const auto& b : kBccStrategies) n.emplace_back(b.name);
    return n;
}
std::vector<std::string> names_of(SignMode) { return sign_mode_names(); }
std::vector<std::string> names_of(BvhBuildSite) {
    std::vector<std::string> n;
    for (const auto& b : kBvhBuildSites) n.emplace_back(b.name);
    return n;
}

const char* name_of(Precision v) { return precision_name(v); }
const char* name_of(BccStrategy v) { return bcc_strategy_name(v); }
const char* name_of(SignMode v) { return sign_mode_name(v); }
const char* name_of(BvhBuildSite v) { return bvh_build_site_name(v); }

/// `name` is one of names_of(out) (checked by the reader before).
void set_from_name(const std::string& name, Precision& out) {
    for (const auto& p : kPrecisions)
        if (name == p.name) out = p.value;
}
void set_from_name(const std::string& name, BccStrategy& out) {
    for (const auto& b : kBccStrategies)
        if (name == b.name) out = b.value;
}
void set_from_name(const std::string& name, SignMode& out) { out = sign_mode_from_name(name, "sampler.sign"); }
void set_from_name(const std::string& name, BvhBuildSite& out) {
    for (const auto& b : kBvhBuildSites)
        if (name == b.name) out = b.value;
}

template <class T>
nlohmann::json encode(const T& v) {
    if constexpr (std::is_enum_v<T>)
        return name_of(v);
    else if constexpr (std::is_same_v<T, DeviceSelection>)
        return v.all ? nlohmann::json("all") : nlohmann::json(v.list);
    else
        return v;
}

// ---- reading ----------------------------------------------------------------------------

/// Reads one field into `v`, whose value on entry (the struct's default) is the fallback.
struct FieldReader {
    JsonReader& r;

    void operator()(const OptionField& f, std::string& v) const {
        switch (f.domain) {
            case OptionDomain::Backend: v = r.choice(f.name, sampler_backend_choices(), v); break;
            case OptionDomain::Method: v = r.choice(f.name, sampler_methods(), v); break;
            default:  // the kernel: checked against its row once backend and method are known
                v = r.optional<std::string>(f.name, v, std::string(f.expected) + " (" + sampler_kernels_help() + ")");
        }
    }

    void operator()(const OptionField& f, DeviceSelection& v) const {
        if (!r.has(f.name)) return;
        std::string error;
        const std::optional<DeviceSelection> read = parse_device_selection(r.raw(f.name), error);
        if (!read) r.fail(f.name, "expected " + std::string(f.expected) + " (or [] for the one \"device\"): " + error);
        v = *read;
        r.record(f.name, encode(v));
    }

    template <class T>
    void operator()(const OptionField& f, T& v) const {
        if constexpr (std::is_enum_v<T>) {
            set_from_name(r.choice(f.name, names_of(v), name_of(v)), v);
        } else if constexpr (std::is_same_v<T, bool>) {
            v = r.optional<bool>(f.name, v, f.expected);
        } else {
            v = r.optional<T>(f.name, v, f.expected);
            check(f, v);
        }
    }

    template <class T>
    void check(const OptionField& f, T v) const {
        const auto got = [&] { return ", got " + r.raw(f.name).dump(); };
        switch (f.domain) {
            case OptionDomain::Count:
                if (v < 0) r.fail(f.name, "expected " + std::string(f.expected) + ": 0 or a positive number" + got());
                break;
            case OptionDomain::PointsPerThread:
                if (v != 0 && v != 1 && v != 2 && v != 4 && v != 8) r.fail(f.name, "expected 0, 1, 2, 4 or 8" + got());
                break;
            case OptionDomain::Width:
                if (!(v >= 0) || !std::isfinite(double(v)))
                    r.fail(f.name, "expected " + std::string(f.expected) + ": a finite number >= 0" + got());
                // Below double's least normal value no field (the cache's float64 included) can
                // hold +-w: refused here, before any sampling.
                if (v > 0 && double(v) < std::numeric_limits<double>::min())
                    r.fail(f.name, "expected " + std::string(f.expected) + ": 0 or at least " +
                                       "2.2250738585072014e-308 (a normal double)" + got());
                break;
            default: break;
        }
    }
};

void check_kernel(const JsonReader& r, const SamplerOptions& o, bool backend_was_auto) {
    if (o.kernel.empty()) return;
    if (backend_was_auto)
        r.fail("kernel", "\"backend\": \"auto\" takes no kernel (each backend uses its default); got \"" + o.kernel +
                             "\": a kernel needs the backend cpu or cuda");
    const std::vector<std::string>& kernels = sampler_kind(o.backend, o.method).kernels;
    if (std::find(kernels.begin(), kernels.end(), o.kernel) != kernels.end()) return;
    const std::string near = nearest_match(o.kernel, kernels);
    r.fail("kernel", "unknown " + o.backend + " " + o.method + " kernel \"" + o.kernel + "\"; expected one of " +
                         quoted_alternatives(kernels) + (near.empty() ? "" : " (did you mean \"" + near + "\"?)"));
}

}  // namespace

std::optional<DeviceSelection> parse_device_selection(const nlohmann::json& value, std::string& error) {
    DeviceSelection out;
    nlohmann::json list = value;
    if (value.is_string()) {  // "all", or the command line's "0,1" / "[0, 1]"
        std::string text = value.get<std::string>();
        if (text == "all") {
            out.all = true;
            return out;
        }
        text.erase(std::remove_if(text.begin(), text.end(), [](char c) { return c == ' ' || c == '[' || c == ']'; }),
                   text.end());
        list = nlohmann::json::array();
        size_t at = 0;
        while (!text.empty() && at <= text.size()) {
            const size_t comma = std::min(text.find(',', at), text.size());
            const std::string item = text.substr(at, comma - at);
            if (item.empty() || item.find_first_not_of("0123456789") != std::string::npos || item.size() > 9) {
                error = "got " + value.dump() + ": \"" + item + "\" is not a device ordinal";
                return std::nullopt;
            }
            list.push_back(std::stoi(item));
            at = comma + 1;
        }
    }
    if (!list.is_array()) {
        error = "got " + value.dump();
        return std::nullopt;
    }
    for (const nlohmann::json& d : list) {
        if (!d.is_number_integer() || d.get<int64_t>() < 0 || d.get<int64_t>() > 1'000'000) {
            error = "got " + value.dump() + ": " + d.dump() + " is not a device ordinal (an integer >= 0)";
            return std::nullopt;
        }
        const int ordinal = d.get<int>();
        if (std::find(out.list.begin(), out.list.end(), ordinal) != out.list.end()) {
            error = "got " + value.dump() + ": device " + std::to_string(ordinal) + " is listed twice";
            return std::nullopt;
        }
        out.list.push_back(ordinal);
    }
    return out;
}

std::string sampler_kernels_help() {
    std::string help;
    for (const SamplerKind& k : sampler_table()) {
        help += (help.empty() ? "" : "; ") + std::string(k.backend) + " " + k.method + ": ";
        for (size_t i = 0; i < k.kernels.size(); ++i) help += (i ? ", " : "") + k.kernels[i];
    }
    return help;
}

SamplerOptions parse_sampler_options(JsonReader& r) {
    SamplerOptions o;  // the defaults
    for_each_sampler_option(o, FieldReader{r});
    const bool backend_was_auto = o.backend == "auto";
    o.backend = resolve_sampler_backend(o.backend);
    r.record("backend", o.backend);  // the manifest names the backend that ran
    check_kernel(r, o, backend_was_auto);
    r.finish();
    return o;
}

SamplerOptions sampler_options_from_json(const nlohmann::json& j, const std::string& source) {
    JsonReader r(j, source, "sampler");
    return parse_sampler_options(r);
}

nlohmann::json sampler_options_to_json(const SamplerOptions& o) {
    nlohmann::json j = nlohmann::json::object();
    for_each_sampler_option(o, [&](const OptionField& f, const auto& v) { j[f.name] = encode(v); });
    return j;
}

nlohmann::json sampler_result_identity(const SamplerOptions& o, LatticeType lattice_type) {
    nlohmann::json j = nlohmann::json::object();
    for_each_sampler_option(o, [&](const OptionField& f, const auto& v) {
        if (f.role == OptionRole::Result) j[f.name] = encode(v);
    });
    // The strategy chooses how a lattice of several cosets is cut into blocks; one coset has none.
    if (lattice_kind(lattice_type).cosets == 1) j["bcc_strategy"] = "-";
    return j;
}

std::vector<std::string> sampler_option_choices(const std::string& key) {
    std::vector<std::string> choices;
    SamplerOptions o;
    for_each_sampler_option(o, [&](const OptionField& f, auto& v) {
        using T = std::decay_t<decltype(v)>;
        if (key != f.name) return;
        if constexpr (std::is_enum_v<T>) {
            choices = names_of(v);
        } else if (f.domain == OptionDomain::Backend) {
            choices = sampler_backend_choices();
        } else if (f.domain == OptionDomain::Method) {
            choices = sampler_methods();
        }
    });
    return choices;
}

}  // namespace sdf
