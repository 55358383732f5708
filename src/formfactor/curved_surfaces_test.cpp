// Form factors of disks, annuli, cylinders, cones, caps, tori and placed (transformed,
// two-sided) surfaces against answers known in advance: the coaxial-disk formula, differences
// of it, closure of closed scenes, and invariance under a transform of the whole scene. Curved
// receivers by their contours: contour_receiver_test.cpp; sensors: sensor_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../tests/test_scenes.h"
#include "formfactor/analytic.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/gauss_legendre.h"

namespace radiosa {

namespace {

FormFactors adaptive(const Scene& scene, double tol) {
    return compute_form_factors(SceneGeometry(scene), FormFactorOptions::adaptive(tol, true));
}

// F from surface a to surface b: the area-weighted sum of their patches' entries.
double surface_factor(const Scene& scene, const FormFactors& ff, int a, int b) {
    const SceneGeometry g(scene);
    double num = 0.0, area = 0.0;
    for (int i = g.first_patch(a); i < g.first_patch(a) + g.ns(a) * g.nt(a); ++i) {
        area += ff.area[i];
        for (int j = g.first_patch(b); j < g.first_patch(b) + g.ns(b) * g.nt(b); ++j)
            num += ff.area[i] * ff.F(i, j);
    }
    return num / area;
}

double err_of(const FormFactors& ff, int i, int j) {
    return ff.error[static_cast<std::size_t>(i) * ff.F.n + j];
}

double max_row_error(const FormFactors& ff) {
    double worst = 0.0;
    for (int i = 0; i < ff.F.n; ++i) {
        double row = 0.0;
        for (int j = 0; j < ff.F.n; ++j) row += ff.F(i, j);
        worst = std::max(worst, std::abs(row - 1.0));
    }
    return worst;
}

// Every row's miss of 1 within the row's summed estimates (plus `slack`).
void expect_rows_within_estimates(const FormFactors& ff, double slack) {
    for (int i = 0; i < ff.F.n; ++i) {
        double row = 0.0, est = 0.0;
        for (int j = 0; j < ff.F.n; ++j) {
            row += ff.F(i, j);
            est += err_of(ff, i, j);
        }
        EXPECT_LE(std::abs(row - 1.0), est + slack) << "row " << i;
    }
}

// The six inward faces f0..f5 of the cube [-h, h]^3, one patch each, `extra` added to each.
std::string box_faces(double h, const std::string& extra = "") {
    return test::cube_faces(h, 0.0, 1, ", reflectance: [0.5, 0.5, 0.5]" + extra);
}

std::string disk(const std::string& name, const std::string& center, const std::string& normal, double r,
                 double inner, const std::string& patches) {
    return "  - {name: " + name + ", type: disk, center: " + center + ", normal: " + normal +
           ", radius: " + std::to_string(r) + ", inner_radius: " + std::to_string(inner) +
           ", patches: " + patches + ", reflectance: [0.5, 0.5, 0.5]}\n";
}

// The inside of a closed can: radius 1, height 2, bottom and top disks and the tube.
std::string can(const std::string& patches, const std::string& extra = "") {
    return disk("bottom", "[0, 0, 0]", "[0, 0, 1]", 1, 0, patches).insert(0, "") +
           disk("top", "[0, 0, 2]", "[0, 0, -1]", 1, 0, patches) +
           "  - {name: side, type: cylinder, base: [0, 0, 0], axis: [0, 0, 2], radius: 1, facing: inward, "
           "patches: " +
           patches + ", reflectance: [0.5, 0.5, 0.5]" + extra + "}\n";
}

}  // namespace

TEST(CurvedSurfaces, CoaxialDisksMatchTheClosedForm) {
    // Disks of radius 0.5 and 1.5 one unit apart, whole and split into ring sectors.
    for (const char* patches : {"[1, 1]", "[3, 2]"}) {
        const Scene scene =
            parse_scene("closed: false\nsurfaces:\n" + disk("a", "[0, 0, 0]", "[0, 0, 1]", 0.5, 0, patches) +
                            disk("b", "[0, 0, 1]", "[0, 0, -1]", 1.5, 0, patches),
                        "disks.yaml");
        const double exact = analytic::coaxial_disks(0.5, 1.5, 1.0);
        for (double tol : {1e-6, 1e-10}) {
            SCOPED_TRACE(std::string(patches) + " at " + std::to_string(tol));
            const FormFactors ff = adaptive(scene, tol);
            EXPECT_NEAR(surface_factor(scene, ff, 0, 1), exact, std::max(1e-8, tol));
            EXPECT_NEAR(surface_factor(scene, ff, 1, 0), exact * 0.25 / 2.25, std::max(1e-8, tol));
            // Each entry's true error is within its estimate: F_01 of one patch pair.
            if (std::string(patches) == "[1, 1]") {
                EXPECT_LE(std::abs(ff.F(0, 1) - exact), err_of(ff, 0, 1) + 1e-15);
            }
        }
    }
}

// Coaxial disks 2.7e-4 apart, radii 15.6 and 52.8, split so that the sectors' edges lie over one
// another: under each edge F(dx -> sector) changes across a band as narrow as the gap, along
// the outer patches' own edges. Every entry at tolerances 1e-6 and 1e-8 is within its estimate
// of the same entry at 1e-10 (plus that one's), and the disks' factor is Howell's C-41. Before,
// an entry toward the sector overhead missed 1.5e-5 at 1e-7 and its estimate said 1e-8 (the
// neighbouring sectors' entries took it, so the rows still summed to 1).
TEST(CurvedSurfaces, NearlyTouchingCoaxialDisksAreWithinTheirEstimatesEntryByEntry) {
    const Scene scene =
        parse_scene("closed: false\nsurfaces:\n" + disk("lo", "[0, 0, 0]", "[0, 0, 1]", 15.609, 0, "[4, 2]") +
                        disk("hi", "[0, 0, 0.00026994]", "[0, 0, -1]", 52.8, 0, "[4, 1]"),
                    "near-disks.yaml");
    const FormFactors ref = adaptive(scene, 1e-10);
    EXPECT_NEAR(surface_factor(scene, ref, 0, 1), analytic::coaxial_disks(15.609, 52.8, 0.00026994), 1e-9);
    for (double tol : {1e-6, 1e-8}) {
        const FormFactors ff = adaptive(scene, tol);
        for (int i = 0; i < 8; ++i)
            for (int j = 8; j < 12; ++j)
                EXPECT_LE(std::abs(ff.F(i, j) - ref.F(i, j)), err_of(ff, i, j) + err_of(ref, i, j))
                    << "tolerance " << tol << ", entry " << i << " -> " << j;
    }
}

TEST(CurvedSurfaces, AnnulusIsTheDifferenceOfTwoDisks) {
    const Scene scene =
        parse_scene("closed: false\nsurfaces:\n" + disk("a", "[0, 0, 0]", "[0, 0, 1]", 0.5, 0, "[1, 1]") +
                        disk("ring", "[0, 0, 1]", "[0, 0, -1]", 1.5, 0.6, "[2, 2]"),
                    "annulus.yaml");
    const double exact = analytic::coaxial_disks(0.5, 1.5, 1.0) - analytic::coaxial_disks(0.5, 0.6, 1.0);
    const FormFactors ff = adaptive(scene, 1e-10);
    EXPECT_NEAR(surface_factor(scene, ff, 0, 1), exact, 1e-8);
}

TEST(CurvedSurfaces, InsideAClosedCanRowsSumToOne) {
    const Scene scene = parse_scene("surfaces:\n" + can("[4, 3]"), "can.yaml");
    const FormFactors ff = adaptive(scene, 1e-10);
    EXPECT_LE(max_row_error(ff), 1e-8);
    const double dd = analytic::coaxial_disks(1.0, 1.0, 2.0);
    EXPECT_NEAR(surface_factor(scene, ff, 0, 1), dd, 1e-8);
    EXPECT_NEAR(surface_factor(scene, ff, 0, 2), 1.0 - dd, 1e-8);
    // Tube to either end by reciprocity, and to itself by difference: 1 - 2 A_d (1 - F_dd) / A_t.
    EXPECT_NEAR(surface_factor(scene, ff, 2, 2), 1.0 - 2.0 * kPi * (1.0 - dd) / (4.0 * kPi), 1e-8);
    // No entry of the matrix is off by more than its own estimate says: the row sums' misses
    // are within the rows' summed estimates.
    expect_rows_within_estimates(ff, 1e-14);
}

TEST(CurvedSurfaces, ConeUnderADiskSeesWhatItsRimsBound) {
    // A disk over an outward cone (base radius 1, height 1), facing down the axis, that sees every
    // patch of it from the front. The projected solid angle of a surface seen whole depends only
    // on its boundary, so the cone receives what its base disk would (Howell C-41), its upper half
    // what the disk of radius 1/2 at height 1/2 would, and a frustum (top radius 0.4) its base
    // disk's share less its top disk's.
    auto scene = [](const std::string& lid, double lid_radius, const std::string& top_radius) {
        return parse_scene("closed: false\nsurfaces:\n" +
                               disk("lid", lid, "[0, 0, -1]", lid_radius, 0, "[1, 1]") +
                               "  - {name: cone, type: cone, base: [0, 0, 0], axis: [0, 0, 1], radius: 1, "
                               "top_radius: " +
                               top_radius + ", patches: [6, 2], reflectance: [0.5, 0.5, 0.5]}\n",
                           "cone.yaml");
    };
    const Scene cone = scene("[0, 0, 2]", 0.5, "0");
    const FormFactors ff = adaptive(cone, 1e-10);
    EXPECT_NEAR(surface_factor(cone, ff, 0, 1), analytic::coaxial_disks(0.5, 1.0, 2.0), 1e-8);
    double upper = 0.0;
    for (int j = 7; j < 13; ++j) {
        upper += ff.F(0, j);
        EXPECT_NEAR(ff.F(0, j), ff.F(0, 7), 1e-10) << j;  // the same for every azimuth
        EXPECT_LE(err_of(ff, 0, j), 1e-10);
    }
    EXPECT_NEAR(upper, analytic::coaxial_disks(0.5, 0.5, 1.5), 1e-8);
    EXPECT_EQ(ff.stats.numeric, 0);
    // The frustum's generators are steeper: the lid must be smaller and higher to face them all
    // (a lid of radius 0.5 at height 2 sees the far generators' backs, and takes the numeric path).
    const Scene frustum = scene("[0, 0, 3]", 0.2, "0.4");
    const FormFactors fr = adaptive(frustum, 1e-10);
    EXPECT_NEAR(surface_factor(frustum, fr, 0, 1),
                analytic::coaxial_disks(0.2, 1.0, 3.0) - analytic::coaxial_disks(0.2, 0.4, 2.0), 1e-8);
    EXPECT_EQ(fr.stats.numeric, 0);
}

// The inside of a closed cone (a pointed one on its base disk) and of a frustum closed by two
// disks, tilted, scaled and moved: every chord between them lies in the cone's solid, so every
// pair takes the contour path (none the numeric one, which left the pointed cone's rows 4.5e-4
// short and the frustum's 5.9e-6 at this tolerance). The base sees only the side, which sends it
// A_base / A_side = r / slant; the frustum's lids see each other by Howell C-41.
TEST(CurvedSurfaces, InsideAClosedConeRowsSumToOne) {
    const std::string xf =
        ", transform: {scale: 2.5, rotate_deg: {axis: [1, 1, 0], angle: 40}, translate: [0, 0, -1]}";
    const Scene pointed = parse_scene(
        "surfaces:\n" + disk("base", "[0, 0, 0]", "[0, 0, 1]", 1.2, 0, "[2, 1]") +
            "  - {name: side, type: cone, base: [0, 0, 0], axis: [0, 0, 0.9], radius: 1.2, top_radius: 0, "
            "facing: inward, patches: [4, 2], reflectance: [0.5, 0.5, 0.5]}\n",
        "cone.yaml");
    FormFactors ff = adaptive(pointed, 1e-10);
    EXPECT_EQ(ff.stats.numeric, 0);
    EXPECT_LE(max_row_error(ff), 1e-9);
    EXPECT_NEAR(surface_factor(pointed, ff, 0, 1), 1.0, 1e-9);
    EXPECT_NEAR(surface_factor(pointed, ff, 1, 0), 1.2 / 1.5, 1e-9);
    expect_rows_within_estimates(ff, 1e-14);

    std::string frustum =
        disk("base", "[0.3, -0.2, 0.1]", "[0, 0, 1]", 0.5, 0, "[2, 1]") +
        disk("top", "[0.3, -0.2, 1.3]", "[0, 0, -1]", 1.1, 0, "[2, 1]") +
        "  - {name: side, type: cone, base: [0.3, -0.2, 0.1], axis: [0, 0, 1.2], radius: 0.5, "
        "top_radius: 1.1, facing: inward, patches: [4, 2], reflectance: [0.5, 0.5, 0.5]}\n";
    for (std::size_t at = frustum.find("}\n"); at != std::string::npos;
         at = frustum.find("}\n", at + xf.size() + 2))
        frustum.insert(at, xf);
    const Scene widening = parse_scene("surfaces:\n" + frustum, "frustum.yaml");
    ff = adaptive(widening, 1e-10);
    EXPECT_EQ(ff.stats.numeric, 0);
    EXPECT_LE(max_row_error(ff), 1e-9);
    const double lids = analytic::coaxial_disks(0.5, 1.1, 1.2);
    EXPECT_NEAR(surface_factor(widening, ff, 0, 1), lids, 1e-9);
    EXPECT_NEAR(surface_factor(widening, ff, 0, 2), 1.0 - lids, 1e-9);
    expect_rows_within_estimates(ff, 1e-14);
}

// A ball close above a wide disk (Howell's sphere to coaxial disk): F(ball -> disk) =
// (1 - 1 / sqrt(1 + (a / h)^2)) / 2 for any ball radius below h. The disk's bounding ball
// reaches into the ball, but the disk's plane does not, so the disk's patches see the ball's
// by the sphere receiver's contour (not the numeric path, which missed by 6.6e-7 at every
// tolerance, its estimates up to 0.82).
TEST(CurvedSurfaces, ABallOverAWideDiskMatchesTheCoaxialFormula) {
    const Scene scene =
        parse_scene("closed: false\nsurfaces:\n" + disk("floor", "[0, 0, 0]", "[0, 0, 1]", 2.1, 0, "[8, 2]") +
                        "  - {name: ball, type: sphere, center: [0, 0, 0.35], radius: 0.3, patches: [8, 4], "
                        "reflectance: [0.5, "
                        "0.5, 0.5]}\n",
                    "ball-over-disk.yaml");
    const double exact = 0.5 * (1.0 - 1.0 / std::sqrt(1.0 + 6.0 * 6.0));
    const FormFactors ff = adaptive(scene, 1e-8);
    EXPECT_EQ(ff.stats.numeric, 0);
    EXPECT_NEAR(surface_factor(scene, ff, 1, 0), exact, 1e-8);
    // The area-weighted estimates cover the error.
    double err = 0.0, area = 0.0;
    for (int i = 16; i < ff.F.n; ++i) {
        area += ff.area[i];
        for (int j = 0; j < 16; ++j) err += ff.area[i] * err_of(ff, i, j);
    }
    EXPECT_LE(std::abs(surface_factor(scene, ff, 1, 0) - exact), err / area);
}

TEST(CurvedSurfaces, HemisphereOverItsBaseDisk) {
    // The base sees only the dome (F = 1); the dome sends half its light to the base
    // (A_base / A_dome = 1/2) and half to itself. A dome split 6 x 3, tipped 20 degrees with its
    // base, and a quarter-turn azimuth range on a second, open dome.
    const Scene scene = parse_scene(
        "surfaces:\n"
        "  - {name: dome, type: sphere, center: [0, 0, 0], radius: 1.5, facing: inward, polar_deg: [0, 90],\n"
        "     patches: [6, 3], reflectance: [0.5, 0.5, 0.5], transform: {rotate_deg: {axis: [1, 0, 0], "
        "angle: 20}}}\n"
        "  - {name: base, type: disk, center: [0, 0, 0], normal: [0, 0, 1], radius: 1.5, patches: [4, 2],\n"
        "     reflectance: [0.5, 0.5, 0.5], transform: {rotate_deg: {axis: [1, 0, 0], angle: 20}}}\n",
        "dome.yaml");
    const FormFactors ff = adaptive(scene, 1e-10);
    EXPECT_LE(max_row_error(ff), 1e-8);
    EXPECT_NEAR(surface_factor(scene, ff, 1, 0), 1.0, 1e-8);
    EXPECT_NEAR(surface_factor(scene, ff, 0, 1), 0.5, 1e-8);
    EXPECT_NEAR(surface_factor(scene, ff, 0, 0), 0.5, 1e-8);
    double dome_area = 0.0;
    for (int i = 0; i < 18; ++i) dome_area += ff.area[i];
    EXPECT_NEAR(dome_area, 2 * kPi * 1.5 * 1.5, 1e-12);
}

TEST(CurvedSurfaces, ATransformOfTheWholeSceneLeavesTheFactors) {
    const std::string xf =
        ", transform: {scale: 0.3, rotate_deg: {axis: [1, 2, 3], angle: 40}, translate: [5, -1, 2]}";
    const Scene plain = parse_scene("surfaces:\n" + can("[2, 2]"), "can.yaml");
    std::string moved_text = can("[2, 2]", xf);
    // The two disks take the same transform.
    for (const char* name : {"name: bottom", "name: top"}) {
        const auto at = moved_text.find(name);
        const auto close = moved_text.find('}', at);
        moved_text.insert(close, xf);
    }
    const Scene moved = parse_scene("surfaces:\n" + moved_text, "moved.yaml");
    const FormFactors a = adaptive(plain, 1e-9), b = adaptive(moved, 1e-9);
    ASSERT_EQ(a.F.n, b.F.n);
    for (int i = 0; i < a.F.n; ++i) {
        EXPECT_NEAR(b.area[i], 0.09 * a.area[i], 1e-13);
        for (int j = 0; j < a.F.n; ++j) EXPECT_NEAR(a.F(i, j), b.F(i, j), 2e-9) << i << "," << j;
    }
    EXPECT_LE(max_row_error(b), 1e-8);
}

TEST(CurvedSurfaces, ARotatedSphereKeepsItsPatchesInPlace) {
    // A sphere split 8 x 4 in a box, the whole scene turned 30 degrees about (1, 1, 0): the
    // sphere's patches turn with it, and every factor stays.
    auto scene_text = [](const std::string& xf) {
        std::string s = "surfaces:\n" + box_faces(2, xf);
        s += "  - {name: ball, type: sphere, center: [0.3, 0.2, -0.1], radius: 1, patches: [8, 4], "
             "reflectance: [0.5, 0.5, 0.5]" +
             xf + "}\n";
        return s;
    };
    const Scene plain = parse_scene(scene_text(""), "box.yaml");
    const Scene turned =
        parse_scene(scene_text(", transform: {rotate_deg: {axis: [1, 1, 0], angle: 30}}"), "turned.yaml");
    const FormFactors a = adaptive(plain, 1e-8), b = adaptive(turned, 1e-8);
    for (int i = 0; i < a.F.n; ++i)
        for (int j = 0; j < a.F.n; ++j) EXPECT_NEAR(a.F(i, j), b.F(i, j), 2e-8) << i << "," << j;
}

TEST(CurvedSurfaces, TwoSidedDiskInABoxCloses) {
    std::string s = "surfaces:\n" + box_faces(1);
    s +=
        "  - {name: plate, type: disk, center: [0, 0, 0.2], normal: [0, 0, 1], radius: 0.5, patches: [1, 1], "
        "reflectance: [0.8, 0.8, 0.8], two_sided: true, back_reflectance: [0.1, 0.2, 0.3]}\n";
    const Scene scene = parse_scene(s, "box.yaml");
    ASSERT_EQ(scene.surfaces.size(), 8u);
    EXPECT_EQ(scene.surfaces[7].name, "plate.back");
    EXPECT_EQ(scene.surfaces[7].reflectance, Rgb(0.1, 0.2, 0.3));
    // Wall-to-wall pairs the plate comes between take its shadow in closed form
    // (formfactor/disk_shadow.h): no pair is left to the numeric path, and the box closes to
    // 1e-8 (measured 2e-10) with every row's miss within its summed estimates.
    const FormFactors ff = adaptive(scene, 1e-9);
    EXPECT_EQ(ff.stats.numeric, 0);
    EXPECT_EQ(ff.stats.capped, 0);
    EXPECT_LE(max_row_error(ff), 1e-8);
    expect_rows_within_estimates(ff, 0.0);
    // The top face sees the front of the plate, the bottom face its back; front and back
    // never see each other.
    EXPECT_GT(ff.F(1, 6), 0.0);
    EXPECT_EQ(ff.F(1, 7), 0.0);
    EXPECT_GT(ff.F(0, 7), 0.0);
    EXPECT_EQ(ff.F(0, 6), 0.0);
    EXPECT_EQ(ff.F(6, 7), 0.0);
}

TEST(CurvedSurfaces, TwoSidedTubeInABoxCloses) {
    // An open tube floating in a box, two-sided: every wall pair it comes between takes its
    // outline in closed form (formfactor/tube_shadow.h: floor to ceiling through the bore, walls
    // past its side), and its inside sees the walls through its two ends (a disk each). No pair
    // is left to the numeric path; the box closes to 1e-8 (measured 2.9e-9).
    std::string s = "surfaces:\n" + box_faces(1);
    s +=
        "  - {name: pipe, type: cylinder, base: [0, 0, -0.5], axis: [0, 0, 1], radius: 0.3, facing: outward, "
        "patches: [4, 1], reflectance: [0.8, 0.8, 0.8], two_sided: true}\n";
    const Scene scene = parse_scene(s, "pipe.yaml");
    const FormFactors ff = adaptive(scene, 1e-8);
    EXPECT_EQ(ff.stats.numeric, 0);
    EXPECT_EQ(ff.stats.capped, 0);
    EXPECT_LE(max_row_error(ff), 1e-8);
    expect_rows_within_estimates(ff, 0.0);
    // The inside sends to the walls what a can's inside sends to its two lids:
    // 2 A_d (1 - F_dd) / A_t, F_dd the coaxial disks' factor (Howell C-41).
    const double ad = kPi * 0.09, at = 2 * kPi * 0.3, fdd = analytic::coaxial_disks(0.3, 0.3, 1.0);
    double to_walls = 0.0;
    for (int w = 0; w < 6; ++w) to_walls += surface_factor(scene, ff, 7, w);
    EXPECT_NEAR(to_walls, 2 * ad * (1 - fdd) / at, 1e-8);
    // The outside sees only the walls.
    for (int w = 0; w < 6; ++w) EXPECT_GT(surface_factor(scene, ff, 6, w), 1e-3);
    EXPECT_NEAR(surface_factor(scene, ff, 6, 6) + surface_factor(scene, ff, 6, 7), 0.0, 0.0);
}

namespace {

// A cone from radius 0.4 at z = -0.5 to `top` at z = 0.5 (0: to its apex), two-sided, floating
// in the box [-1, 1]^3: no pair left to the numeric path, closure within 1e-8 with every row
// within its estimates at tolerance 1e-8, and the inside sends the walls `inside_to_walls`.
void expect_cone_in_a_box_closes(double top, double inside_to_walls) {
    std::string s = "surfaces:\n" + box_faces(1);
    s += "  - {name: cone, type: cone, base: [0, 0, -0.5], axis: [0, 0, 1], radius: 0.4, top_radius: " +
         std::to_string(top) +
         ", facing: outward, patches: [4, 1], reflectance: [0.8, 0.8, 0.8], two_sided: true}\n";
    const Scene scene = parse_scene(s, "cone.yaml");
    const FormFactors ff = adaptive(scene, 1e-8);
    EXPECT_EQ(ff.stats.numeric, 0);
    EXPECT_LE(max_row_error(ff), 1e-8);
    expect_rows_within_estimates(ff, 0.0);
    double to_walls = 0.0;
    for (int w = 0; w < 6; ++w) to_walls += surface_factor(scene, ff, 7, w);
    EXPECT_NEAR(to_walls, inside_to_walls, 1e-8);
}

}  // namespace

TEST(CurvedSurfaces, TwoSidedShadeInABoxCloses) {
    // A lamp shade (a truncated cone, radius 0.4 below, 0.15 above) floating in a box, two-sided:
    // its outline between walls and its inside through its ends in closed form, as a tube's.
    // Closure within 1e-8 (measured 1.5e-9); the inside sends the walls what a can of that
    // shape's inside sends its lids, (A_b (1 - F_bt) + A_t (1 - F_tb)) / A_side.
    const double ab = kPi * 0.16, at = kPi * 0.0225, side = kPi * 0.55 * std::sqrt(1.0 + 0.25 * 0.25);
    const double fbt = analytic::coaxial_disks(0.4, 0.15, 1.0), ftb = ab * fbt / at;
    expect_cone_in_a_box_closes(0.15, (ab * (1 - fbt) + at * (1 - ftb)) / side);
}

TEST(CurvedSurfaces, APointedConeInABoxCloses) {
    // A cone to its apex (radius 0.4, height 1). From a side wall's corner, the tangent plane of
    // the outside passes it along a whole generator (a cone's tangent plane is the same all along
    // one), and the outer integral over the outside's patch cuts along that line
    // (EventSet::cut_along_curved); before, twelve wall pairs stopped at the refinement cap at 39
    // times their target and the box closed to 1.7e-8 (measured now: 1.9e-9). The inside and its
    // open base enclose a volume, and the base sees only the inside, so the inside sends the
    // walls A_base / A_inside = r / l.
    expect_cone_in_a_box_closes(0.0, 0.4 / std::sqrt(1.0 + 0.4 * 0.4));
}

namespace {

// A cap of the sphere of radius 0.4 (polar angles 0 to `polar`), two-sided, floating in a box
// (placed by `transform`): every wall pair the cap comes between takes its outline in closed
// form (formfactor/cap_shadow.h), and its inside sees the walls through its open end (a disk).
// No pair is left to the numeric path; the box closes to 1e-8. The inside and its open end
// enclose a volume, so the inside sends the walls what the end's disk receives from it:
// A_disk / A_inside = (1 + cos theta) / 2.
void expect_cap_in_a_box_closes(double polar, const std::string& transform) {
    std::string s = "surfaces:\n" + box_faces(1);
    s += "  - {name: dome, type: sphere, center: [0.1, 0, -0.2], radius: 0.4, facing: outward, polar_deg: "
         "[0, " +
         std::to_string(polar) + "], patches: [4, 1], reflectance: [0.8, 0.8, 0.8], two_sided: true" +
         transform + "}\n";
    const Scene scene = parse_scene(s, "dome.yaml");
    const FormFactors ff = adaptive(scene, 1e-8);
    EXPECT_EQ(ff.stats.numeric, 0);
    EXPECT_EQ(ff.stats.capped, 0);
    EXPECT_LE(max_row_error(ff), 1e-8);
    expect_rows_within_estimates(ff, 0.0);
    double to_walls = 0.0;
    for (int w = 0; w < 6; ++w) to_walls += surface_factor(scene, ff, 7, w);
    EXPECT_NEAR(to_walls, 0.5 * (1.0 + std::cos(polar * kPi / 180.0)), 1e-8);
    // The outside sees only the walls.
    EXPECT_NEAR(surface_factor(scene, ff, 6, 6) + surface_factor(scene, ff, 6, 7), 0.0, 0.0);
}

}  // namespace

TEST(CurvedSurfaces, TwoSidedDomeInABoxCloses) {
    // A hemisphere, open side down (measured: closure 1.5e-9).
    expect_cap_in_a_box_closes(90.0, "");
}

TEST(CurvedSurfaces, ATurnedCapInABoxCloses) {
    // A smaller cap, turned on its side about the box's centre (measured: closure 5.9e-9).
    expect_cap_in_a_box_closes(60.0, ", transform: {rotate_deg: {axis: [0, 1, 0], angle: 80}}");
}

TEST(CurvedSurfaces, APlateInsideADomeSeesItsInsideDirectly) {
    // A square plate inside a hemispherical dome (radius 0.8, open side down at z = -0.5), facing
    // down at z = -0.1: every direction from it meets the dome's inside or leaves through the
    // open end, so it sends the inside 1 - F(plate -> the end's disk), the point-to-coaxial-disk
    // formula integrated over the plate. The inside must not take it for a receiver seen
    // through the open end (the plate is inside the solid): it took that path once, and the
    // plate's row missed 1 by 0.21.
    std::string s = "surfaces:\n" + box_faces(1);
    s += "  - {name: dome, type: sphere, center: [0, 0, -0.5], radius: 0.8, facing: outward, polar_deg: [0, "
         "90], "
         "patches: [4, 1], reflectance: [0.8, 0.8, 0.8], two_sided: true}\n"
         "  - {name: plate, type: quad, corners: [[-0.2, -0.2, -0.1], [-0.2, 0.2, -0.1], [0.2, 0.2, -0.1], "
         "[0.2, -0.2, -0.1]], patches: [1, 1], reflectance: [0.5, 0.5, 0.5]}\n";
    const Scene scene = parse_scene(s, "plate.yaml");
    const FormFactors ff = adaptive(scene, 1e-7);
    // F(dA -> disk of radius r) from a point h below its plane, a off its axis (Howell B-13 form).
    const auto point_to_disk = [](double h, double a, double r) {
        const double sum = h * h + a * a + r * r;
        return 0.5 * (1.0 - (h * h + a * a - r * r) / std::sqrt(sum * sum - 4.0 * a * a * r * r));
    };
    const GaussRule rule = gauss_legendre(24);
    double to_disk = 0.0;
    for (std::size_t u = 0; u < rule.x.size(); ++u)
        for (std::size_t w = 0; w < rule.x.size(); ++w)
            to_disk += 0.25 * rule.w[u] * rule.w[w] *
                       point_to_disk(0.4, std::hypot(0.2 * rule.x[u], 0.2 * rule.x[w]), 0.8);
    EXPECT_NEAR(surface_factor(scene, ff, 8, 7), 1.0 - to_disk, 1e-6);
    EXPECT_GT(1.0 - to_disk, 0.1);
}

TEST(CurvedSurfaces, OccludersWhoseShadowsAreApartHideWhatEachHidesAlone) {
    // A small floor patch under a wide ceiling, and between them a ball, a disk and a dome whose
    // shadows never meet as seen from the patch: the three hide what each hides alone, so
    // F(all three) = F(ball) + F(disk) + F(dome) - 2 F(none), each in closed form
    // (formfactor/planar_receiver.h, `apart`); without it the pair took the numeric path, whose
    // estimate stayed far above 1e-10.
    const std::string floor =
        "  - {name: floor, type: quad, corners: [[-0.05, -0.05, 0], [0.05, -0.05, 0], "
        "[0.05, 0.05, 0], [-0.05, 0.05, 0]], patches: [1, 1], reflectance: [0.5, 0.5, 0.5]}\n";
    const std::string ceiling =
        "  - {name: ceiling, type: quad, corners: [[-1, -1, 4], [-1, 1, 4], [1, 1, 4], [1, -1, "
        "4]], patches: [1, 1], reflectance: [0.5, 0.5, 0.5]}\n";
    const std::string ball =
        "  - {name: ball, type: sphere, center: [-0.35, 0, 2], radius: 0.15, patches: [4, 2], "
        "reflectance: [0.5, 0.5, 0.5]}\n";
    const std::string plate =
        "  - {name: plate, type: disk, center: [0.35, 0, 2], normal: [0.3, 0, 1], radius: "
        "0.15, patches: [4, 1], reflectance: [0.5, 0.5, 0.5], two_sided: true}\n";
    const std::string dome =
        "  - {name: dome, type: sphere, center: [0, 0.4, 2], radius: 0.15, polar_deg: [0, 90], "
        "patches: [4, 1], reflectance: [0.5, 0.5, 0.5], two_sided: true}\n";
    // F(floor -> ceiling), checked within its estimate's reach of the tolerance.
    const auto f = [&](const std::string& occluders) {
        const FormFactors ff = adaptive(
            parse_scene("closed: false\nsurfaces:\n" + floor + ceiling + occluders, "apart.yaml"), 1e-10);
        EXPECT_LE(err_of(ff, 0, 1), 1e-10);
        return ff.F(0, 1);
    };
    const double none = f(""), all = f(ball + plate + dome);
    const double each = f(ball) + f(plate) + f(dome) - 2.0 * none;
    EXPECT_NEAR(all, each, 1e-9);
    EXPECT_GT(none - all, 1e-3);  // they do hide something
}

TEST(CurvedSurfaces, ATiltedAnnulusInABoxCloses) {
    // A two-sided annulus, tilted and off centre, in a box split 2 x 2: every wall pair it comes
    // between takes its shadow in closed form (the hole's included), walls seeing each other
    // through the hole too. Closure within the tolerance, every row and every pair's two
    // independently integrated directions within their estimates.
    std::string s = "surfaces:\n" + test::cube_faces(1.0, 0.0, 2);
    s += "  - {name: ring, type: disk, center: [0.1, -0.2, 0.1], normal: [0.2, 0.3, 1], radius: 0.6, "
         "inner_radius: 0.2, patches: [4, 1], reflectance: [0.8, 0.8, 0.8], two_sided: true}\n";
    const FormFactors ff = adaptive(parse_scene(s, "ring.yaml"), 1e-6);
    EXPECT_EQ(ff.stats.numeric, 0);
    EXPECT_EQ(ff.stats.capped, 0);
    EXPECT_LE(max_row_error(ff), 1e-6);  // measured 2.7e-7
    expect_rows_within_estimates(ff, 0.0);
    for (int i = 0; i < ff.F.n; ++i)
        for (int j = i + 1; j < ff.F.n; ++j)
            EXPECT_LE(std::abs(ff.area[i] * ff.F(i, j) - ff.area[j] * ff.F(j, i)),
                      ff.area[i] * err_of(ff, i, j) + ff.area[j] * err_of(ff, j, i) + 1e-15)
                << i << "," << j;
}

TEST(CurvedSurfaces, ALampDiskLosesToTheFloorWhatTheTableUnderItReceives) {
    // A lamp disk (radius 0.3, height 1.5, facing down, 4 x 1 patches) over a wide floor (2 x 2
    // patches) with a two-sided table disk (radius 0.5, height 0.5) coaxial between them: the
    // lamp's patches are not polygons, and their pairs with the floor take the table's shadow in
    // closed form. The table hides from the floor exactly what it receives from the lamp, the
    // coaxial disks' factor (Howell C-41), so F(lamp -> floor) falls by that much.
    auto scene = [](bool table) {
        std::string s =
            "closed: false\nsurfaces:\n"
            "  - {name: floor, type: quad, corners: [[-20, -20, 0], [20, -20, 0], [20, 20, 0], "
            "[-20, 20, 0]], patches: [2, 2], reflectance: [0.5, 0.5, 0.5]}\n"
            "  - {name: lamp, type: disk, center: [0, 0, 1.5], normal: [0, 0, -1], radius: 0.3, "
            "patches: [4, 1], reflectance: [0.5, 0.5, 0.5]}\n";
        if (table)
            s += "  - {name: table, type: disk, center: [0, 0, 0.5], normal: [0, 0, 1], radius: 0.5, "
                 "patches: [1, 1], reflectance: [0.5, 0.5, 0.5], two_sided: true}\n";
        return parse_scene(s, "lamp.yaml");
    };
    auto lamp_to_floor = [](const FormFactors& ff) {
        double af = 0.0, a = 0.0;
        for (int k = 4; k < 8; ++k) {
            a += ff.area[k];
            for (int j = 0; j < 4; ++j) af += ff.area[k] * ff.F(k, j);
        }
        return af / a;
    };
    const FormFactors open = adaptive(scene(false), 1e-10), shaded = adaptive(scene(true), 1e-10);
    EXPECT_EQ(shaded.stats.numeric, 0);
    const double R1 = 0.3 / 1.0, R2 = 0.5 / 1.0, X = 1.0 + (1.0 + R2 * R2) / (R1 * R1);
    const double coaxial = 0.5 * (X - std::sqrt(X * X - 4.0 * (R2 / R1) * (R2 / R1)));
    EXPECT_NEAR(lamp_to_floor(open) - lamp_to_floor(shaded), coaxial, 1e-8);
    double table = 0.0;  // the lamp's factor to the table's top, as a check of the formula
    for (int k = 4; k < 8; ++k) table += shaded.area[k] * shaded.F(k, 8);
    EXPECT_NEAR(table / (kPi * 0.09), coaxial, 1e-8);
}

TEST(CurvedSurfaces, TorusInABoxCloses) {
    // A ring that sees itself (its inner half) and blocks itself: the numeric path throughout.
    std::string s = "surfaces:\n" + box_faces(2);
    s += "  - {name: ring, type: torus, center: [0, 0, 0], axis: [0, 0.3, 1], major_radius: 1, minor_radius: "
         "0.3, "
         "patches: [4, 2], reflectance: [0.5, 0.5, 0.5]}\n";
    const Scene scene = parse_scene(s, "ring.yaml");
    const FormFactors ff = adaptive(scene, 1e-3);
    EXPECT_LE(max_row_error(ff), 1e-2);
    expect_rows_within_estimates(ff, 0.0);
    // Reciprocity is exact by construction for pairs integrated once; the torus's area is Pappus's.
    double area = 0.0;
    for (int i = 6; i < ff.F.n; ++i) area += ff.area[i];
    EXPECT_NEAR(area, 4 * kPi * kPi * 0.3, 1e-12);
    EXPECT_GT(ff.F(6, 9), 0.0);  // the outer equator's patches see the inner half across the hole
}

TEST(CurvedSurfaces, AFlatBezierOccluderCastsItsQuadsShadowAlongLines) {
    // Two unit squares facing each other across a gap of 1, a square of side 0.5 halfway between
    // as a quad (its shadow in closed form) or as a flat Bezier patch (the numeric path). Its
    // shadow's edges cross the far square, where the fixed rules' error stops at 2.2e-4 whatever
    // the tolerance; along lines the entry meets its tolerance and its estimate.
    std::string quads =
        "surfaces:\n"
        "  - {name: lo, type: quad, corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], patches: [1, 1], "
        "reflectance: [0.5, 0.5, 0.5]}\n"
        "  - {name: hi, type: quad, corners: [[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]], patches: [1, 1], "
        "reflectance: [0.5, 0.5, 0.5]}\n";
    std::string points;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
            points += (points.empty() ? "[" : ", [") + std::to_string(0.3 + 0.5 * i / 3.0) + ", " +
                      std::to_string(0.2 + 0.5 * j / 3.0) + ", 0.5]";
    const std::string as_quad =
        quads +
        "  - {name: mid, type: quad, two_sided: true, corners: [[0.3, 0.2, 0.5], [0.8, 0.2, "
        "0.5], [0.8, 0.7, 0.5], [0.3, 0.7, 0.5]], patches: [1, 1], reflectance: [0.5, 0.5, "
        "0.5]}\n";
    const std::string as_bezier = quads + "  - {name: mid, type: bezier, two_sided: true, control_points: [" +
                                  points + "], patches: [1, 1], reflectance: [0.5, 0.5, 0.5]}\n";
    const FormFactors exact = adaptive(parse_scene(as_quad, "quad.yaml"), 1e-12);
    EXPECT_EQ(exact.stats.numeric, 0);
    FormFactorOptions o = FormFactorOptions::adaptive(1e-5);
    o.numeric_lines = true;
    const FormFactors lines = compute_form_factors(SceneGeometry(parse_scene(as_bezier, "bezier.yaml")), o);
    EXPECT_GT(lines.stats.numeric, 0);
    // F(lo -> hi) with the quad's shadow (its closed form at 1e-12). The control points along each
    // edge are collinear, so the patch is the square exactly (their rounding to six digits only
    // moves its parameters).
    const double want = exact.F(0, 1);
    EXPECT_NEAR(want, 0.101858934289, 1e-11);
    EXPECT_NEAR(lines.F(0, 1), want, 3e-6);
    EXPECT_LE(std::abs(lines.F(0, 1) - want), lines.error[1]);
    EXPECT_LE(lines.error[1], 1e-5);
}

}  // namespace radiosa
