#include "formfactor/disk_shadow.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "formfactor/circle_arc.h"
#include "formfactor/convex_clip.h"
#include "formfactor/point_polygon.h"
#include "formfactor/polygon_cone.h"
#include "util/convex_distance.h"

namespace radiosa {

namespace {

constexpr std::size_t kRegionMax = 4 + PolygonCone::kMaxEdges + 4;
using Region = PolygonBuffer<kRegionMax>;

// The contour integral of n . (r x dr) / |r|^2 counter-clockwise (about the circle's normal)
// around the part of the circle's disk inside the region g (a convex polygon in the circle's
// plane, counter-clockwise, cut by the same planes as `cone`).
ContourValue disk_in_region(const Circle& k, const Region& g, const PolygonCone& cone, const Vec3& x,
                            const Vec3& n) {
    ContourValue out;
    std::array<double, 2 * kRegionMax> angles{};
    int na = 0;
    for (int e = 0; e < g.n; ++e) {
        const Vec3 a = g.v[e], d = g.v[(e + 1) % g.n] - a, p = a - k.c;
        // |p + t d|^2 = rho^2, by the cancellation-free pair of roots.
        const double A = glm::dot(d, d), B = 2.0 * glm::dot(p, d), C = glm::dot(p, p) - k.rho * k.rho;
        const double disc = B * B - 4.0 * A * C;
        if (!(A > 0.0) || !(disc > 0.0)) continue;  // the edge's line misses the circle or touches it
        const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
        double t0 = q / A, t1 = q != 0.0 ? C / q : -t0;
        if (t0 > t1) std::swap(t0, t1);
        const double lo = std::max(0.0, t0), hi = std::min(1.0, t1);
        if (hi > lo) out.value += segment_term(x, n, a + lo * d, a + hi * d);
        // Where the edge crosses the circle (half-open, so a corner on it counts once).
        for (const double t : {t0, t1})
            if (t >= 0.0 && t < 1.0) {
                const Vec3 y = p + t * d;
                angles[static_cast<std::size_t>(na++)] = std::atan2(glm::dot(y, k.e2), glm::dot(y, k.e1));
            }
    }
    const double nearest = k.nearest_angle(x);
    constexpr double kArcTol = 1e-14;
    auto add_arc = [&](double a, double b) {
        const ContourValue c = circle_arc_integral(k, x, n, nearest, a, b, kArcTol);
        out.value += c.value;
        out.error += c.error;
    };
    if (na == 0) {
        if (cone.inside(x, k.at(0.0))) add_arc(0.0, 2.0 * kPi);  // the whole rim
        return out;
    }
    std::sort(angles.begin(), angles.begin() + na);
    for (int i = 0; i < na; ++i) {
        const double a = angles[static_cast<std::size_t>(i)];
        const double b = i + 1 < na ? angles[static_cast<std::size_t>(i) + 1] : angles[0] + 2.0 * kPi;
        if (b > a && cone.inside(x, k.at(0.5 * (a + b)))) add_arc(a, b);
    }
    return out;
}

}  // namespace

double disk_min_signed_distance(const FlatDisk& disk, const Vec3& m, double o) {
    const double c = glm::dot(m, disk.normal);
    return glm::dot(m, disk.center) - o - disk.radius * std::sqrt(std::max(0.0, 1.0 - c * c));
}

bool hull_meets_disk(std::span<const Vec3> points, const FlatDisk& disk) {
    std::array<Vec3, 64> slice;
    std::size_t n = 0;
    for (std::size_t a = 0; a < points.size(); ++a) {
        const double da = glm::dot(disk.normal, points[a] - disk.center);
        if (da == 0.0 && n < slice.size()) slice[n++] = points[a];
        for (std::size_t b = a + 1; b < points.size(); ++b) {
            const double db = glm::dot(disk.normal, points[b] - disk.center);
            if (((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) && n < slice.size())
                slice[n++] = points[a] + (points[b] - points[a]) * (da / (da - db));
        }
    }
    if (n == 0) return false;
    const std::array<Vec3, 1> c = {disk.center};
    return convex_distance(std::span<const Vec3>(slice.data(), n), c, disk.radius) <= disk.radius;
}

ShadowValue point_to_polygon_hidden_by_disk(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                            const FlatDisk& disk) {
    if (count < 3 || count > 16 || !(disk.radius > disk.inner_radius)) return {};
    PolygonCone cone;
    if (!polygon_cone(x, n, v, count, &cone)) return {};
    // The disk's plane cut by those planes: a square around the rim, clipped.
    Circle k;
    k.c = disk.center;
    k.n = disk.normal;
    k.e1 = unit_across(k.n);
    k.e2 = glm::cross(k.n, k.e1);
    const double half = 1.25 * disk.radius;
    Region g;
    constexpr double kCorner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (const auto& c : kCorner) g.v[g.n++] = k.c + half * (c[0] * k.e1 + c[1] * k.e2);
    for (int f = 0; f < cone.count && g.n >= 3; ++f)
        g = clip_half_space(g, cone.f[static_cast<std::size_t>(f)], x);
    if (g.n < 3) return {};
    k.rho = disk.radius;
    ContourValue total = disk_in_region(k, g, cone, x, n);
    if (disk.inner_radius > 0.0) {
        k.rho = disk.inner_radius;
        const ContourValue hole = disk_in_region(k, g, cone, x, n);
        total.value -= hole.value;
        total.error += hole.error;
    }
    // Counter-clockwise about the disk's normal is clockwise seen from its front side.
    const double sign = glm::dot(k.n, x - k.c) > 0.0 ? -1.0 : 1.0;
    const double open = point_to_polygon(x, n, v, count, nullptr);
    return {std::clamp(sign * total.value / (2.0 * kPi), 0.0, open), total.error / (2.0 * kPi)};
}

}  // namespace radiosa
