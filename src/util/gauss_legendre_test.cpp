#include "util/gauss_legendre.h"

#include <gtest/gtest.h>

#include <cmath>

namespace radiosa {

TEST(GaussLegendre, ThreePointRuleMatchesTable) {
    const GaussRule r = gauss_legendre(3);
    ASSERT_EQ(r.x.size(), 3u);
    EXPECT_NEAR(r.x[0], -std::sqrt(0.6), 1e-15);
    EXPECT_NEAR(r.x[1], 0.0, 1e-15);
    EXPECT_NEAR(r.x[2], std::sqrt(0.6), 1e-15);
    EXPECT_NEAR(r.w[0], 5.0 / 9.0, 1e-15);
    EXPECT_NEAR(r.w[1], 8.0 / 9.0, 1e-15);
    EXPECT_NEAR(r.w[2], 5.0 / 9.0, 1e-15);
}

TEST(GaussLegendre, FourPointRuleMatchesTable) {
    const GaussRule r = gauss_legendre(4);
    const double a = std::sqrt(3.0 / 7.0 - 2.0 / 7.0 * std::sqrt(6.0 / 5.0));
    const double b = std::sqrt(3.0 / 7.0 + 2.0 / 7.0 * std::sqrt(6.0 / 5.0));
    EXPECT_NEAR(r.x[2], a, 1e-15);
    EXPECT_NEAR(r.x[3], b, 1e-15);
    EXPECT_NEAR(r.w[2], (18.0 + std::sqrt(30.0)) / 36.0, 1e-15);
    EXPECT_NEAR(r.w[3], (18.0 - std::sqrt(30.0)) / 36.0, 1e-15);
}

TEST(GaussLegendre, ExactForPolynomialsUpToDegree2nMinus1) {
    for (int n : {1, 2, 5, 8, 16, 32, 64}) {
        const GaussRule r = gauss_legendre(n);
        double wsum = 0.0;
        for (double w : r.w) wsum += w;
        EXPECT_NEAR(wsum, 2.0, 1e-13) << "n=" << n;
        // integral of x^k over [-1,1] = 2/(k+1) for even k, 0 for odd k
        for (int k = 0; k <= 2 * n - 1; ++k) {
            double q = 0.0;
            for (int i = 0; i < n; ++i) q += r.w[i] * std::pow(r.x[i], k);
            const double exact = k % 2 ? 0.0 : 2.0 / (k + 1);
            EXPECT_NEAR(q, exact, 1e-13) << "n=" << n << " k=" << k;
        }
    }
}

TEST(GaussLegendre, RejectsZeroPoints) { EXPECT_THROW(gauss_legendre(0), std::invalid_argument); }

}  // namespace radiosa
