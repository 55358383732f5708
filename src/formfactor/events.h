#pragma once
// Visibility and horizon events: where the inner form factor toward a polygon, as a function of
// the outer point, stops being smooth (formfactor/form_factor.cpp checks regions they cross).
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "formfactor/cubature.h"
#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

// The largest share of a region's value that a kink inside it can cost (cubature.h's `suspect`). A
// sphere's outline meeting an edge, or an arc of what a point sees on a sphere passing a
// corner, bends the integrand smoothly (the largest such error measured on the seed scene was
// 1.6e-5 of the region's value, a quarter patch of the floor against a wall patch at tolerance
// 1e-9); a flat occluder's edge meeting a corner breaks its slope, so its share is the whole
// value.
inline constexpr double kSphereKinkFraction = 1e-4;
inline constexpr double kFlatKinkFraction = 1.0;

// Where, as a function of the outer point x, the inner form factor toward a polygon stops being
// smooth: x's horizon passing a vertex of the polygon (curved outer patches), and a blocking
// sphere's outline touching an edge's great circle (x on a plane through the edge tangent to
// the sphere) or passing a vertex (x on the cone from the vertex tangent to the sphere). Each is
// the zero set of a signed function; a region whose sample points see different signs holds one.
class EventSet {
public:
    void add_horizons(const std::array<Vec3, 4>& v) {
        for (const Vec3& p : v) m_horizons.push_back(p);
    }
    void add_sphere(const std::array<Vec3, 4>& v, const BoundingSphere& b) {
        for (int k = 0; k < 4; ++k) {
            const Vec3 &p = v[k], &q = v[(k + 1) % 4];
            const Vec3 u = glm::normalize(q - p);
            const Vec3 w = (b.center - p) - glm::dot(b.center - p, u) * u;
            const double d = glm::length(w);
            if (d > b.radius) {
                const double alpha = b.radius / d, beta = std::sqrt(1.0 - alpha * alpha);
                const Vec3 wh = w / d, m = glm::cross(u, wh);
                m_planes.push_back({alpha * wh + beta * m, p});
                m_planes.push_back({alpha * wh - beta * m, p});
            }
            const Vec3 to_c = b.center - p;
            const double l2 = glm::dot(to_c, to_c);
            if (l2 > b.radius * b.radius)
                m_cones.push_back({p, to_c / std::sqrt(l2), 1.0 - b.radius * b.radius / l2});
        }
    }
    // Flat occluders: x on a plane through an edge of one polygon and a vertex of another (the
    // target or another occluder), where a shadow's edge meets a corner.
    void add_flats(const std::array<Vec3, 4>& v, const std::vector<std::array<Vec3, 4>>& occ) {
        auto edges_vertices = [&](const std::array<Vec3, 4>& a, const std::array<Vec3, 4>& b) {
            for (int k = 0; k < 4; ++k)
                for (const Vec3& w : b) {
                    const Vec3 nrm = glm::cross(a[(k + 1) % 4] - a[k], w - a[k]);
                    if (glm::length(nrm) > 0.0) m_planes.push_back({nrm, a[k]});
                }
        };
        for (std::size_t k = 0; k < occ.size(); ++k) {
            edges_vertices(occ[k], v);
            edges_vertices(v, occ[k]);
            for (std::size_t l = 0; l < occ.size(); ++l)
                if (l != k) edges_vertices(occ[k], occ[l]);
        }
    }
    // The receiver's own plane (x passing behind it). `n` need not be unit.
    void add_plane(const Vec3& n, const Vec3& p) { m_planes.push_back({n, p}); }
    bool empty() const { return m_horizons.empty() && m_planes.empty() && m_cones.empty(); }

