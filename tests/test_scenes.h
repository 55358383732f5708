#pragma once
// Small scenes shared by the tests, built from YAML strings.
#include <fmt/format.h>

#include <string>

#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "render/camera.h"
#include "render/raycast.h"
#include "render/shading.h"
#include "scene/scene.h"
#include "schedule/sequence.h"
#include "solve/solver.h"

namespace radiosa::test {

// One quad surface as a YAML list item.
inline std::string quad(const std::string& name, const std::string& corners, int ns = 1, int nt = 1,
                        const std::string& rho = "[0, 0, 0]") {
    return "  - name: " + name + "\n    type: quad\n    corners: " + corners + "\n    patches: [" +
           std::to_string(ns) + ", " + std::to_string(nt) + "]\n    reflectance: " + rho + "\n";
}

// Three unit squares 4 x 4 (a floor at z = -1, a ceiling at z = 1, a side wall at x = 0.5) and
// a ball of radius 0.3 near the wall, 8 x 4: ball patches see the squares past their horizons, the
// floor and ceiling see each other around the ball's shadow, the wall sees the ball from 0.1 away.
inline std::string ball_beside_walls() {
    return quad("low", "[[-0.5, -0.5, -1], [0.5, -0.5, -1], [0.5, 0.5, -1], [-0.5, 0.5, -1]]", 4, 4,
                "[0.5, 0.5, 0.5]") +
           quad("high", "[[-0.5, -0.5, 1], [-0.5, 0.5, 1], [0.5, 0.5, 1], [0.5, -0.5, 1]]", 4, 4,
                "[0.5, 0.5, 0.5]") +
           quad("side", "[[0.5, -0.5, -1], [0.5, -0.5, 1], [0.5, 0.5, 1], [0.5, 0.5, -1]]", 4, 4,
                "[0.5, 0.5, 0.5]") +
           "  - {name: ball, type: sphere, center: [0.1, 0.05, 0], radius: 0.3, patches: [8, 4], "
           "reflectance: [0.5, 0.5, 0.5]}\n";
}

inline Scene scene_of(const std::string& surfaces, bool closed = false) {
    return parse_scene(std::string("closed: ") + (closed ? "true" : "false") + "\nsurfaces:\n" + surfaces,
                       "test.yaml");
}

// A furnace: a closed inward sphere of radius 1 split 8 x 4 with reflectance rho and emission
// `emission` in every channel. Every row of its form factors sums to 1, so B = E / (1 - rho).
inline Scene furnace(double rho, double emission = 1.0) {
    const auto num = [](double x) { return fmt::format("{:.17g}", x); };
    const std::string r = num(rho), e = num(emission);
    return parse_scene(
        "closed: true\nsurfaces:\n  - name: shell\n    type: sphere\n    center: [0, 0, 0]\n"
        "    radius: 1\n    facing: inward\n    patches: [8, 4]\n    reflectance: [" +
            r + ", " + r + ", " + r + "]\n    emission: [" + e + ", " + e + ", " + e + "]\n",
        "furnace.yaml");
}

// The six faces of the cube [-h, h]^3 shifted by `offset` along every axis, facing in, as YAML list
// items f0..f5 (at -z, +z, -y, +y, -x, +x) of `patches` x `patches` each; `extra` goes inside each
// item's braces.
inline std::string cube_faces(double h, double offset = 0.0, int patches = 1,
                              const std::string& extra = ", reflectance: [0.5, 0.5, 0.5]") {
    // Corner signs, counter-clockwise about each face's inward normal.
    static const int sign[6][4][3] = {{{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}},
                                      {{-1, -1, 1}, {-1, 1, 1}, {1, 1, 1}, {1, -1, 1}},
                                      {{-1, -1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, -1, -1}},
                                      {{-1, 1, -1}, {1, 1, -1}, {1, 1, 1}, {-1, 1, 1}},
                                      {{-1, -1, -1}, {-1, 1, -1}, {-1, 1, 1}, {-1, -1, 1}},
                                      {{1, -1, -1}, {1, -1, 1}, {1, 1, 1}, {1, 1, -1}}};
    std::string s;
    for (int k = 0; k < 6; ++k) {
        std::string c = "[";
        for (int v = 0; v < 4; ++v) {
            c += v ? ", [" : "[";
            for (int a = 0; a < 3; ++a) c += (a ? ", " : "") + std::to_string(offset + sign[k][v][a] * h);
            c += "]";
        }
        s += "  - {name: f" + std::to_string(k) + ", type: quad, corners: " + c + "], patches: [" +
             std::to_string(patches) + ", " + std::to_string(patches) + "]" + extra + "}\n";
    }
    return s;
}

// A bicubic bump as a `control_points` list: its edges the square [-0.5, 0.5]^2 at z = 0, its
// inner four control points raised 0.2; front toward +z.
inline std::string bezier_bump() {
    std::string cp;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            const bool inner = (i == 1 || i == 2) && (j == 1 || j == 2);
            cp += (cp.empty() ? "[" : ", [") + std::to_string(-0.5 + j / 3.0) + ", " +
                  std::to_string(-0.5 + i / 3.0) + ", " + (inner ? "0.2" : "0") + "]";
        }
    return "[" + cp + "]";
}

// Unit square in z = 0 facing +z, and its opposite at z = 1 facing -z.
inline const char* kFloor = "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]";
inline const char* kCeiling = "[[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]";
// Unit square in y = 0 facing +y, sharing the edge x in [0,1], y = z = 0 with kFloor.
inline const char* kWall = "[[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]";

// Frame k of a sequence rendered on its own from `scene` (surfaces placed as the frame has them):
// form factors from scratch with `options`, an LU solve for the frame's lights and colours, the
// frame's camera. What a scheduled frame must equal.
inline Image frame_alone(const Scene& scene, const Sequence& seq, int k, const FormFactorOptions& options,
                         int width, int height, int samples) {
    const SceneGeometry g(scene);
    const FormFactors ff = compute_form_factors(g, options);
    const Materials m = seq.materials_at(patch_materials(scene), g, seq.frame_time(k));
    const RadiositySolver solver(ff.F, m.rho, SolverMethod::LU);
    const NodeRadiosity nodes(g, solver.solve(m.E), m.E);
    RenderOptions ro;
    ro.width = width;
    ro.height = height;
    ro.samples = samples;
    return render_image(g, nodes, PinholeCamera(seq.camera_at(seq.frame_time(k)), width, height), ro);
}

}  // namespace radiosa::test
