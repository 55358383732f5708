#pragma once
// The distance between the convex hulls of two small point sets, by the Gilbert-Johnson-
// Keerthi iteration on their Minkowski difference (Gilbert, Johnson & Keerthi 1988; the
// sub-simplex search done by enumeration, which for at most four points is cheap and robust).
// Used to prove that nothing can come between two patches: every segment between two convex
// patches lies in the hull of their corners, so an occluder whose hull keeps a positive
// distance from it (a sphere: a distance above its radius) blocks none of them.
#include <array>
#include <span>

#include "util/math.h"

namespace radiosa {

// A lower bound on the distance between hull(a) and hull(b), exact to rounding when the
// iteration converges; returns as soon as the bound exceeds `enough` (the caller's question is
// "is it more than this?"). 0 when the hulls meet.
double convex_distance(std::span<const Vec3> a, std::span<const Vec3> b, double enough);

// Distance from x to the segment [a, b].
double distance_to_segment(const Vec3& x, const Vec3& a, const Vec3& b);

// Distance from x to a convex planar quadrilateral (either winding).
double distance_to_polygon(const Vec3& x, const std::array<Vec3, 4>& v);

}  // namespace radiosa