    // Does an event cross the region? Planes, and the horizons of a sphere (x's tangent plane
    // passes v where (x - c) . (v - c) = R^2: a plane too), exactly, from the range of a . x
    // over the region (Surface::linear_range: a feature between sample points cannot hide);
    // cones exactly on polygon patches (cone_meets_polygon); cones on curved patches and the
    // horizons of other curved surfaces from the signs at a 3 x 3 grid of points.
    bool crosses(const Surface& si, const Rect& r) const {
        if (empty()) return false;
        auto straddles = [&](const Vec3& a, double offset) {
            const auto [lo, hi] = si.linear_range(a, r.s0, r.s1, r.t0, r.t1);
            return lo < offset && offset < hi;
        };
        for (const auto& [nrm, p] : m_planes)
            if (straddles(nrm, glm::dot(nrm, p))) return true;
        const std::optional<BoundingSphere> ball = si.sphere();
        if (ball)
            for (const Vec3& v : m_horizons) {
                const Vec3 a = v - ball->center;
                if (straddles(a, glm::dot(a, ball->center) + ball->radius * ball->radius)) return true;
            }
        // On a polygon patch a region is a convex polygon, and cones are tested exactly.
        const bool flat = si.plane() && si.patches_are_polygons();
        if (flat) {
            const std::array<Vec3, 4> q = {si.point(r.s0, r.t0), si.point(r.s1, r.t0), si.point(r.s1, r.t1),
                                           si.point(r.s0, r.t1)};
            for (const Cone& c : m_cones)
                if (cone_meets_polygon(c, q)) return true;
        }
        const std::size_t cones = flat ? 0 : m_cones.size();
        const std::size_t n = (ball ? 0 : m_horizons.size()) + cones;
        if (n == 0) return false;
        std::vector<signed char> sign(n, 0), mixed(n, 0);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) {
                const double s = r.s0 + 0.5 * a * (r.s1 - r.s0), t = r.t0 + 0.5 * b * (r.t1 - r.t0);
                const Vec3 x = si.point(s, t);
                std::size_t k = 0;
                auto note = [&](double e) {
                    const signed char sg = e > 0.0 ? 1 : (e < 0.0 ? -1 : 0);
                    if (a + b == 0)
                        sign[k] = sg;
                    else if (sg != sign[k])
                        mixed[k] = 1;
                    ++k;
                };
                if (!ball && !m_horizons.empty()) {
                    const Vec3 nx = si.normal(s, t);
                    for (const Vec3& v : m_horizons) note(glm::dot(nx, v - x));
                }
                for (std::size_t ci = 0; ci < cones; ++ci) {
                    const Cone& c = m_cones[ci];
                    const Vec3 d = x - c.apex;
                    const double along = glm::dot(d, c.axis);
                    note(along > 0.0 ? along * along - c.cos2 * glm::dot(d, d) : -1.0);
                }
            }
        return std::any_of(mixed.begin(), mixed.end(), [](signed char m) { return m != 0; });
    }

    // Which way to halve a region an event crosses, to close in on it: the direction in which
    // fewer halves are still crossed (an event along a long thin band is approached across the
    // band, not along it); `fallback` when both are alike.
    int split_toward(const Surface& si, const Rect& r, int fallback) const {
        int crossed[2] = {0, 0};
        for (int dir = 0; dir < 2; ++dir)
            for (const Rect& h : r.halves(dir)) crossed[dir] += crosses(si, h);
        return crossed[0] < crossed[1] ? 0 : (crossed[1] < crossed[0] ? 1 : fallback);
    }

    // Where to cut the region so that a plane event runs along the cut instead of through a
    // region (planar patches only, where a plane meets the patch in a straight line): the first
    // plane that enters through one pair of opposite edges and leaves through the other within
    // a tenth of the region's width of the same parameter. Nested rules cannot see a kink
    // that no node lies beyond; after the cut the kink is on an edge, where it costs nothing.
    Cut cut_along(const Surface& si, const Rect& r) const {
        if (m_planes.empty() || !si.plane()) return {};
        const Vec3 p00 = si.point(r.s0, r.t0), p10 = si.point(r.s1, r.t0), p01 = si.point(r.s0, r.t1),
                   p11 = si.point(r.s1, r.t1);
        const double size =
            std::max({glm::length(p10 - p00), glm::length(p01 - p00), glm::length(p11 - p00)});
        for (const auto& plane : m_planes) {
            // Named copies, not structured bindings: clang 14 cannot capture those in a lambda.
            const Vec3& nrm = plane.first;
            const Vec3& p = plane.second;
            const double scale = glm::length(nrm) * size * 1e-12;
            auto f = [&](const Vec3& x) {
                const double v = glm::dot(nrm, x - p);
                return std::abs(v) <= scale ? 0.0 : v;
            };
            const double f00 = f(p00), f10 = f(p10), f01 = f(p01), f11 = f(p11);
            // a . P is linear along each edge of a bilinear patch: where it crosses zero.
            auto root = [](double fa, double fb, double a, double b) -> std::optional<double> {
                if (!((fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0))) return std::nullopt;
                return a + (b - a) * fa / (fa - fb);
            };
            for (int dir = 0; dir < 2; ++dir) {
                const auto a = dir == 0 ? root(f00, f10, r.s0, r.s1) : root(f00, f01, r.t0, r.t1);
                const auto b = dir == 0 ? root(f01, f11, r.s0, r.s1) : root(f10, f11, r.t0, r.t1);
                if (!a || !b) continue;
                const double lo = dir == 0 ? r.s0 : r.t0, hi = dir == 0 ? r.s1 : r.t1;
                const double at = 0.5 * (*a + *b);
                if (std::abs(*a - *b) <= 0.1 * (hi - lo) && at > lo + 1e-9 * (hi - lo) &&
                    at < hi - 1e-9 * (hi - lo))
                    return Cut{dir, at};
            }
        }
        return {};
    }

