#pragma once
// Closed-form form factors from the radiative-transfer literature (Howell's catalogue,
// configurations C-11 and C-14, and superpositions of them): answers known in advance for the
// tests and the `radiosa accuracy` study.
#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include "util/gauss_legendre.h"

namespace radiosa::analytic {

// The formulas take the floating-point type as a parameter: the validation study evaluates them
// in long double (64-bit mantissa), so that their own rounding (up to 1e-13 at extreme aspect
// ratios in double) is not counted against radiosa's estimates.
template <class T>
constexpr T kPiT = T(3.14159265358979323846264338327950288L);

// Coaxial parallel disks of radii r1 (the emitter) and r2 a distance h apart (Howell C-41):
// F = (X - sqrt(X^2 - 4 (R2 / R1)^2)) / 2, R = r / h, X = 1 + (1 + R2^2) / R1^2, taken as
// 2 (R2 / R1)^2 / (X + sqrt(...)) so that it keeps its digits when F is small.
template <class T = double>
inline T coaxial_disks(std::type_identity_t<T> r1, std::type_identity_t<T> r2, std::type_identity_t<T> h) {
    const T R1 = r1 / h, R2 = r2 / h, X = 1 + (1 + R2 * R2) / (R1 * R1), q = (R2 / R1) * (R2 / R1);
    return 2 * q / (X + std::sqrt(X * X - 4 * q));
}

// Two directly opposed, parallel, equal rectangles a x b at distance c (Howell C-11).
template <class T = double>
inline T parallel_rectangles(std::type_identity_t<T> a, std::type_identity_t<T> b,
                             std::type_identity_t<T> c) {
    const T X = a / c, Y = b / c;
    const T t1 = T(0.5) * std::log((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y));
    const T t2 = X * std::sqrt(1 + Y * Y) * std::atan(X / std::sqrt(1 + Y * Y));
    const T t3 = Y * std::sqrt(1 + X * X) * std::atan(Y / std::sqrt(1 + X * X));
    return T(2) / (kPiT<T> * X * Y) * (t1 + t2 + t3 - X * std::atan(X) - Y * std::atan(Y));
}

// From rectangle 1 (l x w) to rectangle 2 (l x h), perpendicular, sharing the edge of
// length l (Howell C-14).
template <class T = double>
inline T perpendicular_rectangles(std::type_identity_t<T> l, std::type_identity_t<T> w,
                                  std::type_identity_t<T> h) {
    const T W = w / l, H = h / l;
    const T W2 = W * W, H2 = H * H, R2 = W2 + H2, R = std::sqrt(R2);
    const T a = W * std::atan(1 / W) + H * std::atan(1 / H) - R * std::atan(1 / R);
    const T l1 = std::log((1 + W2) * (1 + H2) / (1 + R2));
    const T l2 = W2 * std::log(W2 * (1 + R2) / ((1 + W2) * R2));
    const T l3 = H2 * std::log(H2 * (1 + R2) / ((1 + H2) * R2));
    return (a + T(0.25) * (l1 + l2 + l3)) / (kPiT<T> * W);
}

// From unit square A on the floor (x in [0,1]) to unit square D on the wall that touches A
// only at a corner (x in [1,2]): superposition of C-14 (2 x 1 pair minus the edge-sharing pair).
// With B, C the other halves: 2 F(AB->CD) = F_AC + F_AD + F_BC + F_BD, F_AC = F_BD, F_AD = F_BC.
inline double perpendicular_squares_corner() {
    return perpendicular_rectangles(2.0, 1.0, 1.0) - perpendicular_rectangles(1.0, 1.0, 1.0);
}

// From a w x l floor rectangle to the l-wide strip of the perpendicular wall between heights
// g and g + h above the shared edge line (a gap g between them): C-14 twice.
template <class T = double>
inline T perpendicular_rectangles_gap(std::type_identity_t<T> l, std::type_identity_t<T> w,
                                      std::type_identity_t<T> g, std::type_identity_t<T> h) {
    return perpendicular_rectangles<T>(l, w, g + h) - perpendicular_rectangles<T>(l, w, g);
}

// From a point to a rectangle [x0, x1] x [y0, y1] in a parallel plane at distance c, facing it,
// the point's foot at (px, py) (Howell B-3 at a corner, superposed with signs).
inline double point_to_parallel_rectangle(double px, double py, double x0, double x1, double y0, double y1,
                                          double c) {
    if (!(x1 > x0) || !(y1 > y0)) return 0.0;
    const double pi = 3.14159265358979323846;
    auto corner = [&](double a, double b) {
        const double A = std::abs(a) / c, B = std::abs(b) / c;
        const double f = (A / std::sqrt(1 + A * A) * std::atan(B / std::sqrt(1 + A * A)) +
                          B / std::sqrt(1 + B * B) * std::atan(A / std::sqrt(1 + B * B))) /
                         (2 * pi);
        return (a < 0) == (b < 0) ? f : -f;
    };
    return corner(x1 - px, y1 - py) - corner(x0 - px, y1 - py) - corner(x1 - px, y0 - py) +
           corner(x0 - px, y0 - py);
}

// From the unit square [0, 1]^2 at z = 0 (facing +z) to the unit square at z = c (facing -z)
// with an axis-aligned rectangular plate [ox0, ox1] x [oy0, oy1] at height h in between: the
// outer integral of the closed-form point factor to the target minus the plate's shadow (a
// rectangle: the plate scaled by c / h about the point), by Gauss-Legendre on the pieces where
// the shadow's bounds are affine in the point (smooth there, so 40 points per axis give
// round-off).
inline double parallel_squares_with_plate(double c, double h, double ox0, double ox1, double oy0,
                                          double oy1) {
    const double k = c / h;  // shadow of q seen from x: x + (q - x) k
    auto breaks = [&](double o0, double o1) {
        std::vector<double> b = {0.0, 1.0};
        for (double o : {o0, o1})
            for (double edge : {0.0, 1.0}) {
                const double x = (edge - o * k) / (1 - k);
                if (x > 0.0 && x < 1.0) b.push_back(x);
            }
        std::sort(b.begin(), b.end());
        return b;
    };
    const std::vector<double> bx = breaks(ox0, ox1), by = breaks(oy0, oy1);
    const radiosa::GaussRule g = radiosa::gauss_legendre(40);
    double f = 0.0;
    for (std::size_t a = 0; a + 1 < bx.size(); ++a)
        for (std::size_t b = 0; b + 1 < by.size(); ++b) {
            const double hx = 0.5 * (bx[a + 1] - bx[a]), hy = 0.5 * (by[b + 1] - by[b]);
            for (std::size_t i = 0; i < g.x.size(); ++i)
                for (std::size_t j = 0; j < g.x.size(); ++j) {
                    const double x = bx[a] + hx * (g.x[i] + 1), y = by[b] + hy * (g.x[j] + 1);
                    const double sx0 = std::max(0.0, x + (ox0 - x) * k),
                                 sx1 = std::min(1.0, x + (ox1 - x) * k);
                    const double sy0 = std::max(0.0, y + (oy0 - y) * k),
                                 sy1 = std::min(1.0, y + (oy1 - y) * k);
                    f += g.w[i] * g.w[j] * hx * hy *
                         (point_to_parallel_rectangle(x, y, 0, 1, 0, 1, c) -
                          point_to_parallel_rectangle(x, y, sx0, sx1, sy0, sy1, c));
                }
        }
    return f;
}

}  // namespace radiosa::analytic
