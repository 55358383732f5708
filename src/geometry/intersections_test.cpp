// Intersecting surfaces are found exactly; surfaces that only touch are not reported.
#include "geometry/intersections.h"

#include <gtest/gtest.h>

#include "../tests/test_scenes.h"
#include "geometry/scene_geometry.h"

namespace radiosa {

using test::quad;
using test::scene_of;

namespace {

std::string sphere(const std::string& name, const std::string& center, double r) {
    return "  - name: " + name + "\n    type: sphere\n    center: " + center +
           "\n    radius: " + std::to_string(r) + "\n    patches: [4, 2]\n    reflectance: [0, 0, 0]\n";
}

int count(const std::string& surfaces) {
    return static_cast<int>(find_intersections(SceneGeometry(scene_of(surfaces))).size());
}

}  // namespace

TEST(Intersections, PolygonsThatCrossAreFound) {
    // A wall through the middle of the floor, reaching below it.
    EXPECT_EQ(count(quad("floor", test::kFloor) +
                    quad("wall", "[[0, 0.5, -0.5], [0, 0.5, 0.5], [1, 0.5, 0.5], [1, 0.5, -0.5]]")),
              1);
}

TEST(Intersections, PolygonsThatTouchAreNot) {
    // Sharing an edge, standing on the floor's middle, parallel, or crossing the floor's plane
    // beside the floor.
    EXPECT_EQ(count(quad("floor", test::kFloor) + quad("wall", test::kWall)), 0);
    EXPECT_EQ(count(quad("floor", test::kFloor) +
                    quad("wall", "[[0, 0.5, 0], [0, 0.5, 1], [1, 0.5, 1], [1, 0.5, 0]]")),
              0);
    EXPECT_EQ(count(quad("floor", test::kFloor) + quad("ceiling", test::kCeiling)), 0);
    EXPECT_EQ(count(quad("floor", test::kFloor) +
                    quad("wall", "[[2, 0.5, -0.5], [2, 0.5, 0.5], [3, 0.5, 0.5], [3, 0.5, -0.5]]")),
              0);
}

TEST(Intersections, SphereThroughAPolygonIsFoundTangentOrInsideIsNot) {
    EXPECT_EQ(count(quad("floor", test::kFloor) + sphere("ball", "[0.5, 0.5, 0.1]", 0.3)), 1);
    // Through the floor's edge only.
    EXPECT_EQ(count(quad("floor", test::kFloor) + sphere("ball", "[1.1, 0.5, 0]", 0.3)), 1);
    EXPECT_EQ(count(quad("floor", test::kFloor) + sphere("ball", "[0.5, 0.5, 0.3]", 0.3)), 0);
    // The floor wholly inside a big sphere, and a ball beside the floor.
    EXPECT_EQ(count(quad("floor", test::kFloor) + sphere("dome", "[0.5, 0.5, 0]", 5)), 0);
    EXPECT_EQ(count(quad("floor", test::kFloor) + sphere("ball", "[3, 0.5, 0]", 0.3)), 0);
}

TEST(Intersections, AHemisphereStandingOnAFloorIsNotAnIntersection) {
    // The whole sphere would cross the floor; its upper half only stands on it (a partial
    // sphere is sampled, and its rim on the floor is the floor's crossing of its edge).
    const std::string dome =
        "  - {name: dome, type: sphere, center: [0.5, 0.5, 0], radius: 0.3, polar_deg: [0, 90], "
        "patches: [4, 2], reflectance: [0, 0, 0]}\n";
    EXPECT_EQ(count(quad("floor", test::kFloor) + dome), 0);
    EXPECT_EQ(count(quad("floor", test::kFloor) + sphere("ball", "[0.5, 0.5, 0]", 0.3)), 1);
}

TEST(Intersections, SpheresThatCrossAreFoundNestedOrTouchingAreNot) {
    EXPECT_EQ(count(sphere("a", "[0, 0, 0]", 1) + sphere("b", "[1.5, 0, 0]", 1)), 1);
    EXPECT_EQ(count(sphere("a", "[0, 0, 0]", 1) + sphere("b", "[2, 0, 0]", 1)), 0);
    EXPECT_EQ(count(sphere("a", "[0, 0, 0]", 1) + sphere("b", "[0.2, 0, 0]", 0.5)), 0);
}

// Curved types other than whole spheres are sampled along their isoparametric lines: a column
// through a table (also through its edge), an upright disk half sunk into the floor, a dome sunk
// into it, a ring sunk into it are found; a column standing between floor and ceiling or on the
// table, a disk standing or lying on the floor, a closed can (two disks on a tube's rims), a
// ring resting on the floor and a shade over its lamp are not.
TEST(Intersections, CurvedTypesThatCrossAreFoundThoseThatTouchAreNot) {
    const std::string floor = quad("floor", "[[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]");
    const std::string ceiling = quad("ceiling", "[[-2, -2, 2], [-2, 2, 2], [2, 2, 2], [2, -2, 2]]");
    const std::string table = quad("table", "[[-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]]");
    const auto column = [](const std::string& base, const std::string& axis) {
        return "  - {name: column, type: cylinder, base: " + base + ", axis: " + axis +
               ", radius: 0.2, patches: [8, 2], reflectance: [0, 0, 0]}\n";
    };
    EXPECT_EQ(count(table + column("[0, 0, 0]", "[0, 0, 2]")), 1);
    EXPECT_EQ(count(table + column("[0.95, 0, 0]", "[0, 0, 2]")), 1);  // through the table's edge
    EXPECT_EQ(count(floor + ceiling + column("[0, 0, 0]", "[0, 0, 2]")), 0);
    EXPECT_EQ(count(table + column("[0, 0, 1]", "[0, 0, 1]")), 0);    // standing on the table
    EXPECT_EQ(count(table + column("[0, 0, 1.5]", "[1, 0, 0]")), 0);  // lying above it, apart

    const auto disk = [](const std::string& center, const std::string& normal, double r,
                         const std::string& name = "disk") {
        return "  - {name: " + name + ", type: disk, center: " + center + ", normal: " + normal +
               ", radius: " + std::to_string(r) + ", patches: [4, 1], reflectance: [0, 0, 0]}\n";
    };
    EXPECT_EQ(count(floor + disk("[0, 0, 0.2]", "[1, 0, 0]", 0.5)), 1);  // upright, half sunk
    EXPECT_EQ(count(floor + disk("[0, 0, 0.5]", "[1, 0, 0]", 0.5)), 0);  // upright, on the floor
    EXPECT_EQ(count(floor + disk("[0, 0, 0]", "[0, 0, 1]", 0.5)), 0);    // lying on it
    // The inside of a closed can.
    EXPECT_EQ(count("  - {name: wall, type: cylinder, base: [0, 0, 0], axis: [0, 0, 1], radius: 0.5, "
                    "facing: inward, patches: [8, 2], reflectance: [0, 0, 0]}\n" +
                    disk("[0, 0, 0]", "[0, 0, 1]", 0.5) + disk("[0, 0, 1]", "[0, 0, -1]", 0.5, "lid")),
              0);

    const std::string dome_sunk =
        "  - {name: dome, type: sphere, center: [0, 0, -0.1], radius: 0.5, polar_deg: [0, 120], "
        "patches: [4, 2], reflectance: [0, 0, 0]}\n";
    EXPECT_EQ(count(floor + dome_sunk), 1);

    const auto ring = [](double z) {
        return "  - {name: ring, type: torus, center: [0, 0, " + std::to_string(z) +
               "], axis: [0, 0, 1], major_radius: 0.5, minor_radius: 0.1, patches: [8, 4], "
               "reflectance: [0, 0, 0]}\n";
    };
    EXPECT_EQ(count(floor + ring(0.05)), 1);
    EXPECT_EQ(count(floor + ring(0.1)), 0);  // resting on the floor

    // A shade (cone) over a lamp disk at its lower rim.
    EXPECT_EQ(count("  - {name: shade, type: cone, base: [0, 0, 1], axis: [0, 0, 0.5], radius: 0.4, "
                    "top_radius: 0.1, facing: inward, patches: [8, 1], reflectance: [0, 0, 0]}\n" +
                    disk("[0, 0, 1]", "[0, 0, -1]", 0.4)),
              0);
}

TEST(Intersections, TheWarningNamesEveryPair) {
    const Scene s = scene_of(quad("floor", test::kFloor) + sphere("ball", "[0.5, 0.5, 0.1]", 0.3) +
                             sphere("other", "[0.5, 0.5, 0.3]", 0.3));
    const SceneGeometry g(s);
    const auto found = find_intersections(g);
    ASSERT_EQ(found.size(), 2u);
    EXPECT_EQ(intersection_names(g, found), "'floor' and 'ball', 'ball' and 'other'");
}

}  // namespace radiosa
