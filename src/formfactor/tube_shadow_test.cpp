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

#include "../tests/closed_forms.h"
#include "formfactor/column_shadow.h"
#include "formfactor/disk_shadow.h"
#include "formfactor/point_polygon.h"

namespace radiosa {

namespace {

// Does the segment from x to y meet the open tube (its side, not its ends)? Along it the
// squared distance from the axis less the squared radius at that height is a quadratic.
bool segment_meets_tube(const Vec3& x, const Vec3& y, const RoundFrustum& t) {
    const Vec3 d = y - x, o = x - t.base;
    const double k = (t.top_radius - t.radius) / t.length, h0 = glm::dot(o, t.axis), dh = glm::dot(d, t.axis);
    const Vec3 dp = d - dh * t.axis, op = o - h0 * t.axis;
    const double r0 = t.radius + k * h0;
    const double A = glm::dot(dp, dp) - k * k * dh * dh, B = 2.0 * (glm::dot(op, dp) - k * dh * r0),
                 C = glm::dot(op, op) - r0 * r0;
    std::array<double, 2> roots{};
    int n = 0;
    if (std::abs(A) < 1e-14) {
        if (B != 0.0) roots[n++] = -C / B;
    } else {
        const double disc = B * B - 4.0 * A * C;
        if (disc < 0.0) return false;
        roots = {(-B - std::sqrt(disc)) / (2.0 * A), (-B + std::sqrt(disc)) / (2.0 * A)};
        n = 2;
    }
    for (int q = 0; q < n; ++q) {
        const double s = roots[static_cast<std::size_t>(q)];
        if (!(s > 0.0 && s < 1.0)) continue;
        const double h = h0 + s * dh;
        if (h >= 0.0 && h <= t.length && t.radius_at(h) >= 0.0) return true;
    }
    return false;
}

const RoundFrustum kTube{Vec3(0, 0, -0.5), Vec3(0, 0, 1), 1.0, 0.3, 0.3};
// A lamp shade, radius 0.4 at the bottom and 0.15 at the top, and the same upside down.
const RoundFrustum kShade{Vec3(0, 0, -0.5), Vec3(0, 0, 1), 1.0, 0.4, 0.15};
const RoundFrustum kFunnel{Vec3(0, 0, -0.5), Vec3(0, 0, 1), 1.0, 0.15, 0.4};
const std::array<RoundFrustum, 3> kTubes = {kTube, kShade, kFunnel};

}  // namespace

TEST(TubeShadow, FromUnderEitherEndTheNearDiskMinusTheFarOne) {
    // x beyond an end, where one rim's cone holds the other's (near the axis; for the cylinder,
    // anywhere within it): the open tube hides what the wider cone's disk hides less what the
    // other disk hides (those directions pass through both ends). Below the base toward a
    // ceiling, and above the top toward a floor; cylinder, shade and funnel.
    const std::array<Vec3, 4> ceiling = {Vec3(-3, -3, 2), Vec3(-3, 3, 2), Vec3(3, 3, 2), Vec3(3, -3, 2)};
    const std::array<Vec3, 4> floor = {Vec3(-3, -3, -2), Vec3(3, -3, -2), Vec3(3, 3, -2), Vec3(-3, 3, -2)};
    const std::array<Vec3, 5> points = {Vec3(0, 0, -1.5), Vec3(0.01, 0.01, -0.51), Vec3(0.01, 0, -0.9),
                                        Vec3(0.1, -0.2, -0.9), Vec3(0.29, 0.0, -0.51)};
    for (const RoundFrustum& tube : kTubes) {
        const auto rims = tube_rims(tube);
        for (const int up : {1, -1})
            for (std::size_t k = 0; k < (tube.radius == tube.top_radius ? points.size() : 3); ++k)
                for (const Vec3& m : {Vec3(0, 0, 1), glm::normalize(Vec3(0.3, 0.2, 1))}) {
                    const auto& v = up > 0 ? ceiling : floor;
                    const Vec3 x(points[k].x, points[k].y, up * points[k].z), n(m.x, m.y, up * m.z);
                    const double disks =
                        std::abs(point_to_polygon_hidden_by_disk(x, n, v.data(), 4, rims[0]).value -
                                 point_to_polygon_hidden_by_disk(x, n, v.data(), 4, rims[1]).value);
                    const ShadowValue t = point_to_polygon_hidden_by_tube(x, n, v.data(), 4, tube);
                    EXPECT_NEAR(t.value, disks, 1e-13)
                        << tube.top_radius << ": " << x.x << "," << x.y << "," << x.z;
                    EXPECT_GT(t.value, 1e-3);
                }
    }
}

TEST(TubeShadow, BetweenItsEndPlanesItsTheColumnsWedge) {
    // A wall within the tube's slab, x too: the tube blocks what the infinite cylinder does, and
    // the column's closed form (a polygon cut by the wedge) applies.
    const RoundTube tall{Vec3(0, 0, -2), Vec3(0, 0, 1), 4.0, 0.3};
    const RoundFrustum same{tall.base, tall.axis, tall.length, tall.radius, tall.radius};
    const auto v = test::wall(1.0, 1.5, 0.0);
    for (const Vec3& x : {Vec3(0, -1.2, 0.0), Vec3(0.4, -0.9, 0.5), Vec3(-0.7, -1.0, -0.6)}) {
        const Vec3 n = glm::normalize(Vec3(0.1, 1.0, 0.2));
        ASSERT_TRUE(column_spans_pair(std::array<Vec3, 1>{x}, v, tall, 1e-9));
        const double column = point_to_polygon_hidden_by_column(x, n, v.data(), 4, tall);
        EXPECT_NEAR(point_to_polygon_hidden_by_tube(x, n, v.data(), 4, same).value, column, 1e-13);
        EXPECT_GT(column, 1e-2);
    }
}

TEST(TubeShadow, AHullMeetsTheSolidNotItsWidestCylinder) {
    // The sliver search asks whether segments from a region to a receiver can meet the tube: a
    // small tetrahedron beside the shade's narrow top (radius 0.175 at its height) does not, though
    // it lies within the wide rim's radius; moved in by 0.2 it does. So for the cylinder.
    const std::array<Vec3, 4> corners = {Vec3(0, 0, 0), Vec3(0.02, 0, 0), Vec3(0, 0.02, 0), Vec3(0, 0, 0.02)};
    auto at = [&](const Vec3& c) {
        std::array<Vec3, 4> q;
        for (int k = 0; k < 4; ++k) q[static_cast<std::size_t>(k)] = c + corners[static_cast<std::size_t>(k)];
        return q;
    };
    EXPECT_FALSE(hull_meets_tube(at(Vec3(0.25, 0, 0.4)), kShade));
    EXPECT_TRUE(hull_meets_tube(at(Vec3(0.05, 0, 0.4)), kShade));
    EXPECT_TRUE(hull_meets_tube(at(Vec3(0.25, 0, 0.4)), kFunnel));
    EXPECT_FALSE(hull_meets_tube(at(Vec3(0.31, 0, 0.4)), kTube));
    EXPECT_TRUE(hull_meets_tube(at(Vec3(0.27, 0, 0.4)), kTube));
    // A segment passing beside the cone's end, through no part of the solid, and one through it.
    EXPECT_FALSE(hull_meets_tube(std::array<Vec3, 2>{Vec3(0.3, 0, 0.6), Vec3(0.3, 0, 0.25)}, kShade));
    EXPECT_TRUE(hull_meets_tube(std::array<Vec3, 2>{Vec3(-1, 0, 0), Vec3(1, 0, 0)}, kShade));
}

TEST(TubeShadow, ContinuousAcrossAnEndPlane) {
    // Crossing an end plane, the outline changes from the two rims' near arcs to the hull of the
    // rims minus the lens: the value must not jump.
    const auto v = test::wall(2.0, 1.5, 0.0);
    const Vec3 n(0, 1, 0);
    for (const RoundFrustum& tube : kTubes)
        for (const double z : {-0.5, 0.5})
            for (const double y : {-1.2, -0.5}) {
                const double below =
                    point_to_polygon_hidden_by_tube(Vec3(0.2, y, z - 1e-9), n, v.data(), 4, tube).value;
                const double above =
                    point_to_polygon_hidden_by_tube(Vec3(0.2, y, z + 1e-9), n, v.data(), 4, tube).value;
                EXPECT_NEAR(below, above, 1e-8) << tube.top_radius << ": " << y << "," << z;
                EXPECT_GT(below, 1e-3);
            }
}

TEST(TubeShadow, MatchesABruteForceSumAnywhere) {
    // Random points around each tube (beyond either end plane, or between them outside it),
    // random normals facing the wall, against 600 x 600 points of a wall behind the tube with an
    // exact ray test (the midpoint rule's error at the shadow's edge is O(1/600)).
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const auto v = test::wall(1.5, 1.0, 0.0);
    for (const RoundFrustum& tube : kTubes) {
        int cases = 0, lens = 0, shaded = 0;
        while (cases < 10) {
            const Vec3 x(1.2 * u(rng), -0.9 + 0.5 * u(rng), 1.4 * u(rng));
            const Vec3 off(x.x, x.y, 0.0);
            if (std::abs(x.z) <= 0.5 && glm::length(off) <= tube.radius_at(x.z + 0.5) + 0.05) continue;
            const Vec3 n = glm::normalize(Vec3(0.4 * u(rng), 1.0, 0.4 * u(rng)));
            const double exact = point_to_polygon_hidden_by_tube(x, n, v.data(), 4, tube).value;
            const double brute = test::brute_force_hidden(
                x, n, v, 600, [&](const Vec3& a, const Vec3& b) { return segment_meets_tube(a, b, tube); });
            EXPECT_NEAR(exact, brute, 2e-3 * point_to_polygon(x, n, v.data(), 4, nullptr) + 1e-6)
                << tube.top_radius << ": " << x.x << "," << x.y << "," << x.z;
            lens += std::abs(x.z) > 0.5;
            shaded += exact > 1e-2;
            ++cases;
        }
        EXPECT_GE(lens, 3);
        EXPECT_GE(shaded, 5);
    }
}

}  // namespace radiosa
