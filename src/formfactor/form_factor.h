#pragma once
// Form factors by the parametric differential method (Baranoski 1991):
//   F_ij = 1/(pi A_i) * integral over both patches' parameter rectangles of
//          (n_i . e_ij)(n_j . e_ji) / L^4  ds dt dtheta dphi,
// n the unnormalised normals dP/ds x dP/dt, e the vector joining the points, L its length,
// evaluated by a tensor Gauss-Legendre rule with p points per parameter (p^4 terms).
#include <vector>

#include "util/dense_matrix.h"

namespace radiosa {

class SceneGeometry;

struct FormFactorOptions {
    int gauss_points = 6;
    bool visibility = true;
};

// Bumped whenever a code change alters computed form factors, so that cached matrices from
// older builds are recomputed rather than trusted (it is part of the cache key).
inline constexpr int kFormFactorAlgorithmVersion = 1;

struct FormFactorStats {
    long long pairs = 0;             // unordered patch pairs, self pairs of concave surfaces included
    long long pairs_culled = 0;      // proven zero without quadrature (coplanar, facing away, convex self)
    long long occluder_checks = 0;   // (pair, surface) combinations considered as possible blockers
    long long occluders_culled = 0;  // ... of which proven unable to block (no per-point tests)
    long long segment_tests = 0;     // exact segment-surface intersection tests performed
    double seconds = 0.0;
};

struct FormFactors {
    DenseMatrix F;              // F(i, j): fraction of energy leaving i that arrives at j
    std::vector<double> area;   // exact patch areas
    // Per-entry error estimates, row-major like F; empty when the method gives none.
    std::vector<double> error;
    int gauss_points = 0;
    FormFactorStats stats;
};

FormFactors compute_form_factors(const SceneGeometry& geometry, const FormFactorOptions& options);

struct FormFactorChecks {
    double closure_max_error = 0.0;      // max_i |sum_j F_ij - 1|
    int closure_worst_patch = -1;
    double reciprocity_max_error = 0.0;  // max_ij |A_i F_ij - A_j F_ji| / max(A_i F_ij, A_j F_ji)
    double min_entry = 0.0;              // most negative entry (must be 0)
};

FormFactorChecks check_form_factors(const FormFactors& ff);

}  // namespace radiosa
