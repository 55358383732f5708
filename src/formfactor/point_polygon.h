#pragma once
// Closed forms for the form factor from a point to a planar polygon, the inner integral of
// the semi-analytic method. With unit directions w on the sphere around the point x,
//   F(dx -> region) = 1/pi  * integral over the region of (n . w) dw
//                   = 1/(2 pi) * contour integral over its boundary of n . (w x dw)
// (Stokes; Lambert's formula when the boundary is made of great-circle arcs). The region is
// the polygon's projection, cut to x's front hemisphere; optionally minus the cone of
// directions blocked by one sphere (its boundary is a small circle, integrated in closed form).
#include <array>
#include <vector>

#include "util/math.h"

namespace radiosa {

// Form factor from the point x with unit normal n to the polygon v[0..count-1] (planar,
// convex, counter-clockwise about its front normal). Zero when x is not on the polygon's
// front side. `blocker`, if given, is a sphere that x is outside of, lying wholly between x
// and the polygon's plane; the directions it covers are taken out.
double point_to_polygon(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                        const BoundingSphere* blocker);

// The part of that form factor the blocker takes away: point_to_polygon(..., nullptr) minus
// point_to_polygon(..., &blocker), computed on its own (no cancellation), in [0, unblocked].
double point_to_polygon_blocked(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                const BoundingSphere& blocker);

// The part of point_to_polygon(x, n, v, count, nullptr) that several balls hide together, their
// shadows free to overlap: Lambert's integral over the polygon's projection cut to the union of
// the balls' cones of directions, whose boundary is the arcs of each cone's circle that lie inside
// the polygon and outside every other cone, and the parts of the polygon's edges inside some
// cone. Each ball must lie wholly between x and the polygon's plane, x outside it (as for
// point_to_polygon's blocker); the same ball given twice counts once. One ball is
// point_to_polygon_blocked to the bit. In [0, unblocked].
inline constexpr std::size_t kMaxBallUnion = 32;
double point_to_polygon_blocked_by_balls(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                         const BoundingSphere* balls, int ball_count);

// The part of point_to_polygon(x, n, v, count, nullptr) that planar convex quads hide: each
// occluder's part between x and the polygon's plane, projected from x onto that plane, cut to
// the polygon; their union by inclusion and exclusion (at most kMaxFlatOccluders). Exact: the
// visible part of a polygon behind flat occluders is a polygon (minus polygons).
inline constexpr std::size_t kMaxFlatOccluders = 4;
double point_to_polygon_hidden(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                               const std::vector<std::array<Vec3, 4>>& occluders);

}  // namespace radiosa
