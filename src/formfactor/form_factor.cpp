#include "formfactor/form_factor.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <span>

#include "formfactor/blocker_set.h"
#include "formfactor/contour_receiver.h"
#include "formfactor/cubature.h"
#include "formfactor/culling.h"
#include "formfactor/planar_receiver.h"
#include "formfactor/polygon_polygon.h"
#include "formfactor/sphere_receiver.h"
#include "formfactor/visible_lines.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/gauss_legendre.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {

// Adds the time between its construction and destruction (one pair's work) to
// stats->seconds_by_surface, half to each patch's surface.
class PairClock {
public:
    PairClock(const SceneGeometry& g, int i, int j, FormFactorStats* st)
        : m_si(g.patch(i).surface), m_sj(g.patch(j).surface), m_st(st) {
        if (st->seconds_by_surface.empty()) st->seconds_by_surface.assign(g.surface_count(), 0.0);
    }
    PairClock(const PairClock&) = delete;
    PairClock& operator=(const PairClock&) = delete;
    ~PairClock() {
        const double half = 0.5 * m_clock.seconds();
        m_st->seconds_by_surface[static_cast<std::size_t>(m_si)] += half;
        m_st->seconds_by_surface[static_cast<std::size_t>(m_sj)] += half;
    }

private:
    Stopwatch m_clock;
    int m_si, m_sj;
    FormFactorStats* m_st;
};

// The centroid of the points (each with its position x) and the largest distance from it.
template <class Point>
BoundingSphere bound_of(const std::vector<Point>& pts) {
    Vec3 c(0.0);
    for (const Point& p : pts) c += p.x;
    c /= static_cast<double>(std::max<std::size_t>(pts.size(), 1));
    double r2 = 0.0;
    for (const Point& p : pts) r2 = std::max(r2, glm::dot(p.x - c, p.x - c));
    return {c, std::sqrt(r2)};
}

class Integrator {
public:
    Integrator(const SceneGeometry& g, const FormFactorOptions& o) : m_geo(g), m_opt(o), m_cull(g) {
        // The fixed rule's points of every patch; the error-controlled method makes its own (it
        // uses this class for culling only); at 101,070 patches leaving them out lowered the peak
        // from 4,244 to 4,084 MB (docs/scale.md).
        if (o.method != FormFactorMethod::Fixed) return;
        const GaussRule rule = gauss_legendre(o.gauss_points);
        const GaussRule offset_rule = gauss_legendre(o.gauss_points + 1);
        m_points.resize(g.patch_count());
        m_self_points.resize(g.patch_count());
        for (int i = 0; i < g.patch_count(); ++i) {
            const Patch& p = g.patch(i);
            const Surface& surf = g.surface(p.surface);
            m_points[i] = quadrature_points(surf, p, rule);
            // A patch that sees itself is integrated against a rule with other nodes, so no
            // term pairs a point with itself (L = 0).
            if (surf.sees_itself()) m_self_points[i] = quadrature_points(surf, p, offset_rule);
        }
    }

    bool culled(int i, int j) const { return m_opt.culling && m_cull.culled(i, j); }
    double eps() const { return m_cull.eps(); }  // lengths below this are zero at the scene's scale
    void occluders(int i, int j, std::vector<int>* out, FormFactorStats* st) const {
        m_cull.occluders(i, j, m_opt.culling, out, st);
    }

    // The double integral of the symmetric kernel: G_ij = pi A_i F_ij = pi A_j F_ji.
    double integrate(const std::vector<QuadPoint>& a_pts, const std::vector<QuadPoint>& b_pts,
                     const std::vector<int>& blockers, FormFactorStats* st) const {
        // Segment ends are excluded from the occlusion test by this fraction of their length.
        constexpr double kEndEps = 1e-9;
        const BlockerSet guard(m_geo, m_opt.visibility ? blockers : std::vector<int>{});
        // The ball holding b's nodes: a blocker far from every segment from a node a to it is
        // left out of that node's tests.
        BoundingSphere ends{Vec3(0.0), 0.0};
        if (!guard.empty()) ends = bound_of(b_pts);
        double sum = 0.0;
        long long tests = 0;
        std::vector<int> near;
        for (const QuadPoint& a : a_pts) {
            if (!guard.empty()) guard.near_list(a.x, ends.center, ends.radius, &near);
            for (const QuadPoint& b : b_pts) {
                const Vec3 e = b.x - a.x;
                const double ci = glm::dot(a.nw, e);
                if (ci <= 0.0) continue;  // b is behind a's tangent plane (or on it)
                const double cj = -glm::dot(b.nw, e);
                if (cj <= 0.0) continue;
                if (!guard.empty() && guard.blocked_among(a.x, e, kEndEps, 1.0 - kEndEps, &tests, near))
                    continue;
                const double l2 = glm::dot(e, e);
                sum += ci * cj / (l2 * l2);
            }
        }
        st->segment_tests += tests;
        return sum;
    }