private:
    struct Cone {
        Vec3 apex, axis;
        double cos2;  // cos^2 of the half-angle
    };

    // Does the cone's surface meet the planar convex polygon q (corners in order)? The angle
    // between x - apex and the axis is largest over the polygon at a corner (its sublevel sets
    // are convex cones), and smallest either 0, where the axis passes through the polygon, or on
    // an edge p0 + l (p1 - p0), where its cosine peaks at l = (a0 q1 - a1 q0) / (a1 q1 - a0 q2)
    // (a = axis . (u, w), q = (u.u, u.w, w.w), u = p0 - apex, w = p1 - p0).
    static bool cone_meets_polygon(const Cone& c, const std::array<Vec3, 4>& q) {
        const double cos_a = std::sqrt(std::max(0.0, c.cos2));
        auto cosine = [&](const Vec3& p) {
            const double l = glm::length(p);
            return l > 0.0 ? glm::dot(c.axis, p) / l : 1.0;
        };
        double lo = 1.0, hi = -1.0;
        for (int k = 0; k < 4; ++k) {
            const Vec3 u = q[k] - c.apex, w = q[(k + 1) % 4] - q[k];
            const double v = cosine(u);
            lo = std::min(lo, v);
            hi = std::max(hi, v);
            const double a0 = glm::dot(c.axis, u), a1 = glm::dot(c.axis, w), q0 = glm::dot(u, u),
                         q1 = glm::dot(u, w), q2 = glm::dot(w, w);
            const double den = a1 * q1 - a0 * q2;
            if (den != 0.0) {
                const double l = (a0 * q1 - a1 * q0) / den;
                if (l > 0.0 && l < 1.0) hi = std::max(hi, cosine(u + l * w));
            }
        }
        const Vec3 nrm = glm::cross(q[1] - q[0], q[2] - q[0]) + glm::cross(q[2] - q[0], q[3] - q[0]);
        const double dn = glm::dot(nrm, c.axis);
        if (dn != 0.0) {
            const double tau = glm::dot(nrm, q[0] - c.apex) / dn;
            const Vec3 h = c.apex + tau * c.axis;
            bool inside = tau > 0.0;
            for (int k = 0; k < 4 && inside; ++k)
                inside = glm::dot(nrm, glm::cross(q[(k + 1) % 4] - q[k], h - q[k])) >= 0.0;
            if (inside) hi = 1.0;
        }
        return lo < cos_a && cos_a < hi;
    }
    std::vector<Vec3> m_horizons;
    std::vector<std::pair<Vec3, Vec3>> m_planes;  // normal, point
    std::vector<Cone> m_cones;
};

}  // namespace radiosa
