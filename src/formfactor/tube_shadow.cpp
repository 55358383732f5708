#include "formfactor/tube_shadow.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "formfactor/circle_arc.h"
#include "formfactor/disk_shadow.h"
#include "formfactor/outline.h"
#include "formfactor/point_polygon.h"
#include "formfactor/polygon_cone.h"
#include "util/convex_distance.h"

namespace radiosa {

namespace {

// How the tube looks from x: x between the end planes or beyond one (the near rim, 0 at the
// base), outside the solid's section at x's height (between the planes) or not, at angle phi
// about the axis (from unit_across(axis)); the silhouette generators at phi +- beta. From beyond an end:
// which rim's cone holds the other's, if one does (`holds`: 0 none, 1 the near one's, 2 the far
// one's); whether the rims' cones cross (the lens of directions through both ends) and where:
// at phi +- lens_near on the near rim, phi + pi +- lens_far on the far one.
struct TubeView {
    bool between = false, outside = false, lens = false;
    int near = 0, holds = 0;
    double phi = 0.0, beta = 0.0, lens_near = 0.0, lens_far = 0.0;
};

TubeView tube_view(const Vec3& x, const RoundFrustum& tube) {
    TubeView out;
    const Vec3 e1 = unit_across(tube.axis), e2 = glm::cross(tube.axis, e1);
    // x's height along the axis, and its offset from the axis: distance D at angle phi.
    const double h = glm::dot(x - tube.base, tube.axis);
    const Vec3 off = x - tube.base - h * tube.axis;
    const double D = glm::length(off);
    out.phi = std::atan2(glm::dot(off, e2), glm::dot(off, e1));
    out.between = h >= 0.0 && h <= tube.length;
    out.near = h > tube.length ? 1 : 0;
    if (out.between) {
        // The silhouette generators touch the planes through x along them: cos(u - phi) D = the
        // section's radius at x's height.
        const double rh = tube.radius_at(h);
        out.outside = D > rh;
        out.beta = out.outside ? std::acos(rh / D) : 0.0;
        return out;
    }
    // The far rim seen from x on the near rim's plane: scaled by t about x's foot (distance D
    // from the near centre), so its centre lies (1 - t) D from the near centre toward x's foot,
    // with radius t r_far. Two circles: one holds the other, or the outer tangents (at the same
    // angle on both, as the silhouette generators are) and perhaps a lens.
    const double hn = h < 0.0 ? -h : h - tube.length, t = hn / (hn + tube.length);
    const double r1 = out.near ? tube.top_radius : tube.radius,
                 r2 = t * (out.near ? tube.radius : tube.top_radius);
    const double d = (1.0 - t) * D;
    if (d + r2 <= r1) {
        out.holds = 1;
        return out;
    }
    if (d + r1 <= r2) {
        out.holds = 2;
        return out;
    }
    out.outside = true;
    out.beta = std::acos(std::clamp((r1 - r2) / d, -1.0, 1.0));
    out.lens = d < r1 + r2;
    if (out.lens) {
        const double a = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
        out.lens_near = r1 > 0.0 ? std::acos(std::clamp(a / r1, -1.0, 1.0)) : 0.0;
        out.lens_far = r2 > 0.0 ? std::acos(std::clamp((d - a) / r2, -1.0, 1.0)) : 0.0;
    }
    return out;
}

}  // namespace

std::array<FlatDisk, 2> tube_rims(const RoundFrustum& tube) {
    return {FlatDisk{tube.base, tube.axis, tube.radius, 0.0},
            FlatDisk{tube.base + tube.length * tube.axis, tube.axis, tube.top_radius, 0.0}};
}

double tube_min_signed_distance(const RoundFrustum& tube, const Vec3& m, double o) {
    const auto rims = tube_rims(tube);
    return std::min(disk_min_signed_distance(rims[0], m, o), disk_min_signed_distance(rims[1], m, o));
}

bool hull_meets_tube(std::span<const Vec3> points, const RoundFrustum& tube) {
    // The hull's part between the end planes is the hull of its points there and of where the
    // segments between its points cross those planes. Along the axis (a cylinder), or from the
    // apex (a cone, whose apex lies beyond the slab, or on an end for a pointed cone: the slab
    // then stops a hair short of it), that part projects onto the wider rim's plane as a convex
    // set, which meets the rim's disk exactly when the hull meets the solid.
    const bool cone = tube.top_radius != tube.radius, wide_top = tube.top_radius > tube.radius;
    const double apex = cone ? tube.length * tube.radius / (tube.radius - tube.top_radius) : 0.0;
    const double ref = wide_top ? tube.length : 0.0, r = std::max(tube.radius, tube.top_radius);
    const double bottom = tube.radius > 0.0 ? 0.0 : 1e-9 * tube.length;
    const double top = tube.top_radius > 0.0 ? tube.length : tube.length * (1.0 - 1e-9);
    std::array<Vec3, 80> slice;
    std::size_t n = 0;
    const Vec3 centre = tube.base + ref * tube.axis;
    const auto height = [&](const Vec3& p) { return glm::dot(p - tube.base, tube.axis); };
    const auto project = [&](const Vec3& p) {
        const double h = height(p);
        const Vec3 flat = p - h * tube.axis - tube.base;  // from the axis
        return centre + (cone ? (ref - apex) / (h - apex) : 1.0) * flat;
    };
    for (std::size_t a = 0; a < points.size(); ++a) {
        const double ha = height(points[a]);
        if (ha >= bottom && ha <= top && n < slice.size()) slice[n++] = project(points[a]);
        for (std::size_t b = a + 1; b < points.size(); ++b) {
            const double hb = height(points[b]);
            for (const double level : {bottom, top})
                if (((ha < level && hb > level) || (ha > level && hb < level)) && n < slice.size())
                    slice[n++] = project(points[a] + (points[b] - points[a]) * ((level - ha) / (hb - ha)));
        }
    }
    if (n == 0) return false;
    const std::array<Vec3, 1> c = {centre};
    return convex_distance(std::span<const Vec3>(slice.data(), n), c, r) <= r;
}

ShadowValue point_to_polygon_hidden_by_tube(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                            const RoundFrustum& tube) {
    if (count < 3 || count > 16 || !(tube.radius >= 0.0) || !(tube.top_radius >= 0.0) ||
        !(tube.radius + tube.top_radius > 0.0) || !(tube.length > 0.0))
        return {};
    PolygonCone cone;
    if (!polygon_cone(x, n, v, count, &cone)) return {};
    std::array<Circle, 2> rims;
    for (int k = 0; k < 2; ++k) {
        rims[static_cast<std::size_t>(k)] = circle_about(tube.base + (k ? tube.length : 0.0) * tube.axis,
                                                         tube.axis, k ? tube.top_radius : tube.radius);
    }
    const TubeView view = tube_view(x, tube);
    const double phi = view.phi, beta = view.beta;
    Outline hull, lens;
    if (view.between) {
        // Between the end planes: the front part (x outside the solid's section at its height,
        // else x is in the solid).
        if (!view.outside) return {};
        hull.arc(rims, 0, phi - beta, phi + beta);
        hull.segment(rims[0].at(phi + beta), rims[1].at(phi + beta));
        hull.arc(rims, 1, phi + beta, phi - beta);
        hull.segment(rims[1].at(phi - beta), rims[0].at(phi - beta));
    } else if (view.holds) {
        // One rim's cone holds the other's (for a cylinder: x within it): that rim's disk, minus
        // the other's seen through it.
        const int outer = view.holds == 1 ? view.near : 1 - view.near;
        hull.arc(rims, outer, 0.0, 2.0 * kPi);
        lens.arc(rims, 1 - outer, 0.0, 2.0 * kPi);
    } else {
        const int near = view.near, far = 1 - near;
        hull.arc(rims, near, phi + beta, phi - beta + 2.0 * kPi);
        hull.segment(rims[near].at(phi - beta), rims[far].at(phi - beta));
        hull.arc(rims, far, phi - beta, phi + beta);
        hull.segment(rims[far].at(phi + beta), rims[near].at(phi + beta));
        if (view.lens) {
            lens.arc(rims, near, phi - view.lens_near, phi + view.lens_near);
            lens.arc(rims, far, phi + kPi - view.lens_far, phi + kPi + view.lens_far);
        }
    }
    ShadowValue out = outline_inside_cone(hull, cone, x, n, rims);
    if (lens.n > 0) {
        const ShadowValue through = outline_inside_cone(lens, cone, x, n, rims);
        out.value -= through.value;
        out.error += through.error;
    }
    const double open = point_to_polygon(x, n, v, count, nullptr);
    out.value = std::clamp(out.value, 0.0, open);
    return out;
}

}  // namespace radiosa
