#include "formfactor/sensor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>

#include "formfactor/blocker_set.h"
#include "formfactor/contour_receiver.h"
#include "formfactor/cubature.h"
#include "formfactor/disk_shadow.h"
#include "formfactor/point_polygon.h"
#include "formfactor/shadow_occluder.h"
#include "formfactor/spherical_region.h"
#include "util/convex_distance.h"

namespace radiosa {

namespace {

// Whether x lies strictly inside the convex solid (so the solid's concave side faces it).
bool strictly_inside(const Vec3& x, const std::optional<ConvexSolid>& solid) {
    if (!solid) return false;
    Vec3 q = x - solid->center;
    if (!solid->cylinder) return glm::length(q) < solid->radius;
    const double h = glm::dot(q, solid->axis);
    q -= h * solid->axis;
    return glm::length(q) < solid->radius_at(h);
}

// Surfaces that might block a segment from x to patch j: the same proofs as between patches
// (a plane with both on one side, a slab, the bounding balls, a convex solid holding both),
// with x a patch of size zero.
std::vector<int> blockers_of(const SceneGeometry& g, const Vec3& x, const Patch& pj, double eps) {
    std::vector<int> out;
    const Surface& sj = g.surface(pj.surface);
    for (int k = 0; k < g.surface_count(); ++k) {
        const Surface& s = g.surface(k);
        if (k == pj.surface && s.front_segments_escape()) continue;
        if (g.twin(k) >= 0 && g.twin(k) == pj.surface && s.back_segments_escape()) continue;
        // j's own surface, when x sees all of it once (a Bezier patch): met only at the end.
        if ((k == pj.surface || (g.twin(k) >= 0 && g.twin(k) == pj.surface)) && !s.plane() &&
            s.seen_once_from(std::span<const Vec3>(&x, 1), 0.0, 1.0, 0.0, 1.0) != 0)
            continue;
        if (strictly_inside(x, s.convex_solid()) &&
            (k == pj.surface || g.twin(k) == pj.surface || inside_solid(g, pj, k)))
            continue;
        if (k != pj.surface)
            if (const auto pl = s.plane()) {
                const double dx = pl->signed_distance(x);
                const auto [lo, hi] = sj.linear_range(pl->normal, pj.s0, pj.s1, pj.t0, pj.t1);
                if ((dx >= -eps && lo - pl->offset >= -eps) || (dx <= eps && hi - pl->offset <= eps))
                    continue;
            }
        const BoundingSphere& b = g.surface_bound(k);
        if (distance_to_segment(b.center, x, pj.bound.center) > b.radius + pj.bound.radius) continue;
        bool separated = false;
        if (k != pj.surface) {
            const Vec3 between = pj.bound.center - x;
            const double len = glm::length(between);
            const Vec3 dirs[4] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1),
                                  len > 0.0 ? between / len : Vec3(1, 0, 0)};
            for (const Vec3& a : dirs) {
                const auto rj = sj.linear_range(a, pj.s0, pj.s1, pj.t0, pj.t1);
                const auto rk = s.linear_range(a, 0.0, 1.0, 0.0, 1.0);
                const double lo = std::min(rj.first, glm::dot(a, x)),
                             hi = std::max(rj.second, glm::dot(a, x));
                if (rk.second <= lo + eps || rk.first >= hi - eps) separated = true;
            }
        }
        if (!separated) out.push_back(k);
    }
    return out;
}

