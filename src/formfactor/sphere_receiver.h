#pragma once
// Form factors toward a patch of a sphere with the inner integral as a contour integral
// (formfactor/spherical_region.h) rather than a 2-D rule: curved-to-curved pairs such as nested
// spheres, which otherwise take the numeric path.
#include <optional>
#include <vector>

#include "formfactor/cubature.h"
#include "geometry/scene_geometry.h"
#include "util/gauss_legendre.h"

namespace radiosa {

// Nested spheres whose outer one is a single patch: A_i F_ij = A_j F_ji exactly (with its
// rounding estimate), or nothing when the pair is not of that kind.
std::optional<Estimate> nested_spheres(const SceneGeometry& g, int i, int j, const std::vector<int>& blockers,
                                       bool visibility);

// How the inner integral toward sphere patch j is cut out for a point x of patch i.
struct SphereReceiver {
    Vec3 center{0.0};
    double radius = 0.0;
    Mat3 axes{1.0};       // the receiver's Surface::sphere_axes
    bool inward = false;  // the receiver is the inside of its sphere
    // Both patches on the inside of one sphere, a ball concentric with it in between: the kernel
    // is the constant 1 / (4 pi R^2) and x sees all of the sphere but a cap around its antipode.
    bool same_sphere = false;
    double ball_radius = 0.0;
};

// Whether F_ij can take this path, and how: patch j lies on a sphere, x is strictly inside it
// (inward) or outside it (outward) for every point of patch i, and nothing can block but the two
// surfaces themselves where the cuts account for them (x's tangent plane, the receiver's visible
// cap), or, for two patches of the inside of one sphere, one ball concentric with it.
std::optional<SphereReceiver> sphere_receiver(const SceneGeometry& g, int i, int j,
                                              const std::vector<int>& blockers, bool visibility);

// A_i F_ij, the outer integral over patch i adaptive to tol x min(A_i, A_j), with the inner
// integral's error added; at most `max_regions` outer regions.
Estimate area_times_f_sphere(const SceneGeometry& g, int i, int j, const SphereReceiver& how, double tol,
                             const GaussRule& outer, int max_regions);

}  // namespace radiosa
