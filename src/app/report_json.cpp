#include "app/report_json.h"

#include <fmt/format.h>

#include <cmath>

namespace radiosa {

nlohmann::json cache_outcome_json(const CacheOutcome& c) {
    using nlohmann::json;
    auto str_or_null = [](const std::string& s) { return s.empty() ? json(nullptr) : json(s); };
    return {{"status", cache_status_name(c.status)},
            {"reason", str_or_null(c.reason)},
            {"file", str_or_null(c.file)},
            {"key", str_or_null(c.key)},
            {"written", c.written},
            {"load_s", c.load_s},
            {"compute_s", c.compute_s},
            {"write_s", c.write_s},
            {"wait_s", c.wait_s}};
}

nlohmann::json form_factor_stats_json(const FormFactorStats& s) {
    nlohmann::json j = nlohmann::json::object();
    s.for_each_counter([&](const char* name, long long v) { j[name] = v; });
    return j;
}

nlohmann::json left_out_json(const FormFactorOptions& o, const FormFactorStats& s,
                             const SharedSolves& solves) {
    return {{"culling", o.culling},
            {"pairs", s.pairs},
            {"pairs_culled", s.pairs_culled},
            {"pairs_unoccluded", s.pairs_unoccluded},
            {"occlusion_tests_skipped", s.occluders_culled},
            {"channel_solves", solves.channel_solves},
            {"channel_solves_shared", solves.channel_solves_possible - solves.channel_solves},
            {"factorisations", solves.factorisations},
            {"factorisations_shared", solves.factorisations_possible - solves.factorisations},
            {"solve_skipped", solves.skipped}};
}

nlohmann::json solve_json(SolverMethod method, const StabilitySummary& stability, double residual) {
    using nlohmann::json;
    return {{"method", solver_method_name(method)},
            {"spectral_radius", stability.spectral_radius},
            {"condition_estimate",
             stability.condition_estimate > 0 ? json(stability.condition_estimate) : json(nullptr)},
            {"residual", residual}};
}

void add_form_factor_method(nlohmann::json& j, const FormFactorOptions& o) {
    using nlohmann::json;
    const bool fixed = o.method == FormFactorMethod::Fixed;
    j["form_factor_method"] = method_name(o.method);
    j["form_factor_tolerance"] = fixed ? json(nullptr) : json(o.tolerance);
    j["gauss_points"] = fixed ? json(o.gauss_points) : json(nullptr);
    j["link_tolerance"] = o.method == FormFactorMethod::Hierarchical ? json(o.link_tolerance) : json(nullptr);
    j["receiver_tolerance"] = o.method == FormFactorMethod::Hierarchical && o.receiver_tolerance > 0.0
                                  ? json(o.receiver_tolerance)
                                  : json(nullptr);
    j["numeric_inner"] =
        o.method == FormFactorMethod::Adaptive ? json(o.numeric_lines ? "lines" : "rules") : json(nullptr);
    j["visibility"] = o.visibility;
}

nlohmann::json hierarchy_json(const Hierarchy& h) {
    return {{"nodes", h.nodes.size()},
            {"links", h.stats.links},
            {"leaf_links", h.stats.leaf_links},
            {"node_pairs", h.stats.node_pairs},
            {"kernel_samples", h.stats.kernel_samples},
            {"dropped", h.stats.dropped},
            {"bytes", hierarchy_bytes(h)},
            {"seconds", h.stats.seconds}};
}

void add_form_factor_checks(nlohmann::json& j, const FormFactorChecks& c) {
    j["reciprocity_abs_error"] = c.reciprocity_abs_error;
    j["reciprocity_vs_estimate"] = c.reciprocity_vs_estimate;
    j["max_error_estimate"] = c.max_error_estimate;
    j["max_row_error_estimate"] = c.max_row_error_estimate;
}

std::string cache_outcome_summary(const CacheOutcome& c) {
    std::string s = cache_status_name(c.status);
    switch (c.status) {
        case CacheStatus::Off:
            return s + (c.reason.empty() ? " (--no-cache)" : " (" + c.reason + ")");
        case CacheStatus::Hit:
            return s + fmt::format(" {} (loaded in {:.3f} s)", c.file, c.load_s);
        case CacheStatus::Rebuilt:
        case CacheStatus::Miss:
            s += fmt::format(" (computed in {:.3f} s{})", c.compute_s,
                             c.written ? ", written" : ", not written");
            if (c.written) s += " " + c.file;
            if (!c.reason.empty()) s += "; " + c.reason;
            return s;
    }
    return s;
}

nlohmann::json error_bound_json(const std::optional<Rgb>& bound) {
    using nlohmann::json;
    if (!bound) return nullptr;
    json a = json::array();
    for (int c = 0; c < 3; ++c) a.push_back(std::isfinite((*bound)[c]) ? json((*bound)[c]) : json(nullptr));
    return a;
}

std::string error_bound_summary(const std::optional<Rgb>& bound) {
    if (!bound) return "";
    auto one = [](double x) {
        return std::isfinite(x) ? fmt::format("{:.1e}", x) : std::string("none proven");
    };
    return fmt::format("  radiosity error bound max |B - B*| / max B: r {}, g {}, b {}\n", one(bound->r),
                       one(bound->g), one(bound->b));
}

}  // namespace radiosa
