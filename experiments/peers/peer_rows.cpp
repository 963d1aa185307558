#include "experiments/peers/peer_rows.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sdf::peers {

Errors compare(const std::vector<double>& d, const std::vector<double>& ref, const std::vector<int64_t>& index,
               bool is_signed, double tolerance, const std::vector<uint8_t>* mask, bool mask_value) {
    Errors e;
    for (size_t k = 0; k < d.size(); ++k) {
        if (mask && !mask->empty() && bool((*mask)[k]) != mask_value) continue;
        const double r = ref[size_t(index.empty() ? int64_t(k) : index[k])];
        const double unsigned_error = std::abs(std::abs(d[k]) - std::abs(r));
        const double error = is_signed ? std::abs(d[k] - r) : unsigned_error;
        e.max_abs = std::max(e.max_abs, error);
        e.sum_abs += error;
        e.max_abs_unsigned = std::max(e.max_abs_unsigned, unsigned_error);
        if (is_signed && r != 0 && (d[k] < 0) != (r < 0)) {
            ++e.sign_disagreements;
            if (std::abs(r) > tolerance) ++e.sign_disagreements_beyond_tolerance;
        }
        ++e.compared;
    }
    return e;
}

void set_errors(nlohmann::json& row, const Errors& e, bool is_signed) {
    row["max_abs_error"] = e.max_abs;
    row["max_abs_error_unsigned"] = e.max_abs_unsigned;
    row["mean_abs_error"] = e.mean_abs();
    row["compared_points"] = e.compared;
    row["sign_disagreements"] = is_signed ? nlohmann::json(e.sign_disagreements) : nlohmann::json("n/a (unsigned)");
    if (is_signed) row["sign_disagreements_beyond_tolerance"] = e.sign_disagreements_beyond_tolerance;
}

void set_check(nlohmann::json& row, const Errors& e, bool is_signed, bool exact, double tolerance) {
    std::string why;
    // The unsigned distance first, then the signs (a wrong sign also shows as a signed error of 2|d|).
    char b[160];
    if (!exact) {
        why = "not an exact method (narrow band)";
    } else if (!(e.max_abs_unsigned <= tolerance)) {
        std::snprintf(b, sizeof b, "max |distance error| %.3g > tolerance %.3g", e.max_abs_unsigned, tolerance);
        why = b;
    } else if (is_signed && e.sign_disagreements_beyond_tolerance > 0) {
        std::snprintf(b, sizeof b, "%lld wrong signs farther than the tolerance %.3g from the surface (max signed error %.3g)",
                      (long long)e.sign_disagreements_beyond_tolerance, tolerance, e.max_abs);
        why = b;
    } else if (!(e.max_abs <= tolerance)) {
        std::snprintf(b, sizeof b, "max |signed distance error| %.3g > tolerance %.3g", e.max_abs, tolerance);
        why = b;
    }
    row["passes_check"] = why.empty();
    row["check"] = why.empty() ? (is_signed ? "exact, signed" : "exact, unsigned (no sign returned)") : why;
    row["signed"] = is_signed;
    row["check_tolerance"] = tolerance;
}

std::string sign_label(const nlohmann::json& row) {
    const std::string sign = row.value("sign", std::string());
    if (sign.empty()) return row.value("signed", true) ? "signed" : "unsigned";
    if (sign == "none") return "unsigned";
    if (sign == "own") return "own: " + row.value("sign_method", std::string("?"));
    return sign;
}

namespace {

using Json = nlohmann::json;

const char* kTime = "query_seconds";

/// The fastest of `rows` by query time; null when there is none.
const Json* fastest(const std::vector<const Json*>& rows) {
    const Json* best = nullptr;
    for (const Json* r : rows)
        if (!best || (*r)[kTime].get<double>() < (*best)[kTime].get<double>()) best = r;
    return best;
}

}  // namespace

