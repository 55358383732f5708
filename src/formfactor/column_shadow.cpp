#include "formfactor/column_shadow.h"

#include <algorithm>
#include <cmath>

#include "formfactor/convex_clip.h"
#include "formfactor/point_polygon.h"
#include "util/convex_distance.h"

namespace radiosa {

namespace {

// p projected along the axis onto the plane through the base.
Vec3 flatten(const Vec3& p, const RoundTube& t) { return p - glm::dot(p - t.base, t.axis) * t.axis; }

}  // namespace

bool column_wedge(const Vec3& p, const RoundTube& tube, std::array<Vec3, 2>* normals) {
    const Vec3 d = tube.base - flatten(p, tube);
    const double dist = glm::length(d);
    if (!(dist > tube.radius)) return false;
    const Vec3 u = d / dist, w = glm::cross(tube.axis, u);
    const double sa = tube.radius / dist, ca = std::sqrt(std::max(0.0, 1.0 - sa * sa));
    (*normals)[0] = sa * u - ca * w;
    (*normals)[1] = sa * u + ca * w;
    return true;
}

double point_to_polygon_hidden_by_column(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                         const RoundTube& tube) {
    if (count < 3 || count > 16) return 0.0;
    std::array<Vec3, 2> h;
    if (!column_wedge(x, tube, &h)) return 0.0;
    PolygonBuffer<20> p;
    for (int k = 0; k < count; ++k) p.v[p.n++] = v[k];
    for (const Vec3& m : h) {
        p = clip_half_space(p, m, x);
        if (p.n < 3) return 0.0;
    }
    return point_to_polygon(x, n, p.v.data(), p.n, nullptr);
}

bool column_spans_pair(std::span<const Vec3> a, std::span<const Vec3> b, const RoundTube& tube,
                       double margin) {
    std::array<Vec3, 24> hull;
    std::size_t nh = 0;
    for (std::span<const Vec3> s : {a, b})
        for (const Vec3& p : s) {
            const double h = glm::dot(p - tube.base, tube.axis);
            if (!(h >= -margin && h <= tube.length + margin)) return false;
        }
    // a's projection clear of the circle: the centre farther from it than the radius (a floor
    // patch around the column's foot holds the circle, though every edge keeps clear of it).
    for (const Vec3& p : a)
        if (nh < hull.size()) hull[nh++] = flatten(p, tube);
    const std::array<Vec3, 1> centre = {tube.base};
    if (!(convex_distance(std::span<const Vec3>(hull.data(), nh), centre, tube.radius + margin) >
          tube.radius + margin))
        return false;
    // The circle inside the 16-gon whose edges touch it.
    const Vec3 e1 = glm::normalize(std::abs(tube.axis.x) < 0.9 ? glm::cross(tube.axis, Vec3(1, 0, 0))
                                                               : glm::cross(tube.axis, Vec3(0, 1, 0)));
    const Vec3 e2 = glm::cross(tube.axis, e1);
    const double r = tube.radius / std::cos(kPi / 16);
    for (int k = 0; k < 16 && nh < hull.size(); ++k)
        hull[nh++] = tube.base + r * (std::cos(kPi / 8 * k) * e1 + std::sin(kPi / 8 * k) * e2);
    std::array<Vec3, 8> flat_b;
    std::size_t nb = 0;
    for (const Vec3& p : b)
        if (nb < flat_b.size()) flat_b[nb++] = flatten(p, tube);
    return convex_distance(std::span<const Vec3>(hull.data(), nh), std::span<const Vec3>(flat_b.data(), nb),
                           margin) > margin;
}

bool hull_meets_column(std::span<const Vec3> points, const RoundTube& tube) {
    std::array<Vec3, 16> flat;
    std::size_t n = 0;
    for (const Vec3& p : points)
        if (n < flat.size()) flat[n++] = flatten(p, tube);
    const std::array<Vec3, 1> c = {tube.base};
    return convex_distance(std::span<const Vec3>(flat.data(), n), c, tube.radius) <= tube.radius;
}

}  // namespace radiosa
