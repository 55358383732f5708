// The closed-form point-to-polygon factor against textbook values and limits.
#include "formfactor/point_polygon.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../tests/closed_forms.h"
#include "util/gauss_legendre.h"

namespace radiosa {

namespace {
// What an on-axis ball of angular radius alpha hides of the half-plane x >= cut on the plane
// z = h, from the origin facing +z: (1/pi) integral over its cap of cos(theta) dw, the azimuths
// of each ring with h tan(theta) cos(phi) >= cut. Past theta* = atan(|cut| / h) the ring is cut,
// with a square-root onset there that the substitution theta = theta* + (alpha - theta*) u^2
// takes out of the Gauss rule's way.
double cap_beyond_chord(double alpha, double h, double cut) {
    const double t0 = std::atan(std::abs(cut) / h);
    const auto ring = [&](double th) {
        return 2.0 * std::acos(std::clamp(cut / (h * std::tan(th)), -1.0, 1.0)) * std::cos(th) *
               std::sin(th) / kPi;
    };
    const GaussRule g = gauss_legendre(40);
    double sum = cut < 0.0 ? std::sin(t0) * std::sin(t0) : 0.0;  // whole rings below theta*
    for (std::size_t k = 0; k < g.x.size(); ++k) {
        const double u = 0.5 * (g.x[k] + 1.0);
        sum += 0.5 * g.w[k] * ring(t0 + (alpha - t0) * u * u) * 2.0 * (alpha - t0) * u;
    }
    return sum;
}

using test::element_on_rectangle_axis;
}  // namespace

TEST(PointPolygon, OnAxisRectangleMatchesClosedForm) {
    // Rectangle in z = 1 facing down (counter-clockwise about -z).
    const Vec3 v[4] = {{-1, -0.5, 1}, {-1, 0.5, 1}, {1, 0.5, 1}, {1, -0.5, 1}};
    const Vec3 x(0, 0, 0), n(0, 0, 1);
    EXPECT_NEAR(point_to_polygon(x, n, v, 4, nullptr), element_on_rectangle_axis(1.0, 0.5, 1.0), 1e-14);
    // Facing away from x: nothing.
    const Vec3 r[4] = {v[3], v[2], v[1], v[0]};
    EXPECT_EQ(point_to_polygon(x, n, r, 4, nullptr), 0.0);
    // A point whose tangent plane cuts the polygon in half sees half of it.
    const Vec3 side(1, 0, 0);
    const double half = point_to_polygon(Vec3(0, 0, 0.999999999), side, v, 4, nullptr);
    EXPECT_GT(half, 0.0);
    EXPECT_LT(half, 0.5);
}

TEST(PointPolygon, HugePolygonTendsToOne) {
    const double L = 1e6;
    const Vec3 v[4] = {{-L, -L, 1}, {-L, L, 1}, {L, L, 1}, {L, -L, 1}};
    EXPECT_NEAR(point_to_polygon(Vec3(0.0), Vec3(0, 0, 1), v, 4, nullptr), 1.0, 1e-5);
}

TEST(PointPolygon, SphereBlockerTakesOutItsProjectedCap) {
    const double L = 100.0;
    const Vec3 v[4] = {{-L, -L, 10}, {-L, L, 10}, {L, L, 10}, {L, -L, 10}};
    const Vec3 x(0.0), n(0, 0, 1);
    const double open = point_to_polygon(x, n, v, 4, nullptr);
    // On the axis: the cap (sin^2 alpha = (R/D)^2) lies wholly inside the polygon.
    const BoundingSphere s{Vec3(0, 0, 4), 1.0};
    EXPECT_NEAR(point_to_polygon(x, n, v, 4, &s), open - 1.0 / 16.0, 1e-13);
    // Off axis at 45 degrees: sin^2(alpha) cos(45 deg).
    const BoundingSphere t{Vec3(3, 0, 3), 1.0};
    EXPECT_NEAR(point_to_polygon(x, n, v, 4, &t), open - (1.0 / 18.0) * std::sqrt(0.5), 1e-13);
    // A sphere covering the whole polygon's cone blocks everything.
    const Vec3 small[4] = {{-0.1, -0.1, 10}, {-0.1, 0.1, 10}, {0.1, 0.1, 10}, {0.1, -0.1, 10}};
    EXPECT_EQ(point_to_polygon(x, n, small, 4, &s), 0.0);
    // Half covered: a sphere whose cone is cut by a polygon edge through its axis. By symmetry
    // the rectangle [0, 50] x [-50, 50] (its cone contains half the cap) loses exactly half of it.
    const Vec3 q[4] = {{0, -50, 5}, {0, 50, 5}, {50, 50, 5}, {50, -50, 5}};
    const double q_open = point_to_polygon(x, n, q, 4, nullptr);
    EXPECT_NEAR(point_to_polygon(x, n, q, 4, &s), q_open - 0.5 / 16.0, 1e-13);
    // Two edges through the axis: the quadrant [0, 50]^2 holds a quarter of the cap (its circle
    // cut in two pieces, the one outside spanning three quarters of a turn), and a wedge of 60
    // degrees a sixth.
    const Vec3 quadrant[4] = {{0, 0, 5}, {0, 50, 5}, {50, 50, 5}, {50, 0, 5}};
    EXPECT_NEAR(point_to_polygon(x, n, quadrant, 4, &s),
                point_to_polygon(x, n, quadrant, 4, nullptr) - 0.25 / 16.0, 1e-13);
    const Vec3 wedge[3] = {{0, 0, 5}, {25, 25 * std::sqrt(3.0), 5}, {50, 0, 5}};
    EXPECT_NEAR(point_to_polygon(x, n, wedge, 3, &s),
                point_to_polygon(x, n, wedge, 3, nullptr) - (1.0 / 6.0) / 16.0, 1e-13);
    // An edge off the axis cuts the cap's circle into a short piece and one of more than half a
    // turn; either side of it hides the part of the cap beyond the chord.
    const double alpha = std::asin(0.25);
    for (const double cut : {0.3, -0.9}) {  // the cap spans |x| < 5 tan(alpha) = 1.29 on z = 5
        const Vec3 right[4] = {{cut, -50, 5}, {cut, 50, 5}, {50, 50, 5}, {50, -50, 5}};
        const Vec3 left[4] = {{-50, -50, 5}, {-50, 50, 5}, {cut, 50, 5}, {cut, -50, 5}};
        const double beyond = cap_beyond_chord(alpha, 5.0, cut);
        EXPECT_NEAR(point_to_polygon(x, n, right, 4, nullptr) - point_to_polygon(x, n, right, 4, &s), beyond,
                    1e-13)
            << cut;
        EXPECT_NEAR(point_to_polygon(x, n, left, 4, nullptr) - point_to_polygon(x, n, left, 4, &s),
                    1.0 / 16.0 - beyond, 1e-13)
            << cut;
    }
}

// The shortcuts of the blocked part: a polygon wholly inside the ball's cone is wholly blocked,
// and one the cone passes beside its corner (crossing both edges' great circles, but not the
// polygon) loses nothing. Four quadrants around that corner share the ball's whole cap.
TEST(PointPolygon, BlockedPartAnswersUmbraAndCornerAtOnce) {
    const Vec3 x(0.0), n(0, 0, 1);
    const BoundingSphere ball{Vec3(-0.9, -0.9, 4.0), 1.0};
    const Vec3 tiny[4] = {{-0.8, -0.8, 10}, {-0.8, -0.7, 10}, {-0.7, -0.7, 10}, {-0.7, -0.8, 10}};
    EXPECT_EQ(point_to_polygon_blocked(x, n, tiny, 4, ball), point_to_polygon(x, n, tiny, 4, nullptr));
    EXPECT_GT(point_to_polygon_blocked(x, n, tiny, 4, ball), 0.0);
    const double L = 50.0, z = 5.0;
    const Vec3 q1[4] = {{0, 0, z}, {0, L, z}, {L, L, z}, {L, 0, z}};
    const Vec3 q2[4] = {{-L, 0, z}, {-L, L, z}, {0, L, z}, {0, 0, z}};
    const Vec3 q3[4] = {{-L, -L, z}, {-L, 0, z}, {0, 0, z}, {0, -L, z}};
    const Vec3 q4[4] = {{0, -L, z}, {0, 0, z}, {L, 0, z}, {L, -L, z}};
    // The corner's direction lies 17.7 degrees from the cone's axis, beyond its 13.8; the edges'
    // planes x = 0 and y = 0 lie 12.4 degrees from it, within.
    EXPECT_EQ(point_to_polygon_blocked(x, n, q1, 4, ball), 0.0);
    double sum = 0.0;
    for (const Vec3* q : {q1, q2, q3, q4}) {
        const double b = point_to_polygon_blocked(x, n, q, 4, ball);
        EXPECT_NEAR(point_to_polygon(x, n, q, 4, nullptr) - point_to_polygon(x, n, q, 4, &ball), b, 1e-15);
        sum += b;
    }
    const double dist = glm::length(ball.center), sin_a = ball.radius / dist;
    EXPECT_GT(point_to_polygon_blocked(x, n, q2, 4, ball), 1e-4);  // the cone reaches past x = 0
    EXPECT_NEAR(sum, sin_a * sin_a * ball.center.z / dist, 1e-14);
}

// Edges wholly inside the ball's cone take their whole angle without the arc's trigonometry.
// A kite whose lower half lies inside the cone (its two lower edges wholly inside) is its upper
// triangle (whose base, the kite's diagonal, lies wholly inside) plus its lower one, which is
// wholly blocked: their blocked parts add up, and the lower one's is its whole factor.
TEST(PointPolygon, EdgesWhollyInsideTheConeAddUp) {
    const Vec3 x(0.0), n(0, 0, 1);
    const BoundingSphere ball{Vec3(0, 0, 4), 1.0};  // its cone meets z = 5 in |(x, y)| < 1.29
    const Vec3 a(-0.5, 0.3, 5), p(0, -0.6, 5), b(0.5, 0.3, 5), q(0, 3, 5);
    const Vec3 kite[4] = {q, b, p, a}, upper[3] = {q, b, a}, lower[3] = {b, p, a};  // facing x
    const double whole_lower = point_to_polygon(x, n, lower, 3, nullptr);
    EXPECT_GT(whole_lower, 0.0);
    EXPECT_EQ(point_to_polygon_blocked(x, n, lower, 3, ball), whole_lower);
    const double k = point_to_polygon_blocked(x, n, kite, 4, ball);
    const double u = point_to_polygon_blocked(x, n, upper, 3, ball);
    EXPECT_GT(u, 0.0);
    EXPECT_LT(u, point_to_polygon(x, n, upper, 3, nullptr));  // the apex q lies outside the cone
    EXPECT_NEAR(k, u + whole_lower, 1e-15);
    // Mirrored in x = 0 (the order reversed to keep the front side): the same values.
    const auto mirror = [](const Vec3& v) { return Vec3(-v.x, v.y, v.z); };
    const Vec3 kite_m[4] = {mirror(a), mirror(p), mirror(b), mirror(q)};
    EXPECT_NEAR(point_to_polygon_blocked(x, n, kite_m, 4, ball), k, 1e-15);
}

// The cap arc of a sphere seen near the far end of a polygon edge that spans almost half the
// sky (the horizon edge of a large wall close to x): its interval on the edge wraps past +pi and
// is found only through the 2 pi shift. The mirror image puts the sphere near the edge's start,
// where no wrap is needed; by symmetry both see exactly as much of the wall.
TEST(PointPolygon, CapArcWrappingPastPiMatchesItsMirrorImage) {
    const double L = 1000.0;
    const Vec3 n(0, 0, 1);
    // Faces -y, towards x; symmetric under x -> -x, which also reverses its first horizon edge.
    const Vec3 wall[4] = {{L, 1, -L}, {L, 1, L}, {-L, 1, L}, {-L, 1, -L}};
    for (double beyond : {0.02, 0.05, 0.1}) {
        const Vec3 d(-std::cos(beyond), -std::sin(beyond), 0.05);
        const BoundingSphere s{0.5 * d, 0.1}, m{0.5 * Vec3(-d.x, d.y, d.z), 0.1};
        const double open = point_to_polygon(Vec3(0.0), n, wall, 4, nullptr);
        const double f = point_to_polygon(Vec3(0.0), n, wall, 4, &s);
        const double g = point_to_polygon(Vec3(0.0), n, wall, 4, &m);
        EXPECT_LT(f, open - 1e-5) << beyond;  // the sphere hides part of the wall
        EXPECT_NEAR(f, g, 1e-12) << beyond;
    }
}

namespace radiosa {

namespace {
std::array<Vec3, 4> square_at(double x0, double x1, double y0, double y1, double z) {
    return {Vec3(x0, y0, z), Vec3(x1, y0, z), Vec3(x1, y1, z), Vec3(x0, y1, z)};
}
}  // namespace

// Flat occluders: their shadows are projections from the point onto the target's plane.
TEST(PointPolygonHidden, ShadowsAreCentralProjectionsAndUnionsCountOnce) {
    // Target: the unit square in z = 0 facing +z (counter-clockwise seen from above); the point
    // at height 1 above its centre, looking down.
    const std::array<Vec3, 4> target = square_at(0, 1, 0, 1, 0);
    const Vec3 x(0.5, 0.5, 1.0), n(0, 0, -1);
    const double open = point_to_polygon(x, n, target.data(), 4, nullptr);
    // Halfway down, a square of half the side hides the whole target ...
    EXPECT_NEAR(point_to_polygon_hidden(x, n, target.data(), 4, {square_at(0.25, 0.75, 0.25, 0.75, 0.5)}),
                open, 1e-15);
    // ... one of a quarter of the side hides the middle half-side square.
    const std::array<Vec3, 4> middle = square_at(0.25, 0.75, 0.25, 0.75, 0);
    const double mid = point_to_polygon(x, n, middle.data(), 4, nullptr);
    EXPECT_NEAR(point_to_polygon_hidden(x, n, target.data(), 4, {square_at(0.375, 0.625, 0.375, 0.625, 0.5)}),
                mid, 1e-15);
    // Two overlapping halves of that occluder hide exactly what it hides, not more.
    EXPECT_NEAR(point_to_polygon_hidden(
                    x, n, target.data(), 4,
                    {square_at(0.375, 0.55, 0.375, 0.625, 0.5), square_at(0.45, 0.625, 0.375, 0.625, 0.5)}),
                mid, 1e-15);
    // An occluder beyond the target's plane, or above the point, hides nothing.
    EXPECT_EQ(point_to_polygon_hidden(x, n, target.data(), 4, {square_at(0.375, 0.625, 0.375, 0.625, -0.5)}),
              0.0);
    EXPECT_EQ(point_to_polygon_hidden(x, n, target.data(), 4, {square_at(0.375, 0.625, 0.375, 0.625, 1.5)}),
              0.0);
    // A tilted occluder reaching through the target's plane only hides with its upper part.
    const std::array<Vec3, 4> tilted = {Vec3(0.375, 0.375, -0.5), Vec3(0.625, 0.375, -0.5),
                                        Vec3(0.625, 0.625, 0.5), Vec3(0.375, 0.625, 0.5)};
    const std::array<Vec3, 4> upper = {Vec3(0.375, 0.5, 0.0), Vec3(0.625, 0.5, 0.0), Vec3(0.625, 0.625, 0.5),
                                       Vec3(0.375, 0.625, 0.5)};
    EXPECT_NEAR(point_to_polygon_hidden(x, n, target.data(), 4, {tilted}),
                point_to_polygon_hidden(x, n, target.data(), 4, {upper}), 1e-15);
    EXPECT_GT(point_to_polygon_hidden(x, n, target.data(), 4, {upper}), 0.0);
}

}  // namespace radiosa

namespace {
// (1/pi) times the integral of n . w over the directions w from x that reach the polygon
// (a rectangle in z = 1 facing down, |X| <= 1, |Y| <= 0.5) through some ball: each ball's cone
// in its own polar angles (rho, t), counting a direction only in the first cone that holds it,
// by the midpoint rule on nr x 2nr cells.
double hidden_by_balls_brute(const Vec3& x, const Vec3& n, const std::vector<BoundingSphere>& balls, int nr) {
    double sum = 0.0;
    for (std::size_t c = 0; c < balls.size(); ++c) {
        const Vec3 to_c = balls[c].center - x;
        const double dist = glm::length(to_c), alpha = std::asin(balls[c].radius / dist);
        const Vec3 d = to_c / dist;
        const Vec3 e1 = glm::normalize(glm::cross(d, Vec3(1, 0, 0))), e2 = glm::cross(d, e1);
        const double hr = alpha / nr, ht = 2 * kPi / (2 * nr);
        for (int i = 0; i < nr; ++i) {
            const double rho = (i + 0.5) * hr, sr = std::sin(rho), cr = std::cos(rho);
            for (int k = 0; k < 2 * nr; ++k) {
                const double t = (k + 0.5) * ht;
                const Vec3 w = cr * d + sr * (std::cos(t) * e1 + std::sin(t) * e2);
                if (!(glm::dot(n, w) > 0.0) || !(w.z > 0.0)) continue;
                const Vec3 p = x + w * ((1.0 - x.z) / w.z);
                if (std::abs(p.x) > 1.0 || std::abs(p.y) > 0.5) continue;
                bool earlier = false;
                for (std::size_t j = 0; j < c && !earlier; ++j) {
                    const Vec3 oj = balls[j].center - x;
                    const double lj = glm::length(oj);
                    earlier =
                        glm::dot(w, oj / lj) > std::sqrt(1.0 - balls[j].radius * balls[j].radius / (lj * lj));
                }
                if (!earlier) sum += glm::dot(n, w) * sr * hr * ht;
            }
        }
    }
    return sum / kPi;
}
}  // namespace

TEST(PointPolygonBalls, OneBallApartOrHiddenBehindAnotherAreTheirKnownParts) {
    const Vec3 v[4] = {{-1, -0.5, 1}, {-1, 0.5, 1}, {1, 0.5, 1}, {1, -0.5, 1}};
    const Vec3 x(0.1, -0.05, 0.0), n(0.0, 0.0, 1.0);
    const BoundingSphere big{{0.2, 0.0, 0.4}, 0.2}, far{{-0.5, 0.1, 0.5}, 0.2};
    const BoundingSphere small{x + 1.6 * (big.center - x) + Vec3(0.05, 0.0, 0.0), 0.05};
    // One ball: the single-ball closed form, to the bit.
    EXPECT_EQ(point_to_polygon_blocked_by_balls(x, n, v, 4, &big, 1),
              point_to_polygon_blocked(x, n, v, 4, big));
    // A ball behind another, inside its cone, adds nothing.
    const auto half_angle = [&](const BoundingSphere& b) {
        return std::asin(b.radius / glm::length(b.center - x));
    };
    ASSERT_LT(std::acos(glm::dot(glm::normalize(small.center - x), glm::normalize(big.center - x))) +
                  half_angle(small),
              half_angle(big) - 0.1);
    const BoundingSphere nested[2] = {big, small};
    EXPECT_NEAR(point_to_polygon_blocked_by_balls(x, n, v, 4, nested, 2),
                point_to_polygon_blocked(x, n, v, 4, big), 1e-15);
    const BoundingSphere nested_other_order[2] = {small, big};
    EXPECT_NEAR(point_to_polygon_blocked_by_balls(x, n, v, 4, nested_other_order, 2),
                point_to_polygon_blocked(x, n, v, 4, big), 1e-15);
    // Shadows apart add up.
    const BoundingSphere apart[2] = {big, far};
    const double sum = point_to_polygon_blocked(x, n, v, 4, big) + point_to_polygon_blocked(x, n, v, 4, far);
    ASSERT_GT(point_to_polygon_blocked(x, n, v, 4, far), 0.01);
    EXPECT_NEAR(point_to_polygon_blocked_by_balls(x, n, v, 4, apart, 2), sum, 1e-15);
}

TEST(PointPolygonBalls, OverlappingShadowsCountOnceAgainstDirectIntegration) {
    // Rectangle in z = 1 facing down; balls between the point and it whose cones overlap one
    // another, cross the rectangle's edges and (tilted normal) its horizon.
    const Vec3 v[4] = {{-1, -0.5, 1}, {-1, 0.5, 1}, {1, 0.5, 1}, {1, -0.5, 1}};
    struct Case {
        Vec3 x, n;
        std::vector<BoundingSphere> balls;
    };
    const std::vector<Case> cases = {
        {{0, 0, 0}, {0, 0, 1}, {{{0.1, 0.0, 0.5}, 0.15}, {{0.25, 0.05, 0.45}, 0.12}}},
        {{0.2, 0.1, 0},
         {0, 0, 1},
         {{{0.6, 0.3, 0.5}, 0.15}, {{0.7, 0.1, 0.6}, 0.2}, {{0.45, 0.3, 0.35}, 0.1}}},
        {{-0.3, 0, 0},
         glm::normalize(Vec3(0.5, 0, 1)),
         {{{-0.6, 0.0, 0.4}, 0.2}, {{-0.45, 0.1, 0.5}, 0.15}, {{-0.5, -0.2, 0.5}, 0.12}}},
        {{0, 0, 0.2},
         glm::normalize(Vec3(0.3, -0.6, 1)),
         {{{0.0, -0.3, 0.5}, 0.15},
          {{0.1, -0.35, 0.6}, 0.15},
          {{0.05, -0.1, 0.55}, 0.1},
          {{0.3, -0.4, 0.6}, 0.1}}},
    };
    for (const Case& c : cases) {
        const double f = point_to_polygon_blocked_by_balls(c.x, c.n, v, 4, c.balls.data(),
                                                           static_cast<int>(c.balls.size()));
        double single_sum = 0.0;
        for (const BoundingSphere& b : c.balls) single_sum += point_to_polygon_blocked(c.x, c.n, v, 4, b);
        const double brute = hidden_by_balls_brute(c.x, c.n, c.balls, 1200);
        EXPECT_NEAR(f, brute, 2e-5) << c.balls.size();
        EXPECT_LT(f, single_sum - 1e-3);  // the shadows do overlap: their sum counts some twice
    }
}
}  // namespace radiosa
