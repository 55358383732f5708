#include "app/pipeline.h"

#include <fmt/format.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "app/report_json.h"
#include "cache/link_file.h"
#include "distribute/cluster.h"
#include "solve/solver.h"
#include "surfaces/registry.h"
#include "util/error.h"
#include "util/memory.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {

// The largest radiosity error bound over the channels, for the scene's own lights and colours.
double scene_error_bound(const Prepared& p) {
    const Materials mat = patch_materials(p.scene);
    if (std::all_of(mat.E.begin(), mat.E.end(), [](const Rgb& e) { return e == Rgb(0.0); })) return 0.0;
    const RadiositySolver solver(p.ff.F, mat.rho, SolverMethod::LU);
    const Rgb b = radiosity_error_bound(solver, p.ff.F, p.ff.error, mat, solver.solve(mat.E));
    return std::max({b.r, b.g, b.b});
}

// Tightens the form-factor tolerance until the radiosity error bound meets `target`: each round
// scales the tolerance by half the ratio of target to bound (at most 1000-fold at once), down to
// kMinFormFactorTolerance; matrices come from the cache like any other.
void meet_solve_target(Prepared* p, double target, const FormFactorRequest& request,
                       const WarningSink& warn) {
    if (p->options.method != FormFactorMethod::Adaptive)
        throw Error(
            p->scene.solve.tolerance ? p->scene.solve_loc : FileLoc{p->scene.file, 0, 0},
            "a solve tolerance needs error-controlled form factors (their estimates bound the error); "
            "drop --gauss-points or form_factors: gauss_points");
    Prepared::SolveTarget t{target, 0.0, false, 1};
    for (;; ++t.rounds) {
        t.bound = scene_error_bound(*p);
        t.reached = t.bound <= target;
        if (t.reached || p->options.tolerance <= kMinFormFactorTolerance) break;
        const double factor = std::isfinite(t.bound) ? std::clamp(0.5 * target / t.bound, 1e-3, 0.5) : 1e-3;
        p->options.tolerance = std::max(kMinFormFactorTolerance, p->options.tolerance * factor);
        p->ff = obtain_form_factors(p->scene, p->geometry, p->options, request.cache, warn, &p->cache);
    }
    p->solve_target = t;
    if (t.reached) return;
    const std::string w = fmt::format(
        "the solve tolerance {:.0e} is out of reach: at form-factor tolerance {:.0e} the radiosity error "
        "bound is {:.2e}; the scene is too stiff (reflectances near 1) for the estimates",
        target, p->options.tolerance, t.bound);
    if (request.strict) throw Error(FileLoc{p->scene.file, 0, 0}, w + "; loosen it or run without --strict");
    warn(w);
}

// The hierarchical method: links instead of the matrix, through the cache like it.
void build_links(Prepared* p, const FormFactorRequest& request, const WarningSink& warn) {
    if (request.solve_tolerance || p->scene.solve.tolerance)
        throw Error(p->scene.solve.tolerance ? p->scene.solve_loc : FileLoc{p->scene.file, 0, 0},
                    "a solve tolerance needs the dense form factors (their estimates bound the error); "
                    "drop form_factors: method: hierarchical (or --ff-method hierarchical)");
    p->hierarchy = obtain_hierarchy(p->scene, p->geometry, p->options, request.cache, warn, &p->cache);
    p->ff.options = p->options;
    p->ff.stats = p->hierarchy->leaf_stats;
    p->ff.stats.seconds = p->hierarchy->stats.seconds;
    for (int i = 0; i < p->geometry.patch_count(); ++i) p->ff.area.push_back(p->geometry.patch(i).area);
}

}  // namespace

