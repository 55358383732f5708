#pragma once
// The scheduler: for every frame of a sequence, what must be computed and what an earlier
// frame already has. Frames are grouped by geometry state (where the moving surfaces stand): one
// form-factor matrix per distinct state, obtained once; a factorisation of (I - diag(rho) F) is
// made once per distinct (state, reflectance set); a substitution once per distinct (state,
// reflectance, emission) — or, with an iterative solver, one warm-started iteration per distinct
// solution; a render whenever the camera or the radiosities differ from the previous frame,
// otherwise the previous frame is copied.
#include <vector>

#include "schedule/sequence.h"

namespace radiosa {

// Iterated: an iterative solver's run (--solver jacobi | gauss-seidel | southwell, and every
// solve over hierarchical links), warm-started from the last solution with the same reflectance.
// Combined: over hierarchical links, an emission that is a linear combination of emissions
// already iterated with the same reflectance (a light ramping between two settings, lights
// dimmed together): radiosity is linear in emission, so B = sum_k w_k B_k per channel, O(N)
// per term and no sweep.
// Ahead: over hierarchical links, an emission solved by the sweeps of an earlier Iterated frame
// with the same reflectance, which carried it along as one more right-hand side (the sweeps read
// every link once for all the emissions they carry): no sweep at its own frame.
enum class SolveAction { Factorised, Substituted, Iterated, Combined, Reused, Ahead };
enum class RenderAction { Rendered, Copied };
const char* solve_action_name(SolveAction a);
const char* render_action_name(RenderAction a);

struct FramePlan {
    int frame = 0;
    double time_s = 0.0;
    CameraDesc camera;
    int geometry = 0;         // index into Plan::geometries
    int reflectance_set = 0;  // index into Plan::reflectances (one factorisation each)
    int solution = 0;         // index into Plan::solutions
    SolveAction solve = SolveAction::Factorised;
    RenderAction render = RenderAction::Rendered;
};

// One term of a Combined solution: the weight, per channel, of an earlier solution's radiosity.
struct Combination {
    int solution = 0;
    Rgb weight{0.0};
};

struct Plan {
    std::vector<FramePlan> frames;
    // Distinct geometry states in order of first use: every surface's displacement from the
    // scene file (all identities for a sequence without motion: one state).
    std::vector<std::vector<Similarity>> geometries;
    std::vector<int> last_frame_of_geometry;  // per state, the last frame that uses it
    // Distinct (geometry, reflectance) sets, in order of first use, and each one's state.
    std::vector<std::vector<Rgb>> reflectances;
    std::vector<int> reflectance_geometry;
    std::vector<Materials> solutions;  // distinct (set, emission), in order of first use
    std::vector<int> solution_set;     // per solution, its reflectance set
    // Per solution: its terms when it is Combined (each an Iterated solution of the same set,
    // first used earlier), else empty.
    std::vector<std::vector<Combination>> combinations;
    // Per solution: the solution whose frame solves it (itself, or with `combine`, an earlier
    // Iterated solution of the same reflectance set whose sweeps carry it along), and, for a
    // solution solved at its own frame, every solution those sweeps solve (itself first).
    std::vector<int> solved_with;
    std::vector<std::vector<int>> solved_together;
    int factorisations() const { return static_cast<int>(reflectances.size()); }
    int substitutions() const { return static_cast<int>(solutions.size()); }
    bool moves() const { return geometries.size() > 1 || !is_identity(geometries[0]); }
    static bool is_identity(const std::vector<Similarity>& motion);
    int renders() const;
};

// `iterative`: the solver iterates, so every new state is Iterated (nothing is factorised).
// `combine` (with `iterative`: the solve over hierarchical links) makes a new state Combined when
// its emission, in every channel, is within 1e-12 (relative, 2-norm) of the span of at most
// kMaxCombinationTerms emissions iterated before with the same reflectance, and the weights
// amplify their solutions' errors at most kMaxCombinationGain times. (A dense iterative solve
// keeps its residual target frame by frame instead: the weights would scale its residual.)
// With `combine`, the emissions left to iterate with one reflectance set are solved together,
// up to kMaxSolvedAhead at a time (fewer above about 75,000 patches, none above 524,288, so that
// the extra right-hand sides hold at most 256 MiB), by the sweeps of the first frame that needs
// one of them: the others' frames are Ahead.
Plan plan_sequence(const Sequence& sequence, const Materials& base, const SceneGeometry& geometry,
                   bool iterative = false, bool combine = false);

inline constexpr int kMaxCombinationTerms = 8;
inline constexpr double kMaxCombinationGain = 1e4;
inline constexpr int kMaxSolvedAhead = 8;
// How many emissions one run of sweeps may carry in a scene of `patches`: each holds about 512
// bytes per patch while the sweeps run (its radiosities, changes and emission side by side, and
// its values at the hierarchy's nodes, about two per patch); the extra ones within 256 MiB.
int solved_ahead_limit(int patches);

bool same_camera(const CameraDesc& a, const CameraDesc& b);

}  // namespace radiosa
