#include "formfactor/sphere_receiver.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "formfactor/events.h"
#include "formfactor/spherical_region.h"

namespace radiosa {

namespace {

// Range of |x - c| over the points x of patch i.
std::pair<double, double> distance_range(const SceneGeometry& g, int i, const Vec3& c) {
    const Patch& p = g.patch(i);
    if (const auto s = g.surface(p.surface).sphere()) {
        const double d = glm::length(s->center - c);
        return {std::abs(s->radius - d), s->radius + d};
    }
    const double d = glm::length(p.bound.center - c);
    double lo = std::max(0.0, d - p.bound.radius);
    // A flat patch is no nearer than its plane: a wide disk under a ball, which its bounding
    // ball would reach into.
    if (const auto pl = g.surface(p.surface).plane()) lo = std::max(lo, std::abs(pl->signed_distance(c)));
    return {lo, d + p.bound.radius};
}

// Where the moving circle (the edge of what x sees: the hidden cap's, x's horizon's or the
// visible cap's) touches an edge circle of patch j. Near there the part of j on one side of it
// grows as the 3/2 power of the distance, a singularity in the slope that nested rules
// underestimate. With x on a sphere concentric with the receiver (or on the receiver itself),
// the moving circle has a fixed angular radius about the direction of x - c, so touching an
// edge circle of axis u and angular radius g happens where the angle between them is the sum
// or the difference of the radii: on planes (x - c) . u = const, which crosses() finds
// exactly. Elsewhere only the corners are events.
// Returns the angle alpha such that x sees a point y of the receiver's sphere (past its
// horizon, the receiver's own horizon, or the ball) only if the angle between x - c and y - c
// is below alpha; -1 when x's surface is not concentric with the receiver.
double add_tangencies(const SceneGeometry& g, int i, int j, const SphereReceiver& how, double cos_beta,
                      EventSet* events) {
    const Patch& pi = g.patch(i);
    const Patch& pj = g.patch(j);
    const auto si = g.surface(pi.surface).sphere();
    const Vec3& c = how.center;
    const double R = how.radius;
    if (!si || glm::length(si->center - c) > 1e-12 * R) return -1.0;
    const double rho = si->radius;  // |x - c|
    // The moving circle: its axis sigma (x - c) / rho and the cosine of its angular radius.
    double sigma = 1.0, cos_radius = 0.0;
    if (how.same_sphere) {
        sigma = -1.0;
        cos_radius = cos_beta;
    } else if (how.inward) {
        cos_radius = rho / R;  // x's horizon on the sphere around it
    } else {
        cos_radius = R / rho;  // the cap x sees from outside
    }
    const double radius = std::acos(std::clamp(cos_radius, -1.0, 1.0));
    SphericalRegion edges;
    edges.center = c;
    edges.radius = R;
    edges.axes = how.axes;
    add_patch_cuts(&edges, g.surface(pj.surface), pj.s0, pj.s1, pj.t0, pj.t1);
    for (const HalfSpace& h : edges.cuts) {
        const Vec3 u = glm::normalize(h.normal);
        const double cos_g = (h.offset / glm::length(h.normal) - glm::dot(u, c)) / R;
        if (!(std::abs(cos_g) < 1.0)) continue;  // a pole: no edge
        const double gam = std::acos(cos_g);
        for (const double angle : {radius + gam, std::abs(radius - gam)})
            events->add_plane(u, c + sigma * rho * std::cos(angle) * u);
    }
    return sigma > 0.0 ? radius : kPi - radius;
}

// A cone of directions from c holding every point of the parameter rectangle of a surface
// around c: the directions of a 5 x 5 grid of points, their mean as the axis, and as the
// half-angle the largest angle to a grid point plus the largest angle between neighbours (no
// point of the smooth map lies farther from the grid than that).
struct Cone {
    Vec3 axis;
    double half_angle;
};
Cone direction_cone(const Surface& s, const Rect& r, const Vec3& c) {
    constexpr int n = 5;
    std::array<Vec3, n * n> d;
    Vec3 sum(0.0);
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
            d[a * n + b] = glm::normalize(
                s.point(r.s0 + (r.s1 - r.s0) * a / (n - 1), r.t0 + (r.t1 - r.t0) * b / (n - 1)) - c);
            sum += d[a * n + b];
        }
    auto angle = [](const Vec3& u, const Vec3& v) {
        return std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v));
    };
    const double len = glm::length(sum);
    if (!(len > 1e-9)) return {Vec3(0, 0, 1), kPi};
    Cone cone{sum / len, 0.0};
    double step = 0.0;
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
            cone.half_angle = std::max(cone.half_angle, angle(cone.axis, d[a * n + b]));
            if (a + 1 < n) step = std::max(step, angle(d[a * n + b], d[(a + 1) * n + b]));
            if (b + 1 < n) step = std::max(step, angle(d[a * n + b], d[a * n + b + 1]));
        }
    cone.half_angle = std::min(kPi, cone.half_angle + step);
    return cone;
}

