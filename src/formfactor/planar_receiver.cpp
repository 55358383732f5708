#include "formfactor/planar_receiver.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <variant>

#include "formfactor/cap_shadow.h"
#include "formfactor/column_shadow.h"
#include "formfactor/disk_shadow.h"
#include "formfactor/events.h"
#include "formfactor/point_polygon.h"
#include "formfactor/polygon_polygon.h"
#include "formfactor/tube_shadow.h"
#include "util/convex_distance.h"

namespace radiosa {

namespace {

// At most what a region of a sphere's patch sends to the polygon v (area `area_v`), in A F:
// only points y of v above x's tangent plane count, where cos(theta_x) = n_x . (y - x) / d <=
// H / d, H the greatest height of a corner of v above the tangent plane of any x of the region
// (on a sphere n_x . (y - x) = +-((x - c) . (y - c) - R^2) / R is linear in x, so
// Surface::linear_range gives H exactly), and cos(theta_y) = p / d with d >= p, p the region's
// least distance to v's plane: F(x -> v) <= H A_v / (pi p^3). Zero when no corner rises above
// any tangent plane (the region sees nothing of v); infinite when the surface is not a sphere
// or the region reaches v's plane. What does not depend on the region is set up once per pair.
class SliverBound {
public:
    SliverBound(const Surface& si, const Patch& pi, const std::array<Vec3, 4>& v, const Vec3& v_normal,
                double area_v)
        : m_si(si), m_ball(si.sphere()), m_area_v(area_v) {
        if (!m_ball) return;
        m_unit = glm::normalize(v_normal);
        m_plane = glm::dot(m_unit, v[0]);
        // Outward normals (+) or inward (-): one sign for the whole sphere.
        const double sm = 0.5 * (pi.s0 + pi.s1), tm = 0.5 * (pi.t0 + pi.t1);
        m_sigma = glm::dot(si.normal(sm, tm), si.point(sm, tm) - m_ball->center) >= 0.0 ? 1.0 : -1.0;
        for (int k = 0; k < 4; ++k) {
            m_a[k] = v[k] - m_ball->center;
            m_offset[k] = glm::dot(m_a[k], m_ball->center) + m_ball->radius * m_ball->radius;
        }
    }

