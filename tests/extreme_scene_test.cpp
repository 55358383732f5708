// Extreme proportions inside whole scenes, with answers known in advance: a sphere 1e-4 the
// size of its room, a single emitting patch of area 1e-8, and a patch 1e4 times longer than
// wide. Each is solved end to end (form factors at the default tolerance, LU) and compared
// with a closed form; the images of the first are checked too.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_run.h"
#include "encode/encode.h"
#include "encode/image_io.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "record.h"
#include "scene/scene.h"
#include "solve/solver.h"

namespace radiosa {

namespace {

// The six inward faces of the cube [0,1]^3, each split n x n, as YAML list items.
std::string unit_cube(int n, const std::string& rho, const std::string& emission, double floor_x1 = 1.0) {
    struct Face {
        const char *name, *corners;
    };
    char floor[160];
    std::snprintf(floor, sizeof floor, "[[0, 0, 0], [%.17g, 0, 0], [%.17g, 1, 0], [0, 1, 0]]", floor_x1,
                  floor_x1);
    const Face faces[] = {{"floor", floor},
                          {"ceiling", "[[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]"},
                          {"south", "[[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]"},
                          {"north", "[[0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]]"},
                          {"west", "[[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]]"},
                          {"east", "[[1, 0, 0], [1, 0, 1], [1, 1, 1], [1, 1, 0]]"}};
    std::string out;
    for (const Face& f : faces)
        out += std::string("  - name: ") + f.name + "\n    type: quad\n    corners: " + f.corners +
               "\n    patches: [" + std::to_string(n) + ", " + std::to_string(n) +
               "]\n    reflectance: " + rho + "\n    emission: " + emission + "\n";
    return out;
}

struct Solution {
    SceneGeometry geometry;
    FormFactors ff;
    FormFactorChecks checks;
    std::vector<Rgb> B;
    SolveDiagnostics energy;
};

Solution solve(const std::string& yaml) {
    const Scene s = parse_scene(yaml, "extreme.yaml");
    Solution out{SceneGeometry(s), {}, {}, {}, {}};
    out.ff = compute_form_factors(out.geometry, FormFactorOptions::adaptive(kDefaultFormFactorTolerance));
    out.checks = check_form_factors(out.ff);
    const Materials m = patch_materials(s);
    const RadiositySolver solver(out.ff.F, m.rho, SolverMethod::LU);
    out.B = solver.solve(m.E);
    out.energy = diagnose_solution(out.ff.F, out.ff.area, m, out.B);
    return out;
}

// Differential area at height c above a corner of an a x b rectangle parallel to it
// (Howell B-3); odd in a and in b, so signed corners superpose.
double point_to_corner_rectangle(double a, double b, double c) {
    const double A = a / c, B = b / c, sa = std::sqrt(1 + A * A), sb = std::sqrt(1 + B * B);
    return (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb)) / (2 * 3.14159265358979323846);
}

}  // namespace

// A sphere of diameter 1e-4 in the centre of a unit furnace room: walls emit 1 with
// reflectance 0.5, the sphere emits nothing and reflects 0.8. The sphere occupies 1.3e-8 of
// the room's view, so the walls stay at E / (1 - rho) = 2 and every sphere patch, which sees
// only walls, is at 0.8 x 2 = 1.6.
TEST(ExtremeScene, SphereOneTenThousandthOfTheRoom) {
    const Solution s =
        solve("closed: true\nsurfaces:\n" + unit_cube(2, "[0.5, 0.5, 0.5]", "[1, 1, 1]") +
              "  - name: bead\n    type: sphere\n    center: [0.5, 0.5, 0.5]\n    radius: 5e-5\n"
              "    patches: [8, 4]\n    reflectance: [0.8, 0.8, 0.8]\n");
    EXPECT_LT(s.checks.closure_max_error, 1e-6);
    double worst_wall = 0.0, worst_bead = 0.0;
    for (int i = 0; i < s.geometry.patch_count(); ++i) {
        const bool bead = s.geometry.surface_name(s.geometry.patch(i).surface) == "bead";
        double& worst = bead ? worst_bead : worst_wall;
        worst = std::max(worst, std::abs(s.B[i].r - (bead ? 1.6 : 2.0)) / (bead ? 1.6 : 2.0));
    }
    EXPECT_LT(worst_wall, 1e-6);
    EXPECT_LT(worst_bead, 1.6e-6);  // measured 1.6e-7
    test::record("bead_rel_error", worst_bead);
}

