// The contour closed form against Howell's catalogue: opposed and perpendicular rectangles at
// gaps from 1 down to 1e-9 and scales from 1e-6 to 1e6, shared edges and corners, far pairs,
// and the cases it must answer with zero.
#include "formfactor/polygon_polygon.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "formfactor/analytic.h"
#include "util/gauss_legendre.h"

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

TEST(PolygonToPolygon, ParallelEdgesInClosedForm) {
    // Collinear edges over one another: the integral of ln|s - t| over [0, L]^2 is
    // L^2 (ln L - 3/2); shifted by ln rho, minus rho's share L^2 ln rho.
    for (double len : {1e-3, 1.0, 7.0}) {
        const ParallelEdges p = parallel_edges_log_integral(len, 0.0, len, 0.0, 0.3);
        EXPECT_NEAR(p.value, len * len * (std::log(len) - 1.5 - 0.3), 1e-14 * std::max(1.0, len * len))
            << len;
        EXPECT_LT(p.error, 1e-13 * std::max(1.0, len * len));
    }
    // Lines apart, overlapping or not, against a 48 x 48 Gauss-Legendre rule over both edges
    // (the integrand is smooth there: the lines lie at least 0.5 apart, the edges at most 2.3
    // long).
    struct Case {
        double len_a, b0, b1, h;
    };
    for (const Case c : {Case{1.0, 0.0, 1.0, 0.5}, Case{1.0, -0.3, 2.0, 0.7}, Case{0.4, 3.0, 5.0, 2.0},
                         Case{2.0, -1.0, 0.5, 1.5}}) {
        const GaussRule rule = gauss_legendre(48);
        double ref = 0.0;
        const double hs = 0.5 * c.len_a, ht = 0.5 * (c.b1 - c.b0);
        for (std::size_t i = 0; i < rule.x.size(); ++i)
            for (std::size_t j = 0; j < rule.x.size(); ++j) {
                const double u = hs * (rule.x[i] + 1.0) - (c.b0 + ht * (rule.x[j] + 1.0));
                ref += rule.w[i] * rule.w[j] * (0.5 * std::log(u * u + c.h * c.h) - 0.2);
            }
        ref *= hs * ht;
        const ParallelEdges p = parallel_edges_log_integral(c.len_a, c.b0, c.b1, c.h, 0.2);
        EXPECT_NEAR(p.value, ref, 1e-12) << c.len_a << " " << c.b0 << " " << c.b1 << " " << c.h;
    }
}

TEST(PolygonToPolygon, OffsetAndTiltedRectanglesTakeTheParallelClosedForm) {
    // Unit square A on z = 0 to unit square B on z = c beside A's opposite, x in [1, 2]:
    // by superposition (2 x 1 rectangles over each other), F_AB = F(2, 1, c) - F(1, 1, c).
    // Given a tolerance, every edge pair counts in closed form (4 evaluations each, 8 pairs),
    // at every gap and scale, and turned by a rotation about a skew axis (edges parallel to a
    // few ulps) the same, the tilt counted in the estimate.
    const glm::dmat3 turn =
        glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.7, glm::normalize(Vec3(1.0, 2.0, 3.0))));
    for (double gap : {1e-6, 0.1, 1.0, 30.0})
        for (double scale : {1e-4, 1.0, 1e4})
            for (bool tilted : {false, true}) {
                SCOPED_TRACE(testing::Message()
                             << "gap " << gap << " scale " << scale << " tilted " << tilted);
                Quad a = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
                Quad b = {Vec3(1, 0, gap), Vec3(1, 1, gap), Vec3(2, 1, gap), Vec3(2, 0, gap)};
                for (Quad* q : {&a, &b})
                    for (Vec3& v : *q) v = (tilted ? turn * v : v) * scale;
                const double exact = analytic::parallel_rectangles<long double>(2, 1, gap) -
                                     analytic::parallel_rectangles<long double>(1, 1, gap);
                const PolygonPair p = polygon_to_polygon(a.data(), 4, b.data(), 4, 1e-10 * scale * scale);
                const double f = p.value / (scale * scale);
                EXPECT_NEAR(f, exact, 1e-12);
                EXPECT_LE(std::abs(f - exact), p.error / (scale * scale) + 1e-15);
                EXPECT_LE(p.error / (scale * scale), 1e-10);
                EXPECT_EQ(p.evaluations, 32);
            }
}

TEST(PolygonToPolygon, TheClosedFormGivesWayWhereItsRoundingWouldNotMeetTheTolerance) {
    // A 1e-4 square 0.9 above a 0.25 floor patch (the extreme-scene test's spark): the closed
    // form's terms are of order the squared distances and its answer of order the spark's area,
    // so at a tight tolerance the adaptive rule takes over and the answer keeps its digits.
    const double e = 0.5e-4;
    const Quad spark = {Vec3(0.5 - e, 0.5 - e, 0.9), Vec3(0.5 - e, 0.5 + e, 0.9), Vec3(0.5 + e, 0.5 + e, 0.9),
                        Vec3(0.5 + e, 0.5 - e, 0.9)};
    const Quad floor = {Vec3(0.25, 0.25, 0), Vec3(0.5, 0.25, 0), Vec3(0.5, 0.5, 0), Vec3(0.25, 0.5, 0)};
    const double a_spark = 4 * e * e;
    const PolygonPair exact = polygon_to_polygon(floor.data(), 4, spark.data(), 4);
    for (const double tol : {1e-6, 1e-9}) {
        SCOPED_TRACE(testing::Message() << "tolerance " << tol);
        const PolygonPair p = polygon_to_polygon(floor.data(), 4, spark.data(), 4, tol * a_spark);
        EXPECT_LE(p.error, tol * a_spark);
        EXPECT_LE(std::abs(p.value - exact.value), p.error + exact.error);
        if (tol == 1e-6) EXPECT_EQ(p.evaluations, 32);
        if (tol == 1e-9) EXPECT_GT(p.evaluations, 32);
    }
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
    // Pairs whose edges are not parallel (which take the adaptive rule): opposed squares one
    // turned, walls leaning over a floor (sharing an edge and a hair apart) and a skewed
    // quad. With a tolerance the contour integral stops once its estimate is within it, costs
    // fewer evaluations, and the estimate still covers its distance from the round-off answer.
    const Quad floor = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    const Quad wall = {Vec3(0, 0, 0), Vec3(0.3, 0, 1), Vec3(1, 0, 0.9), Vec3(1, 0, 0)};
    const Quad strip = {Vec3(0, 0, 1e-6), Vec3(0, 0.1, 1), Vec3(1, 0.1, 1), Vec3(1, 0, 1e-6)};
    const Quad offset = {Vec3(0.5, 0.3, 0.2), Vec3(0.6, 1.3, 0.2), Vec3(1.5, 1.2, 0.2), Vec3(1.4, 0.3, 0.2)};
    auto [lo, hi] = opposed(0.05, 1.0);
    const glm::dmat3 turn = glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.3, Vec3(0.0, 0.0, 1.0)));
    for (Vec3& v : hi) v = turn * (v - Vec3(0.5, 0.5, 0.0)) + Vec3(0.5, 0.5, 0.0);
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