    double operator()(const Rect& r) const {
        if (!m_ball) return std::numeric_limits<double>::infinity();
        const double p = m_si.linear_range(m_unit, r.s0, r.s1, r.t0, r.t1).first - m_plane;
        if (!(p > 0.0)) return std::numeric_limits<double>::infinity();
        double h = 0.0;
        for (int k = 0; k < 4; ++k) {
            const auto [lo, hi] = m_si.linear_range(m_a[k], r.s0, r.s1, r.t0, r.t1);
            h = std::max(h, (m_sigma > 0.0 ? hi - m_offset[k] : m_offset[k] - lo) / m_ball->radius);
        }
        return m_si.area(r.s0, r.s1, r.t0, r.t1) * std::min(1.0, h * m_area_v / (kPi * p * p * p));
    }

private:
    const Surface& m_si;
    std::optional<BoundingSphere> m_ball;
    double m_area_v;
    Vec3 m_unit{0.0};  // v's unit front normal
    double m_plane = 0.0;
    double m_sigma = 1.0;
    std::array<Vec3, 4> m_a{};         // corners from the centre
    std::array<double, 4> m_offset{};  // a . c + R^2: the corner on x's horizon
};

// The receiver's front normal, times twice its area.
Vec3 doubled_normal(const std::array<Vec3, 4>& v) {
    return glm::cross(v[1] - v[0], v[2] - v[0]) + glm::cross(v[2] - v[0], v[3] - v[0]);
}

// A region much larger than its distance to the receiver v may hide a near-singularity
// between its Gauss nodes (patches a hair apart): split it along the direction in which that
// distance changes most, until it is no larger than the distance. Touching patches
// (distance 0) are left to the error estimate: their integrand is bounded.
Cut split_near(const Surface& si, const Rect& r, const std::array<Vec3, 4>& v) {
    const Vec3 c00 = si.point(r.s0, r.t0), c10 = si.point(r.s1, r.t0), c01 = si.point(r.s0, r.t1),
               c11 = si.point(r.s1, r.t1);
    const double d00 = distance_to_polygon(c00, v), d10 = distance_to_polygon(c10, v),
                 d01 = distance_to_polygon(c01, v), d11 = distance_to_polygon(c11, v);
    const double dmin = std::min({d00, d10, d01, d11});
    if (!(dmin > 0.0)) return Cut{};
    const double var_s = std::abs(d10 - d00) + std::abs(d11 - d01),
                 var_t = std::abs(d01 - d00) + std::abs(d11 - d10);
    const int dir = var_t > var_s ? 1 : 0;
    const double size = dir == 0 ? std::max(glm::length(c10 - c00), glm::length(c11 - c01))
                                 : std::max(glm::length(c01 - c00), glm::length(c11 - c10));
    return Cut{size > dmin ? dir : -1};
}

// Where its shadow's outline bends as x moves (formfactor/events.h).
void add_events(EventSet* events, const std::array<Vec3, 4>& v, const ShadowOccluder& o) {
    if (const auto* b = std::get_if<BoundingSphere>(&o)) events->add_sphere(v, *b);
    if (const auto* d = std::get_if<FlatDisk>(&o)) events->add_disk(v, *d);
    if (const auto* t = std::get_if<RoundFrustum>(&o)) events->add_tube(v, *t);
    if (const auto* c = std::get_if<SphericalCap>(&o)) events->add_cap(v, *c);
}

// Whether the union of the balls' cones changes its shape across the region, where no event marks
// it: seen from the region's corners, some two cones meet from one and not from another (where two
// cones start to overlap, what they hide together bends: a 3/2-power kink in x, the lens between
// their circles), or a point where two circles cross (a corner of the union's outline) lies inside
// the polygon v from one corner and outside from another (an edge of v passes it, and the hidden
// part's slope bends). Such a region takes the 3 x 3 check. (A change between the corners and
// back, inside a small region, is not seen: the cones and the crossings move smoothly with x.)
bool union_changes_shape(const Surface& si, const Rect& r, const std::vector<BoundingSphere>& balls,
                         const std::array<Vec3, 4>& v) {
    // From each corner x: each ball's direction u and half-angle, and v's edges' planes through x
    // (a direction toward v, not away from it, lies on one side of all four).
    struct Seen {
        Vec3 u;
        double sin_a, cos_a;
    };
    struct Corner {
        std::array<Seen, kMaxShadowBalls> seen;
        std::array<Vec3, 4> m;
        Vec3 toward;
        bool inside(const Vec3& w) const {
            int pos = 0;
            for (const Vec3& me : m) pos += glm::dot(w, me) >= 0.0;
            return (pos == 4 || pos == 0) && glm::dot(w, toward) > 0.0;
        }
    };
    const std::size_t nb = std::min(balls.size(), kMaxShadowBalls);
    std::array<Corner, 4> corners;
    const std::array<Vec3, 4> xs = {si.point(r.s0, r.t0), si.point(r.s1, r.t0), si.point(r.s1, r.t1),
                                    si.point(r.s0, r.t1)};
    for (std::size_t k = 0; k < 4; ++k) {
        const Vec3& x = xs[k];
        for (std::size_t b = 0; b < nb; ++b) {
            const Vec3 d = balls[b].center - x;
            const double l = glm::length(d), sa = std::min(1.0, balls[b].radius / l);
            corners[k].seen[b] = {d / l, sa, std::sqrt(1.0 - sa * sa)};
        }
        for (std::size_t e = 0; e < 4; ++e) corners[k].m[e] = glm::cross(v[e] - x, v[(e + 1) % 4] - x);
        corners[k].toward = 0.25 * (v[0] + v[1] + v[2] + v[3]) - x;
    }
    // Balls a and b from one corner, in three bits: their cones meet, and each of the two points
    // where their circles cross lies inside v.
    const auto shape = [&](const Corner& c, std::size_t a, std::size_t b) {
        const Seen &p = c.seen[a], &q = c.seen[b];
        const double dd = glm::dot(p.u, q.u);
        int bits = dd > p.cos_a * q.cos_a - p.sin_a * q.sin_a ? 1 : 0;
        // The circles w . u_a = cos_a, w . u_b = cos_b cross at w = alpha u_a + beta u_b
        // +- gamma (u_a x u_b), where |w| = 1 leaves gamma real.
        const double det = 1.0 - dd * dd;
        if (!(det > 1e-12)) return bits;
        const double alpha = (p.cos_a - dd * q.cos_a) / det, beta = (q.cos_a - dd * p.cos_a) / det;
        const double g2 = (1.0 - alpha * alpha - beta * beta - 2.0 * alpha * beta * dd) / det;
        if (!(g2 > 0.0)) return bits;
        const Vec3 base = alpha * p.u + beta * q.u, side = std::sqrt(g2) * glm::cross(p.u, q.u);
        return bits | (c.inside(base + side) ? 2 : 0) | (c.inside(base - side) ? 4 : 0);
    };
    for (std::size_t a = 0; a < nb; ++a)
        for (std::size_t b = a + 1; b < nb; ++b) {
            const int first = shape(corners[0], a, b);
            for (std::size_t k = 1; k < 4; ++k)
                if (shape(corners[k], a, b) != first) return true;
        }
    return false;
}

// Where the semi path's cubature over patch i splits a region, and which regions take the kink
// check: the events where the inner integral over the receiver v (closed form) bends.
class SemiRefinement {
public:
    SemiRefinement(const Surface& si, const Patch& pi, const std::array<Vec3, 4>& v, double area_v,
                   const PlanarReceiver& shadow)
        : m_si(si),
          m_pi(pi),
          m_v(v),
          m_shadow(shadow),
          m_ends(!shadow.openings.empty()),
          m_sliver_bound(si, pi, v, doubled_normal(v), area_v) {
        if (!pi.polygon) {
            m_events.add_horizons(v);
            // Points of a curved patch may pass behind the receiver's plane.
            m_events.add_plane(doubled_normal(v), v[0]);
        }
        for (const BoundingSphere& ball : shadow.spheres) m_events.add_sphere(v, ball);
        m_events.add_flats(v, shadow.flats);
        if (shadow.disk) m_events.add_disk(v, *shadow.disk);
        for (const FlatDisk& rim : shadow.openings) m_events.add_disk(v, rim);
    }