    // F(i, j) and F(j, i), j >= i, into entries that hold zeros (they are zeroed first).
    void pair(int i, int j, PairEntries* out, std::vector<int>& blockers, FormFactorStats* st) const {
        *out = PairEntries{};
        ++st->pairs;
        const bool self = i == j;
        if (self ? m_self_points[i].empty() : culled(i, j)) {
            if (!self) ++st->pairs_culled;
            return;
        }
        const PairClock clock(m_geo, i, j, st);  // pairs proven zero cost nothing worth timing
        occluders(i, j, &blockers, st);
        const double g = integrate(m_points[i], self ? m_self_points[i] : m_points[j], blockers, st);
        out->f_ij = g / (kPi * m_geo.patch(i).area);
        if (!self) out->f_ji = g / (kPi * m_geo.patch(j).area);
    }

private:
    const SceneGeometry& m_geo;
    const FormFactorOptions& m_opt;
    std::vector<std::vector<QuadPoint>> m_points, m_self_points;
    Culling m_cull;
};

// ---- error-controlled form factors ----

class AdaptiveIntegrator {
public:
    AdaptiveIntegrator(const SceneGeometry& g, const FormFactorOptions& o, const Integrator& base)
        : m_geo(g),
          m_opt(o),
          m_base(base),
          m_outer(gauss_legendre(4)),
          m_inner(gauss_legendre(5)),
          m_inner_fine(gauss_legendre(7)) {}

    // The planar polygon of patch j, counter-clockwise about its front normal.
    std::array<Vec3, 4> polygon(int j) const { return m_geo.front_polygon(j); }

    // A_i F_ij = A_j F_ji exactly (to round-off, with its rounding estimate), when a closed
    // form covers the pair: two polygons nothing can come between (the contour integral), or two
    // patches of the inside of one sphere with nothing in the way (every point sees every other
    // at cos_i cos_j / (pi r^2) = 1 / (4 pi R^2), so F_ij = A_j / (4 pi R^2), F_ii included).
    std::optional<Estimate> closed_form(int i, int j, const std::vector<int>& blockers) const {
        if (const auto e = nested_spheres(m_geo, i, j, blockers, m_opt.visibility)) return e;
        if (m_opt.visibility && !blockers.empty()) return std::nullopt;
        const Patch& pi = m_geo.patch(i);
        const Patch& pj = m_geo.patch(j);
        Estimate e;
        if (pi.polygon && pj.polygon && i != j) {
            const std::array<Vec3, 4> a = polygon(i), b = polygon(j);
            // Pairs integrated in one direction (the hierarchy's) need only the tolerance.
            const double abs_tol = m_opt.one_direction ? m_opt.tolerance * std::min(pi.area, pj.area) : 0.0;
            const PolygonPair p = polygon_to_polygon(a.data(), 4, b.data(), 4, abs_tol);
            e.value = p.value;
            e.error = p.error;
            return e;
        }
        const Surface& s = m_geo.surface(pi.surface);
        if (pi.surface != pj.surface || !s.sees_itself()) return std::nullopt;
        if (const auto sph = s.sphere()) {
            e.value = pi.area * pj.area / (4.0 * kPi * sph->radius * sph->radius);
            e.error = 8 * std::numeric_limits<double>::epsilon() * e.value;
            return e;
        }
        return std::nullopt;
    }

    // A node of the inner rule over patch j: its point, normal (|normal| = dA/ds dt) and weight.
    struct InnerNode {
        Vec3 x, n;
        double w;
    };
    // Appends the tensor rule's nodes over patch j in the order the inner sum takes them. The
    // same for every outer point, so computed once per pair: on a sphere every point and
    // normal costs sines and cosines, and recomputing them at each outer node took 65 % of a
    // room of balls' form factors.
    void add_inner_nodes(const Patch& pj, const Surface& sj, const GaussRule& rule,
                         std::vector<InnerNode>* nodes) const {
        const double hs = 0.5 * (pj.s1 - pj.s0), ht = 0.5 * (pj.t1 - pj.t0);
        for (std::size_t b = 0; b < rule.x.size(); ++b)
            for (std::size_t a = 0; a < rule.x.size(); ++a) {
                const double u = pj.s0 + hs * (rule.x[a] + 1.0), w = pj.t0 + ht * (rule.x[b] + 1.0);
                InnerNode& node = nodes->emplace_back();
                sj.point_and_normal(u, w, &node.x, &node.n);
                node.w = rule.w[a] * rule.w[b];
            }
    }

