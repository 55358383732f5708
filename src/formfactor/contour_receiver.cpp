#include "formfactor/contour_receiver.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "formfactor/events.h"
#include "util/gauss_kronrod.h"

namespace radiosa {

namespace {

// The integral of n . (r x dr) / |r|^2 along the cubic Bezier curve with control points q, r its
// point less x, by adaptive Gauss-Kronrod rules: the curve keeps clear of x on this path.
ContourValue cubic_integral(const std::array<Vec3, 4>& q, const Vec3& x, const Vec3& n, double tol) {
    const Vec3 d0 = 3.0 * (q[1] - q[0]), d1 = 3.0 * (q[2] - q[1]), d2 = 3.0 * (q[3] - q[2]);
    auto f = [&](double u) {
        const double v = 1.0 - u;
        const Vec3 r =
            v * v * v * q[0] + 3.0 * u * v * v * q[1] + 3.0 * u * u * v * q[2] + u * u * u * q[3] - x;
        const Vec3 dr = v * v * d0 + 2.0 * u * v * d1 + u * u * d2;
        const double rr = glm::dot(r, r);
        return rr > 0.0 ? glm::dot(n, glm::cross(r, dr)) / rr : 0.0;
    };
    const Integral1D v = adaptive_kronrod(f, 0.0, 1.0, tol);
    return ContourValue{v.value, v.error};
}

// Where F(dx -> j) changes fast when patch i comes close to a flat receiver j: x passing under an
// edge of j (the plane through a segment along j's normal, or the round cylinder over an arc
// about it), where the inner factor changes by up to its whole value across a band as wide as
// the gap. An outer rule whose nodes all fall on one side of that band, as a region's do when
// the band runs along its edge, sees nothing of it: two coaxial disks 7e-11 of their radii
// apart gave 0.2704 for 0.2661 with an estimate of 1.5e-11. A region that comes within a
// twentieth of its size of j's plane is cut along such a line where it runs across the region
// (EventSet::cut_where). Along an edge of the region that such a line runs along, the band is
// worth at most the gap times the edge's length (the factor changes by at most 1 across it):
// where that could exceed a tenth of the pair's tolerance the region is halved toward the edge
// until it is no wider than 4 gaps, so that its nodes reach into the band (a patch of a disk
// under a sector of another whose edges lie over its own, 8e-5 of their radii apart, missed
// 1.5e-5 of its factor otherwise); below that, the band's worth is added to the estimate
// (unresolved). Elsewhere the band crosses the nodes and the estimates see it.
class EdgeBands {
public:
    EdgeBands(const Surface& si, const Surface& sj, const std::vector<ContourPiece>& pieces, double tol)
        : m_si(si), m_tol(tol) {
        const auto plane = sj.plane();
        if (!plane) return;
        m_plane = *plane;
        for (const ContourPiece& c : pieces) {
            if (c.cubic) return;  // a flat Bezier patch: none (its edges are not these)
            if (c.arc)
                m_arcs.push_back({c.center, c.radius});
            else if (const Vec3 m = glm::cross(c.b - c.a, m_plane.normal); glm::length(m) > 0.0)
                m_segments.push_back({c.a, m / glm::length(m)});
        }
    }

    Cut cut(const Rect& r) const {
        if (m_arcs.empty() && m_segments.empty()) return {};
        const Vec3 p00 = m_si.point(r.s0, r.t0), p11 = m_si.point(r.s1, r.t1);
        const double size =
            std::max(glm::length(p11 - p00), glm::length(m_si.point(r.s1, r.t0) - m_si.point(r.s0, r.t1)));
        const double gap = m_si.linear_range(m_plane.normal, r.s0, r.s1, r.t0, r.t1).first - m_plane.offset;
        if (!(gap < 0.05 * size)) return {};
        for (int k = 0; k < count(); ++k) {
            const double eps = k < static_cast<int>(m_arcs.size()) ? 1e-9 * m_arcs[k].radius : 1e-12 * size;
            auto e = [&](double s, double t) {
                const double v = distance(k, m_si.point(s, t));
                return std::abs(v) <= eps ? 0.0 : v;
            };
            if (const Cut c = EventSet::cut_where(r, e, 0.0, 1.0, 0.1); c.dir >= 0) return c;
        }
        if (gap > 0.0)
            for (int k = 0; k < count(); ++k)
                if (const Edge b = along_edge(r, k, gap); b.dir >= 0 && b.worth > 0.1 * m_tol)
                    return Cut{b.dir};
        return {};
    }

