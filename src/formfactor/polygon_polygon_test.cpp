// The contour closed form against Howell's catalogue: opposed and perpendicular rectangles at
// gaps from 1 down to 1e-9 and scales from 1e-6 to 1e6, shared edges and corners, far pairs,
// and the cases it must answer with zero.
#include "formfactor/polygon_polygon.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "formfactor/analytic.h"

namespace radiosa {

namespace {

using Quad = std::array<Vec3, 4>;

// A unit square at height 0 facing +z and one at height c facing -z, both scaled by `scale`.
std::pair<Quad, Quad> opposed(double c, double scale) {
    const Quad lo = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    const Quad hi = {Vec3(0, 0, c), Vec3(0, 1, c), Vec3(1, 1, c), Vec3(1, 0, c)};
    std::pair<Quad, Quad> q{lo, hi};
    for (auto& v : q.first) v *= scale;
    for (auto& v : q.second) v *= scale;
    return q;
}

double f_ab(const Quad& a, const Quad& b, PolygonPair* out = nullptr) {
    const PolygonPair p = polygon_to_polygon(a.data(), 4, b.data(), 4);
    if (out) *out = p;
    const double area = glm::length(glm::cross(a[1] - a[0], a[3] - a[0]));
    return p.value / area;
}

}  // namespace

TEST(PolygonToPolygon, OpposedSquaresAtEveryGapAndScale) {
    // Howell C-11 evaluated to 50 digits (mpmath): in double precision the formula itself
    // loses digits to cancellation at large gaps.
    const std::pair<double, double> cases[] = {{10.0, 0.0031620568387576016251},
                                               {1.0, analytic::parallel_rectangles(1, 1, 1)},
                                               {1e-3, analytic::parallel_rectangles(1, 1, 1e-3)},
                                               {1e-6, analytic::parallel_rectangles(1, 1, 1e-6)},
                                               {1e-9, analytic::parallel_rectangles(1, 1, 1e-9)}};
    for (double scale : {1e-6, 1.0, 1e6})
        for (const auto& [gap, exact] : cases) {
            SCOPED_TRACE(testing::Message() << "gap " << gap << " scale " << scale);
            const auto [lo, hi] = opposed(gap, scale);
            PolygonPair p;
            const double f = f_ab(lo, hi, &p);
            EXPECT_NEAR(f, exact, 1e-12);
            // The estimate covers the true error and is itself at round-off level.
            EXPECT_LE(std::abs(f - exact), p.error / (scale * scale) + 4e-16);
            EXPECT_LT(p.error / (scale * scale), 1e-11);
            // The other direction gives the same exchange.
            EXPECT_NEAR(f_ab(hi, lo), f, 1e-13);
        }
}

TEST(PolygonToPolygon, PerpendicularSquaresSharingAnEdgeOrACorner) {
    const Quad floor = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    const Quad wall = {Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 0, 0)};
    EXPECT_NEAR(f_ab(floor, wall), analytic::perpendicular_rectangles(1, 1, 1), 1e-13);
    const Quad corner = {Vec3(1, 0, 0), Vec3(1, 0, 1), Vec3(2, 0, 1), Vec3(2, 0, 0)};
    EXPECT_NEAR(f_ab(floor, corner), analytic::perpendicular_squares_corner(), 1e-13);
    // A wall strip a hair above the floor's edge line.
    for (double gap : {1e-3, 1e-9}) {
        const Quad strip = {Vec3(0, 0, gap), Vec3(0, 0, 1 + gap), Vec3(1, 0, 1 + gap), Vec3(1, 0, gap)};
        EXPECT_NEAR(f_ab(floor, strip), analytic::perpendicular_rectangles_gap(1, 1, gap, 1), 1e-13) << gap;
    }
}

TEST(PolygonToPolygon, FarApartPairsKeepTheirDigits) {
    // Two unit squares 1000 apart: F is about 3.2e-7 (Howell C-11 to 50 digits by mpmath;
    // the double-precision formula is off by 3e-11 here) and must be right to 1e-15.
    const auto [lo, hi] = opposed(1000.0, 1.0);
    EXPECT_NEAR(f_ab(lo, hi), 3.1830967397738025777e-7, 1e-15);
}

TEST(PolygonToPolygon, PartlyBehindEachOther) {
    // The wall reaches below the floor's plane: only its upper half is seen, and the answer
    // is the shared-edge one for the upper 1 x 1 part.
    const Quad floor = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    const Quad wall = {Vec3(0, 0, -1), Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 0, -1)};
    EXPECT_NEAR(f_ab(floor, wall), analytic::perpendicular_rectangles(1, 1, 1), 1e-13);
}

TEST(PolygonToPolygon, NothingPassesBetweenCoplanarOrBackToBackPolygons) {
    const Quad a = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    const Quad beside = {Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(2, 1, 0), Vec3(1, 1, 0)};
    EXPECT_EQ(f_ab(a, beside), 0.0);
    // b above a but facing up, away from it.
    const Quad away = {Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 1, 1), Vec3(0, 1, 1)};
    EXPECT_EQ(f_ab(a, away), 0.0);
}

TEST(PolygonToPolygon, AToleranceStopsEarlyAndItsEstimateCoversTheError) {
    // Opposed, perpendicular (shared edge and a hair apart) and offset pairs: with a tolerance
    // the contour integral stops once its estimate is within it, costs fewer evaluations, and
    // the estimate still covers its distance from the round-off answer.
    const Quad floor = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    const Quad wall = {Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 0, 0)};
    const Quad strip = {Vec3(0, 0, 1e-6), Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 0, 1e-6)};
    const Quad offset = {Vec3(0.5, 0.3, 0.2), Vec3(0.5, 1.3, 0.2), Vec3(1.5, 1.3, 0.2), Vec3(1.5, 0.3, 0.2)};
    const auto [lo, hi] = opposed(0.05, 1.0);
    const std::pair<Quad, Quad> pairs[] = {{lo, hi}, {floor, wall}, {floor, strip}, {floor, offset}};
    long long exact_evaluations = 0, loose_evaluations = 0;
    for (const auto& [a, b] : pairs)
        for (const double tol : {1e-4, 1e-7, 1e-10}) {
            SCOPED_TRACE(testing::Message() << "tolerance " << tol);
            const PolygonPair exact = polygon_to_polygon(a.data(), 4, b.data(), 4);
            const PolygonPair p = polygon_to_polygon(a.data(), 4, b.data(), 4, tol);
            ASSERT_GT(exact.value, 0.0);
            EXPECT_LE(p.error, tol + exact.error);
            EXPECT_LE(std::abs(p.value - exact.value), p.error + exact.error);
            EXPECT_LE(p.evaluations, exact.evaluations);
            exact_evaluations += exact.evaluations;
            loose_evaluations += p.evaluations;
        }
    EXPECT_LT(2 * loose_evaluations, exact_evaluations);
}

}  // namespace radiosa
