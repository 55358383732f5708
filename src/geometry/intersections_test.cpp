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
    // The whole sphere would cross the floor; its upper half only stands on it. Partial spheres
    // are not checked as balls (the checks cover quads and whole spheres).
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

TEST(Intersections, TheWarningNamesEveryPair) {
    const Scene s = scene_of(quad("floor", test::kFloor) + sphere("ball", "[0.5, 0.5, 0.1]", 0.3) +
                             sphere("other", "[0.5, 0.5, 0.3]", 0.3));
    const SceneGeometry g(s);
    const auto found = find_intersections(g);
    ASSERT_EQ(found.size(), 2u);
    EXPECT_EQ(intersection_names(g, found), "'floor' and 'ball', 'ball' and 'other'");
}

}  // namespace radiosa
