#include "formfactor/form_factor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "geometry/scene_geometry.h"
#include "util/gauss_legendre.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {

// A quadrature point of a patch: its position and its normal scaled by the weight and by
// the Jacobian of the map from [-1,1]^2 to the patch's parameter rectangle, so that
// sum over points of f(x) |nw| approximates the integral of f over the patch area.
struct QuadPoint {
    Vec3 x;
    Vec3 nw;
};

std::vector<QuadPoint> quadrature_points(const Surface& surf, const Patch& p, const GaussRule& rule) {
    const int n = static_cast<int>(rule.x.size());
    const double hs = 0.5 * (p.s1 - p.s0), ht = 0.5 * (p.t1 - p.t0);
    std::vector<QuadPoint> pts;
    pts.reserve(static_cast<size_t>(n) * n);
    for (int b = 0; b < n; ++b)
        for (int a = 0; a < n; ++a) {
            const double s = p.s0 + hs * (rule.x[a] + 1.0);
            const double t = p.t0 + ht * (rule.x[b] + 1.0);
            pts.push_back({surf.point(s, t), surf.normal(s, t) * (rule.w[a] * rule.w[b] * hs * ht)});
        }
    return pts;
}

// Signed distance range of a patch from a plane.
std::pair<double, double> extent(const Patch& p, const Plane& plane) {
    if (p.planar) {
        double lo = plane.signed_distance(p.corners[0]), hi = lo;
        for (int k = 1; k < 4; ++k) {
            const double d = plane.signed_distance(p.corners[k]);
            lo = std::min(lo, d);
            hi = std::max(hi, d);
        }
        return {lo, hi};
    }
    const double d = plane.signed_distance(p.bound.center);
    return {d - p.bound.radius, d + p.bound.radius};
}

double distance_to_segment(const Vec3& x, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(x - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(x - (a + t * ab));
}

class Integrator {
public:
    Integrator(const SceneGeometry& g, const FormFactorOptions& o) : m_geo(g), m_opt(o) {
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
        m_eps = 1e-12 * g.scale();
    }

    // True when no energy can pass between the two patches: either one lies entirely
    // behind or in the plane of the other (this covers patches of one planar surface), or
    // both are patches of one surface that cannot see itself.
    bool culled(int i, int j) const {
        const Patch& pi = m_geo.patch(i);
        const Patch& pj = m_geo.patch(j);
        if (pi.surface == pj.surface && !m_geo.surface(pi.surface).sees_itself()) return true;
        if (auto pl = m_geo.surface(pi.surface).plane(); pl && extent(pj, *pl).second <= m_eps) return true;
        if (auto pl = m_geo.surface(pj.surface).plane(); pl && extent(pi, *pl).second <= m_eps) return true;
        return false;
    }

    // Surfaces that might block a segment between the two patches; the rest are proven
    // unable to and skip the per-point tests.
    void occluders(int i, int j, std::vector<int>* out, FormFactorStats* st) const {
        out->clear();
        const Patch& pi = m_geo.patch(i);
        const Patch& pj = m_geo.patch(j);
        const double reach = std::max(pi.bound.radius, pj.bound.radius);
        for (int k = 0; k < m_geo.surface_count(); ++k) {
            const Surface& s = m_geo.surface(k);
            ++st->occluder_checks;
            const bool on_i = pi.surface == k, on_j = pj.surface == k;
            bool can_block = true;
            if (on_i && on_j) can_block = !s.chords_never_cross();
            else if (on_i || on_j) can_block = !s.front_segments_escape();
            if (can_block)
                if (auto pl = s.plane()) {
                    // A segment between points on one closed side of a plane cannot cross it.
                    const auto ei = extent(pi, *pl), ej = extent(pj, *pl);
                    if ((ei.first >= -m_eps && ej.first >= -m_eps) || (ei.second <= m_eps && ej.second <= m_eps))
                        can_block = false;
                }
            if (can_block) {
                // Every point of a segment between the patches lies within `reach` of the
                // segment between their bounding centres.
                const BoundingSphere& b = m_geo.surface_bound(k);
                if (distance_to_segment(b.center, pi.bound.center, pj.bound.center) > b.radius + reach)
                    can_block = false;
            }
            if (can_block) out->push_back(k);
            else ++st->occluders_culled;
        }
    }

    // The double integral of the symmetric kernel: G_ij = pi A_i F_ij = pi A_j F_ji.
    double integrate(const std::vector<QuadPoint>& a_pts, const std::vector<QuadPoint>& b_pts,
                     const std::vector<int>& blockers, FormFactorStats* st) const {
        // Segment ends are excluded from the occlusion test by this fraction of their length.
        constexpr double kEndEps = 1e-9;
        double sum = 0.0;
        long long tests = 0;
        for (const QuadPoint& a : a_pts)
            for (const QuadPoint& b : b_pts) {
                const Vec3 e = b.x - a.x;
                const double ci = glm::dot(a.nw, e);
                if (ci <= 0.0) continue;  // b is behind a's tangent plane (or on it)
                const double cj = -glm::dot(b.nw, e);
                if (cj <= 0.0) continue;
                if (m_opt.visibility && !blockers.empty()) {
                    const Ray seg{a.x, e};
                    bool blocked = false;
                    for (int k : blockers) {
                        ++tests;
                        if (m_geo.surface(k).intersect(seg, kEndEps, 1.0 - kEndEps, HitSide::Any)) {
                            blocked = true;
                            break;
                        }
                    }
                    if (blocked) continue;
                }
                const double l2 = glm::dot(e, e);
                sum += ci * cj / (l2 * l2);
            }
        st->segment_tests += tests;
        return sum;
    }

    void row(int i, DenseMatrix* F, FormFactorStats* st) const {
        std::vector<int> blockers;
        const int n = m_geo.patch_count();
        const double ai = m_geo.patch(i).area;
        for (int j = i; j < n; ++j) {
            ++st->pairs;
            const bool self = i == j;
            if (self ? m_self_points[i].empty() : culled(i, j)) {
                if (!self) ++st->pairs_culled;
                continue;
            }
            occluders(i, j, &blockers, st);
            const double g = integrate(m_points[i], self ? m_self_points[i] : m_points[j], blockers, st);
            (*F)(i, j) = g / (kPi * ai);
            if (!self) (*F)(j, i) = g / (kPi * m_geo.patch(j).area);
        }
    }

private:
    const SceneGeometry& m_geo;
    const FormFactorOptions& m_opt;
    std::vector<std::vector<QuadPoint>> m_points, m_self_points;
    double m_eps = 0.0;
};

}  // namespace

