// SIMD atan2 and acos (SLEEF) against glibc's, one value at a time: within 4.5 ulp (SLEEF's
// promise of 3.5 for its u35 functions, plus glibc's own 1), for any count (partial lanes), on
// the quadrants' edges and the poles, and the same bits whatever a value's lane.
#include "util/angles.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "util/angles_avx2.h"

namespace radiosa {

namespace {

// |a - b| in units of b's last place (b's spacing, at least the smallest normal's).
double ulps(double a, double b) {
    const double spacing = std::nextafter(std::abs(b), INFINITY) - std::abs(b);
    return std::abs(a - b) / spacing;
}

using Angles = void (*)(std::size_t, const double*, const double*, const double*, double*, double*);

void expect_within_its_ulps(Angles f, const char* name) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> y, x, z;
    for (int i = 0; i < 997; ++i) {  // odd: the last lanes are partial
        y.push_back(u(rng));
        x.push_back(u(rng));
        z.push_back(u(rng));
    }
    // The axes, both signs of zero, the poles and a z one step beyond them (clamped to +-1).
    const double above = std::nextafter(1.0, 2.0);
    const double edges[][3] = {{0.0, 1.0, 1.0},      {1.0, 0.0, -1.0},  {0.0, -1.0, 0.0},
                               {-1.0, 0.0, 0.5},     {-0.0, -1.0, 0.0}, {1e-300, -1.0, 1e-300},
                               {-1e-17, 1.0, above}, {3.0, 4.0, -above}};
    for (const auto& e : edges) {
        y.push_back(e[0]);
        x.push_back(e[1]);
        z.push_back(e[2]);
    }
    const std::size_t n = y.size();
    std::vector<double> phi(n), theta(n);
    f(n, y.data(), x.data(), z.data(), phi.data(), theta.data());
    for (std::size_t i = 0; i < n; ++i) {
        EXPECT_LE(ulps(phi[i], std::atan2(y[i], x[i])), 4.5)
            << name << " atan2(" << y[i] << ", " << x[i] << ")";
        EXPECT_LE(ulps(theta[i], std::acos(std::fmin(1.0, std::fmax(-1.0, z[i])))), 4.5)
            << name << " acos(" << z[i] << ")";
    }
    EXPECT_EQ(theta[n - 2], 0.0);                         // z just above 1 is the pole
    EXPECT_NEAR(theta[n - 1], 3.141592653589793, 1e-15);  // z just below -1 the other
    // Alone, each value is the same bits as among the others.
    for (std::size_t i = 0; i < n; i += 97) {
        double p, t;
        f(1, &y[i], &x[i], &z[i], &p, &t);
        EXPECT_EQ(p, phi[i]) << name << " " << i;
        EXPECT_EQ(t, theta[i]) << name << " " << i;
    }
}

}  // namespace

TEST(Angles, TwoLanesAreWithinTheirUlpsOfGlibc) { expect_within_its_ulps(atan2_acos_sse2, "sse2"); }

TEST(Angles, FourLanesAreWithinTheirUlpsOfGlibc) {
    if (!(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")))
        GTEST_SKIP() << "this processor has no AVX2 and FMA";
    expect_within_its_ulps(atan2_acos_avx2, "avx2");
}

TEST(Angles, TheDispatchedOneIsOneOfThem) { expect_within_its_ulps(atan2_acos, "dispatched"); }

}  // namespace radiosa