    template <class Fine>
    Cut cut(const Rect& r, const Fine& fine) const {
        // A shadow's edge makes the integrand only once differentiable where it sweeps
        // across the patch; nested estimates on the whole patch can miss that, so shadowed
        // pairs start from quarters.
        if (!m_shadow.spheres.empty() || !m_shadow.flats.empty() || m_shadow.disk || m_ends) {
            if (const Cut c = quarter_of(Rect{m_pi.s0, m_pi.s1, m_pi.t0, m_pi.t1}, r); c.dir >= 0) return c;
        }
        if (const Cut c = m_events.cut_along(m_si, r); c.dir >= 0) return c;
        // Every node of the region sees nothing, yet an event crosses it: a sliver of it sees
        // the receiver past a horizon (the top of a sphere grazing a long floor). Split it
        // until its nodes find the sliver, down to 1e-6 of the patch. Not under a sphere's
        // shadow: its event crosses the shadowed regions, whose nodes all see nothing, and
        // the search split each of them to the cap (a ball's patches toward the walls past
        // the seed room's sphere: 4,096 regions a pair, 30 s instead of 3.5 s for the room,
        // entries moving by 8e-8 at tolerance 1e-6); the kink test below still refines
        // where a shadow's edge crosses.
        // On a sphere, what the sliver can be worth is bounded (SliverBound): the region
        // is then refined like any other, by its share of the error, and the search ends
        // when the bounds are small enough instead of at the cap. Nor under a disk's shadow
        // or through a tube's or a cap's open ends, for the same reason.
        if (m_shadow.spheres.empty() && !m_shadow.disk && !m_ends && !m_events.empty() && fine() == 0.0 &&
            m_events.crosses(m_si, r)) {
            const double ls = glm::length(m_si.point(r.s1, 0.5 * (r.t0 + r.t1)) -
                                          m_si.point(r.s0, 0.5 * (r.t0 + r.t1))),
                         lt = glm::length(m_si.point(0.5 * (r.s0 + r.s1), r.t1) -
                                          m_si.point(0.5 * (r.s0 + r.s1), r.t0));
            const int dir = m_events.split_toward(m_si, r, ls >= lt ? 0 : 1);
            const double bound = m_sliver_bound(r);
            if (std::isfinite(bound)) {
                const Cut near = split_near(m_si, r, m_v);
                return near.dir >= 0 ? near : Cut{dir, std::numeric_limits<double>::quiet_NaN(), bound};
            }
            if (std::max((r.s1 - r.s0) / (m_pi.s1 - m_pi.s0), (r.t1 - r.t0) / (m_pi.t1 - m_pi.t0)) > 1e-6)
                return Cut{dir};
        }
        return split_near(m_si, r, m_v);
    }

    // On a curved patch the events are x's horizon passing the receiver's corners: past one,
    // a sliver of the region sees a corner of j that its nodes do not, whatever the region's
    // value (a ball's patch beside a wall gave 7.8e-12 for 3.4e-10, estimate 3.1e-11; and
    // 3.6e-7 off with an estimate of 1.4e-7 where a kink fraction had skipped the check).
    // Every region one crosses takes the 3 x 3 check: about 15 % more time on the seed scene,
    // the same regions and values. A shadow's outline costs at most its kink fraction.
    double suspect(const Rect& r) const {
        if (m_shadow.spheres_overlap && union_changes_shape(m_si, r, m_shadow.spheres, m_v))
            return kCheckRegion;
        if (!m_events.crosses(m_si, r)) return 0.0;
        if (!m_pi.polygon) return kCheckRegion;
        return m_shadow.flats.empty() ? kSphereKinkFraction : kFlatKinkFraction;
    }

private:
    const Surface& m_si;
    const Patch& m_pi;
    const std::array<Vec3, 4>& m_v;
    const PlanarReceiver& m_shadow;
    bool m_ends;  // patch i inside a tube or a cap, seeing the receiver through its open ends
    SliverBound m_sliver_bound;
    EventSet m_events;
};

// The outer integrals of the planar-receiver path, over patch i of the geometry.
class PlanarIntegrator {
public:
    PlanarIntegrator(const SceneGeometry& g, const GaussRule& outer, int max_regions, double eps)
        : m_geo(g), m_outer(outer), m_max_regions(max_regions), m_eps(eps) {}

