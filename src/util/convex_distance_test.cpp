#include "util/convex_distance.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace radiosa {

namespace {
std::vector<Vec3> cube(const Vec3& lo, double side) {
    std::vector<Vec3> c;
    for (int k = 0; k < 8; ++k) c.push_back(lo + side * Vec3(k & 1, (k >> 1) & 1, (k >> 2) & 1));
    return c;
}
}  // namespace

TEST(ConvexDistance, CubesAtKnownDistances) {
    const auto a = cube(Vec3(0.0), 1.0);
    EXPECT_NEAR(convex_distance(a, cube(Vec3(1.5, 0, 0), 1.0), 1e9), 0.5, 1e-12);
    // Corner to corner: sqrt(3) * 0.5.
    EXPECT_NEAR(convex_distance(a, cube(Vec3(1.5, 1.5, 1.5), 1.0), 1e9), std::sqrt(3.0) * 0.5, 1e-12);
    EXPECT_EQ(convex_distance(a, cube(Vec3(0.5, 0.5, 0.5), 1.0), 1e9), 0.0);
    // Touching faces.
    EXPECT_LT(convex_distance(a, cube(Vec3(1, 0, 0), 1.0), 1e9), 1e-12);
}

TEST(ConvexDistance, PointToSquareAndEarlyAnswer) {
    const std::vector<Vec3> sq = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    const std::vector<Vec3> above = {Vec3(0.3, 0.6, 2.0)};
    EXPECT_NEAR(convex_distance(sq, above, 1e9), 2.0, 1e-12);
    const std::vector<Vec3> beside = {Vec3(2, 2, 1)};
    EXPECT_NEAR(convex_distance(sq, beside, 1e9), std::sqrt(3.0), 1e-12);
    // Asked only whether it exceeds 0.5: a lower bound above 0.5 and never above the truth.
    const double quick = convex_distance(sq, beside, 0.5);
    EXPECT_GT(quick, 0.5);
    EXPECT_LE(quick, std::sqrt(3.0) + 1e-12);
}

TEST(ConvexDistance, NeverAboveTheTrueDistanceOnRandomSets) {
    // Against brute force for a point and a segment set: the distance from a point to the hull
    // of two points is a segment distance.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    for (int trial = 0; trial < 500; ++trial) {
        const std::vector<Vec3> seg = {Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng))};
        const std::vector<Vec3> p = {Vec3(u(rng), u(rng), u(rng))};
        const Vec3 ab = seg[1] - seg[0];
        const double t = std::clamp(glm::dot(p[0] - seg[0], ab) / glm::dot(ab, ab), 0.0, 1.0);
        const double exact = glm::length(p[0] - (seg[0] + t * ab));
        EXPECT_NEAR(convex_distance(seg, p, 1e9), exact, 1e-10) << trial;
    }
    // Random tetrahedra against random points, against the minimum over the tetrahedron's
    // vertices, edges and faces (0 inside).
    auto seg_dist = [](const Vec3& x, const Vec3& a, const Vec3& b) {
        const Vec3 ab = b - a;
        const double t = std::clamp(glm::dot(x - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
        return glm::length(x - (a + t * ab));
    };
    for (int trial = 0; trial < 500; ++trial) {
        std::vector<Vec3> tet;
        for (int k = 0; k < 4; ++k) tet.push_back(Vec3(u(rng), u(rng), u(rng)));
        const Vec3 x(1.5 * u(rng), 1.5 * u(rng), 1.5 * u(rng));
        double exact = 1e300;
        bool inside = true;
        for (int k = 0; k < 4; ++k) {
            const Vec3 &a = tet[k], &b = tet[(k + 1) % 4], &c = tet[(k + 2) % 4], &o = tet[(k + 3) % 4];
            for (int l = k + 1; l < 4; ++l) exact = std::min(exact, seg_dist(x, tet[k], tet[l]));
            Vec3 n = glm::normalize(glm::cross(b - a, c - a));
            if (glm::dot(n, o - a) > 0) n = -n;  // outward
            const double h = glm::dot(x - a, n);
            inside = inside && h <= 0.0;
            const Vec3 p = x - h * n;
            const bool in_face = glm::dot(glm::cross(b - a, p - a), glm::cross(b - a, c - a)) >= 0 &&
                                 glm::dot(glm::cross(c - b, p - b), glm::cross(c - b, a - b)) >= 0 &&
                                 glm::dot(glm::cross(a - c, p - c), glm::cross(a - c, b - c)) >= 0;
            if (in_face) exact = std::min(exact, std::abs(h));
        }
        if (inside) exact = 0.0;
        const std::vector<Vec3> p = {x};
        EXPECT_NEAR(convex_distance(tet, p, 1e9), exact, 1e-9) << trial;
    }
}

}  // namespace radiosa
