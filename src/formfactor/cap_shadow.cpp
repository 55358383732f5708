#include "formfactor/cap_shadow.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "formfactor/disk_shadow.h"
#include "formfactor/outline.h"
#include "formfactor/point_polygon.h"
#include "util/convex_distance.h"

namespace radiosa {

namespace {

double angle_on(const Circle& c, const Vec3& p) {
    return std::atan2(glm::dot(p - c.c, c.e2), glm::dot(p - c.c, c.e1));
}

// The arc of circle k from angle a to angle b, the way round whose middle point passes `keep`.
template <class Keep>
void add_arc(Outline* o, const std::array<Circle, 2>& circles, int k, double a, double b, Keep keep) {
    double d = std::fmod(b - a, 2.0 * kPi);
    if (d < 0.0) d += 2.0 * kPi;
    if (!keep(circles[static_cast<std::size_t>(k)].at(a + 0.5 * d))) d -= 2.0 * kPi;
    o->arc(circles, k, a, a + d);
}

}  // namespace

FlatDisk cap_rim(const SphericalCap& cap) {
    return FlatDisk{cap.center + cap.height * cap.axis, cap.axis, cap.rim_radius(), 0.0};
}

double cap_min_signed_distance(const SphericalCap& cap, const Vec3& m, double o) {
    if (-cap.radius * glm::dot(m, cap.axis) >= cap.height) return glm::dot(m, cap.center) - o - cap.radius;
    return disk_min_signed_distance(cap_rim(cap), m, o);
}

bool hull_meets_cap(std::span<const Vec3> points, const SphericalCap& cap) {
    // The hull's part on the cap's side of the rim plane is the hull of its points there and of
    // where the segments between its points cross the plane; the solid is that side of the
    // ball, so the hull meets it exactly when that part comes within the radius of the centre.
    std::array<Vec3, 40> slice;
    std::size_t n = 0;
    const auto above = [&](const Vec3& p) { return glm::dot(p - cap.center, cap.axis) - cap.height; };
    for (std::size_t a = 0; a < points.size(); ++a) {
        const double da = above(points[a]);
        if (da >= 0.0 && n < slice.size()) slice[n++] = points[a];
        for (std::size_t b = a + 1; b < points.size(); ++b) {
            const double db = above(points[b]);
            if (((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) && n < slice.size())
                slice[n++] = points[a] + (points[b] - points[a]) * (da / (da - db));
        }
    }
    if (n == 0) return false;
    const std::array<Vec3, 1> c = {cap.center};
    return convex_distance(std::span<const Vec3>(slice.data(), n), c, cap.radius) <= cap.radius;
}

ShadowValue point_to_polygon_hidden_by_cap(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                           const SphericalCap& cap) {
    const double R = cap.radius, h = cap.height;
    if (count < 3 || count > 16 || !(R > 0.0) || !(std::abs(h) < R)) return {};
    PolygonCone cone;
    if (!polygon_cone(x, n, v, count, &cone)) return {};
    const Vec3& a = cap.axis;
    const Vec3 q = x - cap.center;
    const double D = glm::length(q), xa = glm::dot(q, a);
    // Circle 0 the rim, circle 1 the ball's contact circle seen from x: the points p with
    // (p - c) . u = R^2 / D, u the unit vector from the centre to x.
    std::array<Circle, 2> circles = {circle_about(cap.center + h * a, a, cap.rim_radius()), Circle{}};
    Outline outline;
    if (D <= R) {
        if (xa >= h) return {};  // in the solid
        outline.arc(circles, 0, 0.0, 2.0 * kPi);
    } else {
        const Vec3 u = q / D;
        const double w = R * R / D;
        circles[1] =
            circle_about(cap.center + w * u, u, R * std::sqrt(std::max(0.0, 1.0 - (R / D) * (R / D))));
        const auto on_cap = [&](const Vec3& p) { return glm::dot(p - cap.center, a) >= h; };
        // A rim point is on the outline when the view along it does not enter the solid: it
        // faces x ((p - c) . u > w) seen from the closed side, faces away from the open side.
        const bool closed_side = xa >= h;
        const auto silhouette = [&](const Vec3& p) {
            return (glm::dot(p - cap.center, u) >= w) == closed_side;
        };
        // Where the two circles cross: on the line where their planes meet, R from the centre.
        const double mu = glm::dot(a, u), det = 1.0 - mu * mu;
        bool crossing = false;
        std::array<Vec3, 2> at{};
        if (det > 1e-24) {
            const double alpha = (h - w * mu) / det, beta = (w - h * mu) / det;
            const Vec3 base = alpha * a + beta * u;
            const double g2 = R * R - glm::dot(base, base);
            if (g2 > 0.0) {
                const Vec3 side = glm::normalize(glm::cross(a, u)) * std::sqrt(g2);
                at = {cap.center + base + side, cap.center + base - side};
                crossing = true;
            }
        }
        if (!crossing) {
            // The contact circle wholly on the cap (the ball's cone) or wholly off it (the rim's).
            outline.arc(circles, on_cap(circles[1].c + circles[1].rho * circles[1].e1) ? 1 : 0, 0.0,
                        2.0 * kPi);
        } else {
            add_arc(&outline, circles, 1, angle_on(circles[1], at[0]), angle_on(circles[1], at[1]), on_cap);
            add_arc(&outline, circles, 0, angle_on(circles[0], at[1]), angle_on(circles[0], at[0]),
                    silhouette);
        }
    }
    ShadowValue out = outline_inside_cone(outline, cone, x, n, circles);
    out.value = std::clamp(out.value, 0.0, point_to_polygon(x, n, v, count, nullptr));
    return out;
}

}  // namespace radiosa
