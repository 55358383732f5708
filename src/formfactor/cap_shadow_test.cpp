// What a spherical cap hides of a polygon from a point, against answers found another way:
// where the ball's silhouette lies wholly on the cap, the whole ball's shadow
// (point_polygon.h); where it lies wholly off it, the rim's disk (disk_shadow.h); continuity
// where the outline changes its shape (across the rim plane, and where the silhouette starts to
// cross the rim); and anywhere, a brute-force sum over the polygon with an exact ray test
// against the cap.
#include "formfactor/cap_shadow.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "../tests/closed_forms.h"
#include "formfactor/disk_shadow.h"
#include "formfactor/point_polygon.h"

namespace radiosa {

namespace {

// Does the segment from x to y meet the cap: cross the sphere at a point on the cap's side of
// the rim plane?
bool segment_meets_cap(const Vec3& x, const Vec3& y, const SphericalCap& cap) {
    const Vec3 d = y - x, o = x - cap.center;
    const double A = glm::dot(d, d), B = 2.0 * glm::dot(o, d), C = glm::dot(o, o) - cap.radius * cap.radius;
    const double disc = B * B - 4.0 * A * C;
    if (disc < 0.0) return false;
    for (const double s : {(-B - std::sqrt(disc)) / (2.0 * A), (-B + std::sqrt(disc)) / (2.0 * A)})
        if (s > 0.0 && s < 1.0 && glm::dot(o + s * d, cap.axis) >= cap.height) return true;
    return false;
}

SphericalCap cap_to(double polar_deg, const Vec3& axis = Vec3(0, 0, 1)) {
    return SphericalCap{Vec3(0.0), glm::normalize(axis), 0.5, 0.5 * std::cos(polar_deg * kPi / 180.0)};
}

// A dome (a hemisphere), a small cap, a cap larger than a hemisphere, and a bowl tilted 30
// degrees (its axis pointing down and aside).
const std::array<SphericalCap, 4> kCaps = {cap_to(90), cap_to(50), cap_to(140),
                                           cap_to(70, Vec3(std::sin(0.5236), 0.0, -std::cos(0.5236)))};

}  // namespace

TEST(CapShadow, TheWholeBallOrTheRimWhereTheSilhouetteMissesTheRim) {
    // Above a large cap near its axis the ball's silhouette lies wholly on the cap: the cap hides
    // what the whole ball hides, toward a floor. Below a small cap, looking up at its open end,
    // the silhouette lies wholly below the rim: the cap hides what its rim's disk hides, toward
    // a ceiling.
    const std::array<Vec3, 4> ceiling = {Vec3(-3, -3, 3), Vec3(-3, 3, 3), Vec3(3, 3, 3), Vec3(3, -3, 3)};
    const std::array<Vec3, 4> floor = {Vec3(-3, -3, -3), Vec3(3, -3, -3), Vec3(3, 3, -3), Vec3(-3, 3, -3)};
    const SphericalCap big = cap_to(140), small = cap_to(40);
    for (const Vec3& m : {Vec3(0, 0, 1), glm::normalize(Vec3(0.3, 0.2, 1))}) {
        // Above the big cap, toward the floor: its silhouette is a circle at height 0.5^2 / 2.
        const Vec3 x1(0.05, 0.0, 2.0);
        const double ball = point_to_polygon_blocked(x1, -m, floor.data(), 4, BoundingSphere{Vec3(0.0), 0.5});
        EXPECT_NEAR(point_to_polygon_hidden_by_cap(x1, -m, floor.data(), 4, big).value, ball, 1e-13);
        EXPECT_GT(ball, 1e-3);
        // Below the small cap, toward the ceiling through its open end.
        for (const Vec3& x2 : {Vec3(0.0, 0.05, -2.0), Vec3(0.1, 0.0, 0.2)}) {
            const double disk =
                point_to_polygon_hidden_by_disk(x2, m, ceiling.data(), 4, cap_rim(small)).value;
            EXPECT_NEAR(point_to_polygon_hidden_by_cap(x2, m, ceiling.data(), 4, small).value, disk, 1e-13)
                << x2.z;
            EXPECT_GT(disk, 1e-3);
        }
    }
}

TEST(CapShadow, ContinuousWhereTheOutlineChangesItsShape) {
    // Across the rim plane (the rim's silhouette arc flips to the other side of the contact
    // circle) and across the ball's surface below the rim (from the rim alone to the rim and the
    // contact circle), the value must not jump.
    const auto v = test::wall(2.0, 1.5, 0.0);
    const Vec3 n(0, 1, 0);
    for (const double polar : {50.0, 90.0, 140.0}) {
        const SphericalCap cap = cap_to(polar);
        for (const double y : {-1.2, -0.7}) {
            const double z = cap.height;
            const double below =
                point_to_polygon_hidden_by_cap(Vec3(0.2, y, z - 1e-9), n, v.data(), 4, cap).value;
            const double above =
                point_to_polygon_hidden_by_cap(Vec3(0.2, y, z + 1e-9), n, v.data(), 4, cap).value;
            EXPECT_NEAR(below, above, 1e-8) << polar << ": " << y;
            EXPECT_GT(below, 1e-3);
        }
        // Just inside and just outside the ball, under the rim plane.
        const double z = cap.height - 0.1, r = std::sqrt(0.25 - z * z);
        const Vec3 dir = glm::normalize(Vec3(0.3, -1.0, 0.0));
        const Vec3 p = r * dir + Vec3(0, 0, z);
        const double in = point_to_polygon_hidden_by_cap(p * (1.0 - 1e-10), n, v.data(), 4, cap).value;
        const double out = point_to_polygon_hidden_by_cap(p * (1.0 + 1e-10), n, v.data(), 4, cap).value;
        EXPECT_NEAR(in, out, 1e-7) << polar;
    }
}

TEST(CapShadow, MatchesABruteForceSumAnywhere) {
    // Random points around each cap (outside its solid, on either side of its rim plane), random
    // normals facing the wall, against 600 x 600 points of a wall behind it with an exact ray
    // test (the midpoint rule's error at the shadow's edge is O(1/600)).
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const auto v = test::wall(1.5, 1.0, 0.0);
    for (const SphericalCap& cap : kCaps) {
        int cases = 0, open_side = 0, crossing = 0;
        while (cases < 10) {
            const Vec3 x(1.0 * u(rng), -0.75 + 0.3 * u(rng), 1.0 * u(rng));
            const double along = glm::dot(x - cap.center, cap.axis);
            if (glm::length(x - cap.center) < cap.radius + 0.02 && along > cap.height - 0.02) continue;
            const Vec3 n = glm::normalize(Vec3(0.4 * u(rng), 1.0, 0.4 * u(rng)));
            const double exact = point_to_polygon_hidden_by_cap(x, n, v.data(), 4, cap).value;
            const double brute = test::brute_force_hidden(
                x, n, v, 600, [&](const Vec3& a, const Vec3& b) { return segment_meets_cap(a, b, cap); });
            EXPECT_NEAR(exact, brute, 2e-3 * point_to_polygon(x, n, v.data(), 4, nullptr) + 1e-6)
                << cap.height << ": " << x.x << "," << x.y << "," << x.z;
            open_side += along < cap.height;
            crossing += glm::length(x - cap.center) > cap.radius && exact > 1e-2;
            ++cases;
        }
        EXPECT_GE(open_side, 2) << cap.height;
        EXPECT_GE(crossing, 5) << cap.height;
    }
}

TEST(CapShadow, HullTestIsExact) {
    // Segments passing just beside the cap's solid (over the rim plane's open side, inside the
    // ball's radius; beside the pole) meet nothing; just into it, they do.
    const SphericalCap dome = cap_to(90), small = cap_to(50);
    auto seg = [](const Vec3& a, const Vec3& b) { return std::array<Vec3, 2>{a, b}; };
    EXPECT_FALSE(hull_meets_cap(seg(Vec3(-1, 0, -0.01), Vec3(1, 0, -0.01)), dome));
    EXPECT_TRUE(hull_meets_cap(seg(Vec3(-1, 0, 0.01), Vec3(1, 0, 0.01)), dome));
    EXPECT_FALSE(hull_meets_cap(seg(Vec3(-1, 0, 0.51), Vec3(1, 0, 0.51)), dome));
    EXPECT_FALSE(hull_meets_cap(seg(Vec3(-1, 0, 0.3), Vec3(1, 0, 0.3)), small));
    EXPECT_TRUE(hull_meets_cap(seg(Vec3(-1, 0, 0.33), Vec3(1, 0, 0.33)), small));
    // The least distance from a plane: below the small cap its rim, beside the dome its ball.
    EXPECT_NEAR(cap_min_signed_distance(small, Vec3(0, 0, 1), -1.0), 1.0 + small.height, 1e-15);
    EXPECT_NEAR(cap_min_signed_distance(dome, Vec3(1, 0, 0), -1.0), 0.5, 1e-15);
    EXPECT_NEAR(cap_min_signed_distance(dome, Vec3(0, 0, 1), -1.0), 1.0, 1e-15);
}

}  // namespace radiosa