    // Squared distances below this are a point meeting itself at the scene's scale.
    double min_l2() const { return 1e-24 * m_geo.scale() * m_geo.scale(); }

    // F(dx -> patch j) for x with normal ni (|ni| = da) along lines (numeric_inner: lines,
    // formfactor/visible_lines.h), to about abs_tol; `near` lists the blockers that may meet a
    // segment from x to patch j (empty: none can).
    LineIntegral inner_by_lines(const Vec3& x, const Vec3& ni, double da, const Patch& pj, const Surface& sj,
                                const BlockerSet& guard, const std::vector<int>& near, double abs_tol,
                                long long* tests) const {
        const double min_l2 = this->min_l2();
        Vec3 e;  // from x to the receiver's point the kernel last took
        auto kernel = [&](double u, double w, double* k) {
            Vec3 y, nj;
            sj.point_and_normal(u, w, &y, &nj);
            e = y - x;
            const double ci = glm::dot(ni, e), cj = -glm::dot(nj, e), l2 = glm::dot(e, e);
            *k = l2 > 0.0 ? ci * cj / (kPi * da * l2 * l2) : 0.0;
            return ci > 0.0 && cj > 0.0 && l2 > min_l2;
        };
        auto blocked = [&] {
            return !near.empty() && guard.blocked_among(x, e, 1e-9, 1.0 - 1e-9, tests, near);
        };
        return integrate_by_lines(Rect{pj.s0, pj.s1, pj.t0, pj.t1}, kernel, blocked, abs_tol);
    }

    // A_i F_ij with both integrals by adaptive quadrature (any surfaces, any occluders).
    Estimate area_times_f_numeric(int i, int j, const std::vector<int>& blockers, double tol,
                                  FormFactorStats* st) const {
        const Patch& pi = m_geo.patch(i);
        const Patch& pj = m_geo.patch(j);
        const Surface& si = m_geo.surface(pi.surface);
        const Surface& sj = m_geo.surface(pj.surface);
        const BlockerSet guard(m_geo, m_opt.visibility ? blockers : std::vector<int>{});
        // The inner integral by two Gauss rules over the whole receiver: their difference
        // estimates its error. A shadow's edge inside them converges like their spacing, and a
        // sliver no node sees (along the patch's edges, where Gauss nodes never are) leaves both
        // rules agreeing on the same wrong value: numeric_inner: lines follows the edges instead.
        std::vector<InnerNode> nodes;  // the fine rule's, then the coarse rule's
        add_inner_nodes(pj, sj, m_inner_fine, &nodes);
        const std::size_t fine_count = nodes.size();
        add_inner_nodes(pj, sj, m_inner, &nodes);
        const std::span<const InnerNode> fine_nodes(nodes.data(), fine_count),
            coarse_nodes(nodes.data() + fine_count, nodes.size() - fine_count);
        const double hs = 0.5 * (pj.s1 - pj.s0), ht = 0.5 * (pj.t1 - pj.t0);
        const double min_l2 = this->min_l2();
        // The ball holding both rules' inner nodes: each outer point x asks only the blockers
        // that may come near a segment from x to it, as in integrate().
        BoundingSphere ends{Vec3(0.0), 0.0};
        if (!guard.empty()) ends = bound_of(nodes);
        double inner_err = 0.0;
        long long tests = 0;
        std::vector<int> near, near_patch;
        // Lines: a node's inner integral may be off by this much (F, over all of patch i) before
        // it spends more than the outer rule's share of the tolerance.
        const double node_budget = 0.5 * tol * std::min(pi.area, pj.area) / pi.area;
        auto g = [&](double s, double t) {
            Vec3 x, ni;
            si.point_and_normal(s, t, &x, &ni);
            const double da = glm::length(ni);
            if (!(da > 0.0)) return 0.0;
            // Lines: wherever a blocker may come between x and patch j.
            auto by_lines = [&](const std::vector<int>& near_x) {
                return inner_by_lines(x, ni, da, pj, sj, guard, near_x, 0.5 * node_budget / kSafety, &tests);
            };
            if (m_opt.numeric_lines && !guard.empty()) {
                guard.near_list(x, pj.bound.center, pj.bound.radius, &near_patch);
                if (!near_patch.empty()) {
                    const LineIntegral v = by_lines(near_patch);
                    inner_err = std::max(inner_err, kSafety * v.error);
                    return da * v.value;
                }
            }
            if (!guard.empty()) guard.near_list(x, ends.center, ends.radius, &near);
            auto rule_sum = [&](std::span<const InnerNode> rule_nodes) {
                double sum = 0.0;
                for (const InnerNode& node : rule_nodes) {
                    const Vec3 e = node.x - x;
                    const double ci = glm::dot(ni, e);
                    if (ci <= 0.0) continue;
                    const double cj = -glm::dot(node.n, e);
                    if (cj <= 0.0) continue;
                    const double l2 = glm::dot(e, e);
                    if (!(l2 > min_l2)) continue;
                    if (!guard.empty() && guard.blocked_among(x, e, 1e-9, 1.0 - 1e-9, &tests, near)) continue;
                    sum += node.w * (ci * cj / (kPi * da * l2 * l2));
                }
                return sum * hs * ht;
            };
            const double fine = rule_sum(fine_nodes), coarse = rule_sum(coarse_nodes);
            const double err = kSafety * std::abs(fine - coarse);
            // Lines, nothing in the way: where the rules disagree beyond the node's share.
            if (m_opt.numeric_lines && err > node_budget) {
                if (const LineIntegral v = by_lines({}); kSafety * v.error < err) {
                    inner_err = std::max(inner_err, kSafety * v.error);
                    return da * v.value;
                }
            }
            inner_err = std::max(inner_err, err);
            return da * fine;
        };
        Estimate e =
            adaptive_rect(g, Rect{pi.s0, pi.s1, pi.t0, pi.t1}, 0.5 * tol * std::min(pi.area, pj.area),
                          kMaxNumericRegions, m_outer, [](const Rect&, const auto&) { return -1; });
        e.error += inner_err * pi.area;
        st->segment_tests += tests;
        return e;
    }

