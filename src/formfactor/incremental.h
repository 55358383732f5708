#pragma once
// Incremental form factors: the matrix of a scene in which some surfaces moved, from the matrix
// before the move, recomputing exactly the pairs a move can change (docs/sequences.md, "Moving
// surfaces"). The result equals, bit for bit, the matrix compute_form_factors gives for the new
// geometry.
#include <string>

#include "formfactor/form_factor.h"

namespace radiosa {

class SceneGeometry;

struct FormFactorUpdate {
    int surfaces_moved = 0;            // surfaces whose placement differs (a two-sided one counts twice)
    long long entries_total = 0;       // N^2
    long long entries_recomputed = 0;  // entries F(i, j) evaluated anew (both directions of a pair)
    // Unordered patch pairs (self pairs included) by why they were or were not recomputed:
    long long pairs_moved = 0;      // a patch on a moved surface
    long long pairs_shadowed = 0;   // a moved surface may come between them, where it was or where it is
    long long pairs_unchanged = 0;  // proven unchanged (no moved surface can come between them): reused
    bool full = false;              // recomputed from scratch (reason says why)
    std::string reason;
    double select_s = 0.0;   // deciding which pairs to recompute
    double compute_s = 0.0;  // recomputing them
    double seconds = 0.0;    // the whole update (also copying the matrix)
    FormFactorStats stats;   // of the recomputed pairs
};

// `from` was computed for `from_geometry` with `options`; `to_geometry` has the same surfaces
// and patches, some of them placed differently. A pair of patches on unmoved surfaces keeps its
// entries when, for every moved surface, the culling tests (formfactor/culling.h) prove that
// surface unable to come between them both before and after the move: its list of possible
// blockers, and so every step of its computation, is then the same. Everything else is
// recomputed. When the scene's extent changes (its tolerances scale with it) or culling is off,
// every pair is.
FormFactors update_form_factors(const SceneGeometry& from_geometry, const FormFactors& from,
                                const SceneGeometry& to_geometry, const FormFactorOptions& options,
                                FormFactorUpdate* update);
// The same, updating `from` in place when the caller has no further use for it (a sequence's
// previous state after its last frame): no copy of the N^2 entries.
FormFactors update_form_factors(const SceneGeometry& from_geometry, FormFactors&& from,
                                const SceneGeometry& to_geometry, const FormFactorOptions& options,
                                FormFactorUpdate* update);

}  // namespace radiosa
