// OBJ meshes (the `mesh` type) and inline triangles: a cube and a tetrahedron read from OBJ files
// give the closed-form factors between their faces, materials come from the .mtl, and broken files
// are refused at their line.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"

namespace radiosa {
namespace {

std::string write(const std::string& name, const std::string& text) {
    const std::string path = testing::TempDir() + name;  // TempDir() ends in '/'
    std::ofstream(path) << text;
    return path;
}

Scene mesh_scene(const std::string& obj_name, const std::string& extra = "",
                 const std::string& patches = "1") {
    const std::string yaml = "surfaces:\n  - {name: m, type: mesh, file: " + obj_name +
                             ", patches: " + patches + ", reflectance: [0.5, 0.5, 0.5]" + extra + "}\n";
    return parse_scene(yaml, write("mesh_scene.yaml", yaml));
}

std::string parse_error(const std::string& obj_name, const std::string& extra = "") {
    try {
        mesh_scene(obj_name, extra);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

// A unit cube seen from inside: each face wound counter-clockwise about the inward normal.
const char* kCube =
    "# unit cube, faces facing in\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n";

TEST(Mesh, CubeFromObjGivesTheClosedFormFactors) {
    write("cube.obj", kCube);
    const Scene s = mesh_scene("cube.obj", "", "2");
    ASSERT_EQ(s.surfaces.size(), 6u);
    EXPECT_EQ(s.surfaces[3].name, "m.3");
    const FormFactors ff = compute_form_factors(SceneGeometry(s), FormFactorOptions::adaptive(1e-9, true));
    // Face to face by surface: opposite unit squares 0.199824895, adjacent 0.200043776 (Howell C-11, C-14).
    auto face = [&](int a, int b) {
        double sum = 0.0;
        for (int i = 4 * a; i < 4 * a + 4; ++i)
            for (int j = 4 * b; j < 4 * b + 4; ++j) sum += ff.F(i, j);
        return sum / 4.0;
    };
    EXPECT_NEAR(face(0, 1), 0.19982489569838737, 1e-8);
    EXPECT_NEAR(face(0, 2), 0.20004377607540316, 1e-8);
    for (int i = 0; i < ff.F.n; ++i) {
        double row = 0.0;
        for (int j = 0; j < ff.F.n; ++j) row += ff.F(i, j);
        EXPECT_NEAR(row, 1.0, 1e-8);
    }
}

TEST(Mesh, TetrahedronOfTrianglesSeesOneThirdEachWay) {
    // A regular tetrahedron from inside: by symmetry and closure every face sends 1/3 to each other.
    write("tet.obj",
          "v 1 1 1\nv 1 -1 -1\nv -1 1 -1\nv -1 -1 1\n"
          "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    const Scene s = mesh_scene("tet.obj", "", "[3, 2]");
    ASSERT_EQ(s.surfaces.size(), 4u);
    const SceneGeometry g(s);
    EXPECT_TRUE(g.surface(0).pole_at_t1());
    const FormFactors ff = compute_form_factors(g, FormFactorOptions::adaptive(1e-9, true));
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
            double num = 0.0, area = 0.0;
            for (int i = 6 * a; i < 6 * a + 6; ++i) {
                area += ff.area[i];
                for (int j = 6 * b; j < 6 * b + 6; ++j) num += ff.area[i] * ff.F(i, j);
            }
            EXPECT_NEAR(num / area, a == b ? 0.0 : 1.0 / 3.0, 1e-8) << a << " " << b;
        }
}

TEST(Mesh, PolygonsAreCutIntoConvexPiecesAndMaterialsComeFromTheMtl) {
    write("hex.mtl", "newmtl glow\nKd 0.2 0.4 0.6\nKe 1 2 3\n");
    write("hex.obj",
          "mtllib hex.mtl\nv 2 0 0\nv 1 1.7320508075688772 0\nv -1 1.7320508075688772 0\nv -2 0 0\n"
          "v -1 -1.7320508075688772 0\nv 1 -1.7320508075688772 0\nusemtl glow\nf 1 2 3 4 5 6\n");
    const Scene s = mesh_scene("hex.obj", ", materials: mtl");
    ASSERT_EQ(s.surfaces.size(), 2u);  // a hexagon: two quads from corner 1
    EXPECT_EQ(s.surfaces[0].name, "m.0.0");
    EXPECT_EQ(s.surfaces[1].name, "m.0.1");
    EXPECT_LT(glm::length(s.surfaces[1].reflectance - Rgb(0.2, 0.4, 0.6)), 1e-15);
    EXPECT_EQ(s.surfaces[0].emission, Rgb(1, 2, 3));
    const SceneGeometry g(s);
    EXPECT_NEAR(g.patch(0).area + g.patch(1).area, 1.5 * std::sqrt(3.0) * 4.0, 1e-13);
    // Without materials: mtl the scene's own reflectance holds.
    EXPECT_EQ(mesh_scene("hex.obj").surfaces[0].reflectance, Rgb(0.5));
}

TEST(Mesh, BrokenFilesAreRefusedAtTheirLine) {
    const std::string dir = testing::TempDir();
    write("bent.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nf 1 2 3\nf 1 2 3 4\n");
    EXPECT_EQ(parse_error("bent.obj"),
              dir +
                  "bent.obj:6:1: mesh 'm': face 1 is not planar: corner 1 is off the plane of the others "
                  "(triangulate it in the modeller)");
    write("dart.obj", "v 0 0 0\nv 2 0 0\nv 0.5 0.5 0\nv 0 2 0\nf 1 2 3 4\n");
    EXPECT_EQ(parse_error("dart.obj"), dir +
                                           "dart.obj:5:1: mesh 'm': face 0 is not convex at corner 3 (or two "
                                           "corners coincide there); split it into convex faces");
    write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    EXPECT_EQ(parse_error("flat.obj"), dir +
                                           "flat.obj:4:1: mesh 'm': face 0 is degenerate: its corners are "
                                           "collinear or coincide (remove it)");
    write("empty.obj", "# nothing\n");
    EXPECT_EQ(parse_error("empty.obj"), dir + "mesh_scene.yaml:2:33: mesh 'm': 'empty.obj' has no faces");
    EXPECT_EQ(parse_error("missing.obj"), dir + "mesh_scene.yaml:2:33: " + dir +
                                              "missing.obj: no such file (file is relative to the scene "
                                              "file's folder)");
    write("nomtl.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    EXPECT_EQ(parse_error("nomtl.obj", ", materials: wood"),
              dir + "mesh_scene.yaml:2:97: materials must be 'none' or 'mtl', got 'wood'");
    write("two.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
    EXPECT_EQ(parse_error("two.obj", ", patch_emission: [{patch: [0, 0], emission: [1, 1, 1]}]"),
              dir +
                  "mesh_scene.yaml:2:84: patch_emission needs a single surface, but 'm' makes 2 (give the "
                  "emission to the whole entry, or to a material)");
    write("badkd.mtl", "newmtl hot\nKd 1.5 0 0\n");
    write("badkd.obj", "mtllib badkd.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl hot\nf 1 2 3\n");
    EXPECT_EQ(parse_error("badkd.obj", ", materials: mtl"),
              dir + "mesh_scene.yaml:2:33: material 'hot': Kd (reflectance) must be in [0, 1], got 1.5");
}

TEST(Triangle, InlineTriangleIsAFlatPatchWithAPole) {
    const std::string yaml =
        "surfaces:\n  - {name: t, type: triangle, corners: [[0, 0, 0], [2, 0, 0], [0, 2, 0]], patches: [2, "
        "2],"
        " reflectance: [0.5, 0.5, 0.5]}\n";
    const Scene s = parse_scene(yaml, "t.yaml");
    const SceneGeometry g(s);
    double area = 0.0;
    for (int i = 0; i < 4; ++i) area += g.patch(i).area;
    EXPECT_NEAR(area, 2.0, 1e-15);
    EXPECT_TRUE(g.surface(0).pole_at_t1());
    EXPECT_GT(g.surface(0).normal(0.3, 0.3).z, 0.0);
    try {
        parse_scene(
            "surfaces:\n  - {name: t, type: triangle, corners: [[0, 0, 0], [1, 1, 1], [2, 2, 2]], "
            "patches: 1, reflectance: [0.5, 0.5, 0.5]}\n",
            "t.yaml");
        FAIL();
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "t.yaml:2:40: triangle 't' is degenerate: its corners are collinear");
    }
}

}  // namespace
}  // namespace radiosa
