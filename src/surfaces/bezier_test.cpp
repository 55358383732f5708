// The bezier type: the map, its partials, areas, bounds and ray hits, degenerate (collapsed)
// edges, and the patch-file reader on the shipped teapot.
#include "surfaces/bezier.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "surfaces/check_surface.h"
#include "util/error.h"

namespace radiosa {
namespace {

// A flat square [0,3]^2 as a Bezier patch whose control points are an even grid: P(s,t) = (3s, 3t, 0).
std::array<Vec3, 16> flat_grid(double lift = 0.0) {
    std::array<Vec3, 16> cp;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            cp[4 * i + j] = Vec3(j, i, (i == 1 || i == 2) && (j == 1 || j == 2) ? lift : 0.0);
    return cp;
}

TEST(Bezier, EvenGridIsTheFlatSquare) {
    const BezierSurface b(flat_grid());
    EXPECT_NEAR(glm::length(b.point(0.3, 0.7) - Vec3(0.9, 2.1, 0)), 0.0, 1e-15);
    EXPECT_NEAR(b.area(0, 1, 0, 1), 9.0, 1e-13);
    EXPECT_NEAR(b.area(0.2, 0.5, 0.1, 0.4), 9.0 * 0.09, 1e-13);
    EXPECT_GT(b.normal(0.5, 0.5).z, 0.0);  // dP/ds x dP/dt = +z: the front
    const auto h = b.intersect(Ray{Vec3(1.5, 0.6, 2), Vec3(0, 0, -1)}, 0, 10, HitSide::FrontOnly);
    ASSERT_TRUE(h);
    EXPECT_NEAR(h->dist, 2.0, 1e-13);
    EXPECT_NEAR(h->s, 0.5, 1e-13);
    EXPECT_NEAR(h->t, 0.2, 1e-13);
    EXPECT_FALSE(b.intersect(Ray{Vec3(1.5, 0.6, -2), Vec3(0, 0, 1)}, 0, 10, HitSide::FrontOnly));
    EXPECT_FALSE(b.intersect(Ray{Vec3(3.5, 0.6, 2), Vec3(0, 0, -1)}, 0, 10, HitSide::Any));
}

TEST(Bezier, BulgedPatchPassesTheSurfaceChecks) {
    const BezierSurface b(flat_grid(1.5));
    // Ranges and bounds come from the sub-patch's control points: valid, within a hull's slack.
    check_surface(b, 0.25);
    // A ray grazing the bulge's top from the side, and one that crosses it twice.
    const Vec3 top = b.point(0.5, 0.5);
    EXPECT_NEAR(top.z, 1.5 * 2 * 3 * 0.125 * 3 * 0.125 * 2, 1e-12);  // (B1 + B2)(1/2)^2 * 1.5
    const auto twice = b.intersect(Ray{Vec3(-1, 1.5, 0.5), Vec3(1, 0, 0)}, 0, 10, HitSide::Any);
    ASSERT_TRUE(twice);
    EXPECT_TRUE(twice->front);  // it meets the rising slope's top side first
    EXPECT_NEAR(b.point(twice->s, twice->t).z, 0.5, 1e-12);
    EXPECT_LT(twice->s, 0.5);
    const auto out =
        b.intersect(Ray{Vec3(-1, 1.5, 0.5), Vec3(1, 0, 0)}, twice->dist + 1e-9, 10, HitSide::Any);
    ASSERT_TRUE(out);  // and leaves through the falling slope's underside
    EXPECT_FALSE(out->front);
    EXPECT_GT(out->s, 0.5);
    EXPECT_NEAR(out->s, 1.0 - twice->s, 1e-12);  // the bulge is symmetric in s
}

TEST(Bezier, CollapsedEdgeIsAPoleWithAFiniteNormal) {
    // The teapot's lid top: a cone-like patch whose t = 0 row is one point.
    std::array<Vec3, 16> cp = flat_grid(0.5);
    for (int j = 0; j < 4; ++j) cp[j] = Vec3(1.5, 0, 1);
    const BezierSurface b(cp);
    EXPECT_TRUE(b.pole_at_t0());
    EXPECT_FALSE(b.pole_at_t1());
    EXPECT_EQ(glm::length(b.normal(0.5, 0.0)), 0.0);
    const Vec3 n = b.unit_normal(0.5, 0.0);
    EXPECT_TRUE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z));
    EXPECT_NEAR(glm::length(n), 1.0, 1e-12);
    // The limit: the normal just inside the pole, where the cross product is still finite.
    EXPECT_GT(glm::dot(n, glm::normalize(b.normal(0.5, 1e-3))), 0.999);
    EXPECT_GT(b.area(0, 1, 0, 1), 0.0);
    check_surface(b, 0.25);
}

TEST(Bezier, TeapotFileHas32PatchesAndIsBounded) {
    const auto patches = read_bezier_file(RADIOSA_SOURCE_DIR "/scenes/teapot.bpt");
    ASSERT_EQ(patches.size(), 32u);
    double area = 0.0;
    int poles = 0;
    for (std::size_t k = 0; k < patches.size(); ++k) {
        const BezierSurface b(patches[k]);
        area += b.area(0, 1, 0, 1);
        poles += b.pole_at_t0() + b.pole_at_t1();
        const BoundingSphere ball = b.bound(0, 1, 0, 1);
        EXPECT_LT(glm::length(ball.center) + ball.radius, 6.0);
        // The body (patches 4-11) faces outward: away from the teapot's axis.
        if (k >= 4 && k < 12) {
            const Vec3 p = b.point(0.5, 0.5), n = b.unit_normal(0.5, 0.5);
            EXPECT_GT(n.x * p.x + n.y * p.y, 0.5 * std::hypot(p.x, p.y)) << k;
        }
    }
    EXPECT_EQ(poles, 8);  // four lid-top and four bottom patches
    // More than the cylinder r = 1.5, h = 2.4 that the body bulges out of.
    EXPECT_GT(area, 2 * kPi * 1.5 * 2.4);
    // A ray down the axis hits the lid's knob top at z = 3.15, front side.
    double best = 1e300;
    for (const auto& cp : patches) {
        const BezierSurface b(cp);
        if (auto h = b.intersect(Ray{Vec3(0.001, 0.001, 5), Vec3(0, 0, -1)}, 0, 10, HitSide::Any)) {
            best = std::min(best, h->dist);
            if (h->dist < 2.0) {
                EXPECT_TRUE(h->front);
            }
        }
    }
    EXPECT_NEAR(best, 5 - 3.15, 1e-5);
}

TEST(Bezier, FileErrorsNameTheirLine) {
    const std::string path = testing::TempDir() + "/bad.bpt";
    auto error_of = [&](const std::string& text) {
        std::ofstream(path) << text;
        try {
            read_bezier_file(path);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(error_of("1\n1,2,3\n"), path + ":2:1: expected a patch's 16 point indices (16 numbers), got 3");
    EXPECT_EQ(error_of("1\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,17\n16\n" + std::string(16 * 6, ' ')),
              path + ":3:1: the file ends where a point x, y, z should follow");
    std::string pts;
    for (int k = 0; k < 16; ++k) pts += "0, 0, " + std::to_string(k) + "\n";
    EXPECT_EQ(error_of("1\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,17\n16\n" + pts),
              path + ":2:1: point index 16 must be an integer from 1 to 16 (indices are 1-based)");
    EXPECT_EQ(error_of("1\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n16\n0, nan, 0\n" + pts),
              path + ":4:4: expected a finite number, got 'nan'");
}

}  // namespace
}  // namespace radiosa
