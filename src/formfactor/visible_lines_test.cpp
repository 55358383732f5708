// The inner integral along lines (formfactor/visible_lines.h) against the closed form of a
// polygon behind a flat occluder (point_to_polygon_hidden): the visible part of a polygon behind
// a square is a polygon minus a polygon, exactly.
#include "formfactor/visible_lines.h"

#include <gtest/gtest.h>

#include <array>
#include <random>

#include "formfactor/point_polygon.h"

namespace radiosa {

namespace {

// The unit square in z = 1 facing down (-z), as the receiver: y(s, t) = (s, t, 1).
const std::array<Vec3, 4> kTarget = {Vec3(0, 0, 1), Vec3(0, 1, 1), Vec3(1, 1, 1), Vec3(1, 0, 1)};

// Whether the segment from x to y crosses the square [x0, x1] x [y0, y1] at height z.
bool crosses(const Vec3& x, const Vec3& y, const std::array<double, 5>& sq) {
    const double f = (sq[4] - x.z) / (y.z - x.z);
    if (!(f > 0.0 && f < 1.0)) return false;
    const Vec3 p = x + f * (y - x);
    return p.x > sq[0] && p.x < sq[1] && p.y > sq[2] && p.y < sq[3];
}

struct Case {
    Vec3 x;
    std::array<double, 5> occluder;  // x0, x1, y0, y1, z
};

LineIntegral by_lines(const Case& c, double tol) {
    const Vec3 n(0, 0, 1);
    Vec3 e;
    auto kernel = [&](double s, double t, double* k) {
        e = Vec3(s, t, 1) - c.x;
        const double ci = glm::dot(n, e), cj = e.z, l2 = glm::dot(e, e);  // receiver normal (0, 0, -1)
        *k = ci * cj / (kPi * l2 * l2);
        return ci > 0.0 && cj > 0.0;
    };
    auto blocked = [&] { return crosses(c.x, c.x + e, c.occluder); };
    return integrate_by_lines(Rect{0, 1, 0, 1}, kernel, blocked, tol);
}

double exact(const Case& c) {
    const Vec3 n(0, 0, 1);
    const auto& q = c.occluder;
    const std::array<Vec3, 4> occ = {Vec3(q[0], q[2], q[4]), Vec3(q[1], q[2], q[4]), Vec3(q[1], q[3], q[4]),
                                     Vec3(q[0], q[3], q[4])};
    return point_to_polygon(c.x, n, kTarget.data(), 4, nullptr) -
           point_to_polygon_hidden(c.x, n, kTarget.data(), 4, {occ});
}

}  // namespace

TEST(VisibleLines, AShadowOnAPolygonMatchesItsClosedForm) {
    // Points below the target and squares between, at random: the shadow's edges run along the
    // lines, across them and off the target.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int within = 0;
    for (int k = 0; k < 40; ++k) {
        Case c;
        c.x = Vec3(-0.5 + 2 * u(rng), -0.5 + 2 * u(rng), 0.2 * u(rng));
        const double z = c.x.z + (1 - c.x.z) * (0.2 + 0.6 * u(rng));
        const double a = u(rng), b = u(rng), w = 0.1 + 0.4 * u(rng), h = 0.1 + 0.4 * u(rng);
        c.occluder = {a - 0.5 * w, a + 0.5 * w, b - 0.5 * h, b + 0.5 * h, z};
        for (const double tol : {1e-4, 1e-7}) {
            const LineIntegral v = by_lines(c, tol);
            const double err = std::abs(v.value - exact(c));
            EXPECT_LE(err, std::max(v.error, 1e-14)) << k << " tol " << tol;
            EXPECT_LE(v.error, tol) << k;
            within += err <= tol;
        }
    }
    EXPECT_EQ(within, 80);
}

TEST(VisibleLines, AnUnblockedReceiverIsItsClosedForm) {
    Case c{Vec3(0.3, 0.6, 0.1), {5, 6, 5, 6, 0.5}};  // the occluder far off to the side
    const LineIntegral v = by_lines(c, 1e-10);
    EXPECT_NEAR(v.value, point_to_polygon(c.x, Vec3(0, 0, 1), kTarget.data(), 4, nullptr), 1e-10);
    EXPECT_EQ(v.ray_tests, v.lines * (kLineSamples + 1));  // no change to place: samples only
}

}  // namespace radiosa
