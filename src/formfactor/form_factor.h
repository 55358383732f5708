#pragma once
// Form factors by the parametric differential method (Baranoski 1991):
//   F_ij = 1/(pi A_i) * integral over both patches' parameter rectangles of
//          (n_i . e_ij)(n_j . e_ji) / L^4  ds dt dtheta dphi,
// n the unnormalised normals dP/ds x dP/dt, e the vector joining the points, L its length,
// evaluated by a tensor Gauss-Legendre rule with p points per parameter (p^4 terms).
#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "util/dense_matrix.h"

namespace radiosa {

class SceneGeometry;

// How form factors are integrated. Reported as form_factor_method: "adaptive" | "gauss" |
// "hierarchical".
enum class FormFactorMethod {
    Fixed,     // the paper's tensor Gauss-Legendre rule, gauss_points per parameter, no estimate
    Adaptive,  // error-controlled to `tolerance` per entry, with a stored estimate (the default)
    // Links between groups of patches (formfactor/hierarchy.h) within link_tolerance; no N x N
    // matrix. Pairs of single patches are integrated as Adaptive at `tolerance`.
    Hierarchical,
};
// "gauss" | "adaptive" | "hierarchical": the report's and the scene file's names.
const char* method_name(FormFactorMethod m);

// The default absolute tolerance on each F_ij (docs/accuracy.md).
inline constexpr double kDefaultFormFactorTolerance = 1e-6;
// The hierarchical method's default tolerance on each link (docs/scale.md).
inline constexpr double kDefaultLinkTolerance = 2e-5;
// Unless a run sets it, a hierarchical run's receiver tolerance is this fraction of its link
// tolerance in scenes of up to kAutoReceiverMaxPatches patches, and off in larger ones, where
// its 1.5 to 1.8 times the time and memory would take 100,000 patches past 4 GB (docs/scale.md,
// "Receiver tolerance").
inline constexpr double kAutoReceiverFraction = 0.125;
inline constexpr int kAutoReceiverMaxPatches = 10000;

struct FormFactorOptions {
    FormFactorMethod method = FormFactorMethod::Adaptive;
    // Adaptive: every pair is refined until the error estimate of A_i F_ij = A_j F_ji is below
    // tolerance x min(A_i, A_j): an absolute tolerance on F_ij in the smaller patch's row,
    // scaled by A_small / A_large in the larger's.
    double tolerance = kDefaultFormFactorTolerance;
    // Fixed: points per parameter (p^4 terms per pair). The adaptive method starts its
    // occlusion-free pairs' base rule from it too.
    int gauss_points = 6;
    bool visibility = true;
    // Adaptive: integrate each pair in one direction only (over the smaller patch; the other
    // entry by reciprocity), about half the work of a pair. Off, both directions are
    // integrated independently wherever the patches' areas are within 4x, so that the
    // matrix's reciprocity checks them. The hierarchy's pairs of patches set it (their links
    // are reciprocal by construction, as the links above them are); their closed forms then
    // stop at the tolerance too, instead of at round-off.
    bool one_direction = false;
    // Adaptive: the numeric path's inner integral (curved receivers, general occluders) along
    // lines whose visibility changes are placed by bisection, wherever a blocker may come
    // between or the two fixed rules disagree (numeric_inner: lines); false: the two fixed rules
    // alone (numeric_inner: rules, the default).
    bool numeric_lines = false;
    // Leave out the work proven useless: pairs that cannot see each other (no quadrature) and
    // surfaces that cannot come between a pair (no occlusion tests; with none left, the closed
    // form applies). false integrates every pair against every surface: a diagnostic that
    // measures what culling saves (docs/performance.md).
    bool culling = true;

    static FormFactorOptions gauss(int p, bool visibility = true) {
        FormFactorOptions o;
        o.method = FormFactorMethod::Fixed;
        o.gauss_points = p;
        o.visibility = visibility;
        return o;
    }
    // Hierarchical: the tolerance on each link's coupling (hierarchy.h).
    double link_tolerance = kDefaultLinkTolerance;
    // Hierarchical: the tolerance on the part of a link's estimate that a receiver's misfit
    // takes (hierarchy.h, HierarchyOptions); 0: the link tolerance alone.
    double receiver_tolerance = 0.0;