// The receiver in pieces of at most a quarter turn of azimuth, each with a point of the sphere
// well away from it (for areas).
struct Piece {
    SphericalRegion region;
    Vec3 away;
};
std::vector<Piece> receiver_pieces(const Surface& sj, const Patch& pj, const SphereReceiver& how) {
    std::vector<Piece> pieces;
    // Pieces of at most a quarter turn of azimuth.
    const double span = sj.sphere_angles(pj.s1, pj.t0).first - sj.sphere_angles(pj.s0, pj.t0).first;
    const int n = std::max(1, static_cast<int>(std::ceil(span / (0.5 * kPi) - 1e-9)));
    for (int k = 0; k < n; ++k) {
        const double s0 = pj.s0 + (pj.s1 - pj.s0) * k / n, s1 = pj.s0 + (pj.s1 - pj.s0) * (k + 1) / n;
        Piece p;
        p.region.center = how.center;
        p.region.radius = how.radius;
        p.region.front = how.inward ? -1.0 : 1.0;
        p.region.axes = how.axes;
        add_patch_cuts(&p.region, sj, s0, s1, pj.t0, pj.t1);
        p.away = how.center -
                 how.radius * glm::normalize(sj.point(0.5 * (s0 + s1), 0.5 * (pj.t0 + pj.t1)) - how.center);
        pieces.push_back(std::move(p));
    }
    return pieces;
}

// Where the inner integral bends: a cut's circle passing a corner of patch j (x's horizon passes
// corner v where x's tangent plane holds it, the visible cap's edge where x lies on the tangent
// plane at v, the hidden cap's edge where (x - c) . (v - c) = -R^2 cos beta), and the
// tangencies (add_tangencies, which sets *alpha).
EventSet receiver_events(const SceneGeometry& g, int i, int j, const SphereReceiver& how, double cos_beta,
                         double* alpha) {
    const Vec3& c = how.center;
    EventSet events;
    if (!how.same_sphere) events.add_horizons(g.patch(j).corners);
    for (const Vec3& v : g.patch(j).corners) {
        if (how.same_sphere) events.add_plane(v - c, c - cos_beta * (v - c));
        if (!how.same_sphere && !how.inward) events.add_plane(v - c, v);
    }
    *alpha = add_tangencies(g, i, j, how, cos_beta, &events);
    return events;
}

}  // namespace

