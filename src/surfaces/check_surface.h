#pragma once
// For the surface types' tests: what every type must satisfy (check_surface).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "surfaces/surface.h"
#include "util/gauss_legendre.h"

namespace radiosa {

// |n| integrated by a 24-point Gauss rule: an independent check of the closed-form areas.
inline double numeric_area(const Surface& s, double s0, double s1, double t0, double t1) {
    const GaussRule r = gauss_legendre(24);
    double a = 0.0;
    for (std::size_t i = 0; i < r.x.size(); ++i)
        for (std::size_t j = 0; j < r.x.size(); ++j) {
            const double u = s0 + 0.5 * (s1 - s0) * (r.x[i] + 1), v = t0 + 0.5 * (t1 - t0) * (r.x[j] + 1);
            a += r.w[i] * r.w[j] * glm::length(s.normal(u, v));
        }
    return a * 0.25 * (s1 - s0) * (t1 - t0);
}

// What every surface type must satisfy on a few parameter rectangles: partials are the
// derivatives of the map, the area is the integral of |n|, linear_range holds every point and
// is attained, bound holds every point, and a ray aimed at P(s, t) from its front hits there.
inline void check_surface(const Surface& surf, double range_slack = 5e-3) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const double rects[3][4] = {{0, 1, 0, 1}, {0.1, 0.35, 0.2, 0.9}, {0.6, 0.95, 0.0, 0.3}};
    for (const auto& r : rects) {
        const double s0 = r[0], s1 = r[1], t0 = r[2], t1 = r[3];
        EXPECT_NEAR(surf.area(s0, s1, t0, t1), numeric_area(surf, s0, s1, t0, t1),
                    1e-11 * (1 + surf.area(0, 1, 0, 1)));
        const BoundingSphere b = surf.bound(s0, s1, t0, t1);
        for (int trial = 0; trial < 5; ++trial) {
            const Vec3 a(u01(rng) - 0.5, u01(rng) - 0.5, u01(rng) - 0.5);
            const auto [lo, hi] = surf.linear_range(a, s0, s1, t0, t1);
            double seen_lo = 1e300, seen_hi = -1e300;
            for (int i = 0; i <= 40; ++i)
                for (int j = 0; j <= 40; ++j) {
                    const Vec3 p = surf.point(s0 + (s1 - s0) * i / 40, t0 + (t1 - t0) * j / 40);
                    const double v = glm::dot(a, p);
                    seen_lo = std::min(seen_lo, v);
                    seen_hi = std::max(seen_hi, v);
                    EXPECT_LE(glm::length(p - b.center), b.radius * (1 + 1e-12) + 1e-12);
                }
            EXPECT_LE(lo, seen_lo + 1e-12);
            EXPECT_GE(hi, seen_hi - 1e-12);
            // Attained: within what 41 samples per side can miss of a smooth extreme (more for types
            // whose ranges are bounds, by range_slack).
            EXPECT_NEAR(lo, seen_lo, range_slack * glm::length(a) * b.radius);
            EXPECT_NEAR(hi, seen_hi, range_slack * glm::length(a) * b.radius);
        }
    }
    for (double s : {0.13, 0.5, 0.81})
        for (double t : {0.17, 0.5, 0.93}) {
            Vec3 ds, dt;
            surf.partials(s, t, &ds, &dt);
            const double h = 1e-6;
            const Vec3 fs = (surf.point(s + h, t) - surf.point(s - h, t)) / (2 * h);
            const Vec3 ft = (surf.point(s, t + h) - surf.point(s, t - h)) / (2 * h);
            EXPECT_LT(glm::length(ds - fs), 1e-6 * (1 + glm::length(ds)));
            EXPECT_LT(glm::length(dt - ft), 1e-6 * (1 + glm::length(dt)));
            const Vec3 p = surf.point(s, t), n = glm::normalize(surf.normal(s, t));
            const Vec3 from = p + 0.7 * n + 0.1 * glm::normalize(ds);
            const auto hit = surf.intersect(Ray{from, p - from}, 1e-9, 2.0, HitSide::FrontOnly);
            ASSERT_TRUE(hit) << s << " " << t;
            EXPECT_NEAR(hit->dist, 1.0, 1e-11);
            EXPECT_NEAR(hit->s, s, 1e-11);
            EXPECT_NEAR(hit->t, t, 1e-11);
            EXPECT_TRUE(hit->front);
            // From behind the same point is crossed only by an Any query.
            const Vec3 behind = p - 0.02 * n;
            const auto back = surf.intersect(Ray{behind, p - behind}, 1e-9, 1.0 + 1e-9, HitSide::Any);
            ASSERT_TRUE(back);
            EXPECT_FALSE(back->front);
        }
}

}  // namespace radiosa
