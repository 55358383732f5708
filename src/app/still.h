#pragma once
// The still-image job: scene -> geometry -> form factors -> solve -> render -> write.
#include <optional>
#include <string>
#include <vector>

#include "app/form_factor_request.h"
#include "app/pipeline.h"
#include "render/raycast.h"
#include "solve/solver.h"
#include "util/warnings.h"

namespace radiosa {

struct StillJob {
    std::string scene_path;
    std::string camera_path;
    std::vector<std::string> outputs;  // image files; format from each extension
    std::optional<std::string> report_path;
    std::optional<std::string> radiosities_path;  // per-patch radiosity, .csv
    RenderOptions render;
    FormFactorRequest form_factors;
    SolverMethod solver = SolverMethod::LU;
    double exposure = 0.0;                         // stops; PNG value = radiosity * 2^exposure
    int threads = 0;                               // 0 = all cores
    WarningSink warn = [](const std::string&) {};  // one-line warnings (damaged cache, ...)
};

struct StageTimes {
    double load_s = 0, form_factors_s = 0, solve_s = 0, render_s = 0, write_s = 0, total_s = 0;
};

struct StillReport {
    explicit StillReport(Prepared p) : prep(std::move(p)) {}

    Prepared prep;  // scene, geometry, form factors, their cache and checks
    int threads = 0;
    int factorisations = 0;
    int channel_solves = 0;      // substitutions run; channels identical to another share one
    bool dark = false;           // no emission anywhere: no solve
    int iterations = 0;          // iterative solvers: sweeps needed
    StabilitySummary stability;  // spectral radius of rho F and LU condition, max over channels
    SolveDiagnostics solve;
    // max |B - B*| / max B per channel (solver.h); empty when the form factors carry no estimates
    std::optional<Rgb> radiosity_error_bound;
    // Hierarchical links: an estimate of the same, not a bound (solve/link_solver.h)
    std::optional<Rgb> radiosity_error_estimate;
    // Per scene sensor: irradiance sum_j F(dA -> j) B_j per channel, and sum_j err_j B_j.
    struct SensorReading {
        std::string name;
        Rgb irradiance{0.0};
        Rgb error{0.0};
    };
    std::vector<SensorReading> sensors;
    StageTimes times;
};

// Runs the job; throws Error for bad input or unwritable outputs (checked before any work).
StillReport run_still(const StillJob& job);

std::string still_report_json(const StillJob& job, const StillReport& r);
std::string still_summary(const StillJob& job, const StillReport& r);

}  // namespace radiosa
