#include "formfactor/cubature.h"

#include <gtest/gtest.h>

#include <cmath>

namespace radiosa {
namespace {

// exp(s + 2t) over [0, 1]^2: (e - 1)(e^2 - 1) / 2.
double smooth(double s, double t) { return std::exp(s + 2.0 * t); }
const double kSmoothIntegral = 0.5 * (std::exp(1.0) - 1.0) * (std::exp(2.0) - 1.0);

TEST(AdaptiveRect, ACutGeometryDemandsEvaluatesOnlyItsParts) {
    const GaussRule rule = gauss_legendre(4);
    const Rect root{0.0, 1.0, 0.0, 1.0};
    int calls = 0;
    auto g = [&](double s, double t) {
        ++calls;
        return smooth(s, t);
    };
    // The root is cut at s = 0.3 (an event line); its parts are left to the estimates.
    auto at_event = [&](const Rect& r, const auto&) {
        return r.s0 == root.s0 && r.s1 == root.s1 ? Cut{0, 0.3} : Cut{};
    };
    const Estimate e = adaptive_rect(g, root, 1e-3, 64, rule, at_event);
    // The two parts' 4 x 4 values, then each part's halves both ways: nothing of the root's
    // own value or halves, which the cut makes useless (they were 80 more calls).
    EXPECT_EQ(e.regions, 2);
    EXPECT_EQ(calls, 2 * 16 + 2 * 4 * 16);
    EXPECT_NEAR(e.value, kSmoothIntegral, 1e-6);
    EXPECT_LE(std::abs(e.value - kSmoothIntegral), e.error);
    EXPECT_FALSE(e.capped);
}

TEST(AdaptiveRect, AForcedRegionLeftAtTheCapIsEstimatedAsAnyOther) {
    const GaussRule rule = gauss_legendre(4);
    const Rect root{0.0, 1.0, 0.0, 1.0};
    // exp(3 s + t) varies most along s, where the estimate splits a region it is not told how
    // to split: the same halves as a forced split along s.
    auto g = [](double s, double t) { return std::exp(3.0 * s + t); };
    auto along_s = [](const Rect&, const auto&) { return Cut{0}; };
    auto free = [](const Rect&, const auto&) { return Cut{}; };
    // One region allowed: the root stays whole, its estimate made at the end.
    const Estimate forced = adaptive_rect(g, root, 1e-30, 1, rule, along_s);
    const Estimate estimated = adaptive_rect(g, root, 1e-30, 1, rule, free);
    EXPECT_EQ(forced.value, estimated.value);
    EXPECT_EQ(forced.error, estimated.error);
    EXPECT_GT(forced.error, 0.0);
    EXPECT_TRUE(forced.capped);
    EXPECT_TRUE(estimated.capped);
}

}  // namespace
}  // namespace radiosa