    // What the bands along the region's edges may be worth that its nodes do not reach.
    double unresolved(const Rect& r) const {
        if (m_arcs.empty() && m_segments.empty()) return 0.0;
        const auto [lo, hi] = m_si.linear_range(m_plane.normal, r.s0, r.s1, r.t0, r.t1);
        const double gap = lo - m_plane.offset;
        const double size = glm::length(m_si.point(r.s1, r.t1) - m_si.point(r.s0, r.t0));
        if (!(gap > 0.0 && gap < 0.05 * size)) return 0.0;
        // The band is as wide as the height over j, at most hi - offset over the region.
        double worth = 0.0;
        for (int k = 0; k < count(); ++k) worth += std::max(0.0, along_edge(r, k, gap).worth);
        return worth * (hi - m_plane.offset) / gap;
    }

private:
    int count() const { return static_cast<int>(m_arcs.size() + m_segments.size()); }
    // Signed distance of x from line k's surface: the cylinder over an arc, or the plane along j's
    // normal through a segment.
    double distance(int k, const Vec3& x) const {
        if (k < static_cast<int>(m_arcs.size())) {
            const Vec3 q = x - m_arcs[k].center;
            const double along = glm::dot(q, m_plane.normal);
            return std::sqrt(std::max(0.0, glm::dot(q, q) - along * along)) - m_arcs[k].radius;
        }
        const Segment& g = m_segments[static_cast<std::size_t>(k) - m_arcs.size()];
        return glm::dot(g.normal, x - g.a);
    }
    // Line k along one of the region's edges (within the gap at both ends and the middle, the
    // region's middle farther off), the region wider than 4 gaps across it: the direction to halve
    // it in, and gap x the edge's length.
    struct Edge {
        int dir = -1;
        double worth = -1.0;
    };
    Edge along_edge(const Rect& r, int k, double gap) const {
        const double sm = 0.5 * (r.s0 + r.s1), tm = 0.5 * (r.t0 + r.t1);
        if (!(std::abs(distance(k, m_si.point(sm, tm))) > gap)) return {};
        auto on_line = [&](double s0, double t0, double s1, double t1) {
            for (double f : {0.0, 0.5, 1.0})
                if (!(std::abs(distance(k, m_si.point(s0 + f * (s1 - s0), t0 + f * (t1 - t0)))) <= gap))
                    return false;
            return true;
        };
        const double across_s = glm::length(m_si.point(r.s1, tm) - m_si.point(r.s0, tm)),
                     across_t = glm::length(m_si.point(sm, r.t1) - m_si.point(sm, r.t0));
        if (across_s > 4.0 * gap && (on_line(r.s0, r.t0, r.s0, r.t1) || on_line(r.s1, r.t0, r.s1, r.t1)))
            return {0, gap * across_t};
        if (across_t > 4.0 * gap && (on_line(r.s0, r.t0, r.s1, r.t0) || on_line(r.s0, r.t1, r.s1, r.t1)))
            return {1, gap * across_s};
        return {};
    }