std::vector<Json> summarise_case(const Json& rows, const std::string& label, const std::string& resolution,
                                 const std::vector<Json>& thread_keys, double goal) {
    std::vector<Json> out;
    for (const Json& threads : thread_keys) {
        std::vector<const Json*> ours, ours_passing, peers, peers_passing, signed_peers_passing;
        for (const Json& row : rows) {
            if (row.value("mesh", "") != label || row.value("resolution", "") != resolution || row.contains("status") ||
                !row.contains("threads") || row["threads"] != threads)
                continue;
            const bool passes = row.value("passes_check", false);
            if (row.value("by", "") == "ours") {
                if (row.value("extrapolated", false)) continue;  // timed on a subset: not a measured time of these points
                ours.push_back(&row);
                if (passes) ours_passing.push_back(&row);
            } else {
                peers.push_back(&row);
                if (passes) peers_passing.push_back(&row);
                if (passes && row.value("signed", false)) signed_peers_passing.push_back(&row);
            }
        }
        if (ours.empty() || peers.empty()) continue;
        Json s = {{"mesh", label}, {"resolution", resolution}, {"threads", threads}, {"goal", goal}};
        Json excluded = Json::array();
        for (const Json* r : ours)
            if (!(*r).value("passes_check", false))
                excluded.push_back({{"method", (*r)["method"]}, {"sign", sign_label(*r)}, {"check", (*r).value("check", std::string())}});
        if (!excluded.empty()) s["excluded"] = excluded;
        const Json* mine = fastest(ours_passing);
        const Json* best = fastest(peers_passing);
        if (!mine || !best) {
            s["not_compared"] = !mine ? "no row of ours passes its check" : "no peer passes its check";
            out.push_back(s);
            continue;
        }
        const Json& m = *mine;
        const Json& b = *best;
        s["ours"] = m["method"];
        s["ours_sign"] = sign_label(m);
        s["ours_passes_check"] = true;
        s["fastest_exact_peer"] = b["method"];
        s["fastest_exact_peer_signed"] = b.value("signed", false);
        s["fastest_exact_peer_sign"] = sign_label(b);
        s["compared_time"] = kTime;
        s["query_speedup"] = b[kTime].get<double>() / m[kTime].get<double>();
        s["total_speedup"] = b["total_seconds"].get<double>() / m["total_seconds"].get<double>();
        if (!threads.is_string() && m.contains("cpu_seconds") && b.contains("cpu_seconds"))
            s["cpu_time_ratio"] = b["cpu_seconds"].get<double>() / m["cpu_seconds"].get<double>();
        if (const Json* bs = fastest(signed_peers_passing)) {
            s["fastest_exact_signed_peer"] = (*bs)["method"];
            s["fastest_exact_signed_peer_sign"] = sign_label(*bs);
            s["query_speedup_vs_signed"] = (*bs)[kTime].get<double>() / m[kTime].get<double>();
        }
        out.push_back(s);
    }
    return out;
}

std::string summary_text(const Json& s) {
    const std::string where = s["threads"].is_string() ? std::string("GPU") : std::to_string(s["threads"].get<int>()) + " threads";
    char line[512];
    std::string text;
    if (s.contains("not_compared")) {
        text = "    => no comparison, " + where + ": " + s["not_compared"].get<std::string>() + "\n";
    } else {
        std::snprintf(line, sizeof line, "    => %s [%s] vs fastest exact peer %s [%s], %s: %.2fx query, %.2fx build+query (goal %.1fx)\n",
                      s["ours"].get<std::string>().c_str(), s["ours_sign"].get<std::string>().c_str(),
                      s["fastest_exact_peer"].get<std::string>().c_str(), s["fastest_exact_peer_sign"].get<std::string>().c_str(),
                      where.c_str(), s["query_speedup"].get<double>(), s["total_speedup"].get<double>(), s["goal"].get<double>());
        text = line;
        if (s.contains("fastest_exact_signed_peer") && s["fastest_exact_signed_peer"] != s["fastest_exact_peer"]) {
            std::snprintf(line, sizeof line, "       fastest exact signed peer %s [%s]: %.2fx query\n",
                          s["fastest_exact_signed_peer"].get<std::string>().c_str(),
                          s["fastest_exact_signed_peer_sign"].get<std::string>().c_str(), s["query_speedup_vs_signed"].get<double>());
            text += line;
        }
    }
    if (s.contains("excluded"))
        for (const Json& e : s["excluded"])
            text += "       not compared: " + e["method"].get<std::string>() + " [" + e["sign"].get<std::string>() +
                    "] fails its check: " + e["check"].get<std::string>() + "\n";
    return text;
}

std::string row_text(const Json& row) {
    char line[640];
    if (row.contains("status")) {
        std::snprintf(line, sizeof line, "    %-18s %s\n", row["method"].get<std::string>().c_str(), row["status"].get<std::string>().c_str());
        return line;
    }
    const std::string threads = row["threads"].is_string() ? row["threads"].get<std::string>() : std::to_string(row["threads"].get<int>());
    const std::string signs = row["sign_disagreements"].is_string() ? "n/a" : std::to_string(row["sign_disagreements"].get<int64_t>());
    std::snprintf(line, sizeof line,
                  "    %-18s %4s threads  build %8.4f s  query %9.4f s  cpu %9.4f s  %10.4g points/s  max|dd| %.3g (unsigned %.3g)  "
                  "sign %s, disagreements %s  %s\n",
                  row["method"].get<std::string>().c_str(), threads.c_str(), row["build_seconds"].get<double>(),
                  row["query_seconds"].get<double>(), row.value("cpu_seconds", -1.0), row["points_per_second"].get<double>(),
                  row["max_abs_error"].get<double>(), row["max_abs_error_unsigned"].get<double>(), sign_label(row).c_str(),
                  signs.c_str(), row.value("passes_check", false) ? "passes" : ("FAILS: " + row.value("check", std::string("?"))).c_str());
    return line;
}

}  // namespace sdf::peers