FormFactors compute_form_factors(const SceneGeometry& geometry, const FormFactorOptions& options) {
    const Stopwatch clock;
    const int n = geometry.patch_count();
    FormFactors ff;
    ff.F = DenseMatrix(n);
    ff.gauss_points = options.gauss_points;
    for (const Patch& p : geometry.patches()) ff.area.push_back(p.area);

    const Integrator integrator(geometry, options);
    std::atomic<long long> pairs{0}, culled{0}, checks{0}, checks_culled{0}, tests{0};
    // Each task owns whole rows i and writes only F(i, j) and F(j, i) for j >= i, so no two
    // tasks write the same entry; results do not depend on the thread count.
    tbb::parallel_for(tbb::blocked_range<int>(0, n, 1), [&](const tbb::blocked_range<int>& r) {
        FormFactorStats local;
        for (int i = r.begin(); i != r.end(); ++i) integrator.row(i, &ff.F, &local);
        pairs += local.pairs;
        culled += local.pairs_culled;
        checks += local.occluder_checks;
        checks_culled += local.occluders_culled;
        tests += local.segment_tests;
    });
    ff.stats.pairs = pairs;
    ff.stats.pairs_culled = culled;
    ff.stats.occluder_checks = checks;
    ff.stats.occluders_culled = checks_culled;
    ff.stats.segment_tests = tests;
    ff.stats.seconds = clock.seconds();
    return ff;
}

FormFactorChecks check_form_factors(const FormFactors& ff) {
    FormFactorChecks c;
    const int n = ff.F.n;
    for (int i = 0; i < n; ++i) {
        double row = 0.0;
        for (int j = 0; j < n; ++j) {
            row += ff.F(i, j);
            c.min_entry = std::min(c.min_entry, ff.F(i, j));
            if (j > i) {
                const double a = ff.area[i] * ff.F(i, j), b = ff.area[j] * ff.F(j, i);
                const double m = std::max(std::abs(a), std::abs(b));
                if (m > 0.0) c.reciprocity_max_error = std::max(c.reciprocity_max_error, std::abs(a - b) / m);
            }
        }
        const double err = std::abs(row - 1.0);
        if (c.closure_worst_patch < 0 || err > c.closure_max_error) {
            c.closure_max_error = err;
            c.closure_worst_patch = i;
        }
    }
    return c;
}

}  // namespace radiosa