    struct Arc {
        Vec3 center;
        double radius;
    };
    struct Segment {
        Vec3 a, normal;  // the plane through the segment along j's normal
    };
    const Surface& m_si;
    double m_tol;  // the pair's target, A_i F_ij
    Plane m_plane{};
    std::vector<Arc> m_arcs;
    std::vector<Segment> m_segments;
};

}  // namespace

ContourValue point_to_contour(const Vec3& x, const Vec3& n, const std::vector<ContourPiece>& pieces,
                              double tol) {
    const double eps = std::numeric_limits<double>::epsilon();
    std::size_t arcs = 0;
    for (const ContourPiece& p : pieces) arcs += p.arc || p.cubic ? 1 : 0;
    const double arc_tol = tol * 2 * kPi / static_cast<double>(std::max<std::size_t>(1, arcs));
    double sum = 0.0, err = 0.0;
    for (const ContourPiece& p : pieces) {
        if (p.cubic) {
            const ContourValue v = cubic_integral(p.q, x, n, arc_tol);
            sum += v.value;
            err += v.error;
            continue;
        }
        if (!p.arc) {
            // Along a segment r x dr = a x b du, and the integral of du / |r|^2 is the angle the
            // segment subtends over |a x b|.
            const Vec3 a = p.a - x, b = p.b - x;
            const Vec3 axb = glm::cross(a, b);
            const double len = glm::length(axb);
            if (!(len > eps * glm::dot(a, a) + eps * glm::dot(b, b))) continue;  // x on its line
            const double v = glm::dot(n, axb) / len * std::atan2(len, glm::dot(a, b));
            sum += v;
            err += 8 * eps * (std::abs(v) + 1.0);
            continue;
        }
        Circle k;
        k.c = p.center;
        k.e1 = p.e1;
        k.e2 = p.e2;
        k.n = glm::cross(p.e1, p.e2);
        k.rho = p.radius;
        if (!(k.rho > 0.0)) continue;
        const double sense = p.to >= p.from ? 1.0 : -1.0;
        const double lo = std::min(p.from, p.to), hi = std::max(p.from, p.to);
        const double nearest = k.nearest_angle(x);
        const ContourValue v = circle_arc_integral(k, x, n, nearest, lo, hi, arc_tol);
        sum += sense * v.value;
        const double gap = glm::length(k.at(nearest) - x);
        err += v.error +
               4 * eps * (glm::length(x - k.c) + k.rho) / std::max(gap, eps * k.rho) * std::abs(v.value);
    }
    ContourValue out;
    out.value = -sum / (2 * kPi);
    out.error = err / (2 * kPi);
    return out;
}

namespace {

// Convex from inside: every point of the surface sees the rest of its solid in front.
bool convex_from_inside(const Surface& s) { return s.sees_itself() && s.chords_never_cross(); }

}  // namespace

bool inside_solid(const SceneGeometry& g, const Patch& p, int k) {
    if (p.surface == k) return true;
    const auto solid = g.surface(k).convex_solid();
    if (!solid) return false;
    const Surface& s = g.surface(p.surface);
    if (solid->cylinder && solid->slope != 0.0) {
        // A cone: the patch's largest distance from the axis within the solid's radius where that
        // is smallest over the patch's heights (the radius is affine in the height).
        const auto [lo, hi] = s.linear_range(solid->axis, p.s0, p.s1, p.t0, p.t1);
        const double h0 = glm::dot(solid->center, solid->axis);
        const double narrowest = solid->radius_at(solid->slope > 0.0 ? lo - h0 : hi - h0);
        const double scale = std::max({solid->radius, std::abs(lo - h0), std::abs(hi - h0)});
        return s.max_distance_from_line(solid->center, solid->axis, p.s0, p.s1, p.t0, p.t1) <=
               narrowest + 1e-12 * scale;
    }
    const double limit = solid->radius * (1.0 + 1e-12);
    if (solid->cylinder)
        return s.max_distance_from_line(solid->center, solid->axis, p.s0, p.s1, p.t0, p.t1) <= limit;
    return s.max_distance_from_point(solid->center, p.s0, p.s1, p.t0, p.t1) <= limit;
}

std::optional<ContourReceiver> contour_receiver(const SceneGeometry& g, int i, int j,
                                                const std::vector<int>& blockers, bool visibility) {
    const Patch& pi = g.patch(i);
    const Patch& pj = g.patch(j);
    const Surface& si = g.surface(pi.surface);
    const Surface& sj = g.surface(pj.surface);
    ContourReceiver how;
    if (!sj.patch_contour(pj.s0, pj.s1, pj.t0, pj.t1, &how.pieces)) return std::nullopt;
    const double eps = 1e-12 * g.scale();
    how.contains_x = i == j;
    if (i == j && !convex_from_inside(sj)) return std::nullopt;
    // Whether every ray from polygon i meets the whole of j's surface at most once
    // (Surface::seen_once_from, a Bezier patch seen from a wall): +1 when i sees its front, -1
    // its back, 0 when not proven. Asked once, and only of a curved surface.
    std::optional<int> once;
    auto seen_once = [&] {
        if (!once) once = pi.polygon && !sj.plane() ? sj.seen_once_from(pi.corners, 0.0, 1.0, 0.0, 1.0) : 0;
        return *once;
    };
    // Every point of patch i in front of every tangent plane of the curved patch j (and j not
    // hiding part of itself): from i's bounding ball, or from each corner of a polygon i (the
    // distance to a tangent plane is affine in x). Asked once.
    std::optional<bool> faces;
    auto faces_j = [&] {
        if (!faces) {
            faces = sj.faces_ball(pj.s0, pj.s1, pj.t0, pj.t1, pi.bound, false);
            if (!*faces && pi.polygon) {
                faces = true;
                for (const Vec3& c : pi.corners)
                    faces =
                        *faces && sj.faces_ball(pj.s0, pj.s1, pj.t0, pj.t1, BoundingSphere{c, 0.0}, false);
            }
        }
        return *faces;
    };
    // Nothing in between: a segment between points inside a convex solid stays inside it; a
    // segment from x to a point of a surface x sees once meets it only there, and so does one
    // to a point on the surface's convex hull from in front of its tangent plane.
    if (visibility)
        for (const int k : blockers) {
            const bool own = k == pj.surface || (g.twin(k) >= 0 && g.twin(k) == pj.surface);
            const bool clear =
                (k == pi.surface && k == pj.surface ? g.surface(k).chords_never_cross()
                                                    : inside_solid(g, pi, k) && inside_solid(g, pj, k)) ||
                (own && k != pi.surface &&
                 (seen_once() != 0 || (sj.on_convex_hull(pj.s0, pj.s1, pj.t0, pj.t1) && faces_j())));
            if (!clear) return std::nullopt;
        }
    // All of j in front of the tangent plane of every x.
    if (const auto p = si.plane()) {
        if (sj.linear_range(p->normal, pj.s0, pj.s1, pj.t0, pj.t1).first < p->offset - eps)
            return std::nullopt;
    } else if (!(convex_from_inside(si) && inside_solid(g, pj, pi.surface))) {
        return std::nullopt;
    }
    // Every x in front of every point of j.
    if (const auto p = sj.plane()) {
        if (si.linear_range(p->normal, pi.s0, pi.s1, pi.t0, pi.t1).first < p->offset - eps)
            return std::nullopt;
    } else if (!(convex_from_inside(sj) ? inside_solid(g, pi, pj.surface) : faces_j() || seen_once() == 1)) {
        return std::nullopt;
    }
    return how;
}

Estimate area_times_f_contour(const SceneGeometry& g, int i, int j, const ContourReceiver& how, double tol,
                              const GaussRule& outer, int max_regions) {
    const Patch& pi = g.patch(i);
    const Patch& pj = g.patch(j);
    const Surface& si = g.surface(pi.surface);
    const double inner_tol = std::max(1e-15, 0.05 * tol * std::min(pi.area, pj.area) / pi.area);
    auto contour_at = [&](double s, double t, double* da) {
        Vec3 x, nrm;
        si.point_and_normal(s, t, &x, &nrm);
        *da = glm::length(nrm);
        if (!(*da > 0.0)) return ContourValue{};
        ContourValue v = point_to_contour(x, nrm / *da, how.pieces, inner_tol);
        if (how.contains_x) v.value += 1.0;
        return v;
    };
    auto gx = [&](double s, double t) {
        double da = 0.0;
        const ContourValue v = contour_at(s, t, &da);
        return da * v.value;
    };
    const Rect root{pi.s0, pi.s1, pi.t0, pi.t1};
    const double region_tol = tol * std::min(pi.area, pj.area);
    const EdgeBands bands(si, g.surface(pj.surface), how.pieces, region_tol);
    auto geometric = [&](const Rect& r, const auto&) {
        if (const Cut c = quarter_of(root, r); c.dir >= 0) return c;
        return bands.cut(r);
    };
    std::vector<Rect> leaves;
    Estimate e = adaptive_rect(gx, Rect{pi.s0, pi.s1, pi.t0, pi.t1}, 0.9 * region_tol, max_regions, outer,
                               geometric, NoSuspects{}, &leaves);
    // The inner integrals' errors, integrated over the final regions: near a touching edge x
    // comes close to an arc only over a sliver, where its rounding estimate peaks.
    auto ex = [&](double s, double t) {
        double da = 0.0;
        const ContourValue v = contour_at(s, t, &da);
        return da * v.error;
    };
    for (const Rect& r : leaves) e.error += kSafety * tensor_gauss(ex, r, outer) + bands.unresolved(r);
    return e;
}

}  // namespace radiosa
