#pragma once
// The sequence job: scene + sequence -> one form-factor matrix -> the scheduler's plan ->
// per frame only what it needs -> video and/or numbered images, and the frame-by-frame report.
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "app/form_factor_request.h"
#include "app/pipeline.h"
#include "encode/palette.h"
#include "formfactor/incremental.h"
#include "render/image.h"
#include "render/raycast.h"
#include "schedule/scheduler.h"
#include "solve/solver.h"

namespace radiosa {

struct SequenceJob {
    std::string scene_path;  // empty: the sequence's `scene:`
    std::string sequence_path;
    std::vector<std::string> outputs;  // .mp4 and/or patterns like out/frames/%04d.png
    std::optional<std::string> report_path;
    // Unset: the sequence's `image:` block, else the RenderOptions defaults.
    std::optional<int> width, height, samples;
    FormFactorRequest form_factors;
    SolverMethod solver = SolverMethod::LU;
    // --solver given: used as it is. Otherwise a sequence with moving surfaces above
    // kMovingIterativeFromPatches patches solves by Gauss-Seidel, warm-started from the previous
    // frame (every geometry state is a new system: docs/sequences.md, "Moving surfaces").
    bool solver_given = false;
    double exposure = 0.0;
    int crf = 18;
    int palette = 0;  // > 0: one palette of this many colours for all frames (.gif / indexed .png)
    Quantiser quantiser = Quantiser::MedianCut;
    int threads = 0;
    WarningSink warn = [](const std::string&) {};
    std::ostream* progress = nullptr;                 // a terminal: progress bar with rate and ETA
    std::function<void(int, const Image&)> on_frame;  // sees every frame (tests)
};

inline constexpr int kMovingIterativeFromPatches = 1000;

struct FrameRecord {
    FramePlan plan;
    const char* form_factors = "reused";  // computed | cached | updated | reused
    // Entries of F evaluated for this frame (all for `computed`, the update's for `updated`).
    long long entries_recomputed = 0;
    std::optional<FormFactorUpdate> update;  // when `updated`: what was recomputed and why
    int rank = 0;                            // the MPI rank that rendered it (0: one process)
    double form_factors_s = 0, solve_s = 0, render_s = 0, encode_s = 0;
    int sweeps = 0;  // an iterative solve's sweeps (max over channels); 0 for direct solves and reuse
};

struct SequenceReport {
    std::string scene_path;
    std::unique_ptr<Prepared> prep;          // scene, geometry, form factors, their cache and checks
    RenderOptions render;                    // as resolved
    SolverMethod solver = SolverMethod::LU;  // as resolved (SequenceJob::solver_given)
    int threads = 0;
    int ranks = 1;  // processes of the MPI job (1: not distributed)
    double fps = 0;
    int reflectance_sets = 0, factorisations = 0, substitutions = 0, channel_solves = 0, renders = 0,
        copies = 0;
    // Over every factorisation and solution of the plan: the worst stability figures, residual
    // and energy balance (closed scenes).
    StabilitySummary stability;
    double residual = 0.0, energy_balance_error = 0.0;
    // The worst radiosity error bound per channel over every solution (solver.h); empty when the
    // form factors carry no estimates.
    std::optional<Rgb> radiosity_error_bound;
    // With hierarchical links: the worst estimate (not a bound) per channel over every solution
    // (solve/link_solver.h); empty otherwise.
    std::optional<Rgb> radiosity_error_estimate;
    std::vector<FrameRecord> frames;
    // Moving surfaces: the geometry states (1 without motion) and the worst closure over them.
    int geometry_states = 1;
    bool moves = false;  // some frame places a surface elsewhere than the scene file (Plan::moves)
    double closure_max_error_over_states = 0.0;
    // Per solution of the plan (FramePlan::solution), per scene sensor: its irradiance.
    std::vector<std::vector<Rgb>> sensor_irradiance;
    struct PaletteResult {
        int colours = 0;
        double psnr_median_cut_db = 0, psnr_popularity_db = 0, seconds = 0;
    } palette;
    double load_s = 0, form_factors_s = 0, solve_s = 0, render_s = 0, encode_s = 0, total_s = 0;
};

SequenceReport run_sequence_job(const SequenceJob& job);
std::string sequence_report_json(const SequenceJob& job, const SequenceReport& r);
std::string sequence_summary(const SequenceJob& job, const SequenceReport& r);

}  // namespace radiosa