Prepared prepare(const std::string& scene_path, const FormFactorRequest& request, const WarningSink& warn,
                 const std::function<void(const Prepared&)>& check_inputs) {
    Stopwatch clock;
    Prepared p(load_scene(scene_path));
    if (check_inputs) check_inputs(p);
    p.intersections = find_intersections(p.geometry);
    if (!p.intersections.empty()) {
        const std::string w = intersection_warning(p.geometry, p.intersections);
        if (request.strict) {
            const SurfaceDesc& d = p.scene.surfaces[static_cast<std::size_t>(p.intersections[0].b)];
            throw Error(d.loc,
                        "surfaces intersect: " + intersection_names(p.geometry, p.intersections) +
                            "; move them apart (touching along an edge is fine) or run without --strict");
        }
        warn(w);
    }
    p.load_s = clock.seconds();

    p.options = request.options_for(p.scene);
    clock = Stopwatch();
    if (p.options.method == FormFactorMethod::Hierarchical) {
        build_links(&p, request, warn);
    } else {
        if (const int n = p.geometry.patch_count(); n > kMaxDensePatches)
            throw Error(FileLoc{p.scene.file, 0, 0},
                        fmt::format("the scene has {} patches; the dense form-factor matrix stops at {} "
                                    "({:.0f} GB here): use form_factors: {{method: hierarchical}} or "
                                    "--ff-method hierarchical",
                                    n, kMaxDensePatches, 8.0 * n * double(n) / 1e9));
        p.ff = obtain_form_factors(p.scene, p.geometry, p.options, request.cache, warn, &p.cache);
        if (const auto target = request.solve_tolerance ? request.solve_tolerance : p.scene.solve.tolerance)
            meet_solve_target(&p, *target, request, warn);
    }
    p.form_factors_s = clock.seconds();
    p.checks = p.hierarchy ? check_hierarchy(*p.hierarchy, p.options.tolerance) : check_form_factors(p.ff);
    if (p.checks.closure_worst_patch >= 0)
        p.closure_worst_patch = p.geometry.patch_label(p.checks.closure_worst_patch);
    if (p.checks.entries_over_tolerance > 0) {
        p.worst_miss = p.checks.worst_miss_i < 0 || p.checks.worst_miss_j < 0
                           ? std::string("a link between groups of patches")
                           : p.geometry.patch_label(p.checks.worst_miss_i) + " -> " +
                                 p.geometry.patch_label(p.checks.worst_miss_j);
        const std::string w = fmt::format(
            "{} form-factor entr{} miss the tolerance {:.0e} ({} integral(s) stopped at their refinement "
            "cap); "
            "the worst, F[{}], has the estimate {:.2e}, {:.3g} times its target",
            p.checks.entries_over_tolerance, p.checks.entries_over_tolerance == 1 ? "y" : "ies",
            p.options.tolerance, p.ff.stats.capped, p.worst_miss, p.checks.worst_miss_estimate,
            p.checks.worst_miss_ratio);
        if (request.strict)
            throw Error(FileLoc{scene_path, 0, 0}, w + "; set a looser form_factors tolerance, split the "
                                                       "patches named, or run without --strict");
        warn(w + "; the matrix is used as it is (--strict refuses it)");
    }
    clock = Stopwatch();
    const double sensor_tol =
        p.options.method == FormFactorMethod::Adaptive ? p.options.tolerance : kDefaultFormFactorTolerance;
    for (const SensorDesc& d : p.scene.sensors)
        p.sensors.push_back(
            sensor_factors(p.geometry, d.position, d.normal, sensor_tol, p.options.visibility));
    p.sensors_s = clock.seconds();
    return p;
}

namespace {

// CPU seconds of the pairs per surface type (a pair's time split between its two surfaces'
// types), in registration order; empty when the matrix was not computed in this run.
std::vector<std::pair<std::string, double>> seconds_by_type(const Prepared& p) {
    const std::vector<double>& by_surface = p.ff.stats.seconds_by_surface;
    std::vector<std::pair<std::string, double>> out;
    if (by_surface.size() != p.scene.surfaces.size()) return out;
    for (const SurfaceType* type : surface_types()) {
        double sum = 0.0;
        bool present = false;
        for (std::size_t k = 0; k < by_surface.size(); ++k)
            if (p.scene.surfaces[k].type == type) {
                sum += by_surface[k];
                present = true;
            }
        if (present) out.emplace_back(type->name, sum);
    }
    return out;
}

nlohmann::json seconds_by_type_json(const Prepared& p) {
    const auto by_type = seconds_by_type(p);
    if (by_type.empty()) return nullptr;
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [name, s] : by_type) j[name] = s;
    return j;
}

}  // namespace

