#pragma once
// Textbook form factors the tests compare against (Howell's catalogue of configuration
// factors), in one place.
#include <array>
#include <cmath>

#include "util/math.h"

namespace radiosa::test {

// A plane element on the axis of a 2a x 2b rectangle at distance h, facing it (Howell B-3).
inline double element_on_rectangle_axis(double a, double b, double h) {
    const double A = a / h, B = b / h;
    return 2.0 / kPi *
           (A / std::sqrt(1 + A * A) * std::atan(B / std::sqrt(1 + A * A)) +
            B / std::sqrt(1 + B * B) * std::atan(A / std::sqrt(1 + B * B)));
}

// What an occluder hides of the quad v (a parallelogram) from x (unit normal n), by the midpoint
// rule on an m x m grid over v with the ray test `meets(x, y)` at each point: the brute-force sum
// the closed-form shadows are checked against (its error at the shadow's edge is O(1/m)).
template <class Meets>
double brute_force_hidden(const Vec3& x, const Vec3& n, const std::array<Vec3, 4>& v, int m,
                          const Meets& meets) {
    const Vec3 e = v[1] - v[0], f = v[3] - v[0];
    const Vec3 nv = glm::cross(e, f);
    const double da = glm::length(nv) / (m * m);
    const Vec3 unit = nv / glm::length(nv);
    double sum = 0.0;
    for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b) {
            const Vec3 y = v[0] + ((a + 0.5) / m) * e + ((b + 0.5) / m) * f;
            const Vec3 r = y - x;
            const double l2 = glm::dot(r, r);
            const double cx = glm::dot(n, r), cy = -glm::dot(unit, r);
            if (cx <= 0.0 || cy <= 0.0 || !meets(x, y)) continue;
            sum += cx * cy / (kPi * l2 * l2) * da;
        }
    return sum;
}

// A wall: the square of half-size a in the plane y = w, centred at height zc, facing -y.
inline std::array<Vec3, 4> wall(double a, double w, double zc) {
    return {Vec3(-a, w, zc - a), Vec3(a, w, zc - a), Vec3(a, w, zc + a), Vec3(-a, w, zc + a)};
}

}  // namespace radiosa::test