    // A_i F_ij with the inner integral in closed form; error estimate on the same scale. The
    // target is tol x min(A_i, A_j), not tol x A_i: the energy two patches exchange is then
    // accurate to tol times what the smaller one sends, so a big patch's entry for a tiny
    // emitter (a 1e-8 spark of radiosity 1e8) is as good as the emitter's own row.
    Estimate area_times_f_semi(int i, int j, const PlanarReceiver& shadow, double tol) const {
        if ((!shadow.spheres.empty() || !shadow.flats.empty() || shadow.disk || shadow.column ||
             !shadow.apart.empty()) &&
            m_geo.patch(i).polygon)
            return area_times_f_shadowed(i, j, shadow, tol);
        const Patch& pi = m_geo.patch(i);
        const Surface& si = m_geo.surface(pi.surface);
        const std::array<Vec3, 4> v = m_geo.front_polygon(j);
        const BoundingSphere* b = shadow.spheres.empty() ? nullptr : &shadow.spheres[0];
        auto g = [&](double s, double t) {
            Vec3 x, nrm;
            si.point_and_normal(s, t, &x, &nrm);
            const double da = glm::length(nrm);
            if (!(da > 0.0)) return 0.0;
            if (!shadow.openings.empty()) {  // from inside a tube or a cap: what each open end lets through
                double through = 0.0;
                for (const FlatDisk& rim : shadow.openings)
                    through += point_to_polygon_hidden_by_disk(x, nrm / da, v.data(), 4, rim).value;
                return da * through;
            }
            if (shadow.spheres_overlap)
                return da * std::max(0.0, point_to_polygon(x, nrm / da, v.data(), 4, nullptr) -
                                              point_to_polygon_blocked_by_balls(
                                                  x, nrm / da, v.data(), 4, shadow.spheres.data(),
                                                  static_cast<int>(shadow.spheres.size())));
            return da * (point_to_polygon(x, nrm / da, v.data(), 4, b) -
                         hidden_past_first_ball(x, nrm / da, v, shadow));
        };
        const SemiRefinement refine(si, pi, v, m_geo.patch(j).area, shadow);
        const double region_tol = tol * std::min(pi.area, m_geo.patch(j).area);
        return adaptive_rect(
            g, Rect{pi.s0, pi.s1, pi.t0, pi.t1}, region_tol, m_max_regions, m_outer,
            [&](const Rect& r, const auto& fine) { return refine.cut(r, fine); },
            [&](const Rect& r, double) { return refine.suspect(r); });
    }

    // What the occluders other than the first ball hide of the polygon v from x (the first
    // ball's cap is taken out by point_to_polygon itself): flat quads, a disk, and further balls,
    // whose shadows never overlap the first's or each other's.
    static double hidden_past_first_ball(const Vec3& x, const Vec3& n, const std::array<Vec3, 4>& v,
                                         const PlanarReceiver& shadow) {
        double hidden = shadow.flats.empty() ? 0.0 : point_to_polygon_hidden(x, n, v.data(), 4, shadow.flats);
        if (shadow.disk) hidden += point_to_polygon_hidden_by_disk(x, n, v.data(), 4, *shadow.disk).value;
        for (std::size_t k = 1; k < shadow.spheres.size(); ++k)
            hidden += point_to_polygon_blocked(x, n, v.data(), 4, shadow.spheres[k]);
        return hidden;
    }

