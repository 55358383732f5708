#pragma once
// Small scenes shared by the tests, built from YAML strings.
#include <string>

#include "scene/scene.h"

namespace radiosa::test {

// One quad surface as a YAML list item.
inline std::string quad(const std::string& name, const std::string& corners, int ns = 1, int nt = 1,
                        const std::string& rho = "[0, 0, 0]") {
    return "  - name: " + name + "\n    type: quad\n    corners: " + corners + "\n    patches: [" +
           std::to_string(ns) + ", " + std::to_string(nt) + "]\n    reflectance: " + rho + "\n";
}

inline Scene scene_of(const std::string& surfaces, bool closed = false) {
    return parse_scene(std::string("closed: ") + (closed ? "true" : "false") + "\nsurfaces:\n" + surfaces,
                       "test.yaml");
}

// Unit square in z = 0 facing +z, and its opposite at z = 1 facing -z.
inline const char* kFloor = "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]";
inline const char* kCeiling = "[[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]";
// Unit square in y = 0 facing +y, sharing the edge x in [0,1], y = z = 0 with kFloor.
inline const char* kWall = "[[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]";

}  // namespace radiosa::test
