#pragma once
// Display of patch radiosities (Cohen & Greenberg 1985, as in the paper): each node takes
// the mean radiosity of the patches of its surface around it, and a point is shaded by
// bilinear interpolation of its patch's four nodes at its parametric coordinates.
#include <vector>

#include "geometry/scene_geometry.h"
#include "util/math.h"

namespace radiosa {

class NodeRadiosity {
public:
    NodeRadiosity(const SceneGeometry& geometry, const std::vector<Rgb>& B);
    Rgb shade(const Hit& hit) const;
    // Node (a, b) of surface k, a in [0, ns], b in [0, nt].
    const Rgb& node(int k, int a, int b) const;

private:
    const SceneGeometry& m_geo;
    std::vector<std::vector<Rgb>> m_nodes;  // per surface, (ns+1) x (nt+1), row-major in b
};

}  // namespace radiosa