    // What the occluders hide of the polygon vj from x (unit normal `unit`): the shadowed
    // path's integrand per unit area of patch i.
    static double hidden_at(const Vec3& x, const Vec3& unit, const std::array<Vec3, 4>& vj,
                            const PlanarReceiver& shadow) {
        if (shadow.disk) return point_to_polygon_hidden_by_disk(x, unit, vj.data(), 4, *shadow.disk).value;
        if (shadow.column) return point_to_polygon_hidden_by_column(x, unit, vj.data(), 4, *shadow.column);
        if (!shadow.apart.empty()) {  // shadows apart: their parts add up
            double hidden = 0.0;
            for (const ShadowOccluder& o : shadow.apart) hidden += hidden_by(o, x, unit, vj);
            return hidden;
        }
        if (shadow.spheres.empty()) return point_to_polygon_hidden(x, unit, vj.data(), 4, shadow.flats);
        if (shadow.spheres_overlap)
            return point_to_polygon_blocked_by_balls(x, unit, vj.data(), 4, shadow.spheres.data(),
                                                     static_cast<int>(shadow.spheres.size()));
        double blocked = 0.0;  // the balls' shadows never overlap: their parts add up
        for (const BoundingSphere& ball : shadow.spheres)
            blocked += point_to_polygon_blocked(x, unit, vj.data(), 4, ball);
        return blocked;
    }

    // A_i F_ij for two polygons with a sphere or flat quads between them: the unblocked
    // exchange in closed form (the contour integral) minus the shadow, integrated over patch i
    // with the shadow's inner integral in closed form (a cap of directions for a sphere,
    // projected polygons for quads). The shadow's integrand is free of the near-singularities of
    // patches that touch or nearly touch (those are in the closed form), so what is left to the
    // cubature is smooth except where an occluder's outline meets the polygon's edges.
    Estimate area_times_f_shadowed(int i, int j, const PlanarReceiver& shadow, double tol) const {
        const Patch& pi = m_geo.patch(i);
        const Surface& si = m_geo.surface(pi.surface);
        const std::array<Vec3, 4> vi = m_geo.front_polygon(i), vj = m_geo.front_polygon(j);
        // The unblocked exchange to a share of the pair's tolerance, not to round-off: on the
        // 20,000-patch room most of the hierarchy's time went to this contour integral's last
        // digits, which the shadow's cubature then could not match.
        const double pair_tol = tol * std::min(pi.area, m_geo.patch(j).area);
        const PolygonPair open = polygon_to_polygon(vi.data(), 4, vj.data(), 4, kOpenShare * pair_tol);
        const Vec3 unit = glm::normalize(si.normal(0.5 * (pi.s0 + pi.s1), 0.5 * (pi.t0 + pi.t1)));
        auto g = [&](double s, double t) {
            Vec3 x, nrm;
            si.point_and_normal(s, t, &x, &nrm);
            return glm::length(nrm) * hidden_at(x, unit, vj, shadow);
        };
        auto reaches = [&](const Rect& r) { return segments_may_meet(si, r, vj, shadow); };
        // A shadow's edge makes the integrand only once differentiable where it sweeps across
        // the patch: the regions it crosses are cut along it (events) or checked by the 3 x 3
        // split (the kink test below). Forcing quarters on top of that was measured: 1.7x the
        // time on the seed geometry at 344 patches (tolerance 1e-6), and no estimate's cover
        // changed (hard-scene table, validation set, analytic tests: docs/accuracy.md).
        // A region whose nodes all see no shadow although some segment from it to patch j
        // meets an occluder holds a sliver of penumbra between its nodes: split it until they
        // see it (down to 1e-6 of the patch).
        const double s_len = glm::length(si.point(pi.s1, pi.t0) - si.point(pi.s0, pi.t0)),
                     t_len = glm::length(si.point(pi.s0, pi.t1) - si.point(pi.s0, pi.t0));
        EventSet events;
        for (const BoundingSphere& ball : shadow.spheres) events.add_sphere(vj, ball);
        events.add_flats(vj, shadow.flats);
        if (shadow.disk) events.add_disk(vj, *shadow.disk);
        if (shadow.column) events.add_column(vj, *shadow.column);
        for (const ShadowOccluder& o : shadow.apart) add_events(&events, vj, o);
        auto geometric = [&](const Rect& r, const auto& fine) {
            const double ws = (r.s1 - r.s0) / (pi.s1 - pi.s0), wt = (r.t1 - r.t0) / (pi.t1 - pi.t0);
            if (const Cut c = events.cut_along(si, r); c.dir >= 0) return c;
            // No event crossing the region: whether x sees the shadow cannot change inside it.
            if (fine() != 0.0 || std::max(ws, wt) < 1e-6 || !reaches(r) || !events.crosses(si, r))
                return Cut{};
            return Cut{events.split_toward(si, r, ws * s_len >= wt * t_len ? 0 : 1)};
        };
        const double region_tol = pair_tol - open.error;
        // A disk's rim bends its outline smoothly, as a ball's does; a tube's outline has corners
        // where its rims cross (the lens of directions through both ends), a cap's where the
        // ball's silhouette crosses the rim.
        const double fraction = (shadow.spheres.empty() && !shadow.disk && shadow.apart.empty()) ||
                                        std::any_of(shadow.apart.begin(), shadow.apart.end(),
                                                    [](const ShadowOccluder& o) { return has_corners(o); })
                                    ? kFlatKinkFraction
                                    : kSphereKinkFraction;
        // A region worth less than its tolerance, with an event crossing it and segments that may
        // meet the occluder, may be the onset of a shadow whose tip its nodes barely see
        // (measured: nodes saw 3e-13 of 1.1e-9, seed scene at 1e-10), so its value says nothing
        // about its error: the 3 x 3 split looks too.
        auto suspect = [&](const Rect& r, double fine) {
            if (shadow.spheres_overlap && union_changes_shape(si, r, shadow.spheres, vj)) return kCheckRegion;
            if (!events.crosses(si, r)) return 0.0;
            if (std::abs(fine) <= region_tol && reaches(r)) return kCheckRegion;
            return fraction;
        };
        Estimate hidden = adaptive_rect(g, Rect{pi.s0, pi.s1, pi.t0, pi.t1}, region_tol, m_max_regions,
                                        m_outer, geometric, suspect);
        hidden.value = std::max(0.0, open.value - hidden.value);
        hidden.error += open.error;
        return hidden;
    }

