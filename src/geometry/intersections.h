#pragma once
// Surfaces that pass through each other. Radiosity assumes surfaces meet at most along their
// edges: where one cuts through another, the parts inside still exchange energy through it, so
// closure and the energy balance no longer mean what they say. Detected exactly for the pairs
// of types whose shape is known in closed form (planar convex polygons and whole spheres);
// touching (a shared edge, a wall standing on a floor, a tangent sphere) is not intersecting.
#include <string>
#include <vector>

namespace radiosa {

class SceneGeometry;

struct SurfaceIntersection {
    int a = -1, b = -1;  // surface indices, a < b
};

std::vector<SurfaceIntersection> find_intersections(const SceneGeometry& geometry);

// "'ball' and 'floor'", "'a' and 'b', 'c' and 'd'": the pairs, for a message.
std::string intersection_names(const SceneGeometry& geometry, const std::vector<SurfaceIntersection>& found);
// The warning: which surfaces, what it does to the results, what to do.
std::string intersection_warning(const SceneGeometry& geometry,
                                 const std::vector<SurfaceIntersection>& found);

}  // namespace radiosa
