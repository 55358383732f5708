#pragma once
// What a whole spherical cap (a dome, a bowl: a sphere cut by a plane, open on that side) hides
// of a polygon, seen from a point outside its solid, in closed form.
//
// The cap's solid, the ball cut by the rim's plane, is convex, and a line that meets it crosses
// its boundary twice, at most once on the flat open end: so every segment between two points
// outside the solid that meets the solid meets the cap. Seen from x the cap hides the cone over
// the solid, whose outline is made of two circles on the sphere: the ball's silhouette seen from
// x (the contact circle, where the view is tangent) where it lies on the cap, and the rim where
// it is a silhouette of the solid (seen from the rim plane's closed side, the rim's part that
// faces x; from its open side, the part that faces away). They meet where the contact circle
// crosses the rim; from inside the ball (below the rim plane) the outline is the whole rim. The
// polygon's cone cuts that outline and its contour integral gives the form factor
// (formfactor/outline.h).
#include <span>

#include "formfactor/polygon_cone.h"
#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

// The part of point_to_polygon(x, n, v, count, nullptr) that the cap hides. The cap's solid
// must lie wholly on the polygon's front side (then every direction to it meets the cap before
// the polygon's plane) and x outside the solid; the polygon is planar and convex,
// counter-clockwise about its front normal, with at most 16 vertices.
ShadowValue point_to_polygon_hidden_by_cap(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                           const SphericalCap& cap);

// The least signed distance of the cap's solid from the plane (unit normal m, offset o): the
// ball's lowest point when it lies on the cap, else the rim's.
double cap_min_signed_distance(const SphericalCap& cap, const Vec3& m, double o);

// Whether the convex hull of the points (at most 8) meets the cap's solid: the sliver search's
// "may a segment in this hull meet the cap?".
bool hull_meets_cap(std::span<const Vec3> points, const SphericalCap& cap);

// The cap's open end, the disk its rim bounds (the shadow's outline bends where the rim passes
// a corner of the polygon or touches an edge's plane: formfactor/events.h).
FlatDisk cap_rim(const SphericalCap& cap);

}  // namespace radiosa
