#pragma once
#include <optional>
// Pieces of the JSON run report shared by the commands that write one.
#include <nlohmann/json.hpp>
#include <string>

#include "cache/cache_file.h"
#include "formfactor/hierarchy.h"
#include "solve/solver.h"

namespace radiosa {

// "form_factor_cache": {status, reason, file, key, load_s, compute_s, write_s, wait_s}
nlohmann::json cache_outcome_json(const CacheOutcome& c);
// One line for stdout, e.g. "hit out/cache/3f...rff (loaded in 0.001 s)".
std::string cache_outcome_summary(const CacheOutcome& c);
// "form_factor_stats": culling counts and, for error-controlled matrices, how entries were integrated.
nlohmann::json form_factor_stats_json(const FormFactorStats& s);
// What the solves shared: channels with identical reflectance (and emission) reuse one
// factorisation (and one substitution); a scene with no light skips the solve.
struct SharedSolves {
    int factorisations = 0, factorisations_possible = 0;  // run, and one per channel and reflectance set
    int channel_solves = 0, channel_solves_possible = 0;  // run, and one per channel and distinct state
    bool skipped = false;
};
// "left_out": what the run proved it did not need to do, counted (docs/cli.md, "Run report").
nlohmann::json left_out_json(const FormFactorOptions& o, const FormFactorStats& s,
                             const SharedSolves& solves);
// Adds form_factor_method ("adaptive" | "gauss" | "hierarchical"), form_factor_tolerance,
// gauss_points, link_tolerance and receiver_tolerance (those that do not apply are null) and
// visibility.
void add_form_factor_method(nlohmann::json& j, const FormFactorOptions& o);
// "hierarchy": {nodes, links, leaf_links, node_pairs, kernel_samples, dropped, bytes, seconds}.
nlohmann::json hierarchy_json(const Hierarchy& h);
// "solve": {method, spectral_radius, condition_estimate (null when none), residual}.
nlohmann::json solve_json(SolverMethod method, const StabilitySummary& stability, double residual);
// Adds max_error_estimate, max_row_error_estimate, reciprocity_abs_error, reciprocity_vs_estimate.
void add_form_factor_checks(nlohmann::json& j, const FormFactorChecks& c);
// radiosity_error_bound: [r, g, b], a channel null where no bound could be proven, null as a
// whole when the form factors carry no estimates (the fixed rule).
nlohmann::json error_bound_json(const std::optional<Rgb>& bound);
// "  radiosity error bound max |B - B*| / max B: r 1.2e-06, g ..., b ...\n", or "".
std::string error_bound_summary(const std::optional<Rgb>& bound);

}  // namespace radiosa