// Nested spheres whose outer one is a single patch (the whole inward-facing sphere): all that
// leaves the inner (outward-facing, wholly inside) sphere reaches it, so A_k F_k,outer = A_k for
// every inner patch k, and it sees itself but for the inner sphere, A_o F_oo = 4 pi (R^2 - r^2).
std::optional<Estimate> nested_spheres(const SceneGeometry& g, int i, int j, const std::vector<int>& blockers,
                                       bool visibility) {
    auto whole_inward = [&](int k) {
        const Patch& p = g.patch(k);
        const Surface& s = g.surface(p.surface);
        return s.whole_sphere() && s.sees_itself() && p.s0 == 0.0 && p.s1 == 1.0 && p.t0 == 0.0 &&
               p.t1 == 1.0;
    };
    auto inside = [&](int inner_surface, const BoundingSphere& outer) {
        const Surface& s = g.surface(inner_surface);
        const auto b = s.sphere();
        return b && s.whole_sphere() && !s.sees_itself() &&
               glm::length(b->center - outer.center) + b->radius < outer.radius * (1.0 - 1e-12);
    };
    Estimate e;
    if (i == j) {
        if (!whole_inward(i) || !visibility || blockers.size() != 1) return std::nullopt;
        const BoundingSphere outer = *g.surface(g.patch(i).surface).sphere();
        if (!inside(blockers[0], outer)) return std::nullopt;
        const double r = g.surface(blockers[0]).sphere()->radius;
        e.value = 4.0 * kPi * (outer.radius * outer.radius - r * r);
    } else {
        const int o = whole_inward(i) ? i : (whole_inward(j) ? j : -1);
        if (o < 0) return std::nullopt;
        const int k = o == i ? j : i;
        // Neither sphere can block a segment from the inside of the one to the front of the
        // other; anything else might.
        const int so = g.patch(o).surface, sk = g.patch(k).surface;
        if (visibility &&
            std::any_of(blockers.begin(), blockers.end(), [&](int b) { return b != so && b != sk; }))
            return std::nullopt;
        if (!inside(g.patch(k).surface, *g.surface(g.patch(o).surface).sphere())) return std::nullopt;
        e.value = g.patch(k).area;
    }
    e.error = 16 * std::numeric_limits<double>::epsilon() * e.value;
    return e;
}

std::optional<SphereReceiver> sphere_receiver(const SceneGeometry& g, int i, int j,
                                              const std::vector<int>& blockers, bool visibility) {
    const Patch& pi = g.patch(i);
    const Patch& pj = g.patch(j);
    const Surface& si = g.surface(pi.surface);
    const Surface& sj = g.surface(pj.surface);
    const auto bj = sj.sphere();
    if (!bj) return std::nullopt;
    SphereReceiver how;
    how.center = bj->center;
    how.radius = bj->radius;
    how.axes = sj.sphere_axes();
    how.inward = sj.sees_itself();
    if (pi.surface == pj.surface) {
        if (!how.inward || !visibility || blockers.size() != 1) return std::nullopt;
        const Surface& b = g.surface(blockers[0]);
        const auto ball = b.sphere();
        if (!ball || b.sees_itself() || glm::length(ball->center - bj->center) > 1e-12 * bj->radius ||
            !(ball->radius < bj->radius))
            return std::nullopt;
        how.same_sphere = true;
        how.ball_radius = ball->radius;
        return how;
    }
    const auto bi = si.sphere();
    for (int k : blockers) {
        if (!visibility) break;
        // The receiver: from inside, a segment meets it only at its end; from outside, the
        // visible cap is cut out. x's own surface: segments leaving its front escape it, or it is
        // the inside of a sphere that holds the receiver's.
        if (k == pj.surface || (k == pi.surface && si.front_segments_escape())) continue;
        if (k == pi.surface && bi && si.sees_itself() &&
            glm::length(bj->center - bi->center) + bj->radius < bi->radius)
            continue;
        return std::nullopt;
    }
    const auto [dmin, dmax] = distance_range(g, i, bj->center);
    if (how.inward ? !(dmax < bj->radius * (1.0 - 1e-9)) : !(dmin > bj->radius * (1.0 + 1e-9)))
        return std::nullopt;
    return how;
}

