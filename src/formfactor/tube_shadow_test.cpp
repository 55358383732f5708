// What a finite round tube hides of a polygon from a point, against answers found another way:
// from under either end, the near rim's disk minus the far rim's (disk_shadow.h); between its end
// planes with a polygon there too, the column's wedge (column_shadow.h); continuity across an end
// plane, where the outline changes its shape; and anywhere, a brute-force sum over the polygon
// with an exact ray test against the open tube.
#include "formfactor/tube_shadow.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "formfactor/column_shadow.h"
#include "formfactor/disk_shadow.h"
#include "formfactor/point_polygon.h"

namespace radiosa {

namespace {

// Does the segment from x to y meet the open tube (its side, not its ends)?
bool segment_meets_tube(const Vec3& x, const Vec3& y, const RoundTube& t) {
    const Vec3 d = y - x, o = x - t.base;
    const Vec3 dp = d - glm::dot(d, t.axis) * t.axis, op = o - glm::dot(o, t.axis) * t.axis;
    const double A = glm::dot(dp, dp), B = 2.0 * glm::dot(op, dp), C = glm::dot(op, op) - t.radius * t.radius;
    const double disc = B * B - 4.0 * A * C;
    if (!(A > 0.0) || disc < 0.0) return false;
    for (const double s : {(-B - std::sqrt(disc)) / (2.0 * A), (-B + std::sqrt(disc)) / (2.0 * A)}) {
        if (!(s > 0.0 && s < 1.0)) continue;
        const double h = glm::dot(o + s * d, t.axis);
        if (h >= 0.0 && h <= t.length) return true;
    }
    return false;
}

// The hidden form factor by the midpoint rule on an m x m grid over the quad v (a
// parallelogram), with the ray test at each point.
double brute_force_hidden(const Vec3& x, const Vec3& n, const std::array<Vec3, 4>& v, const RoundTube& t,
                          int m) {
    const Vec3 e = v[1] - v[0], f = v[3] - v[0];
    const Vec3 nv = glm::cross(e, f);
    const double da = glm::length(nv) / (m * m);
    const Vec3 unit = nv / glm::length(nv);
    double sum = 0.0;
    for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b) {
            const Vec3 y = v[0] + ((a + 0.5) / m) * e + ((b + 0.5) / m) * f;
            const Vec3 r = y - x;
            const double l2 = glm::dot(r, r);
            const double cx = glm::dot(n, r), cy = -glm::dot(unit, r);
            if (cx <= 0.0 || cy <= 0.0 || !segment_meets_tube(x, y, t)) continue;
            sum += cx * cy / (kPi * l2 * l2) * da;
        }
    return sum;
}

// A wall: the square of half-size a in the plane y = w, centred at height zc, facing -y.
std::array<Vec3, 4> wall(double a, double w, double zc) {
    return {Vec3(-a, w, zc - a), Vec3(a, w, zc - a), Vec3(a, w, zc + a), Vec3(-a, w, zc + a)};
}

const RoundTube kTube{Vec3(0, 0, -0.5), Vec3(0, 0, 1), 1.0, 0.3};

}  // namespace

TEST(TubeShadow, FromUnderEitherEndTheNearDiskMinusTheFarOne) {
    // x beyond an end, within the tube's cylinder: the open tube hides what its near rim's disk
    // hides less what its far rim's disk hides (the far disk's directions pass through both
    // ends). Below the base toward a ceiling, and above the top toward a floor.
    const std::array<Vec3, 4> ceiling = {Vec3(-3, -3, 2), Vec3(-3, 3, 2), Vec3(3, 3, 2), Vec3(3, -3, 2)};
    const std::array<Vec3, 4> floor = {Vec3(-3, -3, -2), Vec3(3, -3, -2), Vec3(3, 3, -2), Vec3(-3, 3, -2)};
    const auto rims = tube_rims(kTube);
    for (const int up : {1, -1}) {
        const auto& v = up > 0 ? ceiling : floor;
        const int near = up > 0 ? 0 : 1;
        for (const Vec3& p : {Vec3(0, 0, -1.5), Vec3(0.1, -0.2, -0.9), Vec3(0.29, 0.0, -0.51)})
            for (const Vec3& m : {Vec3(0, 0, 1), glm::normalize(Vec3(0.3, 0.2, 1))}) {
                const Vec3 x(p.x, p.y, up * p.z), n(m.x, m.y, up * m.z);
                const double disks =
                    point_to_polygon_hidden_by_disk(x, n, v.data(), 4, rims[static_cast<std::size_t>(near)])
                        .value -
                    point_to_polygon_hidden_by_disk(x, n, v.data(), 4,
                                                    rims[static_cast<std::size_t>(1 - near)])
                        .value;
                const TubeShadowValue t = point_to_polygon_hidden_by_tube(x, n, v.data(), 4, kTube);
                EXPECT_NEAR(t.value, disks, 1e-13) << x.x << "," << x.y << "," << x.z;
                EXPECT_GT(t.value, 1e-3);
            }
    }
}