    static FormFactorOptions adaptive(double tol, bool visibility = true) {
        FormFactorOptions o;
        o.tolerance = tol;
        o.visibility = visibility;
        return o;
    }
    // Pairs of patches within a tenth of the link tolerance (never looser than 1e-5).
    static FormFactorOptions hierarchical(double link_tol, bool visibility = true) {
        FormFactorOptions o = adaptive(std::min(1e-5, 0.1 * link_tol), visibility);
        o.method = FormFactorMethod::Hierarchical;
        o.link_tolerance = link_tol;
        return o;
    }
};

struct FormFactorSettings;
// The options a run uses: the command line's --ff-method, --gauss-points (fixed rule) or
// --ff-tolerance, else the scene's form_factors block, else error control at
// kDefaultFormFactorTolerance. A receiver tolerance of 0 (command line or scene) is off; none
// given is the automatic one (kAutoReceiverFraction) for scenes of up to
// kAutoReceiverMaxPatches `patches`.
FormFactorOptions resolve_form_factor_options(const FormFactorSettings& scene,
                                              std::optional<std::string> method,
                                              std::optional<double> tolerance,
                                              std::optional<int> gauss_points, std::optional<bool> visibility,
                                              std::optional<double> receiver_tolerance = std::nullopt,
                                              int patches = 0);
// "adaptive, tolerance 1e-06" or "Gauss p = 6 (1296 terms/pair)".
std::string describe(const FormFactorOptions& o);

// Bumped whenever a code change alters computed form factors, so that cached matrices from
// older builds are recomputed rather than trusted (it is part of the cache key).
inline constexpr int kFormFactorAlgorithmVersion = 24;
// The same for the hierarchy's links (formfactor/hierarchy.h), in their cache key.
inline constexpr int kHierarchyAlgorithmVersion = 19;

struct FormFactorStats {
    long long pairs = 0;             // unordered patch pairs, self pairs of concave surfaces included
    long long pairs_culled = 0;      // proven zero without quadrature (coplanar, facing away, convex self)
    long long occluder_checks = 0;   // (pair, surface) combinations considered as possible blockers
    long long occluders_culled = 0;  // ... of which proven unable to block (no per-point tests)
    long long pairs_unoccluded = 0;  // computed pairs that no surface can block: no occlusion tests at all
    long long segment_tests = 0;     // segment-occluder tests (by the bounding-sphere guard or exactly)
    // Error-controlled mode: how each computed direction of a pair was integrated.
    long long closed_form = 0;     // pairs exact to round-off: unoccluded polygons (contour integral),
                                   // two patches of the inside of one sphere (A_j / 4 pi R^2)
    long long semi_analytic = 0;   // closed-form inner integral (planar or sphere receiver), adaptive outer
    long long numeric = 0;         // adaptive quadrature of both integrals (curved receivers, occluders)
    long long by_reciprocity = 0;  // entries set from the other direction: A_i F_ij = A_j F_ji
    long long regions = 0;         // outer integration regions (refinement effort)
    long long capped = 0;          // integrals that hit the refinement limit before the tolerance
    double seconds = 0.0;          // not stored: equal inputs give byte-identical cache files
    // CPU seconds spent on the pairs, per surface: each pair's time is split equally between
    // its two patches' surfaces. Not stored either (empty for a matrix read from the cache).
    std::vector<double> seconds_by_surface;