    // F_ij (fwd) and F_ji (bwd) by `integrate(a, b)` (A_a F_ab). Both directions are integrated
    // independently (so that reciprocity checks them) only for patches of comparable size.
    // Otherwise the smaller patch is the outer domain and the larger one's entry follows by
    // reciprocity: integrating over a large patch toward a small receiver to the same
    // tol x A_small costs far more regions (the accuracy study's cube face toward a sphere of
    // 512 facets: 82 s, not 0.11 s). A self pair is one direction.
    template <class Integrate, class Set>
    void directions(int i, int j, bool fwd, bool bwd, const Integrate& integrate, const Set& set,
                    FormFactorStats* st) const {
        const double ai = m_geo.patch(i).area, aj = m_geo.patch(j).area;
        if (fwd && bwd &&
            (m_opt.one_direction || std::max(ai, aj) > kIndependentAreaRatio * std::min(ai, aj))) {
            if (ai <= aj)
                bwd = false;
            else
                fwd = false;
        }
        for (const int a : {i, j}) {
            if (!(a == i ? fwd : bwd)) continue;
            const int b = a == i ? j : i;
            const Estimate e = integrate(a, b);
            st->regions += e.regions;
            st->capped += e.capped;
            ++st->semi_analytic;
            set(a, b, e, m_geo.patch(a).area);
            if (a != b && !(a == i ? bwd : fwd)) {
                set(b, a, e, m_geo.patch(b).area);
                ++st->by_reciprocity;
            }
            if (a == b) break;
        }
    }

    // F_ab's estimate from A_a F_ab's: whatever the integral's own estimate, F_ab lies in
    // [0, min(1, A_b / A_a)] (F_ba <= 1 and reciprocity), so it is at most that far from the value.
    // A numeric integral stopped at its region cap can claim more (rows of the curved room's
    // estimates at 1e-3 summed to 22.9).
    static double capped_estimate(const Estimate& e, double area_a, double area_b) {
        const double f = e.value / area_a, ub = std::min(1.0, area_b / area_a);
        return f >= 0.0 ? std::min(e.error / area_a, std::max(f, ub - f)) : e.error / area_a;
    }

