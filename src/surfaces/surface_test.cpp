#include <gtest/gtest.h>

#include <cmath>

#include "../tests/test_scenes.h"
#include "geometry/scene_geometry.h"
#include "surfaces/quad.h"
#include "surfaces/sphere.h"
#include "util/gauss_legendre.h"

namespace radiosa {

namespace {
// Area of a parameter rectangle by a 16-point Gauss rule on |n|: an independent check of
// the closed forms.
double numeric_area(const Surface& s, double s0, double s1, double t0, double t1) {
    const GaussRule r = gauss_legendre(16);
    double a = 0.0;
    for (int i = 0; i < 16; ++i)
        for (int j = 0; j < 16; ++j) {
            const double u = s0 + 0.5 * (s1 - s0) * (r.x[i] + 1), v = t0 + 0.5 * (t1 - t0) * (r.x[j] + 1);
            a += r.w[i] * r.w[j] * glm::length(s.normal(u, v));
        }
    return a * 0.25 * (s1 - s0) * (t1 - t0);
}

void expect_partials_match_finite_differences(const Surface& surf, double s, double t) {
    Vec3 ds, dt;
    surf.partials(s, t, &ds, &dt);
    const double h = 1e-6;
    const Vec3 fs = (surf.point(s + h, t) - surf.point(s - h, t)) / (2 * h);
    const Vec3 ft = (surf.point(s, t + h) - surf.point(s, t - h)) / (2 * h);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(ds[k], fs[k], 1e-6 * (1 + glm::length(ds)));
        EXPECT_NEAR(dt[k], ft[k], 1e-6 * (1 + glm::length(dt)));
    }
}
}  // namespace

TEST(Sphere, AreasMatchClosedForms) {
    const SphereSurface sph(Vec3(1, 2, 3), 2.5, false);
    EXPECT_NEAR(sph.area(0, 1, 0, 1), 4 * kPi * 2.5 * 2.5, 1e-12);
    // A polar cap patch and an equatorial band patch against the Gauss-integrated |n|.
    EXPECT_NEAR(sph.area(0, 0.125, 0, 0.25), numeric_area(sph, 0, 0.125, 0, 0.25), 1e-12);
    EXPECT_NEAR(sph.area(0.3, 0.55, 0.4, 0.6), numeric_area(sph, 0.3, 0.55, 0.4, 0.6), 1e-12);
    // The 8 x 4 split of the paper: patches of one latitude row have equal area and the
    // rows sum to the sphere.
    double total = 0.0;
    for (int it = 0; it < 4; ++it)
        for (int is = 0; is < 8; ++is) total += sph.area(is / 8.0, (is + 1) / 8.0, it / 4.0, (it + 1) / 4.0);
    EXPECT_NEAR(total, 4 * kPi * 6.25, 1e-12);
}

TEST(Sphere, NormalPointsOutwardUnlessInward) {
    const SphereSurface out(Vec3(0), 1, false), in(Vec3(0), 1, true);
    for (double t : {0.1, 0.5, 0.9}) {
        const Vec3 p = out.point(0.3, t);
        EXPECT_GT(glm::dot(out.normal(0.3, t), p), 0.0);
        EXPECT_LT(glm::dot(in.normal(0.3, t), p), 0.0);
        // |n| = 2 pi^2 R^2 sin(theta)
        EXPECT_NEAR(glm::length(out.normal(0.3, t)), 2 * kPi * kPi * std::sin(kPi * (1 - t)), 1e-12);
    }
    EXPECT_NEAR(out.point(0.7, 0.0).z, -1.0, 1e-15);  // t = 0 south pole
    EXPECT_NEAR(out.point(0.7, 1.0).z, 1.0, 1e-15);   // t = 1 north pole
}

TEST(Sphere, PartialsMatchFiniteDifferences) {
    const SphereSurface sph(Vec3(0.5, -1, 2), 1.7, false);
    for (double s : {0.1, 0.45, 0.8})
        for (double t : {0.2, 0.5, 0.77}) expect_partials_match_finite_differences(sph, s, t);
}

