#pragma once
// The still-image job: scene -> geometry -> form factors -> solve -> render -> write.
#include <optional>
#include <string>
#include <vector>

#include "app/form_factor_request.h"
#include "cache/cache_file.h"
#include "formfactor/form_factor.h"
#include "render/raycast.h"
#include "solve/solver.h"

namespace radiosa {

struct StillJob {
    std::string scene_path;
    std::string camera_path;
    std::vector<std::string> outputs;  // image files; format from each extension
    std::optional<std::string> report_path;
    RenderOptions render;
    FormFactorRequest form_factors;
    SolverMethod solver = SolverMethod::LU;
    double exposure = 0.0;             // stops; PNG value = radiosity * 2^exposure
    int threads = 0;                   // 0 = all cores
    WarningSink warn = [](const std::string&) {};  // one-line warnings (damaged cache, ...)
};

struct StageTimes {
    double load_s = 0, form_factors_s = 0, solve_s = 0, render_s = 0, write_s = 0, total_s = 0;
};

struct StillReport {
    std::string scene_name;
    int surfaces = 0;
    int patches = 0;
    bool closed = true;
    FormFactorOptions ff_options;
    int threads = 0;
    FormFactorStats form_factor_stats;  // of the computation, stored with a cached matrix
    CacheOutcome cache;
    FormFactorChecks checks;
    std::string closure_worst_patch;  // "surface[is,it]"
    int factorisations = 0;
    int channel_solves = 0;           // substitutions run; channels identical to another share one
    bool dark = false;                // no emission anywhere: no solve
    int iterations = 0;               // iterative solvers: sweeps needed
    double spectral_radius = 0.0;     // upper bound, max over channels, of the spectral radius of rho F
    double condition_estimate = 0.0;  // max over channels of the LU's condition estimate (0: none)
    SolveDiagnostics solve;
    StageTimes times;
};

// Runs the job; throws Error for bad input or unwritable outputs (checked before any work).
StillReport run_still(const StillJob& job);

std::string still_report_json(const StillJob& job, const StillReport& r);
std::string still_summary(const StillJob& job, const StillReport& r);

}  // namespace radiosa