// F(dA -> j) for an unblocked patch by a contour, when one applies.
std::optional<ContourValue> by_contour(const SceneGeometry& g, const Vec3& x, const Vec3& n, int j,
                                       double tol) {
    const Patch& pj = g.patch(j);
    const Surface& sj = g.surface(pj.surface);
    if (pj.polygon) {
        const std::array<Vec3, 4> v = g.front_polygon(j);
        ContourValue c;
        c.value = point_to_polygon(x, n, v.data(), 4, nullptr);
        c.error = 64 * std::numeric_limits<double>::epsilon();
        return c;
    }
    // All of j in front of x's tangent plane.
    if (sj.linear_range(n, pj.s0, pj.s1, pj.t0, pj.t1).first < glm::dot(n, x)) return std::nullopt;
    std::vector<ContourPiece> pieces;
    if (sj.patch_contour(pj.s0, pj.s1, pj.t0, pj.t1, &pieces)) {
        bool faces = false;
        if (const auto pl = sj.plane())
            faces = pl->signed_distance(x) > 0.0;
        else if (sj.sees_itself() && sj.chords_never_cross())
            faces = strictly_inside(x, sj.convex_solid());
        else
            faces = sj.faces_ball(pj.s0, pj.s1, pj.t0, pj.t1, BoundingSphere{x, 0.0}, false) ||
                    sj.seen_once_from(std::span<const Vec3>(&x, 1), pj.s0, pj.s1, pj.t0, pj.t1) == 1;
        if (faces) return point_to_contour(x, n, pieces, tol);
        return std::nullopt;
    }
    if (const auto ball = sj.sphere()) {
        const double d = glm::length(x - ball->center);
        const bool inward = sj.sees_itself();
        if (inward ? !(d < ball->radius) : !(d > ball->radius)) return std::nullopt;
        // Pieces of at most a quarter turn of azimuth (add_patch_cuts).
        const auto [phi0, th_max] = sj.sphere_angles(pj.s0, pj.t0);
        const auto [phi1, th_min] = sj.sphere_angles(pj.s1, pj.t1);
        const int pieces_n = std::max(1, static_cast<int>(std::ceil((phi1 - phi0) / (0.5 * kPi) - 1e-9)));
        ContourValue sum;
        for (int q = 0; q < pieces_n; ++q) {
            SphericalRegion r;
            r.center = ball->center;
            r.radius = ball->radius;
            r.front = inward ? -1.0 : 1.0;
            r.axes = sj.sphere_axes();
            add_patch_cuts(&r, phi0 + (phi1 - phi0) * q / pieces_n, phi0 + (phi1 - phi0) * (q + 1) / pieces_n,
                           th_min, th_max);
            r.cuts.push_back({n, glm::dot(n, x)});
            if (!inward)
                r.cuts.push_back({x - ball->center,
                                  ball->radius * ball->radius + glm::dot(x - ball->center, ball->center)});
            const ContourValue v = point_to_spherical_region(x, n, r, tol / pieces_n);
            sum.value += v.value;
            sum.error += v.error;
        }
        return sum;
    }
    return std::nullopt;
}

// F(dA -> j) in closed form for a polygon patch that only one ball, or only balls (their shadows
// may overlap), or occluders with closed-form
// shadows that never overlap as seen from x (balls, disks, tubes or cones, caps: either side or
// both of a two-sided one), can hide: Lambert's formula minus each one's cone of directions cut
// to the polygon (formfactor/shadow_occluder.h). The occluders must lie wholly on j's front
// side and in front of x (one ball alone: in front of j).
std::optional<ContourValue> by_shadow(const SceneGeometry& g, const Vec3& x, const Vec3& n, int j,
                                      const std::vector<int>& blockers) {
    const Patch& pj = g.patch(j);
    const auto plane = g.surface(pj.surface).plane();
    if (!pj.polygon || !plane || blockers.empty()) return std::nullopt;
    const std::array<Vec3, 4> v = g.front_polygon(j);
    const double margin = 1e-9 * g.scale();
    ContourValue c;
    c.error = 64 * std::numeric_limits<double>::epsilon();
    const Surface& first = g.surface(blockers[0]);
    if (const auto ball = first.sphere(); ball && first.whole_sphere() && blockers.size() == 1) {
        if (!(plane->signed_distance(ball->center) > ball->radius + margin) ||
            !(glm::length(x - ball->center) > ball->radius + margin))
            return std::nullopt;
        c.value = point_to_polygon(x, n, v.data(), 4, &*ball);
        return c;
    }
    // Whole balls alone, each wholly on j's front side and x outside it: what they hide together,
    // their shadows overlapping or not (point_to_polygon_blocked_by_balls).
    std::vector<BoundingSphere> balls;
    for (int k : blockers) {
        const Surface& s = g.surface(k);
        const auto b = s.sphere();
        if (!b || !s.whole_sphere() || blockers.size() > kMaxBallUnion ||
            !(plane->signed_distance(b->center) > b->radius + margin) ||
            !(glm::length(x - b->center) > b->radius + margin)) {
            balls.clear();
            break;
        }
        balls.push_back(*b);
    }
    if (!balls.empty()) {
        c.value = std::max(0.0, point_to_polygon(x, n, v.data(), 4, nullptr) -
                                    point_to_polygon_blocked_by_balls(x, n, v.data(), 4, balls.data(),
                                                                      static_cast<int>(balls.size())));
        return c;
    }
    // Whole balls, disks, tubes or cones and caps whose shadows never overlap as seen from x
    // (shadows_apart on their bounding balls, from the point x): the parts they hide add up.
    // The two sides of a two-sided surface are one occluder.
    const auto occluders =
        occluders_apart(g, blockers, BoundingSphere{x, 0.0}, *plane, Plane{n, glm::dot(n, x)});
    if (!occluders) return std::nullopt;
    double hidden = 0.0;
    for (const ShadowOccluder& o : *occluders) hidden += hidden_by(o, x, n, v, &c.error);
    c.value = std::max(0.0, point_to_polygon(x, n, v.data(), 4, nullptr) - hidden);
    return c;
}

