// The disk, cylinder and cone types and placed (transformed, two-sided) surfaces, each against
// closed forms: areas, partials, normals, ray hits, linear ranges and bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "surfaces/cone.h"
#include "surfaces/disk.h"
#include "surfaces/placed.h"
#include "surfaces/sphere.h"
#include "util/gauss_legendre.h"

namespace radiosa {

namespace {

AngleRange degrees(double a0, double a1) {
    AngleRange r;
    r.phi0 = deg_to_rad(a0);
    r.span = a1 - a0 == 360.0 ? 2 * kPi : deg_to_rad(a1 - a0);
    return r;
}

// |n| integrated by a 24-point Gauss rule: an independent check of the closed-form areas.
double numeric_area(const Surface& s, double s0, double s1, double t0, double t1) {
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
void check_surface(const Surface& surf) {
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
            // Attained: within what 41 samples per side can miss of a smooth extreme.
            EXPECT_NEAR(lo, seen_lo, 5e-3 * glm::length(a) * b.radius);
            EXPECT_NEAR(hi, seen_hi, 5e-3 * glm::length(a) * b.radius);
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

}  // namespace

TEST(Disk, AnnularSectorMatchesClosedForms) {
    const DiskSurface d(Vec3(1, 2, 3), glm::normalize(Vec3(1, -2, 2)), 2.0, 0.5, degrees(30, 250));
    check_surface(d);
    // Area (span / 2)(R^2 - r^2); front normal along the given normal.
    EXPECT_NEAR(d.area(0, 1, 0, 1), 0.5 * deg_to_rad(220) * (4.0 - 0.25), 1e-13);
    EXPECT_GT(glm::dot(d.normal(0.3, 0.4), Vec3(1, -2, 2)), 0.0);
    EXPECT_TRUE(d.plane().has_value());
    EXPECT_FALSE(d.patches_are_polygons());
}

TEST(Disk, FullDiskHasAPoleAndWraps) {
    const DiskSurface d(Vec3(0), Vec3(0, 0, 1), 1.0, 0.0, AngleRange{});
    check_surface(d);
    EXPECT_NEAR(d.area(0, 1, 0, 1), kPi, 1e-14);
    EXPECT_TRUE(d.wraps_in_s());
    EXPECT_TRUE(d.pole_at_t0());
    // Azimuth 0 is +x; the hole and the outside are missed.
    EXPECT_NEAR(glm::length(d.point(0.0, 1.0) - Vec3(1, 0, 0)), 0.0, 1e-15);
    EXPECT_NEAR(glm::length(d.point(0.25, 1.0) - Vec3(0, 1, 0)), 0.0, 1e-15);
    const DiskSurface ring(Vec3(0), Vec3(0, 0, 1), 1.0, 0.5, AngleRange{});
    EXPECT_FALSE(ring.intersect(Ray{Vec3(0.2, 0.1, 1), Vec3(0, 0, -1)}, 0, 10, HitSide::Any));
    EXPECT_FALSE(ring.intersect(Ray{Vec3(1.1, 0, 1), Vec3(0, 0, -1)}, 0, 10, HitSide::Any));
    EXPECT_TRUE(ring.intersect(Ray{Vec3(0.7, 0, 1), Vec3(0, 0, -1)}, 0, 10, HitSide::FrontOnly));
    const DiskSurface half(Vec3(0), Vec3(0, 0, 1), 1.0, 0.0, degrees(0, 180));
    EXPECT_FALSE(half.intersect(Ray{Vec3(0.1, -0.5, 1), Vec3(0, 0, -1)}, 0, 10, HitSide::Any));
}

TEST(Cylinder, TubeMatchesClosedForms) {
    const FrustumSurface out(Vec3(1, 0, -1), Vec3(0, 1, 2), 0.75, 0.75, degrees(-40, 200), false);
    check_surface(out);
    EXPECT_NEAR(out.area(0, 1, 0, 1), deg_to_rad(240) * 0.75 * std::sqrt(5.0), 1e-13);
    const FrustumSurface in(Vec3(0), Vec3(0, 0, 3), 1.0, 1.0, AngleRange{}, true);
    check_surface(in);
    // The inside of a full tube: a ray along +x from the axis meets it at distance R, front.
    const auto h = in.intersect(Ray{Vec3(0, 0, 1.5), Vec3(1, 0, 0)}, 0, 10, HitSide::FrontOnly);
    ASSERT_TRUE(h);
    EXPECT_NEAR(h->dist, 1.0, 1e-14);
    EXPECT_NEAR(h->t, 0.5, 1e-14);
    // Above the top rim and along the axis: no hit.
    EXPECT_FALSE(in.intersect(Ray{Vec3(0, 0, 3.5), Vec3(1, 0, 0)}, 0, 10, HitSide::Any));
    EXPECT_FALSE(in.intersect(Ray{Vec3(0, 0, -1), Vec3(0, 0, 1)}, 0, 10, HitSide::Any));
    EXPECT_TRUE(in.chords_never_cross());
    EXPECT_TRUE(in.sees_itself());
    EXPECT_FALSE(out.sees_itself());
    EXPECT_TRUE(out.front_segments_escape());
}

TEST(Cone, FrustumAndApexMatchClosedForms) {
    const FrustumSurface frustum(Vec3(0, 0, 1), Vec3(0, 0, 0.5), 0.4, 0.1, AngleRange{}, true);
    check_surface(frustum);
    // Lateral area pi (r0 + r1) slant.
    EXPECT_NEAR(frustum.area(0, 1, 0, 1), kPi * 0.5 * std::hypot(0.5, 0.3), 1e-13);
    const FrustumSurface apex(Vec3(0), Vec3(1, 1, 0), 1.0, 0.0, degrees(0, 300), false);
    check_surface(apex);
    EXPECT_TRUE(apex.pole_at_t1());
    EXPECT_NEAR(glm::length(apex.point(0.4, 1.0) - Vec3(1, 1, 0)), 0.0, 1e-15);
}

TEST(Sphere, PartialRangesMatchClosedForms) {
    // A zone between polar angles 30 and 100 degrees over a 200-degree lune, and a cap.
    const SphereSurface zone(Vec3(0.2, 0, -1), 1.5, false, degrees(-30, 170), deg_to_rad(30),
                             deg_to_rad(100));
    check_surface(zone);
    EXPECT_NEAR(zone.area(0, 1, 0, 1),
                1.5 * 1.5 * deg_to_rad(200) * (std::cos(deg_to_rad(30)) - std::cos(deg_to_rad(100))), 1e-13);
    EXPECT_FALSE(zone.wraps_in_s() || zone.pole_at_t0() || zone.pole_at_t1() || zone.whole_sphere());
    const SphereSurface dome(Vec3(0), 2.0, true, AngleRange{}, 0.0, 0.5 * kPi);
    check_surface(dome);
    EXPECT_NEAR(dome.area(0, 1, 0, 1), 8 * kPi, 1e-13);
    EXPECT_TRUE(dome.pole_at_t1());
    EXPECT_FALSE(dome.pole_at_t0());
    // Below the equator there is no dome: a ray from inside going down misses it.
    EXPECT_FALSE(dome.intersect(Ray{Vec3(0), Vec3(0.1, 0, -1)}, 0, 10, HitSide::Any));
    EXPECT_TRUE(dome.intersect(Ray{Vec3(0), Vec3(0.1, 0, 1)}, 0, 10, HitSide::FrontOnly));
}

TEST(Placed, TransformMapsEveryQueryExactly) {
    auto sphere = std::make_shared<SphereSurface>(Vec3(0.5, 0, 0), 1.0, false);
    Similarity xf;
    xf.scale = 2.5;
    const double c = std::cos(0.7), s = std::sin(0.7);
    xf.rotate = Mat3(Vec3(c, s, 0), Vec3(-s, c, 0), Vec3(0, 0, 1));  // 0.7 rad about +z
    xf.translate = Vec3(1, -2, 3);
    const PlacedSurface placed(sphere, xf, false);
    check_surface(placed);
    EXPECT_NEAR(placed.area(0, 1, 0, 1), 4 * kPi * 2.5 * 2.5, 1e-12);
    EXPECT_NEAR(glm::length(placed.point(0.3, 0.6) - xf.apply(sphere->point(0.3, 0.6))), 0.0, 1e-14);
    const auto ball = placed.sphere();
    ASSERT_TRUE(ball);
    EXPECT_NEAR(glm::length(ball->center - xf.apply(Vec3(0.5, 0, 0))), 0.0, 1e-14);
    EXPECT_NEAR(ball->radius, 2.5, 1e-15);
    // The sphere's axes turn with it: its azimuth 0 now points along the rotated +x.
    EXPECT_NEAR(glm::length(placed.sphere_axes()[0] - Vec3(c, s, 0)), 0.0, 1e-15);
    auto disk = std::make_shared<DiskSurface>(Vec3(0), Vec3(0, 0, 1), 1.0, 0.0, AngleRange{});
    const PlacedSurface moved(disk, xf, false);
    check_surface(moved);
    const auto plane = moved.plane();
    ASSERT_TRUE(plane);
    EXPECT_NEAR(plane->signed_distance(moved.point(0.3, 0.7)), 0.0, 1e-14);
    EXPECT_NEAR(plane->normal.z, 1.0, 1e-15);
}

TEST(Placed, BackSideFlipsNormalsHitsAndConvexity) {
    auto tube = std::make_shared<FrustumSurface>(Vec3(0), Vec3(0, 0, 2), 1.0, 1.0, AngleRange{}, false);
    const PlacedSurface back(tube, Similarity{}, true);
    check_surface(back);
    for (double t : {0.2, 0.8}) EXPECT_LT(glm::dot(back.normal(0.1, t), tube->normal(0.1, t)), 0.0);
    // The outward tube's back is the inside: it sees itself, and segments from it do not escape.
    EXPECT_TRUE(back.sees_itself());
    EXPECT_FALSE(back.front_segments_escape());
    EXPECT_FALSE(back.back_sees_itself());
    EXPECT_TRUE(back.back_segments_escape());
    // From the axis the back is hit front-on; from outside only by an Any query.
    EXPECT_TRUE(back.intersect(Ray{Vec3(0, 0, 1), Vec3(1, 0, 0)}, 0, 10, HitSide::FrontOnly));
    EXPECT_FALSE(tube->intersect(Ray{Vec3(0, 0, 1), Vec3(1, 0, 0)}, 0, 10, HitSide::FrontOnly));
    const auto far = back.intersect(Ray{Vec3(3, 0, 1), Vec3(-1, 0, 0)}, 0, 10, HitSide::FrontOnly);
    ASSERT_TRUE(far);  // through the near wall (its back's back) to the far wall's inside
    EXPECT_NEAR(far->dist, 4.0, 1e-14);
    auto disk = std::make_shared<DiskSurface>(Vec3(0), Vec3(0, 0, 1), 1.0, 0.0, AngleRange{});
    const PlacedSurface under(disk, Similarity{}, true);
    EXPECT_NEAR(under.plane()->normal.z, -1.0, 0.0);
    EXPECT_NEAR(under.plane()->offset, 0.0, 0.0);
}

}  // namespace radiosa
