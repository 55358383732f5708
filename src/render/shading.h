#pragma once
// Display of patch radiosities (Cohen & Greenberg 1985, as in the paper): each node takes
// the mean radiosity of the patches of its surface around it, and a point is shaded by
// bilinear interpolation of its patch's four nodes at its parametric coordinates.
// One change from the paper: only the reflected part B - E is averaged and interpolated;
// a patch's own emission E is added unsmoothed. Emission is constant per patch by
// definition, and averaging it into the nodes smears a single emitting patch over its
// neighbours (the lit ceiling patch of image C would spread over the whole ceiling).
#include <vector>

#include "geometry/scene_geometry.h"
#include "util/math.h"

namespace radiosa {

class NodeRadiosity {
public:
    NodeRadiosity(const SceneGeometry& geometry, const std::vector<Rgb>& B, const std::vector<Rgb>& E);
    Rgb shade(const Hit& hit) const;
    // Reflected radiosity at node (a, b) of surface k, a in [0, ns], b in [0, nt].
    const Rgb& node(int k, int a, int b) const;

private:
    const SceneGeometry& m_geo;
    std::vector<std::vector<Rgb>> m_nodes;  // per surface, (ns+1) x (nt+1), row-major in b
    std::vector<Rgb> m_E;
};

}  // namespace radiosa
