#pragma once
// The scheduler: for every frame of a sequence, what must be computed and what an earlier
// frame already has. Geometry never changes within a sequence, so the form-factor matrix is
// obtained once (from the cache or by computing it); a factorisation of (I - diag(rho) F) is
// made once per distinct reflectance set; a substitution once per distinct (reflectance,
// emission) — or, with an iterative solver, one warm-started iteration per distinct state; a
// render whenever the camera or the radiosities differ from the previous frame, otherwise the
// previous frame is copied.
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
    int reflectance_set = 0;  // index into Plan::reflectances (one factorisation each)
    int solution = 0;         // index into Plan::solutions
    SolveAction solve = SolveAction::Factorised;
    RenderAction render = RenderAction::Rendered;
};

struct Plan {
    std::vector<FramePlan> frames;
    std::vector<std::vector<Rgb>> reflectances;  // distinct reflectance sets, in order of first use
    std::vector<Materials> solutions;            // distinct (reflectance, emission), in order of first use
    int factorisations() const { return static_cast<int>(reflectances.size()); }
    int substitutions() const { return static_cast<int>(solutions.size()); }
    int renders() const;
};

// `iterative`: the solver iterates, so every new state is Iterated (nothing is factorised).
Plan plan_sequence(const Sequence& sequence, const Materials& base, const SceneGeometry& geometry,
                   bool iterative = false);

bool same_camera(const CameraDesc& a, const CameraDesc& b);

}  // namespace radiosa
