#pragma once
// Visibility and horizon events: where the inner form factor toward a polygon, as a function of
// the outer point, stops being smooth (formfactor/form_factor.cpp checks regions they cross).
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "formfactor/cap_shadow.h"
#include "formfactor/column_shadow.h"
#include "formfactor/convex_clip.h"
#include "formfactor/cubature.h"
#include "formfactor/tube_shadow.h"
#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

// The largest share of a region's value that a kink inside it can cost (cubature.h's `suspect`). A
// sphere's outline meeting an edge, or an arc of what a point sees on a sphere passing a
// corner, bends the integrand smoothly. Measured, not proven: 1.6e-5 of the region's value on
// the seed scene (a quarter patch of the floor against a wall patch at tolerance 1e-9), but
// 1.5e-4 on pairs of wall patches in the penumbra of the room split into 5,216 patches (3 of
// 3,000 such pairs past their estimates at 1e-4), so 1e-3; checked on 3,000 pairs of the
// 20,198-patch room (5 past at 1e-4, none at 1e-3, the largest at 0.57 of its estimate). A flat
// occluder's edge meeting a corner breaks its slope, so its share is the whole value.
inline constexpr double kSphereKinkFraction = 1e-3;
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
    // A flat disk or annulus between the source and the polygon v (formfactor/disk_shadow.h):
    // x on a plane through an edge of v tangent to a rim (the rim's outline touching the
    // edge's great circle), and x on the cone from a vertex of v over a rim (the outline
    // passing the vertex); and x on the disk's plane, where the disk turns edge-on and its
    // shadow starts or ends.
    void add_disk(const std::array<Vec3, 4>& v, const FlatDisk& d) {
        m_planes.push_back({d.normal, d.center});
        for (const double rho : {d.radius, d.inner_radius}) {
            if (!(rho > 0.0)) continue;
            for (int k = 0; k < 4; ++k) {
                add_rim_tangents(v[k], v[(k + 1) % 4], d.center, d.normal, rho);
                if (glm::dot(d.normal, v[k] - d.center) != 0.0)
                    m_rim_cones.push_back({v[k], d.center, d.normal, rho});
            }
        }
    }
    // A round tube spanning the pair (formfactor/column_shadow.h): x on a plane through a
    // vertex of v along the axis, tangent to the cylinder (the wedge's edge passing the vertex).
    void add_column(const std::array<Vec3, 4>& v, const RoundTube& t) {
        for (const Vec3& p : v) {
            std::array<Vec3, 2> h;
            if (column_wedge(p, t, &h))
                for (const Vec3& m : h) m_planes.push_back({m, p});
        }
    }
    // A whole spherical cap in front of the pair (formfactor/cap_shadow.h): its ball's events
    // and its rim's, the two circles its outline is made of.
    void add_cap(const std::array<Vec3, 4>& v, const SphericalCap& c) {
        add_sphere(v, BoundingSphere{c.center, c.radius});
        add_disk(v, cap_rim(c));
    }
    // A whole round tube in front of the pair (formfactor/tube_shadow.h): its rims' events as a
    // disk's (x on an end plane, a rim touching an edge's plane or passing a vertex), and the
    // silhouette generators passing a vertex: x on a plane through the vertex tangent to the
    // surface (along the axis for a cylinder, through the apex for a cone).
    void add_tube(const std::array<Vec3, 4>& v, const RoundFrustum& t) {
        for (const FlatDisk& rim : tube_rims(t)) add_disk(v, rim);
        if (const auto column = t.column()) {
            add_column(v, *column);
            return;
        }
        // Planes through the apex tangent to the cone touch its wider rim.
        const Vec3 apex = t.base + (t.length * t.radius / (t.radius - t.top_radius)) * t.axis;
        const bool top = t.top_radius > t.radius;
        for (const Vec3& p : v)
            add_rim_tangents(p, apex, t.base + (top ? t.length : 0.0) * t.axis, t.axis,
                             top ? t.top_radius : t.radius);
    }
    // The receiver's own plane (x passing behind it). `n` need not be unit.
    void add_plane(const Vec3& n, const Vec3& p) { m_planes.push_back({n, p}); }
    bool empty() const {
        return m_horizons.empty() && m_planes.empty() && m_cones.empty() && m_rim_cones.empty();
    }

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
            for (const RimCone& c : m_rim_cones)
                if (rim_cone_meets_polygon(c, q)) return true;
        }
        const std::size_t cones = flat ? 0 : m_cones.size(), rims = flat ? 0 : m_rim_cones.size();
        const std::size_t n = (ball ? 0 : m_horizons.size()) + cones + rims;
        if (n == 0) return false;
        // Signs seen at the nodes, bit 0 positive, bit 1 negative: an event crosses where both
        // are. A horizon within rounding of a node (x's tangent plane through the vertex: on the
        // edge of a region cut along it, cut_along_curved) counts as neither.
        std::vector<unsigned char> seen(n, 0);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) {
                const double s = r.s0 + 0.5 * a * (r.s1 - r.s0), t = r.t0 + 0.5 * b * (r.t1 - r.t0);
                const Vec3 x = si.point(s, t);
                std::size_t k = 0;
                auto note = [&](double e, double zero = 0.0) {
                    seen[k] |= e > zero ? 1 : (e < -zero ? 2 : 0);
                    ++k;
                };
                if (!ball && !m_horizons.empty()) {
                    const Vec3 nx = si.normal(s, t);
                    for (const Vec3& v : m_horizons)
                        note(glm::dot(nx, v - x), 1e-12 * glm::length(nx) * glm::length(v - x));
                }
                for (std::size_t ci = 0; ci < cones; ++ci) {
                    const Cone& c = m_cones[ci];
                    const Vec3 d = x - c.apex;
                    const double along = glm::dot(d, c.axis);
                    note(along > 0.0 ? along * along - c.cos2 * glm::dot(d, d) : -1.0);
                }
                for (std::size_t ci = 0; ci < rims; ++ci) note(rim_cone_side(m_rim_cones[ci], x));
            }
        return std::any_of(seen.begin(), seen.end(), [](unsigned char m) { return m == 3; });
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
    // region (on planar patches, where a plane meets the patch in a straight line; curved
    // ones below, cut_along_curved): the first
    // plane that enters through one pair of opposite edges and leaves through the other within
    // a tenth of the region's width of the same parameter. Nested rules cannot see a kink
    // that no node lies beyond; after the cut the kink is on an edge, where it costs nothing.
    Cut cut_along(const Surface& si, const Rect& r) const {
        if (!si.plane()) return cut_along_curved(si, r);
        if (m_planes.empty()) return {};
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

    // On a curved patch, where an event's trace runs nearly along a parameter line across the
    // region:
    // - x's horizon passing a vertex of the polygon (n(x) . (v - x) = 0), not on a sphere (its
    //   horizons are planes in x, left to crosses as before). On a cylinder or a cone
    //   the tangent plane is the same all along a generator, so the trace is a parameter line:
    //   its sign changes at the same parameter (within 1e-9 of the width) on two lines a quarter
    //   in from the region's edges (a pole's edge has no normal).
    // - a plane event, whose trace enters and leaves through opposite edges within a tenth of the
    //   width of the same parameter, as on a planar patch.
    // Elsewhere the event bends and no cut is made; a cut only moves where the nested rules look,
    // never what their estimates promise.
    Cut cut_along_curved(const Surface& si, const Rect& r) const {
        if (!si.sphere())
            for (const Vec3& v : m_horizons) {
                auto h = [&](double s, double t) { return glm::dot(si.normal(s, t), v - si.point(s, t)); };
                if (const Cut c = cut_where(r, h, 0.25, 0.75, 1e-9); c.dir >= 0) return c;
            }
        for (const auto& plane : m_planes) {
            const Vec3& nrm = plane.first;
            const Vec3& p = plane.second;
            auto g = [&](double s, double t) { return glm::dot(nrm, si.point(s, t) - p); };
            if (const Cut c = cut_where(r, g, 0.0, 1.0, 0.1); c.dir >= 0) return c;
        }
        return {};
    }

    // A cut across the region where e(s, t) changes sign along two lines through it (at fractions
    // f0 and f1 of its extent in the other parameter), at parameters within `agree` of its width
    // of each other: halfway between them, in the first direction where that holds.
    template <class E>
    static Cut cut_where(const Rect& r, const E& e, double f0, double f1, double agree) {
        for (int dir = 0; dir < 2; ++dir) {
            const double lo = dir == 0 ? r.s0 : r.t0, hi = dir == 0 ? r.s1 : r.t1;
            const double c0 = dir == 0 ? r.t0 : r.s0, c1 = dir == 0 ? r.t1 : r.s1;
            std::optional<double> at[2];
            for (int k = 0; k < 2; ++k) {
                const double across = c0 + (k == 0 ? f0 : f1) * (c1 - c0);
                at[k] = sign_change([&](double u) { return dir == 0 ? e(u, across) : e(across, u); }, lo, hi);
                if (!at[k]) break;
            }
            if (!at[0] || !at[1] || std::abs(*at[0] - *at[1]) > agree * (hi - lo)) continue;
            const double c = 0.5 * (*at[0] + *at[1]);
            if (c > lo + 1e-9 * (hi - lo) && c < hi - 1e-9 * (hi - lo)) return Cut{dir, c};
        }
        return {};
    }

    // Where f, of opposite signs at a and b, changes sign, by bisection to 1e-13 of b - a.
    template <class F>
    static std::optional<double> sign_change(const F& f, double a, double b) {
        double fa = f(a);
        const double fb = f(b);
        if (!((fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0))) return std::nullopt;
        for (int it = 0; it < 44 && b - a > 0.0; ++it) {
            const double m = 0.5 * (a + b), fm = f(m);
            if (fm == 0.0) return m;
            if ((fm < 0.0) == (fa < 0.0)) {
                a = m;
                fa = fm;
            } else {
                b = m;
            }
        }
        return 0.5 * (a + b);
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
    // The cone from `apex` over the circle of radius rho about `center` in the plane with unit
    // normal `normal`.
    struct RimCone {
        Vec3 apex, center, normal;
        double rho;
    };

    // Does the cone meet the planar convex polygon q? Only points x beyond the circle's plane
    // from the apex see the apex past the circle: q is cut to them and projected from the apex
    // onto the plane (a convex polygon); the cone meets q where that polygon has points both
    // nearer the centre than rho and farther (the farthest is a corner, the nearest the centre
    // itself when inside, else a point of an edge).
    static bool rim_cone_meets_polygon(const RimCone& c, const std::array<Vec3, 4>& q) {
        const double side = glm::dot(c.normal, c.apex - c.center);
        PolygonBuffer<8> p;
        for (const Vec3& y : q) p.v[p.n++] = y;
        p = clip_half_space(p, side > 0.0 ? -c.normal : c.normal, c.center);
        if (p.n < 3) return false;
        double far2 = 0.0;
        for (int k = 0; k < p.n; ++k) {
            const Vec3 d = p.v[k] - c.apex;
            const double along = glm::dot(c.normal, d);
            if (along == 0.0) return true;  // a corner on the plane through the apex: cannot tell
            p.v[k] = c.apex + d * (-side / along) - c.center;  // on the plane, from the centre
            far2 = std::max(far2, glm::dot(p.v[k], p.v[k]));
        }
        const double rho2 = c.rho * c.rho;
        if (!(far2 > rho2)) return false;
        // The centre is inside when it lies on the same side of every edge as the polygon turns.
        double turn = 0.0;
        for (int k = 0; k < p.n; ++k) turn += glm::dot(c.normal, glm::cross(p.v[k], p.v[(k + 1) % p.n]));
        bool inside = true;
        double near2 = far2;
        for (int k = 0; k < p.n; ++k) {
            const Vec3 a = p.v[k], e = p.v[(k + 1) % p.n] - a;
            inside = inside && glm::dot(c.normal, glm::cross(a, p.v[(k + 1) % p.n])) * turn >= 0.0;
            const double l2 = glm::dot(e, e);
            const double t = l2 > 0.0 ? std::clamp(-glm::dot(a, e) / l2, 0.0, 1.0) : 0.0;
            const Vec3 w = a + t * e;
            near2 = std::min(near2, glm::dot(w, w));
        }
        return inside || near2 < rho2;
    }

    // Where the segment from x to the apex crosses the circle's plane, its squared distance
    // from the centre less rho^2 (negative inside the circle); positive when it does not cross.
    static double rim_cone_side(const RimCone& c, const Vec3& x) {
        const double side = glm::dot(c.normal, c.apex - c.center), at = glm::dot(c.normal, x - c.center);
        if (!((side > 0.0 && at < 0.0) || (side < 0.0 && at > 0.0))) return 1.0;
        const Vec3 p = c.apex + (x - c.apex) * (side / (side - at)) - c.center;
        return glm::dot(p, p) - c.rho * c.rho;
    }

    // The planes through the line p -> q tangent to the circle: with (a, b) an orthonormal pair
    // across the line, the plane of normal N = cos(t) a + sin(t) b touches the circle where
    // (N . (centre - p))^2 = rho^2 (1 - (N . normal)^2), a quadratic form in (cos t, sin t)
    // whose two zero directions lie between its eigenvectors.
    void add_rim_tangents(const Vec3& p, const Vec3& q, const Vec3& center, const Vec3& normal, double rho) {
        const double len = glm::length(q - p);
        if (!(len > 0.0)) return;
        const Vec3 u = (q - p) / len;
        const Vec3 a = unit_across(u);
        const Vec3 b = glm::cross(u, a);
        const double wa = glm::dot(a, center - p), wb = glm::dot(b, center - p);
        const double na = glm::dot(a, normal), nb = glm::dot(b, normal), r2 = rho * rho;
        const double q11 = wa * wa + r2 * (na * na - 1.0), q22 = wb * wb + r2 * (nb * nb - 1.0),
                     q12 = wa * wb + r2 * na * nb;
        // Eigenvalues l1 <= l2 and the unit eigenvector (c1, s1) of l1.
        const double mean = 0.5 * (q11 + q22), dev = std::hypot(0.5 * (q11 - q22), q12);
        const double l1 = mean - dev, l2 = mean + dev;
        if (!(l1 < 0.0 && l2 > 0.0)) return;  // every plane through the line cuts the circle, or none does
        const double angle = 0.5 * std::atan2(2.0 * q12, q11 - q22);  // eigenvector of l2
        const double c2 = std::cos(angle), s2 = std::sin(angle), c1 = -s2, s1 = c2;
        const double phi = std::atan(std::sqrt(-l1 / l2));
        for (const double sg : {1.0, -1.0}) {
            const double cf = std::cos(phi), sf = sg * std::sin(phi);
            const double cc = cf * c1 + sf * c2, ss = cf * s1 + sf * s2;
            m_planes.push_back({cc * a + ss * b, p});
        }
    }

    std::vector<RimCone> m_rim_cones;
    std::vector<Vec3> m_horizons;
    std::vector<std::pair<Vec3, Vec3>> m_planes;  // normal, point
    std::vector<Cone> m_cones;
};

}  // namespace radiosa
