// Sensors (formfactor/sensor.h): F from a differential element to each patch, with occlusion,
// against point-to-area formulas known in advance (Howell B-3, the coaxial disk, a ball's and a
// plate's cones, a Bezier bump's boundary).
#include "formfactor/sensor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../tests/test_scenes.h"
#include "formfactor/analytic.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
namespace radiosa {

namespace {
Scene sensor_scene(const std::string& surfaces) {
    return parse_scene("closed: false\nsurfaces:\n" + surfaces, "s.yaml");
}
}  // namespace

TEST(Sensor, UnderABezierBumpSeesWhatItsBoundaryBounds) {
    // The bump of test::bezier_bump(), two-sided, 1 above the sensor: seen once,
    // its back's four patches subtend what its boundary, the square [-0.5, 0.5]^2 at z = 0, does
    // (Howell B-3, superposed), each by its contour; the front's patches are behind it.
    const Scene scene =
        sensor_scene("  - {name: sheet, type: bezier, control_points: " + test::bezier_bump() +
                     ", patches: [2, 2], reflectance: [0.5, 0.5, 0.5], two_sided: true}\n");
    const SensorFactors s =
        sensor_factors(SceneGeometry(scene), Vec3(0.1, 0.2, -1), Vec3(0, 0, 1), 1e-10, true);
    ASSERT_EQ(s.F.size(), 8u);
    double sum = 0.0;
    for (int j = 0; j < 8; ++j) {
        if (j < 4) EXPECT_EQ(s.F[j], 0.0);
        sum += s.F[j];
    }
    EXPECT_EQ(s.closed_form, 4);
    EXPECT_NEAR(sum, analytic::point_to_parallel_rectangle(0.1, 0.2, -0.5, 0.5, -0.5, 0.5, 1.0), 1e-10);
}

TEST(Sensor, BelowACoaxialDiskAndFacingARectangle) {
    // A disk of radius 0.8 at height 1.5 facing down, split 6 x 3: F = r^2 / (r^2 + h^2).
    const Scene scene = sensor_scene(
        "  - {name: lamp, type: disk, center: [0, 0, 1.5], normal: [0, 0, -1], radius: 0.8, patches: [6, 3],"
        " reflectance: [0, 0, 0]}\n"
        "  - {name: meter, type: sensor, position: [0, 0, 0], normal: [0, 0, 1]}\n");
    ASSERT_EQ(scene.sensors.size(), 1u);
    const SceneGeometry g(scene);
    const SensorFactors s =
        sensor_factors(g, scene.sensors[0].position, scene.sensors[0].normal, 1e-10, true);
    double sum = 0.0;
    for (double f : s.F) sum += f;
    EXPECT_NEAR(sum, 0.64 / (0.64 + 2.25), 1e-10);
    EXPECT_EQ(s.closed_form, 18);
    // A 2 x 3 rectangle 1.2 above the sensor, one corner straight over it (Howell B-3):
    // F = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))].
    const Scene rect = sensor_scene(
        "  - {name: panel, type: quad, corners: [[0, 0, 1.2], [0, 3, 1.2], [2, 3, 1.2], [2, 0, 1.2]], "
        "patches: [3, 2],"
        " reflectance: [0, 0, 0]}\n");
    const double X = 2 / 1.2, Y = 3 / 1.2;
    const double exact = (X / std::sqrt(1 + X * X) * std::atan(Y / std::sqrt(1 + X * X)) +
                          Y / std::sqrt(1 + Y * Y) * std::atan(X / std::sqrt(1 + Y * Y))) /
                         (2 * kPi);
    const SensorFactors r = sensor_factors(SceneGeometry(rect), Vec3(0), Vec3(0, 0, 1), 1e-10, true);
    double rsum = 0.0;
    for (double f : r.F) rsum += f;
    EXPECT_NEAR(rsum, exact, 1e-12);
}

TEST(Sensor, UnderADomeSeesAllOfIt) {
    // A sensor on the base of a hemisphere, facing up, sees nothing but the dome: the factors
    // sum to 1, each patch by the sphere-region contour (the dome holds the sensor, so it
    // cannot block its own patches). Turned 40 degrees about its axis with the sensor, every
    // patch's factor stays: the cuts follow the sphere's axes.
    const std::string dome =
        "  - {name: dome, type: sphere, center: [0, 0, 0], radius: 1, facing: inward, polar_deg: [0, 90],"
        " patches: [6, 3], reflectance: [0, 0, 0]";
    const Scene plain = sensor_scene(dome + "}\n");
    const Scene turned = sensor_scene(dome + ", transform: {rotate_deg: {axis: [0, 0, 1], angle: 40}}}\n");
    const Vec3 x(0.2, 0.1, 0.0);
    const double c = std::cos(deg_to_rad(40)), sn = std::sin(deg_to_rad(40));
    const SensorFactors a = sensor_factors(SceneGeometry(plain), x, Vec3(0, 0, 1), 1e-10, true);
    const SensorFactors b = sensor_factors(
        SceneGeometry(turned), Vec3(c * x.x - sn * x.y, sn * x.x + c * x.y, 0.0), Vec3(0, 0, 1), 1e-10, true);
    double sum = 0.0;
    for (std::size_t j = 0; j < a.F.size(); ++j) {
        sum += a.F[j];
        EXPECT_NEAR(a.F[j], b.F[j], 1e-10) << j;
    }
    EXPECT_NEAR(sum, 1.0, 1e-10);
    EXPECT_EQ(a.closed_form, 18);
    EXPECT_EQ(b.closed_form, 18);
}

TEST(Sensor, AnOccluderTakesItsConeAway) {
    // A two-sided plate of radius 0.23 at height 0.5 under the lamp of radius 0.8 at 1.5: the
    // plate's cone (0.23 / 0.5 < 0.8 / 1.5: it lies inside the lamp's) hides r^2 / (r^2 + h^2)
    // of it. The hidden pairs take the cubature with every blocker tested; the shadow's edge
    // crosses the lamp's outer ring off every midline.
    const Scene scene = sensor_scene(
        "  - {name: lamp, type: disk, center: [0, 0, 1.5], normal: [0, 0, -1], radius: 0.8, patches: [6, 3],"
        " reflectance: [0, 0, 0]}\n"
        "  - {name: plate, type: disk, center: [0, 0, 0.5], normal: [0, 0, -1], radius: 0.23, patches: [1, "
        "1],"
        " reflectance: [0, 0, 0], two_sided: true}\n");
    const SceneGeometry g(scene);
    const SensorFactors s = sensor_factors(g, Vec3(0), Vec3(0, 0, 1), 1e-8, true);
    double lamp = 0.0, err = 0.0;
    for (int j = 0; j < 18; ++j) {
        lamp += s.F[j];
        err += s.error[j];
    }
    const double exact = 0.64 / (0.64 + 2.25) - 0.0529 / (0.0529 + 0.25);
    EXPECT_NEAR(lamp, exact, std::max(1e-6, err));
    EXPECT_NEAR(s.F[18], 0.0529 / 0.3029, 1e-10);  // the plate's underside itself
    EXPECT_EQ(s.F[19], 0.0);                       // its top faces away
    // Without visibility the lamp counts whole.
    const SensorFactors open = sensor_factors(g, Vec3(0), Vec3(0, 0, 1), 1e-8, false);
    double all = 0.0;
    for (int j = 0; j < 18; ++j) all += open.F[j];
    EXPECT_NEAR(all, 0.64 / 2.89, 1e-8);
}

TEST(Sensor, UnderAPlateOrABallTheCeilingLosesTheirConeInClosedForm) {
    // A sensor at the origin facing up, a ceiling 4 x 4 at height 2 split 3 x 3, and between
    // them a two-sided plate of radius 0.4 at height 0.7 (it hides r^2 / (r^2 + h^2)) or a ball
    // of radius 0.3 at height 0.8 (it hides sin^2 of its angular radius, (R / L)^2), a dome, a
    // lamp shade, a ball and a plate apart, or two balls whose shadows overlap: every ceiling
    // patch in closed form, the sum exact.
    const std::string ceiling =
        "  - {name: ceiling, type: quad, corners: [[-2, -2, 2], [-2, 2, 2], [2, 2, 2], [2, -2, 2]], patches: "
        "[3, 3],"
        " reflectance: [0, 0, 0]}\n";
    const double X = 1.0, Y = 1.0;  // each quarter of the ceiling: a 2 x 2 rectangle with a corner overhead
    const double quarter = (X / std::sqrt(1 + X * X) * std::atan(Y / std::sqrt(1 + X * X)) +
                            Y / std::sqrt(1 + Y * Y) * std::atan(X / std::sqrt(1 + Y * Y))) /
                           (2 * kPi);
    struct Case {
        std::string occluder;
        double hidden;
    };
    const Case cases[] = {
        {"  - {name: plate, type: disk, center: [0, 0, 0.7], normal: [0, 0, 1], radius: 0.4, patches: [1, 1],"
         " reflectance: [0, 0, 0], two_sided: true}\n",
         0.16 / (0.16 + 0.49)},
        {"  - {name: ball, type: sphere, center: [0, 0, 0.8], radius: 0.3, patches: [2, 2], reflectance: [0, "
         "0, 0]}\n",
         0.09 / 0.64},
        // A dome open below, its rim where the plate was: seen from below its outline is the rim.
        {"  - {name: dome, type: sphere, center: [0, 0, 0.7], radius: 0.4, polar_deg: [0, 90], patches: [4, "
         "1],"
         " reflectance: [0, 0, 0], two_sided: true}\n",
         0.16 / (0.16 + 0.49)},
        // A lamp shade from radius 0.4 at height 0.7 to 0.1 at 1: its wide rim's disk less the
        // narrow one's, seen through both ends.
        {"  - {name: shade, type: cone, base: [0, 0, 0.7], axis: [0, 0, 0.3], radius: 0.4, top_radius: 0.1, "
         "patches: [4, 1], reflectance: [0, 0, 0], two_sided: true}\n",
         0.16 / (0.16 + 0.49) - 0.01 / (0.01 + 1.0)},
        // A ball and a plate off the axis whose shadows never meet: cos(theta) (R / L)^2 for the
        // ball, and the off-axis point-to-disk formula for the plate (Howell B-13), added up.
        {"  - {name: ball, type: sphere, center: [0.5, 0, 1], radius: 0.15, patches: [2, 2], reflectance: "
         "[0, 0, "
         "0]}\n  - {name: plate, type: disk, center: [-0.5, 0, 1], normal: [0, 0, 1], radius: 0.15, patches: "
         "[1, 1], reflectance: [0, 0, 0], two_sided: true}\n",
         (1.0 / std::sqrt(1.25)) * 0.0225 / 1.25 +
             0.5 * (1.0 - (1.0 + 0.25 - 0.0225) / std::sqrt((1.0 + 0.25 + 0.0225) * (1.0 + 0.25 + 0.0225) -
                                                            4.0 * 0.25 * 0.0225))},
        // Two balls on the axis whose shadows overlap, the wider cone holding the other: a ball
        // of radius 0.3 at height 0.8 before one of 0.2 at 1.4 hides (0.3 / 0.8)^2, a ball of
        // 0.1 at 0.5 before one of 0.4 at 1.2 hides (0.4 / 1.2)^2 (their union's closed form).
        {"  - {name: near, type: sphere, center: [0, 0, 0.8], radius: 0.3, patches: [2, 2], reflectance: [0, "
         "0, 0]}\n  - {name: far, type: sphere, center: [0, 0, 1.4], radius: 0.2, patches: [2, 2], "
         "reflectance: [0, 0, 0]}\n",
         0.09 / 0.64},
        {"  - {name: near, type: sphere, center: [0, 0, 0.5], radius: 0.1, patches: [2, 2], reflectance: [0, "
         "0, 0]}\n  - {name: far, type: sphere, center: [0, 0, 1.2], radius: 0.4, patches: [2, 2], "
         "reflectance: [0, 0, 0]}\n",
         1.0 / 9.0},
        // A two-sided ball: its two sides are one ball, counted once.
        {"  - {name: ball, type: sphere, center: [0, 0, 0.8], radius: 0.3, patches: [2, 2], reflectance: [0, "
         "0, 0], two_sided: true}\n",
         0.09 / 0.64}};
    for (const Case& c : cases) {
        const Scene scene = sensor_scene(ceiling + c.occluder);
        const SensorFactors s = sensor_factors(SceneGeometry(scene), Vec3(0), Vec3(0, 0, 1), 1e-10, true);
        double sum = 0.0;
        for (int j = 0; j < 9; ++j) sum += s.F[static_cast<std::size_t>(j)];
        EXPECT_NEAR(sum, 4 * quarter - c.hidden, 1e-12) << c.occluder;
        EXPECT_GE(s.closed_form, 9) << c.occluder;
    }
}

TEST(Sensor, InsideAClosedConeSeesItsSideAndLidInClosedForm) {
    // A sensor on the base of a frustum closed by a lid, off its axis and facing up: the cone's
    // solid holds it, so the side cannot block its own patches and every patch takes its
    // contour. The lid is Howell's off-axis point-to-disk formula (B-13), the side what is left
    // of the hemisphere.
    const Scene frustum = sensor_scene(
        "  - {name: side, type: cone, base: [0, 0, 0], axis: [0, 0, 1.2], radius: 1, top_radius: 0.4, "
        "facing: inward, patches: [6, 3], reflectance: [0, 0, 0]}\n"
        "  - {name: lid, type: disk, center: [0, 0, 1.2], normal: [0, 0, -1], radius: 0.4, patches: [4, 2], "
        "reflectance: [0, 0, 0]}\n");
    const double a = 0.3, h = 1.2, r = 0.4;
    const double z = h * h + a * a + r * r;
    const double lid = 0.5 * (1.0 - (h * h + a * a - r * r) / std::sqrt(z * z - 4.0 * a * a * r * r));
    const SensorFactors s = sensor_factors(SceneGeometry(frustum), Vec3(a, 0, 0), Vec3(0, 0, 1), 1e-10, true);
    ASSERT_EQ(s.F.size(), 26u);
    double side = 0.0, top = 0.0;
    for (int j = 0; j < 18; ++j) side += s.F[static_cast<std::size_t>(j)];
    for (int j = 18; j < 26; ++j) top += s.F[static_cast<std::size_t>(j)];
    EXPECT_NEAR(top, lid, 1e-10);
    EXPECT_NEAR(side, 1.0 - lid, 1e-9);
    EXPECT_EQ(s.closed_form, 26);
}

TEST(Sensor, APointedConeHoldsASensorWhereItsRadiusAtThatHeightDoes) {
    // A pointed cone of radius 0.5 and height 1 split 6 x 3, sensors at height 0.3 facing up,
    // where its radius is 0.35: at 0.3 from the axis the sensor sees all of the inside above it,
    // the two upper bands' twelve patches each by its contour (the band it stands in is half
    // behind it: cubature); at 0.4 it is outside (the base's radius would hold it) and sees only
    // the side's back, no patch.
    const Scene pointed = sensor_scene(
        "  - {name: side, type: cone, base: [0, 0, 0], axis: [0, 0, 1], radius: 0.5, top_radius: 0, "
        "facing: inward, patches: [6, 3], reflectance: [0, 0, 0]}\n");
    const SceneGeometry g(pointed);
    const SensorFactors in = sensor_factors(g, Vec3(0.3, 0, 0.3), Vec3(0, 0, 1), 1e-10, true);
    double all = 0.0;
    for (const double f : in.F) all += f;
    EXPECT_NEAR(all, 1.0, 1e-9);
    EXPECT_EQ(in.closed_form, 12);
    const SensorFactors out = sensor_factors(g, Vec3(0.4, 0, 0.3), Vec3(0, 0, 1), 1e-10, true);
    for (std::size_t j = 0; j < out.F.size(); ++j) EXPECT_NEAR(out.F[j], 0.0, 1e-12) << j;
}

}  // namespace radiosa