// F(dA -> j) by adaptive cubature over j, every blocker tested.
Estimate by_cubature(const SceneGeometry& g, const Vec3& x, const Vec3& n, const Patch& pj,
                     const std::vector<int>& blockers, double tol) {
    const Surface& sj = g.surface(pj.surface);
    const double floor2 = 1e-24 * g.scale() * g.scale();
    const BlockerSet guard(g, blockers);
    auto h = [&](double u, double w) {
        const Vec3 e = sj.point(u, w) - x;
        const double ci = glm::dot(n, e);
        if (ci <= 0.0) return 0.0;
        const double cj = -glm::dot(sj.normal(u, w), e);
        if (cj <= 0.0) return 0.0;
        const double l2 = glm::dot(e, e);
        if (!(l2 > floor2)) return 0.0;
        long long tests = 0;
        if (guard.blocked(x, e, 1e-9, 1.0 - 1e-9, &tests)) return 0.0;
        return ci * cj / (kPi * l2 * l2);
    };
    const Rect root{pj.s0, pj.s1, pj.t0, pj.t1};
    auto quarters = [&](const Rect& r, const auto&) { return quarter_of(root, r); };
    return adaptive_rect(h, Rect{pj.s0, pj.s1, pj.t0, pj.t1}, tol, 4096, gauss_legendre(4), quarters);
}

}  // namespace

Rgb sensor_irradiance(const SensorFactors& s, const std::vector<Rgb>& B, Rgb* error) {
    Rgb e(0.0), err(0.0);
    for (std::size_t j = 0; j < B.size(); ++j) {
        e += s.F[j] * B[j];
        err += s.error[j] * B[j];
    }
    if (error) *error = err;
    return e;
}

SensorFactors sensor_factors(const SceneGeometry& g, const Vec3& x, const Vec3& unit_normal, double tolerance,
                             bool visibility) {
    const int n = g.patch_count();
    SensorFactors out;
    out.F.assign(n, 0.0);
    out.error.assign(n, 0.0);
    std::vector<char> closed(n, 0);
    const double eps = 1e-12 * g.scale();
    tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& range) {
        for (int j = range.begin(); j != range.end(); ++j) {
            const Patch& pj = g.patch(j);
            const Surface& sj = g.surface(pj.surface);
            // Wholly behind the sensor, or the sensor behind a planar patch: nothing.
            if (sj.linear_range(unit_normal, pj.s0, pj.s1, pj.t0, pj.t1).second <= glm::dot(unit_normal, x))
                continue;
            if (const auto pl = sj.plane(); pl && pl->signed_distance(x) <= 0.0) continue;
            // The sensor sees only the patch's back (a Bezier patch, Surface::seen_once_from).
            if (!sj.plane() && !sj.sphere() &&
                sj.seen_once_from(std::span<const Vec3>(&x, 1), pj.s0, pj.s1, pj.t0, pj.t1) == -1)
                continue;
            const std::vector<int> blockers = visibility ? blockers_of(g, x, pj, eps) : std::vector<int>{};
            if (const auto c = blockers.empty() ? by_contour(g, x, unit_normal, j, tolerance)
                                                : by_shadow(g, x, unit_normal, j, blockers)) {
                out.F[j] = c->value;
                out.error[j] = c->error;
                closed[j] = 1;
                continue;
            }
            const Estimate e = by_cubature(g, x, unit_normal, pj, blockers, tolerance);
            out.F[j] = e.value;
            out.error[j] = e.error;
        }
    });
    for (char c : closed) out.closed_form += c;
    return out;
}

}  // namespace radiosa
