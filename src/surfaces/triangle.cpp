// The `triangle` surface type: a quad whose last two corners coincide, P(s, t) = c0 + s(1 - t)(c1 - c0)
// + t(c2 - c0): flat, its patches the polygons of their corners, the edge t = 1 collapsed to c2 (a
// pole). Mesh faces with three corners are these (mesh.cpp).
#include "surfaces/quad.h"
#include "surfaces/registry.h"

namespace radiosa {

std::shared_ptr<const Surface> make_triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
    return std::make_shared<QuadSurface>(a, b, c, c);
}

namespace {

// corners: [[x,y,z] x 3], counter-clockwise about the front side.
std::shared_ptr<const Surface> read_triangle(YamlMap& m, const std::string& name) {
    const YAML::Node list = m.required("corners");
    if (!list.IsSequence() || list.size() != 3)
        throw Error(loc_of(list, m.file()), "corners must be a list of 3 points [[x,y,z], ...]");
    Vec3 c[3];
    for (int k = 0; k < 3; ++k) c[k] = yaml_vec3(list[k], m.file(), "corners[" + std::to_string(k) + "]");
    const double size =
        std::max({glm::length(c[1] - c[0]), glm::length(c[2] - c[1]), glm::length(c[0] - c[2])});
    if (!(glm::length(glm::cross(c[1] - c[0], c[2] - c[0])) > 1e-12 * size * size))
        throw Error(loc_of(list, m.file()),
                    "triangle '" + name + "' is degenerate: its corners are collinear");
    return make_triangle(c[0], c[1], c[2]);
}

}  // namespace

extern const SurfaceType kTriangleType;
const SurfaceType kTriangleType = {
    .name = "triangle",
    .key_id = 7,
    .keys = "corners",
    .read = read_triangle,
    .example = {{"corners", "[[0, 0, 0], [1, 0, 0], [0, 1, 0]]"}},
    .variants = {{"corners", "[[0, 0, 0.5], [1, 0, 0], [0, 1, 0]]"},
                 {"corners", "[[0, 0, 0], [1.5, 0, 0], [0, 1, 0]]"},
                 {"corners", "[[0, 0, 0], [1, 0, 0], [0, 1.5, 0]]"},
                 {"corners", "[[0, 0, 0], [0, 1, 0], [1, 0, 0]]"}},
};

}  // namespace radiosa
