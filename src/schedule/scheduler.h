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

// Iterated: an iterative solver's run (--solver jacobi | gauss-seidel | southwell), warm-started
// from the last solution with the same reflectance.
enum class SolveAction { Factorised, Substituted, Iterated, Reused };
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
    int factorisations() const { return static_cast<int>(reflectances.size()); }
    int substitutions() const { return static_cast<int>(solutions.size()); }
    bool moves() const { return geometries.size() > 1 || !is_identity(geometries[0]); }
    static bool is_identity(const std::vector<Similarity>& motion);
    int renders() const;
};

// `iterative`: the solver iterates, so every new state is Iterated (nothing is factorised).
Plan plan_sequence(const Sequence& sequence, const Materials& base, const SceneGeometry& geometry,
                   bool iterative = false);

bool same_camera(const CameraDesc& a, const CameraDesc& b);

}  // namespace radiosa
