#pragma once
// Surfaces that pass through each other. Radiosity assumes surfaces meet at most along their
// edges: where one cuts through another, the parts inside still exchange energy through it, so
// closure and the energy balance no longer mean what they say. Detected exactly for the pairs
// of types whose shape is known in closed form (planar convex polygons and whole spheres);
// touching (a shared edge, a wall standing on a floor, a tangent sphere) is not intersecting.
// Other pairs (disks, tubes, cones, tori, partial spheres, Bezier patches, with any type) are
// sampled: each surface's isoparametric lines, as chords between 33 x 33 points, are tested
// against the other with its exact ray intersection; a crossing counts when it lies strictly
// inside both (not at a chord's end, not on the other's parameter boundary, where surfaces
// meet along an edge or a rim) and the chord passes through the other's tangent plane there
// (not touching it, as a ring resting on a floor). Surfaces made by one entry of the scene file (a type's
// parts, a back side) are not compared by sampling.
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
