#pragma once
// Form factors toward a patch whose boundary is made of segments and circle arcs (a disk sector,
// a cylinder patch: Surface::patch_contour), with the inner integral as a contour integral:
//   F(dx -> j) = -1/(2 pi) contour integral over j's boundary of n . (r x dr) / |r|^2,
// valid when every point x of patch i sees all of j from its front, in front of x's tangent
// plane and with nothing in between (contour_receiver checks that). The segments are Lambert's
// terms, the arcs formfactor/circle_arc.h; the outer integral over patch i is adaptive. Curved
// pairs that touch (a disk's rim on a tube) thus converge like touching polygons, where the
// 4-D rule stalls.
#include <optional>
#include <vector>

#include "formfactor/circle_arc.h"
#include "formfactor/cubature.h"
#include "geometry/scene_geometry.h"
#include "util/gauss_legendre.h"

namespace radiosa {

// F(dx -> region) for the point x with unit normal n; the pieces run counter-clockwise about
// the region's front normal. `tol` is shared out among the arcs.
ContourValue point_to_contour(const Vec3& x, const Vec3& n, const std::vector<ContourPiece>& pieces,
                              double tol);

// Whether patch p lies in the convex solid whose boundary holds surface k (Surface::convex_solid),
// proven exactly where the built-in types allow; true for k's own patches.
bool inside_solid(const SceneGeometry& g, const Patch& p, int k);

struct ContourReceiver {
    std::vector<ContourPiece> pieces;  // patch j's boundary
    // A patch of a concave surface toward itself: x lies inside the region, whose image on the
    // sphere of directions is then bounded by x's whole horizon as well; that great circle adds 1.
    bool contains_x = false;
};

// Whether F_ij can take this path: j has a contour; every point of patch i lies on j's front
// side with all of j in front of its own tangent plane; and nothing can block: the blockers left
// are the pair's own surfaces or convex solids' boundaries holding both patches.
std::optional<ContourReceiver> contour_receiver(const SceneGeometry& g, int i, int j,
                                                const std::vector<int>& blockers, bool visibility);

// A_i F_ij with the contour inner integral, to tol x min(A_i, A_j) like the other paths.
Estimate area_times_f_contour(const SceneGeometry& g, int i, int j, const ContourReceiver& how, double tol,
                              const GaussRule& outer, int max_regions);

}  // namespace radiosa
