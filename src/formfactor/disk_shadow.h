#pragma once
// What a flat disk or annulus hides of a polygon, seen from a point: the inner integral of a
// form factor between two planar patches with a disk between them (a table top, a lamp, a
// plate), in closed form. Seen from x the disk covers the cone over its rim, and the polygon
// the cone over its edges; the form factor of the directions in both is the contour integral
// 1/(2 pi) of n . (r x dr) / |r|^2 around their common part (point_polygon.h), and that integral
// does not change when its path moves along rays from x. So the path is taken where the cones
// meet the disk's plane: the disk cut by the planes through x and the polygon's edges, a convex
// region bounded by straight segments (Lambert's closed form) and arcs of the rim
// (circle_arc.h). An annulus is its outer disk minus its hole.
#include <span>

#include "formfactor/polygon_cone.h"
#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

// The part of point_to_polygon(x, n, v, count, nullptr) that the disk hides. The disk must lie
// wholly on the polygon's front side and in x's front half-space n . (y - x) > 0 (then every
// direction to it meets the disk before the polygon's plane); the polygon is planar and convex,
// counter-clockwise about its front normal, with at most 16 vertices.
ShadowValue point_to_polygon_hidden_by_disk(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                            const FlatDisk& disk);

// The least signed distance of the disk's points from the plane (unit normal m, offset o):
// m . center - o - radius sqrt(1 - (m . normal)^2).
double disk_min_signed_distance(const FlatDisk& disk, const Vec3& m, double o);

// Whether the convex hull of the points meets the disk (annulus holes included): the hull's
// slice by the disk's plane, the hull of where the points' segments cross it, within the
// radius of the centre.
bool hull_meets_disk(std::span<const Vec3> points, const FlatDisk& disk);

}  // namespace radiosa