    // Does some segment from the region to the polygon v meet an occluder? Every such segment
    // lies in the convex hull of the region's corners and v's. The region is shrunk by 1e-6 of
    // its size first: after a cut along a shadow's edge, the region on the lit side touches that
    // edge's plane and would "reach" at its boundary.
    bool segments_may_meet(const Surface& si, const Rect& full, const std::array<Vec3, 4>& v,
                           const PlanarReceiver& shadow) const {
        const double ds = 1e-6 * (full.s1 - full.s0), dt = 1e-6 * (full.t1 - full.t0);
        const Rect r{full.s0 + ds, full.s1 - ds, full.t0 + dt, full.t1 - dt};
        const std::array<Vec3, 8> hull = {si.point(r.s0, r.t0),
                                          si.point(r.s1, r.t0),
                                          si.point(r.s1, r.t1),
                                          si.point(r.s0, r.t1),
                                          v[0],
                                          v[1],
                                          v[2],
                                          v[3]};
        for (const BoundingSphere& ball : shadow.spheres) {
            const std::array<Vec3, 1> c = {ball.center};
            if (convex_distance(hull, c, ball.radius) <= ball.radius) return true;
        }
        for (const auto& q : shadow.flats)
            if (convex_distance(hull, q, m_eps) <= m_eps) return true;
        if (shadow.column && hull_meets_column(hull, *shadow.column)) return true;
        for (const ShadowOccluder& o : shadow.apart)
            if (hull_meets(hull, o)) return true;
        return shadow.disk && hull_meets_disk(hull, *shadow.disk);
    }

private:
    // The share of a shadowed pair's tolerance its unblocked exchange may use.
    static constexpr double kOpenShare = 0.125;
    const SceneGeometry& m_geo;
    const GaussRule& m_outer;
    int m_max_regions;
    double m_eps;  // lengths below this are zero at the scene's scale (Culling::eps)
};

bool same_tube(const RoundFrustum& a, const RoundFrustum& b) {
    return a.base == b.base && a.axis == b.axis && a.length == b.length && a.radius == b.radius &&
           a.top_radius == b.top_radius;
}

// The one flat disk or annulus that every blocker is (the two sides of a two-sided disk are
// one), when it lies wholly in front of patch i's plane and of the receiver's, by more than
// rounding at the scene's scale.
std::optional<FlatDisk> one_disk_between(const SceneGeometry& g, const Patch& pi, const Plane& receiver,
                                         const std::vector<int>& blockers) {
    std::optional<FlatDisk> disk;
    for (int k : blockers) {
        const auto d = g.surface(k).flat_disk();
        if (!d || k == pi.surface) return std::nullopt;
        if (disk && !(d->center == disk->center && d->radius == disk->radius &&
                      d->inner_radius == disk->inner_radius &&
                      (d->normal == disk->normal || d->normal == -disk->normal)))
            return std::nullopt;
        disk = d;
    }
    const auto source = g.surface(pi.surface).plane();
    const double margin = 1e-9 * g.scale();
    if (!disk || !source || !(disk_min_signed_distance(*disk, receiver.normal, receiver.offset) > margin) ||
        !(disk_min_signed_distance(*disk, source->normal, source->offset) > margin))
        return std::nullopt;
    return disk;
}

// The one whole round tube (cylinder or truncated cone) that every blocker is (its two sides
// are one).
std::optional<RoundFrustum> one_tube(const SceneGeometry& g, const std::vector<int>& blockers) {
    std::optional<RoundFrustum> tube;
    for (int k : blockers) {
        const auto t = g.surface(k).round_frustum();
        if (!t || (tube && !same_tube(*t, *tube))) return std::nullopt;
        tube = t;
    }
    return tube;
}

// The same, between two polygons.
std::optional<RoundFrustum> one_tube_between(const SceneGeometry& g, int i, int j,
                                             const std::vector<int>& blockers) {
    if (!g.patch(i).polygon || !g.patch(j).polygon) return std::nullopt;
    return one_tube(g, blockers);
}

// The whole round tube or cone that patch i lies inside of, when that surface (either side) is
// every blocker and both its ends lie wholly in front of the receiver's plane: from inside, i
// sees the receiver through the ends and nothing else (a segment from the inside to a point of
// either end stays in the solid).
std::optional<RoundFrustum> tube_around(const SceneGeometry& g, int i, const Plane& receiver,
                                        const std::vector<int>& blockers) {
    const Patch& pi = g.patch(i);
    const Surface& si = g.surface(pi.surface);
    const auto tube = si.round_frustum();
    const auto blocker = one_tube(g, blockers);
    if (!tube || !blocker || !same_tube(*blocker, *tube)) return std::nullopt;
    const double sm = 0.5 * (pi.s0 + pi.s1), tm = 0.5 * (pi.t0 + pi.t1);
    const Vec3 p = si.point(sm, tm), off = p - tube->base - glm::dot(p - tube->base, tube->axis) * tube->axis;
    if (!(glm::dot(si.normal(sm, tm), off) < 0.0)) return std::nullopt;  // the outside
    if (!(tube_min_signed_distance(*tube, receiver.normal, receiver.offset) > 1e-9 * g.scale()))
        return std::nullopt;
    return tube;
}

bool same_cap(const SphericalCap& a, const SphericalCap& b) {
    return a.center == b.center && a.axis == b.axis && a.radius == b.radius && a.height == b.height;
}

// The one whole spherical cap that every blocker is (its two sides are one).
std::optional<SphericalCap> one_cap(const SceneGeometry& g, const std::vector<int>& blockers) {
    std::optional<SphericalCap> cap;
    for (int k : blockers) {
        const auto c = g.surface(k).spherical_cap();
        if (!c || (cap && !same_cap(*c, *cap))) return std::nullopt;
        cap = c;
    }
    return cap;
}

// The one whole spherical cap that every blocker is, between two polygons, its solid wholly in
// front of both planes by more than rounding at the scene's scale.
std::optional<SphericalCap> one_cap_between(const SceneGeometry& g, int i, int j, const Plane& receiver,
                                            const std::vector<int>& blockers) {
    const auto cap = one_cap(g, blockers);
    if (!cap || !g.patch(i).polygon || !g.patch(j).polygon) return std::nullopt;
    const auto source = g.surface(g.patch(i).surface).plane();
    const double margin = 1e-9 * g.scale();
    if (!source || !(cap_min_signed_distance(*cap, receiver.normal, receiver.offset) > margin) ||
        !(cap_min_signed_distance(*cap, source->normal, source->offset) > margin))
        return std::nullopt;
    return cap;
}

// The whole spherical cap that patch i lies on the concave side of, when that surface (either
// side) is every blocker, its open end lies wholly in front of the receiver's plane and the
// receiver v wholly outside its solid: from inside, i sees the receiver through the open end
// and nothing else (a segment from the cap to a point outside the solid leaves it once, through
// the open end or the cap, and past the end's plane there is no cap). A receiver inside the
// solid (a plate under a dome, facing down) is seen directly, not through the end. For a tube
// the first two conditions suffice: its solid is the hull of its rims, so a plane with both
// rims in front of it misses the solid.
std::optional<SphericalCap> cap_around(const SceneGeometry& g, int i, const Plane& receiver,
                                       const std::array<Vec3, 4>& v, const std::vector<int>& blockers) {
    const Patch& pi = g.patch(i);
    const Surface& si = g.surface(pi.surface);
    const auto cap = si.spherical_cap();
    const auto blocker = one_cap(g, blockers);
    if (!cap || !blocker || !same_cap(*blocker, *cap)) return std::nullopt;
    const double sm = 0.5 * (pi.s0 + pi.s1), tm = 0.5 * (pi.t0 + pi.t1);
    if (!(glm::dot(si.normal(sm, tm), si.point(sm, tm) - cap->center) < 0.0))
        return std::nullopt;  // the outside
    if (!(disk_min_signed_distance(cap_rim(*cap), receiver.normal, receiver.offset) > 1e-9 * g.scale()) ||
        hull_meets_cap(v, *cap))
        return std::nullopt;
    return cap;
}

// Several occluders with closed-form shadows between two polygons, each wholly in front of
// both planes and none of them a side of either patch's surface, whose shadows never overlap as
// seen from patch i (occluders_apart).
std::optional<std::vector<ShadowOccluder>> apart_occluders(const SceneGeometry& g, int i, int j,
                                                           const Plane& receiver,
                                                           const std::vector<int>& blockers) {
    const Patch &pi = g.patch(i), &pj = g.patch(j);
    const auto source = g.surface(pi.surface).plane();
    if (!pi.polygon || !pj.polygon || !source || blockers.size() > kMaxApartOccluders) return std::nullopt;
    for (int k : blockers)
        if (k == pi.surface || k == pj.surface) return std::nullopt;
    auto out = occluders_apart(g, blockers, pi.bound, receiver, *source);
    if (!out || out->empty()) return std::nullopt;
    return out;
}

}  // namespace

std::optional<PlanarReceiver> planar_receiver(const SceneGeometry& g, int i, int j,
                                              const std::vector<int>& blockers, bool visibility) {
    const Patch& pj = g.patch(j);
    if (!pj.polygon) return std::nullopt;
    PlanarReceiver how;
    if (!visibility || blockers.empty()) return how;
    const Patch& pi = g.patch(i);
    if (blockers.size() <= kMaxFlatOccluders) {
        for (int k : blockers) {
            const Surface& s = g.surface(k);
            if (!s.plane() || !s.patches_are_polygons() || k == pi.surface) {
                how.flats.clear();
                break;
            }
            how.flats.push_back({s.point(0, 0), s.point(1, 0), s.point(1, 1), s.point(0, 1)});
        }
        if (!how.flats.empty()) return how;
    }
    const auto plane = g.surface(pj.surface).plane();
    if (!plane) return std::nullopt;
    if (const auto t = tube_around(g, i, *plane, blockers)) {
        const auto rims = tube_rims(*t);
        how.openings.assign(rims.begin(), rims.end());
        return how;
    }
    if (const auto c = cap_around(g, i, *plane, g.front_polygon(j), blockers)) {
        how.openings = {cap_rim(*c)};
        return how;
    }
    if (const auto d = one_disk_between(g, pi, *plane, blockers)) {
        how.disk = d;
        return how;
    }
    if (const auto t = one_tube_between(g, i, j, blockers)) {
        // Spanning the pair (column_spans_pair): the wedge, a polygon. Else wholly in front of
        // both planes, by more than rounding at the scene's scale: the tube's outline.
        const double margin = 1e-9 * g.scale();
        const auto source = g.surface(pi.surface).plane();
        if (const auto c = t->column();
            c && column_spans_pair(g.front_polygon(i), g.front_polygon(j), *c, margin)) {
            how.column = *c;
            return how;
        }
        if (source && tube_min_signed_distance(*t, plane->normal, plane->offset) > margin &&
            tube_min_signed_distance(*t, source->normal, source->offset) > margin) {
            how.apart = {*t};
            return how;
        }
    }
    if (const auto c = one_cap_between(g, i, j, *plane, blockers)) {
        how.apart = {*c};
        return how;
    }
    const auto apart = [&]() -> std::optional<PlanarReceiver> {
        auto occluders = apart_occluders(g, i, j, *plane, blockers);
        if (!occluders) return std::nullopt;
        PlanarReceiver mixed;
        mixed.apart = std::move(*occluders);
        return mixed;
    };
    if (blockers.size() > kMaxShadowBalls) return std::nullopt;
    for (int k : blockers) {
        // A solid ball: a whole sphere (a dome hides what its cap's solid does, above).
        const auto sph = g.surface(k).sphere();
        if (!sph || !g.surface(k).whole_sphere() || k == pi.surface ||
            plane->signed_distance(sph->center) < sph->radius)
            return apart();
        // Every point of patch i must lie outside the sphere: exactly for a polygon, by its
        // bounding sphere otherwise.
        if (pi.polygon ? distance_to_polygon(sph->center, g.front_polygon(i)) <= sph->radius
                       : glm::length(pi.bound.center - sph->center) <= sph->radius + pi.bound.radius)
            return std::nullopt;
        for (const BoundingSphere& other : how.spheres)
            how.spheres_overlap = how.spheres_overlap || !shadows_apart(pi.bound, other, *sph);
        how.spheres.push_back(*sph);
    }
    return how;
}

Estimate area_times_f_planar(const SceneGeometry& g, int i, int j, const PlanarReceiver& how, double tol,
                             const GaussRule& outer, int max_regions, double eps) {
    return PlanarIntegrator(g, outer, max_regions, eps).area_times_f_semi(i, j, how, tol);
}

}  // namespace radiosa