// The outer integrals take a node's point and normal in one call (point_and_normal), which a
// sphere computes from one sine and cosine of each angle: it must give exactly point() and
// normal(), so that form factors keep their bits, on a partial and inward sphere too.
TEST(Sphere, PointAndNormalAreExactlyPointAndNormal) {
    const SphereSurface whole(Vec3(0.5, -1, 2), 1.7, false);
    const SphereSurface zone(Vec3(-2, 0.25, 1), 0.6, true, AngleRange{0.4, 2.1}, 0.3, 2.2);
    for (const SphereSurface* sph : {&whole, &zone})
        for (double s : {0.0, 0.1, 0.45, 0.8, 1.0})
            for (double t : {0.0, 0.2, 0.5, 0.77, 1.0}) {
                Vec3 x, n;
                sph->point_and_normal(s, t, &x, &n);
                const Vec3 px = sph->point(s, t), pn = sph->normal(s, t);
                for (int k = 0; k < 3; ++k) {
                    EXPECT_EQ(x[k], px[k]) << s << " " << t;
                    EXPECT_EQ(n[k], pn[k]) << s << " " << t;
                }
            }
}

TEST(Sphere, RayHitsFrontThenBack) {
    const SphereSurface sph(Vec3(0), 1, false);
    const Ray r{Vec3(5, 0, 0), Vec3(-1, 0, 0)};
    auto h = sph.intersect(r, 0, 1e9, HitSide::Any);
    ASSERT_TRUE(h);
    EXPECT_NEAR(h->dist, 4.0, 1e-12);
    EXPECT_TRUE(h->front);
    EXPECT_NEAR(h->s, 0.0, 1e-12);  // +x is azimuth 0
    EXPECT_NEAR(h->t, 0.5, 1e-12);  // equator
    // From inside only the back side is crossed: no front hit for an outward sphere.
    const Ray inside{Vec3(0), Vec3(0, 1, 0)};
    EXPECT_FALSE(sph.intersect(inside, 0, 1e9, HitSide::FrontOnly));
    auto back = sph.intersect(inside, 0, 1e9, HitSide::Any);
    ASSERT_TRUE(back);
    EXPECT_NEAR(back->dist, 1.0, 1e-12);
    EXPECT_NEAR(back->s, 0.25, 1e-12);
    // An inward sphere is seen from inside.
    const SphereSurface in(Vec3(0), 1, true);
    auto hin = in.intersect(inside, 0, 1e9, HitSide::FrontOnly);
    ASSERT_TRUE(hin);
    EXPECT_NEAR(hin->dist, 1.0, 1e-12);
    // A miss and a segment that stops short.
    EXPECT_FALSE(sph.intersect(Ray{Vec3(5, 1.01, 0), Vec3(-1, 0, 0)}, 0, 1e9, HitSide::Any));
    EXPECT_FALSE(sph.intersect(r, 0, 3.9, HitSide::Any));
}

TEST(Sphere, HitParametersRoundTrip) {
    const SphereSurface sph(Vec3(1, 1, 1), 2, false);
    for (double s : {0.05, 0.3, 0.6, 0.95})
        for (double t : {0.1, 0.5, 0.85}) {
            const Vec3 p = sph.point(s, t);
            const Vec3 from = Vec3(1, 1, 1) + 3.0 * (p - Vec3(1, 1, 1));
            auto h = sph.intersect(Ray{from, p - from}, 0, 1e9, HitSide::FrontOnly);
            ASSERT_TRUE(h);
            EXPECT_NEAR(h->dist, 1.0, 1e-12);
            EXPECT_NEAR(h->s, s, 1e-12);
            EXPECT_NEAR(h->t, t, 1e-12);
        }
}

