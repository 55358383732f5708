#pragma once
// The contour integral of n . (r x dr) / |r|^2 along an arc of a circle, r = y - x: the piece
// of the inner form-factor integral F(dx -> region) = -1/(2 pi) (contour integral) that an arc
// of the region's boundary contributes (spherical_region.cpp, contour_receiver.cpp). In closed
// form where that keeps its digits, by graded adaptive Gauss-Kronrod near the circle.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "util/gauss_kronrod.h"
#include "util/math.h"

namespace radiosa {

struct ContourValue {
    double value = 0.0;
    double error = 0.0;  // quadrature and rounding
    bool valid = true;   // false when the cuts leave no boundary (the whole sphere)
};

// A circle: centre, radius rho, an orthonormal basis (e1, e2) of its plane and its unit normal
// n = e1 x e2 (and, for a sphere's cut, the cut's offset d).
struct Circle {
    Vec3 c, e1, e2, n;
    double rho = 0.0, d = 0.0;
    Vec3 at(double a) const { return c + rho * (std::cos(a) * e1 + std::sin(a) * e2); }
    Vec3 tangent(double a) const { return rho * (-std::sin(a) * e1 + std::cos(a) * e2); }
    // The angle of the circle's point nearest x.
    double nearest_angle(const Vec3& x) const {
        const Vec3 in_plane = x - c - glm::dot(x - c, n) * n;
        return std::atan2(glm::dot(in_plane, e2), glm::dot(in_plane, e1));
    }
};

// The circle about `centre` in the plane of unit normal `normal`, radius rho, its basis from
// unit_across(normal).
inline Circle circle_about(const Vec3& centre, const Vec3& normal, double rho) {
    Circle k;
    k.c = centre;
    k.n = normal;
    k.e1 = unit_across(normal);
    k.e2 = glm::cross(normal, k.e1);
    k.rho = rho;
    return k;
}

namespace circle_arc_detail {

// The contour integral of n . (r x dr) / |r|^2 along the circle from angle a to b, r = y - x, by
// adaptive Gauss-Kronrod. Near x the integrand peaks over a width of x's distance from the
// circle, which no node of a wide interval may see: the arc is cut into pieces that grow
// geometrically away from the circle's point y* nearest x, each no longer than its distance
// from x. And y - x is taken as (y* - x) + (y - y*), the second term by half-angle formulas:
// free of the cancellation that would cost digits at small distances.
inline ContourValue arc_by_quadrature(const Circle& k, const Vec3& n, const Vec3& base, double nearest,
                                      double a, double b, double tol) {
    const double gap = glm::length(base) / k.rho;
    auto f = [&](double al) {
        const double half = std::sin(0.5 * (al - nearest)), mid = 0.5 * (al + nearest);
        const Vec3 rv = base + 2.0 * k.rho * half * (-std::sin(mid) * k.e1 + std::cos(mid) * k.e2);
        const double l2 = glm::dot(rv, rv);
        return l2 > 0.0 ? glm::dot(n, glm::cross(rv, k.tangent(al))) / l2 : 0.0;
    };
    std::vector<double> breaks{a, b};
    for (double shift : {-2 * kPi, 0.0, 2 * kPi}) {
        const double mid = nearest + shift;
        if (mid > a && mid < b) breaks.push_back(mid);
        for (double h = gap; h < b - a; h *= 2) {
            if (mid - h > a && mid - h < b) breaks.push_back(mid - h);
            if (mid + h > a && mid + h < b) breaks.push_back(mid + h);
        }
    }
    std::sort(breaks.begin(), breaks.end());
    ContourValue out;
    for (std::size_t q = 0; q + 1 < breaks.size(); ++q) {
        if (!(breaks[q + 1] > breaks[q])) continue;
        const Integral1D v = adaptive_kronrod(f, breaks[q], breaks[q + 1], tol / (breaks.size() - 1));
        out.value += v.value;
        out.error += v.error;
    }
    return out;
}

// The same integral in closed form. With q = c - x, along the circle
//   n . (r x dr/da) = A cos a + B sin a + C,  |r|^2 = D + E cos a + G sin a,
// and with E cos a + G sin a = M cos(a - psi), b = a - psi, the integrand is
// (P cos b + Q sin b + C) / (D + M cos b), whose antiderivative is
//   (P/M) b + (C - P D/M) J(b) - (Q/M) ln(D + M cos b),  J = int db / (D + M cos b)
//   = 2 / sqrt(D^2 - M^2) atan(sqrt((D - M)/(D + M)) tan(b/2)), continued across b = pi.
// D - M is x's squared distance from the circle, taken from `base` without cancellation.
// Nothing (use the quadrature) where M << D, where P/M and D/M would cost digits, or where x is
// within a hundredth of the circle's size from it.
inline std::optional<ContourValue> arc_closed_form(const Circle& k, const Vec3& x, const Vec3& n,
                                                   const Vec3& base, double a, double b) {
    const Vec3 q = k.c - x;
    const double A = k.rho * glm::dot(n, glm::cross(q, k.e2)), B = -k.rho * glm::dot(n, glm::cross(q, k.e1)),
                 C = k.rho * k.rho * glm::dot(n, k.n);
    const double D = glm::dot(q, q) + k.rho * k.rho, E = 2 * k.rho * glm::dot(q, k.e1),
                 G = 2 * k.rho * glm::dot(q, k.e2);
    const double M = std::hypot(E, G);
    if (!(M > 1e-3 * D)) return std::nullopt;
    const double psi = std::atan2(G, E), cp = E / M, sp = G / M;
    const double P = A * cp + B * sp, Q = -A * sp + B * cp;
    const double d_minus = glm::dot(base, base), d_plus = D + M;
    // Close to the circle the terms grow as 1 / distance and cancel: the quadrature, which
    // takes y - x without cancellation, keeps more digits there.
    if (!(d_minus > 1e-4 * D)) return std::nullopt;
    const double root = std::sqrt(d_minus * d_plus), t = std::sqrt(d_minus / d_plus);
    const double K = C - P * D / M;
    auto J = [&](double beta) {
        const double turns = std::round(beta / (2 * kPi));
        return 2.0 / root * (std::atan(t * std::tan(0.5 * beta - kPi * turns)) + kPi * turns);
    };
    // ln(D + M cos b), with D + M cos b = (D - M) + M (1 + cos b) = (D - M) + 2 M cos^2(b/2).
    auto L = [&](double beta) {
        const double c = std::cos(0.5 * beta);
        return std::log(d_minus + 2 * M * c * c);
    };
    const double ba = a - psi, bb = b - psi;
    const double t1 = P / M * (bb - ba), t2 = K * (J(bb) - J(ba)), t3 = -Q / M * (L(bb) - L(ba));
    ContourValue out;
    out.value = t1 + t2 + t3;
    out.error =
        32 * std::numeric_limits<double>::epsilon() *
        (std::abs(P / M) * (std::abs(ba) + std::abs(bb)) + std::abs(K) * (std::abs(J(ba)) + std::abs(J(bb))) +
         std::abs(Q / M) * (std::abs(L(ba)) + std::abs(L(bb))));
    return out;
}

}  // namespace circle_arc_detail

// The integral from angle a to b (a < b) for x with unit normal n; `nearest` is
// k.nearest_angle(x). Rounding of x's position relative to the circle is not included.
inline ContourValue circle_arc_integral(const Circle& k, const Vec3& x, const Vec3& n, double nearest,
                                        double a, double b, double tol) {
    const Vec3 base = k.at(nearest) - x;  // from x to the circle's point nearest it
    if (const auto closed = circle_arc_detail::arc_closed_form(k, x, n, base, a, b)) return *closed;
    return circle_arc_detail::arc_by_quadrature(k, n, base, nearest, a, b, tol);
}

}  // namespace radiosa
