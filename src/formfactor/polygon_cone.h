#pragma once
// The cone of directions from a point x to the part of a convex polygon in front of x's
// tangent plane, as the planes through x and that part's edges, and Lambert's term of a
// straight piece of a contour: what the closed-form shadows (disk_shadow.cpp, tube_shadow.cpp)
// cut their outlines with and integrate their chords by, and the value they return.
#include <array>
#include <cmath>

#include "formfactor/convex_clip.h"
#include "util/math.h"

namespace radiosa {

// What a closed-form shadow hides of a polygon seen from a point.
struct ShadowValue {
    double value = 0.0;  // form factor hidden, in [0, the unblocked point_to_polygon]
    double error = 0.0;  // the rim arcs' quadrature, where they took it
};

struct PolygonCone {
    static constexpr int kMaxEdges = 20;  // a polygon of up to 16 vertices, cut by x's horizon
    std::array<Vec3, kMaxEdges> f{};      // the planes' normals, pointing into the cone
    int count = 0;
    bool inside(const Vec3& x, const Vec3& p) const {
        for (int k = 0; k < count; ++k)
            if (glm::dot(f[static_cast<std::size_t>(k)], p - x) < 0.0) return false;
        return true;
    }
};

// The cone from x (unit normal n) over the polygon v[0..count-1] (at most 16 vertices) cut to
// x's front half-space; false when less than a polygon of it is left there.
inline bool polygon_cone(const Vec3& x, const Vec3& n, const Vec3* v, int count, PolygonCone* cone) {
    PolygonBuffer<PolygonCone::kMaxEdges> poly;
    for (int k = 0; k < count; ++k) poly.v[static_cast<std::size_t>(poly.n++)] = v[k];
    poly = clip_half_space(poly, n, x);
    if (poly.n < 3) return false;
    // The planes through x and the visible part's edges, turned toward its centroid.
    Vec3 mid(0.0);
    for (int k = 0; k < poly.n; ++k) mid += poly.v[static_cast<std::size_t>(k)] - x;
    cone->count = 0;
    for (int k = 0; k < poly.n; ++k) {
        Vec3 f = glm::cross(poly.v[static_cast<std::size_t>(k)] - x,
                            poly.v[static_cast<std::size_t>((k + 1) % poly.n)] - x);
        if (!(glm::length(f) > 0.0)) continue;
        if (glm::dot(f, mid) < 0.0) f = -f;
        cone->f[static_cast<std::size_t>(cone->count++)] = f;
    }
    return true;
}

// Lambert's term of the straight segment a -> b seen from x: its angle times n . the unit
// normal of its great circle (only the directions from x to a and b matter).
inline double segment_term(const Vec3& x, const Vec3& n, const Vec3& a, const Vec3& b) {
    const Vec3 ra = a - x, rb = b - x;
    const Vec3 cr = glm::cross(ra, rb);
    const double l = glm::length(cr);
    if (!(l > 0.0)) return 0.0;
    return std::atan2(l, glm::dot(ra, rb)) * glm::dot(n, cr) / l;
}

}  // namespace radiosa