void add_prepared_json(nlohmann::json& j, const Prepared& p) {
    using nlohmann::json;
    j["scene_name"] = p.scene.name;
    j["surfaces"] = p.geometry.surface_count();
    j["patches"] = p.geometry.patch_count();
    j["closed"] = p.scene.closed;
    j["ranks"] = Cluster::current().size();
    add_form_factor_method(j, p.options);
    // Closure only means something for a closed scene.
    j["closure_max_error"] = p.scene.closed ? json(p.checks.closure_max_error) : json(nullptr);
    j["closure_worst_patch"] = p.scene.closed ? json(p.closure_worst_patch) : json(nullptr);
    j["reciprocity_max_error"] = p.checks.reciprocity_max_error;
    j["min_entry"] = p.checks.min_entry;
    add_form_factor_checks(j, p.checks);
    const bool estimates = !p.ff.error.empty() || p.hierarchy;
    j["entries_over_tolerance"] = estimates ? json(p.checks.entries_over_tolerance) : json(nullptr);
    j["worst_entry_over_tolerance"] = p.worst_miss.empty()
                                          ? json(nullptr)
                                          : json{{"pair", p.worst_miss},
                                                 {"estimate", p.checks.worst_miss_estimate},
                                                 {"estimate_over_target", p.checks.worst_miss_ratio}};
    json pairs = json::array();
    for (const SurfaceIntersection& x : p.intersections)
        pairs.push_back({p.geometry.surface_name(x.a), p.geometry.surface_name(x.b)});
    j["surface_intersections"] = pairs;
    j["form_factor_stats"] = form_factor_stats_json(p.ff.stats);
    j["form_factor_seconds_by_type"] = seconds_by_type_json(p);
    j["peak_memory_mb"] = peak_memory_mb();
    j["hierarchy"] = p.hierarchy ? hierarchy_json(*p.hierarchy) : json(nullptr);
    j["form_factor_cache"] = cache_outcome_json(p.cache);
    j["solve_target"] = p.solve_target ? json{{"tolerance", p.solve_target->tolerance},
                                              {"bound", p.solve_target->bound},
                                              {"reached", p.solve_target->reached},
                                              {"rounds", p.solve_target->rounds},
                                              {"form_factor_tolerance", p.options.tolerance}}
                                       : json(nullptr);
}

std::string prepared_summary(const Prepared& p) {
    const FormFactorStats& st = p.ff.stats;
    std::string s =
        fmt::format("  {:<13} {:8.3f} s  {}, visibility {}, {} pairs, {} culled, {} segment tests\n",
                    "form factors", p.form_factors_s, describe(p.options),
                    p.options.visibility ? "on" : "off", st.pairs, st.pairs_culled, st.segment_tests);
    s += fmt::format("  {:<13}    cache {}\n", "", cache_outcome_summary(p.cache));
    if (const auto by_type = seconds_by_type(p); by_type.size() > 1) {
        std::string parts;
        for (const auto& [name, sec] : by_type)
            parts += fmt::format("{}{} {:.3g} s", parts.empty() ? "" : ", ", name, sec);
        s += fmt::format("  {:<13}    CPU time by surface type: {}\n", "", parts);
    }
    if (Cluster::current().distributed() && p.cache.compute_s > 0)
        s += fmt::format("  {:<13}    computed by {} MPI ranks\n", "", Cluster::current().size());
    if (p.scene.closed)
        s += fmt::format("  closure max |sum_j F_ij - 1| = {:.2e} (worst: {})\n", p.checks.closure_max_error,
                         p.closure_worst_patch);
    s += fmt::format(
        "  reciprocity max |F_ij - A_j F_ji / A_i| = {:.2e} (relative {:.2e}, {:.2f} of the estimates)\n",
        p.checks.reciprocity_abs_error, p.checks.reciprocity_max_error, p.checks.reciprocity_vs_estimate);
    if (const auto& t = p.solve_target)
        s += fmt::format(
            "  solve target {:.0e}: {} after {} form-factor run(s), bound {:.2e} at tolerance {:.1e}\n",
            t->tolerance, t->reached ? "met" : "NOT met", t->rounds, t->bound, p.options.tolerance);
    if (!p.ff.error.empty() || p.hierarchy)
        s += fmt::format("  error estimates: max per {} {:.2e}, max per row {:.2e}\n",
                         p.hierarchy ? "link" : "entry", p.checks.max_error_estimate,
                         p.checks.max_row_error_estimate);
    if (const auto& h = p.hierarchy)
        s += fmt::format(
            "  hierarchy     {} nodes, {} links ({} between two patches, {} above them), {:.0f} MB\n",
            h->nodes.size(), h->stats.links, h->stats.leaf_links, h->stats.links - h->stats.leaf_links,
            static_cast<double>(hierarchy_bytes(*h)) / 1e6);
    return s;
}

ThreadLimit::ThreadLimit(int threads) : m_threads(threads > 0 ? threads : tbb::info::default_concurrency()) {
    if (threads > 0)
        m_control =
            std::make_shared<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
}

}  // namespace radiosa