Estimate area_times_f_sphere(const SceneGeometry& g, int i, int j, const SphereReceiver& how, double tol,
                             const GaussRule& outer, int max_regions) {
    const Patch& pi = g.patch(i);
    const Patch& pj = g.patch(j);
    const Surface& si = g.surface(pi.surface);
    const Surface& sj = g.surface(pj.surface);
    const Vec3& c = how.center;
    const double R = how.radius;
    const std::vector<Piece> pieces = receiver_pieces(sj, pj, how);
    // x sees the sphere but for the cap {(y - c) . (c - x) >= R^2 cos beta} around its antipode,
    // beta the angle from the centre between the antipode and where a chord from x grazes the
    // ball: cos beta = 1 - 2 (r / R)^2.
    const double cos_beta = 1.0 - 2.0 * (how.ball_radius / R) * (how.ball_radius / R);
    // The inner integrals' error counts in full (times A_i): a twentieth of the target each.
    const double inner_tol = std::max(1e-15, 0.05 * tol * std::min(pi.area, pj.area) / pi.area);
    double inner_err = 0.0;
    SphericalRegion work;
    auto gx = [&](double s, double t) {
        Vec3 x, nrm;
        si.point_and_normal(s, t, &x, &nrm);
        const double da = glm::length(nrm);
        if (!(da > 0.0)) return 0.0;
        const Vec3 unit = nrm / da;
        double sum = 0.0, err = 0.0;
        for (const Piece& p : pieces) {
            work = p.region;
            ContourValue v;
            if (how.same_sphere) {
                work.cuts.push_back({x - c, glm::dot(x - c, c) - R * R * cos_beta});
                v = spherical_region_area(work, p.away, inner_tol / pieces.size());
                v.value /= 4 * kPi * R * R;
                v.error /= 4 * kPi * R * R;
            } else {
                work.cuts.push_back({unit, glm::dot(unit, x)});
                if (!how.inward) work.cuts.push_back({x - c, R * R + glm::dot(x - c, c)});
                v = point_to_spherical_region(x, unit, work, inner_tol / pieces.size());
            }
            sum += v.value;
            err += v.error;
        }
        inner_err = std::max(inner_err, err);
        return da * sum;
    };
    double alpha = -1.0;
    const EventSet events = receiver_events(g, i, j, how, cos_beta, &alpha);
    const Cone cone_j = direction_cone(sj, Rect{pj.s0, pj.s1, pj.t0, pj.t1}, c);
    // Can some x of the region see some of j? Only if their directions from c come closer than
    // alpha (concentric surfaces only; elsewhere no sliver is looked for).
    auto may_see = [&](const Rect& r) {
        if (alpha < 0.0) return false;
        const Cone cr = direction_cone(si, r, c);
        const double gap = std::acos(std::clamp(glm::dot(cr.axis, cone_j.axis), -1.0, 1.0));
        return gap - cr.half_angle - cone_j.half_angle < alpha + 1e-9;
    };
    const Rect root{pi.s0, pi.s1, pi.t0, pi.t1};
    auto quarters = [&](const Rect& r, const auto&) { return quarter_of(root, r); };
    const double region_tol = tol * std::min(pi.area, pj.area);
    // The outer integral gets nine tenths of the target, the inner integrals' sum the rest.
    Estimate e = adaptive_rect(gx, Rect{pi.s0, pi.s1, pi.t0, pi.t1}, 0.9 * region_tol, max_regions, outer,
                               quarters, [&](const Rect& r, double fine) {
                                   // A region whose nodes see (almost) nothing of j, although
                                   // its directions come close enough, may hold a sliver that
                                   // does (x's horizon just reaching j): the 3 x 3 split looks.
                                   if (!events.crosses(si, r)) return 0.0;
                                   const bool sliver = std::abs(fine) <= region_tol && may_see(r);
                                   return sliver ? kCheckRegion : kSphereKinkFraction;
                               });
    e.error += inner_err * pi.area;
    return e;
}

}  // namespace radiosa