    // F(i, j) and F(j, i), j >= i, and their estimates (zeroed first).
    void pair(int i, int j, PairEntries* out, std::vector<int>& blockers, FormFactorStats* st) const {
        *out = PairEntries{};
        const double tol = m_opt.tolerance;
        ++st->pairs;
        const bool self = i == j;
        const double ai = m_geo.patch(i).area, aj = m_geo.patch(j).area;
        if (self ? !m_geo.surface(m_geo.patch(i).surface).sees_itself() : m_base.culled(i, j)) {
            if (!self) ++st->pairs_culled;
            return;
        }
        const PairClock clock(m_geo, i, j, st);  // pairs proven zero cost nothing worth timing
        m_base.occluders(i, j, &blockers, st);
        // Entry (a, b): (i, j) when a is i (a self pair included), else (j, i).
        auto set = [&](int a, int b, const Estimate& e, double area_a) {
            const bool forward = a == i;
            (forward ? out->f_ij : out->f_ji) = e.value / area_a;
            (forward ? out->e_ij : out->e_ji) = capped_estimate(e, area_a, m_geo.patch(b).area);
        };
        if (const std::optional<Estimate> e = closed_form(i, j, blockers)) {
            ++st->closed_form;
            set(i, j, *e, ai);
            if (!self) set(j, i, *e, aj);
            return;
        }
        const auto pf =
            self ? std::optional<PlanarReceiver>{} : planar_receiver(m_geo, i, j, blockers, m_opt.visibility);
        const auto pb =
            self ? std::optional<PlanarReceiver>{} : planar_receiver(m_geo, j, i, blockers, m_opt.visibility);
        if (pf || pb) {
            directions(
                i, j, pf.has_value(), pb.has_value(),
                [&](int a, int b) {
                    return area_times_f_planar(m_geo, a, b, a == i ? *pf : *pb, tol, m_outer,
                                               kMaxOuterRegions, m_base.eps());
                },
                set, st);
            return;
        }
        // A sphere receiver with nothing in the way that the cuts of its contour do not
        // account for (nested spheres).
        const auto sf = sphere_receiver(m_geo, i, j, blockers, m_opt.visibility);
        const auto sb =
            self ? std::optional<SphereReceiver>{} : sphere_receiver(m_geo, j, i, blockers, m_opt.visibility);
        if (sf || sb) {
            directions(
                i, j, sf.has_value(), sb.has_value(),
                [&](int a, int b) {
                    return area_times_f_sphere(m_geo, a, b, a == i ? *sf : *sb, tol, m_outer,
                                               kMaxOuterRegions);
                },
                set, st);
            return;
        }
        // A receiver bounded by segments and arcs (disks, cylinders) that all of the other
        // patch sees whole.
        const auto cf = contour_receiver(m_geo, i, j, blockers, m_opt.visibility);
        const auto cb = self ? std::optional<ContourReceiver>{}
                             : contour_receiver(m_geo, j, i, blockers, m_opt.visibility);
        if (cf || cb) {
            directions(
                i, j, cf.has_value(), cb.has_value(),
                [&](int a, int b) {
                    return area_times_f_contour(m_geo, a, b, a == i ? *cf : *cb, tol, m_outer,
                                                kMaxOuterRegions);
                },
                set, st);
            return;
        }
        // Neither direction has a planar receiver free of general occluders: one symmetric
        // numeric integral gives both entries.
        const Estimate e = area_times_f_numeric(i, j, blockers, tol, st);
        st->regions += e.regions;
        st->capped += e.capped;
        ++st->numeric;
        set(i, j, e, ai);
        if (!self) set(j, i, e, aj);
    }

private:
    static constexpr int kMaxOuterRegions = 4096;
    static constexpr double kIndependentAreaRatio = 4.0;
    static constexpr int kMaxNumericRegions = 64;
    const SceneGeometry& m_geo;
    const FormFactorOptions& m_opt;
    const Integrator& m_base;
    GaussRule m_outer, m_inner, m_inner_fine;
};

}  // namespace

struct FormFactorRows::Impl {
    Impl(const SceneGeometry& g, const FormFactorOptions& o)
        : geometry(g), options(o), integrator(g, options), adaptive(g, options, integrator) {}
    const SceneGeometry& geometry;
    FormFactorOptions options;
    Integrator integrator;
    AdaptiveIntegrator adaptive;
};

FormFactorRows::FormFactorRows(const SceneGeometry& geometry, const FormFactorOptions& options)
    : m(std::make_unique<Impl>(geometry, options)) {}
