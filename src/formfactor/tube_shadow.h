#pragma once
// What a whole round tube of finite length (a cylinder, or a truncated cone: a lamp shade) hides
// of a polygon, seen from a point outside its solid, in closed form: a column that does not span
// the pair, a pipe or a can without lids between two walls.
//
// The tube hides the directions that meet its solid, except those that pass through both open
// ends. Seen from x that is
//   - between the end planes: the cone over the tube's front part, bounded by the two
//     silhouette generators and the near arcs of both rims (no ray from between the planes
//     enters through an end);
//   - beyond an end plane: the hull of the two rims' cones (the near rim's far arc, the far
//     rim's near arc, the silhouette generators; one rim's whole disk when its cone holds the
//     other's) minus the lens of directions through both rims. Projected from x onto the near
//     rim's plane the far rim is a circle, so both are found from two circles in one plane.
// Each region is convex on the sphere of directions; the polygon's cone cuts it (planes through
// x), and its form factor is the contour integral 1/(2 pi) of n . (r x dr) / |r|^2 around it
// (point_polygon.h): Lambert's term on straight pieces, the closed-form arc integral on rim arcs
// (circle_arc.h). The integral does not change when a piece moves along rays from x, so the cut
// pieces are chords between the points where the outline crosses the cutting planes.
#include <array>
#include <span>

#include "formfactor/polygon_cone.h"
#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

// The part of point_to_polygon(x, n, v, count, nullptr) that the tube hides. The tube must lie
// wholly on the polygon's front side (then every direction to it meets the tube before the
// polygon's plane) and x outside its solid; the polygon is planar and convex,
// counter-clockwise about its front normal, with at most 16 vertices.
ShadowValue point_to_polygon_hidden_by_tube(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                            const RoundFrustum& tube);

// The least signed distance of the tube's points from the plane (unit normal m, offset o): the
// least of its two rims'.
double tube_min_signed_distance(const RoundFrustum& tube, const Vec3& m, double o);

// Whether the convex hull of the points (at most 8) meets the tube's solid: the sliver
// search's "may a segment in this hull meet the tube?".
bool hull_meets_tube(std::span<const Vec3> points, const RoundFrustum& tube);

// The tube's two rims as flat disks, the base's first (the shadow's outline bends where a rim
// passes a corner of the polygon or touches an edge's plane: formfactor/events.h).
std::array<FlatDisk, 2> tube_rims(const RoundFrustum& tube);

}  // namespace radiosa