TEST(Quad, AreaOfParallelogramAndTrapezoid) {
    const QuadSurface square(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(2, 3, 0), Vec3(0, 3, 0));
    EXPECT_NEAR(square.area(0, 1, 0, 1), 6.0, 1e-14);
    EXPECT_NEAR(square.area(0, 0.5, 0, 1.0 / 3), 1.0, 1e-14);
    // Trapezoid with parallel sides 4 and 2, height 1: area 3; sub-rectangles against |n|.
    const QuadSurface trap(Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(3, 1, 0), Vec3(1, 1, 0));
    EXPECT_NEAR(trap.area(0, 1, 0, 1), 3.0, 1e-14);
    EXPECT_NEAR(trap.area(0.2, 0.7, 0.1, 0.6), numeric_area(trap, 0.2, 0.7, 0.1, 0.6), 1e-13);
    expect_partials_match_finite_differences(trap, 0.3, 0.6);
}

TEST(Quad, RayHitInvertsTheBilinearMap) {
    const QuadSurface trap(Vec3(0, 0, 1), Vec3(4, 0, 1), Vec3(3, 1, 1), Vec3(1, 1, 1));  // faces +z
    for (double s : {0.0, 0.25, 0.5, 0.9})
        for (double t : {0.1, 0.5, 1.0}) {
            const Vec3 p = trap.point(s, t);
            auto h = trap.intersect(Ray{p + Vec3(0.3, -0.2, 2.0), Vec3(-0.3, 0.2, -2.0)}, 0, 10,
                                    HitSide::FrontOnly);
            ASSERT_TRUE(h) << s << " " << t;
            EXPECT_NEAR(h->dist, 1.0, 1e-12);
            EXPECT_NEAR(h->s, s, 1e-12);
            EXPECT_NEAR(h->t, t, 1e-12);
        }
    // From behind: only an Any query hits; outside the quad: no hit.
    EXPECT_FALSE(trap.intersect(Ray{Vec3(2, 0.5, 0), Vec3(0, 0, 1)}, 0, 10, HitSide::FrontOnly));
    EXPECT_TRUE(trap.intersect(Ray{Vec3(2, 0.5, 0), Vec3(0, 0, 1)}, 0, 10, HitSide::Any));
    EXPECT_FALSE(trap.intersect(Ray{Vec3(0.2, 0.9, 2), Vec3(0, 0, -1)}, 0, 10, HitSide::Any));
}

TEST(SceneGeometry, LocatesHitPatchAndLocalCoordinates) {
    const Scene scene =
        test::scene_of(test::quad("floor", "[[0, 0, 0], [3, 0, 0], [3, 2, 0], [0, 2, 0]]", 3, 2));
    const SceneGeometry geo(scene);
    ASSERT_EQ(geo.patch_count(), 6);
    auto h = geo.intersect_front(Ray{Vec3(2.25, 1.5, 5), Vec3(0, 0, -1)});
    ASSERT_TRUE(h);
    EXPECT_EQ(h->patch, geo.patch_index(0, 2, 1));
    EXPECT_NEAR(h->u, 0.25, 1e-12);
    EXPECT_NEAR(h->v, 0.5, 1e-12);
    EXPECT_NEAR(geo.patch(h->patch).area, 1.0, 1e-14);
}

TEST(SceneGeometry, OneSidedSurfacesAreSeenThrough) {
    // Looking at the cube from outside, the nearest face is seen from behind and skipped.
    const Scene scene = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    const SceneGeometry geo(scene);
    auto h = geo.intersect_front(Ray{Vec3(6, 0, 0), Vec3(-1, 0, 0)});
    ASSERT_TRUE(h);
    EXPECT_EQ(geo.surface_name(h->surface), "sphere");
    EXPECT_NEAR(h->dist, 5.0, 1e-12);
    auto wall = geo.intersect_front(Ray{Vec3(6, 0, 1.5), Vec3(-1, 0, 0)});
    ASSERT_TRUE(wall);
    EXPECT_EQ(geo.surface_name(wall->surface), "face4");
    EXPECT_NEAR(wall->dist, 8.0, 1e-12);
}

}  // namespace radiosa