TEST(TubeShadow, BetweenItsEndPlanesItsTheColumnsWedge) {
    // A wall within the tube's slab, x too: the tube blocks what the infinite cylinder does, and
    // the column's closed form (a polygon cut by the wedge) applies.
    const RoundTube tall{Vec3(0, 0, -2), Vec3(0, 0, 1), 4.0, 0.3};
    const auto v = wall(1.0, 1.5, 0.0);
    for (const Vec3& x : {Vec3(0, -1.2, 0.0), Vec3(0.4, -0.9, 0.5), Vec3(-0.7, -1.0, -0.6)}) {
        const Vec3 n = glm::normalize(Vec3(0.1, 1.0, 0.2));
        ASSERT_TRUE(column_spans_pair(std::array<Vec3, 1>{x}, v, tall, 1e-9));
        const double column = point_to_polygon_hidden_by_column(x, n, v.data(), 4, tall);
        EXPECT_NEAR(point_to_polygon_hidden_by_tube(x, n, v.data(), 4, tall).value, column, 1e-13);
        EXPECT_GT(column, 1e-2);
    }
}

TEST(TubeShadow, ContinuousAcrossAnEndPlane) {
    // Crossing the top end plane, the outline changes from the two rims' near arcs to the hull
    // of the rims minus the lens: the value must not jump.
    const auto v = wall(2.0, 1.5, 0.0);
    const Vec3 n(0, 1, 0);
    for (const double y : {-1.2, -0.5}) {
        const double below =
            point_to_polygon_hidden_by_tube(Vec3(0.2, y, 0.5 - 1e-9), n, v.data(), 4, kTube).value;
        const double above =
            point_to_polygon_hidden_by_tube(Vec3(0.2, y, 0.5 + 1e-9), n, v.data(), 4, kTube).value;
        EXPECT_NEAR(below, above, 1e-8);
        EXPECT_GT(below, 1e-3);
    }
}

TEST(TubeShadow, MatchesABruteForceSumAnywhere) {
    // Random points around the tube (beyond either end plane, or between them outside the
    // cylinder), random normals facing the wall, against 600 x 600 points of a wall behind the
    // tube with an exact ray test (the midpoint rule's error at the shadow's edge is O(1/600)).
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const auto v = wall(1.5, 1.0, 0.0);
    int cases = 0, lens = 0, shaded = 0;
    while (cases < 12) {
        const Vec3 x(1.2 * u(rng), -0.9 + 0.5 * u(rng), 1.4 * u(rng));
        const Vec3 off(x.x, x.y, 0.0);
        if (std::abs(x.z) <= 0.5 && glm::length(off) <= kTube.radius + 0.05) continue;
        const Vec3 n = glm::normalize(Vec3(0.4 * u(rng), 1.0, 0.4 * u(rng)));
        const double exact = point_to_polygon_hidden_by_tube(x, n, v.data(), 4, kTube).value;
        const double brute = brute_force_hidden(x, n, v, kTube, 600);
        EXPECT_NEAR(exact, brute, 2e-3 * point_to_polygon(x, n, v.data(), 4, nullptr) + 1e-6)
            << x.x << "," << x.y << "," << x.z;
        lens += std::abs(x.z) > 0.5;
        shaded += exact > 1e-2;
        ++cases;
    }
    EXPECT_GE(lens, 4);
    EXPECT_GE(shaded, 8);
}

}  // namespace radiosa
