#pragma once
// What a round column hides of a polygon, seen from a point, when the column spans the pair: a
// tube from floor to ceiling between two walls. Between its end planes a tube blocks exactly
// what the infinite cylinder blocks (a segment between two points of the slab that enters the
// solid cylinder crosses its side), and from x that is the wedge between the two planes through
// x along the axis tangent to the cylinder, beyond the cylinder. When the polygon lies beyond
// the cylinder wherever it is in the wedge, the hidden part is the polygon cut by the wedge's
// two planes: Lambert's formula on that polygon (point_polygon.h), exact.
#include <array>
#include <span>

#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

// The part of point_to_polygon(x, n, v, count, nullptr) that the tube hides. The caller
// guarantees (column_spans_pair) that x and the polygon lie within the tube's slab and that
// the polygon, projected along the axis, keeps clear of the hull of x's projection and the
// cylinder's circle; x lies outside the cylinder.
double point_to_polygon_hidden_by_column(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                         const RoundTube& tube);

// The two planes through p along the axis that touch the cylinder, as inward normals of the
// wedge they bound (toward the axis): nothing when p is within `margin` of the cylinder.
bool column_wedge(const Vec3& p, const RoundTube& tube, std::array<Vec3, 2>* normals);

// Whether the tube spans the pair of polygons a (the source) and b for the closed form above:
// every corner of both within the tube's slab (to `margin`), and b's projection along the axis
// clear, by `margin`, of the hull of a's projection and the cylinder's circle (so wherever b is
// in the wedge from a point of a, it is beyond the cylinder).
bool column_spans_pair(std::span<const Vec3> a, std::span<const Vec3> b, const RoundTube& tube,
                       double margin);

// Whether the hull of the points, projected along the axis, meets the cylinder's circle: the
// sliver search's "may a segment in this hull meet the column?" (the slab is not asked).
bool hull_meets_column(std::span<const Vec3> points, const RoundTube& tube);

}  // namespace radiosa
