#pragma once
// Closed-form form factors from the radiative-transfer literature (Howell's catalogue,
// configurations C-11 and C-14, and superpositions of them): answers known in advance for the
// tests and the `radiosa accuracy` study.
#include <cmath>

namespace radiosa::analytic {

// Two directly opposed, parallel, equal rectangles a x b at distance c (Howell C-11).
inline double parallel_rectangles(double a, double b, double c) {
    const double X = a / c, Y = b / c;
    const double pi = 3.14159265358979323846;
    const double t1 = 0.5 * std::log((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y));
    const double t2 = X * std::sqrt(1 + Y * Y) * std::atan(X / std::sqrt(1 + Y * Y));
    const double t3 = Y * std::sqrt(1 + X * X) * std::atan(Y / std::sqrt(1 + X * X));
    return 2.0 / (pi * X * Y) * (t1 + t2 + t3 - X * std::atan(X) - Y * std::atan(Y));
}

// From rectangle 1 (l x w) to rectangle 2 (l x h), perpendicular, sharing the edge of
// length l (Howell C-14).
inline double perpendicular_rectangles(double l, double w, double h) {
    const double W = w / l, H = h / l;
    const double pi = 3.14159265358979323846;
    const double W2 = W * W, H2 = H * H, R2 = W2 + H2, R = std::sqrt(R2);
    const double a = W * std::atan(1 / W) + H * std::atan(1 / H) - R * std::atan(1 / R);
    const double l1 = std::log((1 + W2) * (1 + H2) / (1 + R2));
    const double l2 = W2 * std::log(W2 * (1 + R2) / ((1 + W2) * R2));
    const double l3 = H2 * std::log(H2 * (1 + R2) / ((1 + H2) * R2));
    return (a + 0.25 * (l1 + l2 + l3)) / (pi * W);
}

// From unit square A on the floor (x in [0,1]) to unit square D on the wall that touches A
// only at a corner (x in [1,2]): superposition of C-14 (2 x 1 pair minus the edge-sharing pair).
// With B, C the other halves: 2 F(AB->CD) = F_AC + F_AD + F_BC + F_BD, F_AC = F_BD, F_AD = F_BC.
inline double perpendicular_squares_corner() {
    return perpendicular_rectangles(2.0, 1.0, 1.0) - perpendicular_rectangles(1.0, 1.0, 1.0);
}

// From a w x l floor rectangle to the l-wide strip of the perpendicular wall between heights
// g and g + h above the shared edge line (a gap g between them): C-14 twice.
inline double perpendicular_rectangles_gap(double l, double w, double g, double h) {
    return perpendicular_rectangles(l, w, g + h) - perpendicular_rectangles(l, w, g);
}

}  // namespace radiosa::analytic
