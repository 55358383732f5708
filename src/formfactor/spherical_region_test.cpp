// Form factors and areas of cut sphere patches by contour integrals, against closed forms.
#include "formfactor/spherical_region.h"

#include <gtest/gtest.h>

#include <cmath>

namespace radiosa {

namespace {
SphericalRegion patch(const Vec3& c, double R, double front, double s0, double s1, double t0, double t1) {
    SphericalRegion r;
    r.center = c;
    r.radius = R;
    r.front = front;
    add_patch_cuts(&r, 2 * kPi * s0, 2 * kPi * s1, kPi * (1 - t1), kPi * (1 - t0));
    return r;
}

// F(dx -> sphere) summed over a 4 x 4 split of the sphere, each piece cut to x's front side and,
// seen from outside, to the cap x can see.
double whole_sphere(const Vec3& x, const Vec3& n, const Vec3& c, double R, double front) {
    double sum = 0.0;
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
            SphericalRegion r = patch(c, R, front, a / 4.0, (a + 1) / 4.0, b / 4.0, (b + 1) / 4.0);
            r.cuts.push_back({n, glm::dot(n, x)});
            if (front > 0) r.cuts.push_back({x - c, R * R + glm::dot(x - c, c)});
            const ContourValue v = point_to_spherical_region(x, n, r);
            EXPECT_TRUE(v.valid);
            EXPECT_LT(v.error, 1e-8);
            sum += v.value;
        }
    return sum;
}
}  // namespace

TEST(SphericalRegion, PatchAreasAreExact) {
    const Vec3 c(0.3, -0.2, 0.5);
    const double R = 1.7;
    for (const auto& [s0, s1, t0, t1] :
         {std::array<double, 4>{0.05, 0.25, 0.2, 0.7}, std::array<double, 4>{0.6, 0.8, 0.75, 1.0},
          std::array<double, 4>{0.9, 1.0, 0.0, 0.3}}) {
        const double exact =
            R * R * 2 * kPi * (s1 - s0) * (std::cos(kPi * (1 - t1)) - std::cos(kPi * (1 - t0)));
        const SphericalRegion r = patch(c, R, 1.0, s0, s1, t0, t1);
        const Vec3 mid = c + R * Vec3(std::sin(kPi * (1 - 0.5 * (t0 + t1))) * std::cos(kPi * (s0 + s1)),
                                      std::sin(kPi * (1 - 0.5 * (t0 + t1))) * std::sin(kPi * (s0 + s1)),
                                      std::cos(kPi * (1 - 0.5 * (t0 + t1))));
        const ContourValue a = spherical_region_area(r, 2.0 * c - mid);
        EXPECT_NEAR(a.value, exact, 1e-13 * exact) << s0 << " " << t0;
        EXPECT_LT(a.error, 1e-12 * exact);
    }
}

TEST(SphericalRegion, CentreOfASphereSeesAQuarterCap) {
    // From the centre of an inward sphere, facing +z: a quarter of the polar cap of half-angle
    // theta has F = sin^2(theta) / 4 (Nusselt: the projected area of the cap is pi sin^2).
    const double theta = 1.1;
    const SphericalRegion r = patch(Vec3(0.0), 2.0, -1.0, 0.25, 0.5, 1.0 - theta / kPi, 1.0);
    const ContourValue v = point_to_spherical_region(Vec3(0.0), Vec3(0, 0, 1), r);
    EXPECT_NEAR(v.value, std::sin(theta) * std::sin(theta) / 4.0, 1e-15);
}

TEST(SphericalRegion, InsideASphereEverythingInFrontIsSeen) {
    // Off centre and tilted, x's front half-space meets only the sphere: the pieces sum to 1.
    const Vec3 c(1, 2, 3);
    const Vec3 x = c + Vec3(0.4, -0.3, 0.55), n = glm::normalize(Vec3(0.3, 0.5, -0.8));
    EXPECT_NEAR(whole_sphere(x, n, c, 1.0, -1.0), 1.0, 1e-13);
    // Near the wall, facing along it (its horizon's circle and the patches' edges pass 1e-3 and
    // 1e-6 from it): still 1.
    const Vec3 m(1, 0, 0);
    EXPECT_NEAR(whole_sphere(c + Vec3(0, 0, 0.999), m, c, 1.0, -1.0), 1.0, 1e-13);
    EXPECT_NEAR(whole_sphere(c + Vec3(0, 0, 0.999999), m, c, 1.0, -1.0), 1.0, 1e-11);
}

TEST(SphericalRegion, SphereSeenFromOutside) {
    // A sphere of radius R at distance D in front of a point: F = (R / D)^2, times cos(tilt)
    // while the whole sphere stays above the point's horizon (Howell's catalogue B-47).
    const Vec3 c(0.5, -1, 2);
    const double R = 0.7, D = 2.5;
    const Vec3 x = c + Vec3(0, 0, -D);
    EXPECT_NEAR(whole_sphere(x, Vec3(0, 0, 1), c, R, 1.0), (R / D) * (R / D), 1e-14);
    const double tilt = 0.9;  // + asin(R / D) < pi / 2
    EXPECT_NEAR(whole_sphere(x, Vec3(std::sin(tilt), 0, std::cos(tilt)), c, R, 1.0),
                (R / D) * (R / D) * std::cos(tilt), 1e-14);
}

TEST(SphericalRegion, CutsThatLeaveNothingGiveZero) {
    SphericalRegion r = patch(Vec3(0.0), 1.0, 1.0, 0.0, 0.25, 0.5, 1.0);
    r.cuts.push_back({Vec3(0, 0, -1), 0.5});  // z <= -0.5: the patch is the upper hemisphere
    const ContourValue v = point_to_spherical_region(Vec3(0, 0, 3), Vec3(0, 0, -1), r);
    EXPECT_EQ(v.value, 0.0);
}

}  // namespace radiosa
