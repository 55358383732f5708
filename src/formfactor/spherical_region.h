#pragma once
// Regions of a sphere cut out by half-spaces, and their form factors seen from a point as
// contour integrals: the inner integral of the form factor toward a sphere patch
// (formfactor/sphere_receiver.cpp). A sphere patch (a latitude-longitude rectangle), the part
// of it in front of a point's tangent plane, the part a point outside the sphere can see and
// the part a concentric ball does not hide are each cut out by planes, so their boundaries are
// arcs of circles. With unit directions w around the point x,
//   F(dx -> region) = 1/pi integral over the region's directions of (n . w) dw
//                   = -1/(2 pi) contour integral over its boundary of n . (r x dr) / |r|^2
// (Stokes; the boundary run counter-clockwise about the region's front normal, r = y - x),
// which holds whenever every ray from x meets the region at most once, from its front, and
// only in front of x: the cuts must say so. Each arc is integrated by adaptive Gauss-Kronrod.
#include <vector>

#include "formfactor/circle_arc.h"
#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

struct HalfSpace {
    Vec3 normal;    // any length
    double offset;  // the half-space normal . y >= offset
};

struct SphericalRegion {
    Vec3 center{0.0};
    double radius = 1.0;
    double front = 1.0;  // +1: the front normal points out of the sphere, -1: into it
    Mat3 axes{1.0};      // columns: the sphere's local x, y, z (add_patch_cuts)
    std::vector<HalfSpace> cuts;
};

// Adds the cuts of the latitude-longitude rectangle of azimuths [phi0, phi1] and polar angles
// [theta_min, theta_max] (from local +z) about the region's axes. The azimuth span 2 pi (s1 -
// s0) must be at most pi / 2 (split wider patches).
void add_patch_cuts(SphericalRegion* region, double phi0, double phi1, double theta_min, double theta_max);
// The same for the parameter rectangle [s0, s1] x [t0, t1] of spherical surface s
// (Surface::sphere_angles).
void add_patch_cuts(SphericalRegion* region, const Surface& s, double s0, double s1, double t0, double t1);

// F(dx -> region) for the point x with unit normal n (see above for when it holds), to the
// absolute tolerance `tol` (or the rounding level, whichever is larger).
ContourValue point_to_spherical_region(const Vec3& x, const Vec3& n, const SphericalRegion& region,
                                       double tol = 1e-15);

// The region's area. `away` is a point of the sphere well away from the region (the antipode of
// a point inside it): the area is 4 pi R^2 times the form factor from there, where the kernel
// is the constant 1 / (4 pi R^2).
// `tol` is relative to the sphere's area.
ContourValue spherical_region_area(const SphericalRegion& region, const Vec3& away, double tol = 1e-15);

}  // namespace radiosa
