// What a disk hides of a polygon from a point, against closed forms: the coaxial disk
// (r^2 / (r^2 + h^2)), Howell's element to a parallel off-axis disk, a ball with the same cone
// of directions (point_to_polygon_blocked), and additivity over a polygon cut in two.
#include "formfactor/disk_shadow.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "formfactor/point_polygon.h"

namespace radiosa {

namespace {

// A square of half-size a at height h, centred over (cx, cy), counter-clockwise about -z (its
// front faces down, toward the points below).
std::array<Vec3, 4> ceiling(double a, double h, double cx = 0.0, double cy = 0.0) {
    return {Vec3(cx - a, cy - a, h), Vec3(cx - a, cy + a, h), Vec3(cx + a, cy + a, h),
            Vec3(cx + a, cy - a, h)};
}

// Howell's catalogue B-13: a plane element facing a parallel disk of radius r at height h whose
// axis passes at distance a from it.
double element_to_parallel_disk(double r, double h, double a) {
    const double H = h / a, R = r / a, Z = 1 + H * H + R * R;
    return 0.5 * (1.0 - (1.0 + H * H - R * R) / std::sqrt(Z * Z - 4.0 * R * R));
}

}  // namespace

TEST(DiskShadow, ACoaxialDiskHidesItsOwnFormFactor) {
    // From the origin facing up, a disk of radius 0.4 at height 0.7 under a wide ceiling at
    // height 2: the disk hides exactly what it would receive, r^2 / (r^2 + h^2). Its annulus
    // (hole 0.15) hides the difference of two such disks; turned over, nothing changes.
    const auto v = ceiling(10.0, 2.0);
    const Vec3 x(0.0), up(0, 0, 1);
    const auto f = [](double r, double h) { return r * r / (r * r + h * h); };
    for (const double nz : {1.0, -1.0}) {
        const ShadowValue d =
            point_to_polygon_hidden_by_disk(x, up, v.data(), 4, {Vec3(0, 0, 0.7), Vec3(0, 0, nz), 0.4, 0.0});
        EXPECT_NEAR(d.value, f(0.4, 0.7), 1e-14);
        EXPECT_LE(d.error, 1e-13);
        const ShadowValue ring =
            point_to_polygon_hidden_by_disk(x, up, v.data(), 4, {Vec3(0, 0, 0.7), Vec3(0, 0, nz), 0.4, 0.15});
        EXPECT_NEAR(ring.value, f(0.4, 0.7) - f(0.15, 0.7), 1e-14);
    }
    // A ceiling narrower than the shadow: all of it is hidden.
    const auto narrow = ceiling(0.3, 2.0);
    const double open = point_to_polygon(x, up, narrow.data(), 4, nullptr);
    EXPECT_NEAR(
        point_to_polygon_hidden_by_disk(x, up, narrow.data(), 4, {Vec3(0, 0, 0.7), up, 0.4, 0.0}).value, open,
        1e-14);
}

TEST(DiskShadow, AnOffAxisDiskMatchesHowell) {
    // The element 0.9 off the axis of a disk of radius 0.5 at height 0.6, and further off, with
    // the whole shadow on a wide ceiling: Howell's B-13.
    const auto v = ceiling(50.0, 3.0);
    for (const double a : {0.2, 0.9, 2.5}) {
        const FlatDisk disk{Vec3(a, 0, 0.6), Vec3(0, 0, 1), 0.5, 0.0};
        EXPECT_NEAR(point_to_polygon_hidden_by_disk(Vec3(0.0), Vec3(0, 0, 1), v.data(), 4, disk).value,
                    element_to_parallel_disk(0.5, 0.6, a), 1e-13)
            << a;
    }
}

TEST(DiskShadow, OnItsAxisADiskHidesWhatABallWithItsConeHides) {
    // Seen from a point on its axis, a disk of radius r at distance L covers the same round cone
    // as a ball centred there with radius r L / sqrt(r^2 + L^2). Random tilts of the disk, the
    // receiving quad and the point's normal, with the quad cutting through the shadow.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int cut = 0;
    for (int trial = 0; trial < 200; ++trial) {
        const Vec3 x(0.0);
        const Vec3 n = glm::normalize(Vec3(0.3 * u(rng), 0.3 * u(rng), 1.0));
        const Vec3 axis = glm::normalize(Vec3(0.4 * u(rng), 0.4 * u(rng), 1.0));
        const double L = 0.8 + 0.3 * u(rng), r = 0.25 + 0.1 * u(rng);
        const Vec3 c = L * axis;
        // A quad on a tilted plane at height about 2, its corners scattered around the shadow.
        const Vec3 m = glm::normalize(Vec3(0.2 * u(rng), 0.2 * u(rng), -1.0));  // front faces down
        const Vec3 centre(0.6 * u(rng), 0.6 * u(rng), 2.0);
        const Vec3 e1 = glm::normalize(glm::cross(m, Vec3(0, 1, 0))), e2 = glm::cross(m, e1);
        std::array<Vec3, 4> v;
        for (int k = 0; k < 4; ++k) {
            const double ang = kPi / 2 * k + 0.3 * u(rng), rad = 0.5 + 0.3 * u(rng);
            v[static_cast<std::size_t>(k)] = centre + rad * (std::cos(ang) * e1 + std::sin(ang) * e2);
        }
        const BoundingSphere ball{c, r * L / std::sqrt(r * r + L * L)};
        const double want = point_to_polygon_blocked(x, n, v.data(), 4, ball);
        const double open = point_to_polygon(x, n, v.data(), 4, nullptr);
        cut += want > 1e-3 && want < open - 1e-3;
        const FlatDisk disk{c, trial % 2 ? axis : -axis, r, 0.0};
        EXPECT_NEAR(point_to_polygon_hidden_by_disk(x, n, v.data(), 4, disk).value, want, 1e-12) << trial;
    }
    EXPECT_GT(cut, 50);  // most quads cut the shadow, not just hold or miss it
}

TEST(DiskShadow, AQuadCutInTwoHidesTheSumOfItsHalves) {
    // Off the axis, a tilted annulus and a quad cut along a random line: what it hides of the
    // quad is what it hides of the two halves.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 100; ++trial) {
        const Vec3 x(0.3 * u(rng), 0.3 * u(rng), 0.0), n(0, 0, 1);
        const FlatDisk disk{Vec3(0.3 * u(rng), 0.3 * u(rng), 0.8),
                            glm::normalize(Vec3(0.5 * u(rng), 0.5 * u(rng), 1.0)), 0.35,
                            trial % 3 == 0 ? 0.12 : 0.0};
        const auto v = ceiling(0.6, 1.7, 0.3 * u(rng), 0.3 * u(rng));
        // The cut from a point on edge 0 to a point on edge 2.
        const double a = 0.5 + 0.45 * u(rng), b = 0.5 + 0.45 * u(rng);
        const Vec3 p = v[0] + a * (v[1] - v[0]), q = v[2] + b * (v[3] - v[2]);
        const std::array<Vec3, 4> left = {v[0], p, q, v[3]}, right = {p, v[1], v[2], q};
        const double whole = point_to_polygon_hidden_by_disk(x, n, v.data(), 4, disk).value;
        const double halves = point_to_polygon_hidden_by_disk(x, n, left.data(), 4, disk).value +
                              point_to_polygon_hidden_by_disk(x, n, right.data(), 4, disk).value;
        EXPECT_NEAR(whole, halves, 1e-13) << trial;
        EXPECT_GT(whole, 0.0) << trial;
    }
}

}  // namespace radiosa