    // Every counter with its report name, in this order: the report, the cache file and the
    // merge of per-thread counts all use this one list (a new counter is one line here and a
    // cache format version).
    template <class Self, class Visitor>
    static void for_each_counter(Self& s, Visitor&& v) {
        v("pairs", s.pairs);
        v("pairs_culled", s.pairs_culled);
        v("occluder_checks", s.occluder_checks);
        v("occluders_culled", s.occluders_culled);
        v("pairs_unoccluded", s.pairs_unoccluded);
        v("segment_tests", s.segment_tests);
        v("closed_form", s.closed_form);
        v("semi_analytic", s.semi_analytic);
        v("numeric", s.numeric);
        v("by_reciprocity", s.by_reciprocity);
        v("regions", s.regions);
        v("capped", s.capped);
    }
    template <class Visitor>
    void for_each_counter(Visitor&& v) {
        for_each_counter(*this, v);
    }
    template <class Visitor>
    void for_each_counter(Visitor&& v) const {
        for_each_counter(*this, v);
    }
    FormFactorStats& operator+=(const FormFactorStats& o);
};

struct FormFactors {
    DenseMatrix F;             // F(i, j): fraction of energy leaving i that arrives at j
    std::vector<double> area;  // exact patch areas
    // Per-entry error estimates, row-major like F; empty when the method gives none.
    std::vector<double> error;
    FormFactorOptions options;  // the method and settings it was computed with
    FormFactorStats stats;
};

// One pair's two entries, F(i, j) and F(j, i), and their estimates (zero when the method gives
// none). A self pair (i == j) has only f_ij and e_ij.
struct PairEntries {
    double f_ij = 0.0, f_ji = 0.0;
    double e_ij = 0.0, e_ji = 0.0;
};

// Called with the number of pairs just finished (from any thread): for progress displays.
using PairProgress = std::function<void(long long pairs)>;

FormFactors compute_form_factors(const SceneGeometry& geometry, const FormFactorOptions& options,
                                 const PairProgress& progress = {});

// The same computation by ranges of rows, for callers that share the rows out (the distributed
// path, src/distribute/): compute(b, e) fills, for every row i in [b, e), F(i, j) and F(j, i)
// for j >= i and their estimates, and adds its counts to `stats`. A row's entries do not
// depend on which other rows are computed, where or by how many threads, so any split of
// [0, n) gives the matrix compute_form_factors gives, bit for bit.
class FormFactorRows {
public:
    FormFactorRows(const SceneGeometry& geometry, const FormFactorOptions& options);
    ~FormFactorRows();
    int patch_count() const;
    FormFactors zeros() const;  // n x n zeros, areas, options and (error-controlled) estimates
    void compute(int begin, int end, FormFactors* ff, FormFactorStats* stats,
                 const PairProgress& progress = {}) const;
    // Only the listed pairs: pairs[i] holds the j >= i whose F(i, j), F(j, i) (and estimates)
    // are computed anew, each exactly as compute() computes it; every other entry is left as it
    // is (incremental updates, formfactor/incremental.h).
    void compute_pairs(const std::vector<std::vector<int>>& pairs, FormFactors* ff,
                       FormFactorStats* stats) const;
    // One pair, i and j in either order, exactly as compute() computes it, with no matrix:
    // the leaf links of hierarchical form factors (formfactor/hierarchy.h). Thread-safe.
    PairEntries pair(int i, int j, FormFactorStats* stats) const;

private:
    void compute_rows(int begin, int end, const std::vector<std::vector<int>>* pairs, FormFactors* ff,
                      FormFactorStats* stats, const PairProgress& progress) const;
    struct Impl;
    std::unique_ptr<Impl> m;
};

struct FormFactorChecks {
    double closure_max_error = 0.0;  // max_i |sum_j F_ij - 1|
    int closure_worst_patch = -1;
    double reciprocity_max_error = 0.0;  // max_ij |A_i F_ij - A_j F_ji| / max(A_i F_ij, A_j F_ji)
    double reciprocity_abs_error = 0.0;  // max_ij |F_ij - A_j F_ji / A_i|, on the tolerance's scale
    double min_entry = 0.0;              // most negative entry (must be 0)
    // Error-controlled matrices: the largest per-entry estimate and the largest row sum of
    // estimates (a bound for the closure error the quadrature alone can explain).
    double max_error_estimate = 0.0;
    double max_row_error_estimate = 0.0;
    // Reciprocity only over pairs whose two directions were computed independently, relative
    // to their combined estimates: max |A_i F_ij - A_j F_ji| / (A_i e_ij + A_j e_ji).
    double reciprocity_vs_estimate = 0.0;
    // Error-controlled matrices: entries whose estimate exceeds their target (tolerance x
    // min(A_i, A_j) / A_i, see FormFactorOptions::tolerance), and the worst of them by
    // estimate / target (-1: none).
    long long entries_over_tolerance = 0;
    double worst_miss_estimate = 0.0;
    double worst_miss_ratio = 0.0;
    int worst_miss_i = -1, worst_miss_j = -1;
};

FormFactorChecks check_form_factors(const FormFactors& ff);

}  // namespace radiosa
