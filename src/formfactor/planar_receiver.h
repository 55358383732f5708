#pragma once
// Form factors toward a planar patch (a polygon) with the inner integral in closed form: the
// point-to-polygon formula (Lambert's), minus what occluders hide. The occluders this path
// accepts are whole balls, their shadows overlapping or not (formfactor/point_polygon.h); disks
// or annuli (disk_shadow.h), round tubes or cones (tube_shadow.h) and spherical caps
// (cap_shadow.h) whose shadows never overlap as seen from the source patch, so that the parts
// they hide add up; a few flat convex quads (their
// shadows on the polygon are polygons); one column spanning the pair (column_shadow.h); and,
// from the inside of a tube or a cap, its open ends. Between two polygons with occluders the
// unblocked exchange is the contour integral and only the shadow is integrated over the source
// patch. The outer integral is adaptive, cut along shadow edges and horizons
// (formfactor/events.h).
#include <array>
#include <optional>
#include <vector>

#include "formfactor/cubature.h"
#include "formfactor/point_polygon.h"
#include "formfactor/shadow_occluder.h"
#include "geometry/scene_geometry.h"
#include "util/gauss_legendre.h"

namespace radiosa {

// What may block the pair on this path (one of the fields is set; none when nothing can):
// balls (their shadows added up when they never overlap as seen from patch i), a few
// flat quads, or one of the cases below.
struct PlanarReceiver {
    std::vector<BoundingSphere> spheres;
    // The balls' shadows may overlap as seen from patch i: what they hide is taken together
    // (point_to_polygon_blocked_by_balls), not added up.
    bool spheres_overlap = false;
    std::vector<std::array<Vec3, 4>> flats;  // each occluder's outline
    // One flat disk or annulus (both sides of a two-sided one are the same disk), wholly in
    // front of both patches' planes: its shadow is in closed form (formfactor/disk_shadow.h).
    std::optional<FlatDisk> disk;
    // One round tube spanning the pair (formfactor/column_shadow.h): a column from floor to
    // ceiling between two walls; its shadow is a polygon.
    std::optional<RoundTube> column;
    // Patch i lies on the inside of a whole round tube or spherical cap, and that surface is
    // all that may block: from inside, the polygon is seen through its open ends (a tube's two
    // rims, a cap's one), each a disk whose cone cuts the polygon in closed form
    // (formfactor/disk_shadow.h).
    std::vector<FlatDisk> openings;
    // Occluders with closed-form shadows between two polygons, each wholly in front of both
    // planes: one whole round tube (a cylinder that does not span them, or a truncated cone:
    // formfactor/tube_shadow.h) or spherical cap (formfactor/cap_shadow.h), or several balls,
    // disks, tubes and caps whose shadows never overlap as seen from patch i (shadows_apart on
    // their bounding balls): the parts they hide add up.
    std::vector<ShadowOccluder> apart;
};

// At most this many balls between a pair (their union: point_to_polygon_blocked_by_balls), and at
// most this many mixed occluders whose shadows never overlap (`apart`).
inline constexpr std::size_t kMaxShadowBalls = kMaxBallUnion;
inline constexpr std::size_t kMaxApartOccluders = 8;

// Whether F_ij can take this path: j must be planar and nothing may block the pair except balls
// that lie wholly between patch i and j's plane, patch i outside them (at most kMaxShadowBalls;
// their shadows may overlap), or at most kMaxFlatOccluders planar convex quads, or one whole flat disk
// or annulus lying wholly in front of both patches (patch i planar too: a polygon or a disk's),
// or one whole round tube between two polygons (spanning them, or in front of both), or one
// whole spherical cap in front of both, or several of those (balls, disks, tubes, caps) in front
// of both whose shadows from patch i never overlap, or patch i lies inside the one tube or cap
// that may block and sees the polygon through its open ends. `blockers`
// are the pair's possible occluders (Culling::occluders); with `visibility` off they are ignored.
std::optional<PlanarReceiver> planar_receiver(const SceneGeometry& g, int i, int j,
                                              const std::vector<int>& blockers, bool visibility);

// A_i F_ij with the closed-form inner integral; error estimate on the same scale. The target
// is tol x min(A_i, A_j), not tol x A_i: the energy two patches exchange is then accurate to
// tol times what the smaller one sends, so a big patch's entry for a tiny emitter (a 1e-8
// spark of radiosity 1e8) is as good as the emitter's own row. `eps`: lengths below it are zero
// at the scene's scale (Culling::eps).
Estimate area_times_f_planar(const SceneGeometry& g, int i, int j, const PlanarReceiver& how, double tol,
                             const GaussRule& outer, int max_regions, double eps);

}  // namespace radiosa