// The same room seen through a camera 3e-4 from the bead: exact ray casting finds the true
// sphere, so the pixel at the centre shows the bead's radiosity and the corners the walls'.
TEST(ExtremeScene, SphereOneTenThousandthOfTheRoomRendersAtCloseRange) {
    const auto d = test::fresh_dir("extreme-bead");
    std::ofstream(d / "bead.yaml")
        << ("closed: true\nsurfaces:\n" + unit_cube(2, "[0.5, 0.5, 0.5]", "[1, 1, 1]") +
            "  - name: bead\n    type: sphere\n    center: [0.5, 0.5, 0.5]\n"
            "    radius: 5e-5\n    patches: [8, 4]\n    reflectance: [0.8, 0.8, 0.8]\n");
    std::ofstream(d / "cam.yaml")
        << ("camera:\n  look_at: [0.5, 0.5, 0.5]\n  distance: 3e-4\n  theta_deg: 30\n"
            "  phi_deg: 80\n  fov_deg: 40\n");
    const test::CliRun r = test::run({"render", (d / "bead.yaml").string(), "-c", (d / "cam.yaml").string(),
                                      "-o", (d / "bead.exr").string(), "--width", "33", "--height", "33",
                                      "--samples", "1", "--no-cache", "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    const Image img = media::read_image((d / "bead.exr").string());
    EXPECT_NEAR(img.pixel(16, 16).r, 1.6, 1.6e-6);
    EXPECT_NEAR(img.pixel(0, 0).r, 2.0, 2e-6);
    std::filesystem::remove_all(d);
}

// One emitting quad of 1e-4 x 1e-4 (area 1e-8) hanging 0.1 below the ceiling, facing down,
// emission 1e8 (power 1). Only the floor reflects (0.5) and it cannot see itself, so each
// floor patch is at 0.5 E F(patch -> emitter) = 0.5 E A_e F(emitter -> patch) / A_patch, and
// the emitter is small enough (1e-4 / 0.9) for F(emitter -> patch) to be the point's closed
// form within 1e-8. The walls and ceiling absorb the rest: absorbed power = 1.
TEST(ExtremeScene, EmittingPatchOfArea1em8) {
    const double h = 0.9, half = 0.5e-4, E = 1e8;
    char emitter[512];
    std::snprintf(
        emitter, sizeof emitter,
        "  - name: spark\n    type: quad\n    corners: [[%.17g, %.17g, %.17g], [%.17g, %.17g, %.17g], "
        "[%.17g, %.17g, %.17g], [%.17g, %.17g, %.17g]]\n    patches: [1, 1]\n    reflectance: [0, 0, 0]\n"
        "    emission: [%.17g, %.17g, %.17g]\n",
        0.5 - half, 0.5 - half, h, 0.5 - half, 0.5 + half, h, 0.5 + half, 0.5 + half, h, 0.5 + half,
        0.5 - half, h, E, E, E);
    std::string room = unit_cube(4, "[0, 0, 0]", "[0, 0, 0]");
    room.replace(room.find("reflectance: [0, 0, 0]"), 22, "reflectance: [0.5, 0.5, 0.5]");  // the floor
    const Solution s = solve("closed: false\nsurfaces:\n" + room + emitter);
    const double area_e = 4 * half * half;
    double worst = 0.0;
    int floor_patches = 0;
    for (int i = 0; i < s.geometry.patch_count(); ++i) {
        const Patch& p = s.geometry.patch(i);
        if (s.geometry.surface_name(p.surface) != "floor") continue;
        ++floor_patches;
        const double x0 = p.s0 - 0.5, x1 = p.s1 - 0.5, y0 = p.t0 - 0.5, y1 = p.t1 - 0.5;
        const double f_ep = point_to_corner_rectangle(x1, y1, h) - point_to_corner_rectangle(x0, y1, h) -
                            point_to_corner_rectangle(x1, y0, h) + point_to_corner_rectangle(x0, y0, h);
        const double expect = 0.5 * E * area_e * f_ep / p.area;
        worst = std::max(worst, std::abs(s.B[i].r - expect) / expect);
    }
    EXPECT_EQ(floor_patches, 16);
    EXPECT_LT(worst, 3.4e-8);  // measured 3.4e-9
    test::record("floor_rel_error", worst);
    EXPECT_NEAR(s.energy.emitted_power.r, 1.0, 1e-12);
    // The power the room absorbs is sum_i A_i F(i -> emitter) E over 24 room patches, each
    // entry within 1e-6 of the emitter's power (the tolerance applies to A_i F_ij on the
    // smaller patch's scale, and the room's entries come from the emitter's row by
    // reciprocity): measured 1.3e-9; with the tolerance on the larger patch's scale it would be
    // 2.8e-4.
    EXPECT_LT(s.energy.energy_balance_error, 1.3e-8);
    test::record("energy_balance_error", s.energy.energy_balance_error);
    const int e = s.geometry.patch_count() - 1;  // the emitter's row: it sees only the room
    double row = 0.0;
    for (int j = 0; j < s.geometry.patch_count(); ++j) row += s.ff.F(e, j);
    EXPECT_NEAR(row, 1.0, 24e-6);
}

// A closed furnace (every surface emits 1 and reflects 0.5) whose floor has a strip 1 long and
// 1e-4 wide along the east wall: the strip shares an edge with the wall it is perpendicular
// to. Every row of a closed scene sums to 1, so every patch, the strip included, is at
// E / (1 - rho) = 2; the strip's row is the hard one (F to the adjoining wall ~ 1/2).
TEST(ExtremeScene, PatchTenThousandTimesLongerThanWide) {
    const double w = 1e-4;
    char strip[512];
    std::snprintf(
        strip, sizeof strip,
        "  - name: strip\n    type: quad\n    corners: [[%.17g, 0, 0], [1, 0, 0], [1, 1, 0], [%.17g, 1, 0]]\n"
        "    patches: [1, 1]\n    reflectance: [0.5, 0.5, 0.5]\n    emission: [1, 1, 1]\n",
        1 - w, 1 - w);
    const Solution s =
        solve("closed: true\nsurfaces:\n" + unit_cube(2, "[0.5, 0.5, 0.5]", "[1, 1, 1]", 1 - w) + strip);
    EXPECT_LT(s.checks.closure_max_error, 1e-6);
    EXPECT_LT(s.checks.reciprocity_abs_error, 1e-6);
    double worst = 0.0;
    for (const Rgb& b : s.B) worst = std::max(worst, std::abs(b.r - 2.0) / 2.0);
    EXPECT_LT(worst, 2e-6);
    test::record("furnace_rel_error", worst);
}

}  // namespace radiosa
