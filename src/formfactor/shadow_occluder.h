#pragma once
// Occluders whose shadow seen from a point is in closed form: a whole ball
// (formfactor/point_polygon.h), a flat disk or annulus (disk_shadow.h), a round tube or cone
// (tube_shadow.h) and a spherical cap (cap_shadow.h). When several of them never overlap as
// seen from a point, the parts they hide of a polygon add up (formfactor/planar_receiver.h
// between patches, formfactor/sensor.h from a sensor).
#include <array>
#include <optional>
#include <span>
#include <variant>
#include <vector>

#include "geometry/scene_geometry.h"
#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

using ShadowOccluder = std::variant<BoundingSphere, FlatDisk, RoundFrustum, SphericalCap>;

// Surface s as an occluder with a closed-form shadow, if it is one (a whole sphere, a whole
// disk, tube, cone or cap).
std::optional<ShadowOccluder> shadow_occluder(const Surface& s);

// What the occluder hides of the polygon v from x (unit normal n), and the arcs' quadrature
// error where they took it: the occluder must lie wholly on v's front side and in x's front
// half-space, x outside it.
double hidden_by(const ShadowOccluder& o, const Vec3& x, const Vec3& n, const std::array<Vec3, 4>& v,
                 double* error = nullptr);

// Whether its outline has corners (a tube's where its rims cross, a cap's where the ball's
// silhouette crosses the rim): then a kink counts like a flat occluder's.
bool has_corners(const ShadowOccluder& o);

// Whether the convex hull of the points meets the occluder (exactly).
bool hull_meets(std::span<const Vec3> hull, const ShadowOccluder& o);

// The least signed distance of the occluder from the plane (unit normal m, offset o).
double min_signed_distance(const ShadowOccluder& occ, const Vec3& m, double o);

// Whether two balls' shadows are apart from every point x of a patch in the ball `patch`
// (centre p, radius rho): from x, the directions to their centres must be further apart than
// the sum of the balls' angular radii. From x instead of p, the direction to a centre at
// distance L turns by at most asin(rho / L), and a ball of radius r looks at most
// asin(r / (L - rho)) wide.
bool shadows_apart(const BoundingSphere& patch, const BoundingSphere& a, const BoundingSphere& b);

// The surfaces `blockers` as occluders whose shadows never overlap as seen from any point of the
// ball `from` (a patch's bound, or a point: radius 0): each has a closed-form shadow
// (shadow_occluder), lies wholly in front of both planes by more than 1e-9 of the scene's size,
// and their bounding balls' shadows are apart (shadows_apart). The two sides of a two-sided
// surface are one occluder. nullopt when one of them is not such an occluder or two may overlap.
std::optional<std::vector<ShadowOccluder>> occluders_apart(const SceneGeometry& g,
                                                           const std::vector<int>& blockers,
                                                           const BoundingSphere& from, const Plane& a,
                                                           const Plane& b);

}  // namespace radiosa