FormFactorRows::~FormFactorRows() = default;

int FormFactorRows::patch_count() const { return m->geometry.patch_count(); }

FormFactors FormFactorRows::zeros() const {
    const int n = patch_count();
    FormFactors ff;
    ff.F = DenseMatrix(n);
    ff.options = m->options;
    for (const Patch& p : m->geometry.patches()) ff.area.push_back(p.area);
    if (m->options.method != FormFactorMethod::Fixed) ff.error.assign(static_cast<std::size_t>(n) * n, 0.0);
    return ff;
}

void FormFactorRows::compute(int begin, int end, FormFactors* ff, FormFactorStats* stats,
                             const PairProgress& progress) const {
    compute_rows(begin, end, nullptr, ff, stats, progress);
}

void FormFactorRows::compute_pairs(const std::vector<std::vector<int>>& pairs, FormFactors* ff,
                                   FormFactorStats* stats) const {
    compute_rows(0, patch_count(), &pairs, ff, stats, {});
}

PairEntries FormFactorRows::pair(int i, int j, FormFactorStats* stats) const {
    if (j < i) {
        PairEntries e = pair(j, i, stats);
        std::swap(e.f_ij, e.f_ji);
        std::swap(e.e_ij, e.e_ji);
        return e;
    }
    PairEntries e;
    std::vector<int> blockers;
    if (m->options.method != FormFactorMethod::Fixed)
        m->adaptive.pair(i, j, &e, blockers, stats);
    else
        m->integrator.pair(i, j, &e, blockers, stats);
    return e;
}

void FormFactorRows::compute_rows(int begin, int end, const std::vector<std::vector<int>>* pairs,
                                  FormFactors* ff, FormFactorStats* stats,
                                  const PairProgress& progress) const {
    const bool controlled = m->options.method != FormFactorMethod::Fixed;
    const int n = patch_count();
    std::mutex merge;
    // Each task owns whole rows i and writes only F(i, j) and F(j, i) for j >= i, so no two
    // tasks write the same entry; results do not depend on the thread count.
    tbb::parallel_for(tbb::blocked_range<int>(begin, end, 1), [&](const tbb::blocked_range<int>& r) {
        FormFactorStats local;
        std::vector<int> blockers;
        const auto nn = static_cast<std::size_t>(n);
        auto one = [&](int i, int j) {
            PairEntries e;
            if (controlled)
                m->adaptive.pair(i, j, &e, blockers, &local);
            else
                m->integrator.pair(i, j, &e, blockers, &local);
            // A self pair (i == j) has one entry, f_ij: written last.
            ff->F(j, i) = e.f_ji;
            ff->F(i, j) = e.f_ij;
            if (controlled) {
                ff->error[static_cast<std::size_t>(j) * nn + static_cast<std::size_t>(i)] = e.e_ji;
                ff->error[static_cast<std::size_t>(i) * nn + static_cast<std::size_t>(j)] = e.e_ij;
            }
        };
        for (int i = r.begin(); i != r.end(); ++i) {
            if (pairs) {
                for (const int j : (*pairs)[static_cast<std::size_t>(i)]) one(i, j);
                continue;
            }
            for (int j = i; j < n; ++j) one(i, j);
            if (progress) progress(n - i);
        }
        std::lock_guard lock(merge);
        *stats += local;
    });
}

FormFactors compute_form_factors(const SceneGeometry& geometry, const FormFactorOptions& options,
                                 const PairProgress& progress) {
    const Stopwatch clock;
    const FormFactorRows rows(geometry, options);
    FormFactors ff = rows.zeros();
    rows.compute(0, rows.patch_count(), &ff, &ff.stats, progress);
    ff.stats.seconds = clock.seconds();
    return ff;
}

FormFactorStats& FormFactorStats::operator+=(const FormFactorStats& o) {
    // Both visits walk the same list in the same order: pair them up through a flat array.
    std::vector<long long> add;
    o.for_each_counter([&](const char*, long long v) { add.push_back(v); });
    std::size_t k = 0;
    for_each_counter([&](const char*, long long& v) { v += add[k++]; });
    seconds += o.seconds;
    if (seconds_by_surface.size() < o.seconds_by_surface.size())
        seconds_by_surface.resize(o.seconds_by_surface.size(), 0.0);
    for (std::size_t k = 0; k < o.seconds_by_surface.size(); ++k)
        seconds_by_surface[k] += o.seconds_by_surface[k];
    return *this;
}

}  // namespace radiosa
