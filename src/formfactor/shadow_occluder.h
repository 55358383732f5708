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

}  // namespace radiosa
