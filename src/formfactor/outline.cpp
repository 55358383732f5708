#include "formfactor/outline.h"

#include <algorithm>
#include <cmath>

#include "formfactor/point_polygon.h"

namespace radiosa {

Outline cut_outline(const Outline& in, const Vec3& f, const Vec3& x, const std::array<Circle, 2>& rims) {
    Outline kept;
    for (int k = 0; k < in.n; ++k) {
        const OutlinePiece& q = in.p[static_cast<std::size_t>(k)];
        if (q.rim < 0) {
            const double da = glm::dot(f, q.a - x), db = glm::dot(f, q.b - x);
            if (da >= 0.0 && db >= 0.0) {
                kept.add(q);
            } else if (da >= 0.0 || db >= 0.0) {
                const Vec3 m = q.a + (q.b - q.a) * (da / (da - db));
                kept.segment(da >= 0.0 ? q.a : m, da >= 0.0 ? m : q.b);
            }
            continue;
        }
        // Along the rim, f . (y - x) = C + P cos u + Q sin u: zero at psi +- delta.
        const Circle& c = rims[static_cast<std::size_t>(q.rim)];
        const double C = glm::dot(f, c.c - x), P = c.rho * glm::dot(f, c.e1), Q = c.rho * glm::dot(f, c.e2);
        const double R = std::hypot(P, Q);
        std::array<double, 6> at{};  // the arc's parameter (0 at `from`, 1 at `to`) of its cuts
        int na = 0;
        const double span = q.to - q.from;
        if (R > std::abs(C) && span != 0.0) {
            const double psi = std::atan2(Q, P), delta = std::acos(-C / R);
            for (const double root : {psi - delta, psi + delta})
                for (int turn = -2; turn <= 2; ++turn) {
                    const double u = (root + 2.0 * kPi * turn - q.from) / span;
                    if (u > 0.0 && u < 1.0 && na < static_cast<int>(at.size()))
                        at[static_cast<std::size_t>(na++)] = u;
                }
        }
        for (int s = 1; s < na; ++s)  // at most six: insertion
            for (int k2 = s;
                 k2 > 0 && at[static_cast<std::size_t>(k2)] < at[static_cast<std::size_t>(k2 - 1)]; --k2)
                std::swap(at[static_cast<std::size_t>(k2)], at[static_cast<std::size_t>(k2 - 1)]);
        double u0 = 0.0;
        for (int s = 0; s <= na; ++s) {
            const double u1 = s < na ? at[static_cast<std::size_t>(s)] : 1.0;
            const double mid = q.from + 0.5 * (u0 + u1) * span;
            if (u1 > u0 && C + P * std::cos(mid) + Q * std::sin(mid) >= 0.0)
                kept.arc(rims, q.rim, q.from + u0 * span, s < na ? q.from + u1 * span : q.to);
            u0 = u1;
        }
    }
    Outline out;
    for (int k = 0; k < kept.n; ++k) {
        const OutlinePiece& q = kept.p[static_cast<std::size_t>(k)];
        out.add(q);
        const Vec3& next = kept.p[static_cast<std::size_t>((k + 1) % kept.n)].a;
        if (q.b != next) out.segment(q.b, next);
    }
    return out;
}

ContourValue integrate_outline(const Outline& o, const Vec3& x, const Vec3& n,
                               const std::array<Circle, 2>& rims) {
    ContourValue out;
    constexpr double kArcTol = 1e-14;
    for (int k = 0; k < o.n; ++k) {
        const OutlinePiece& q = o.p[static_cast<std::size_t>(k)];
        if (q.rim < 0) {
            out.value += segment_term(x, n, q.a, q.b);
            continue;
        }
        if (q.from == q.to) continue;
        const Circle& c = rims[static_cast<std::size_t>(q.rim)];
        double lo = std::min(q.from, q.to), hi = std::max(q.from, q.to);
        const double turns = std::floor((lo + kPi) / (2.0 * kPi));  // lo into [-pi, pi)
        lo -= 2.0 * kPi * turns;
        hi -= 2.0 * kPi * turns;
        const ContourValue v = circle_arc_integral(c, x, n, c.nearest_angle(x), lo, hi, kArcTol);
        out.value += q.to > q.from ? v.value : -v.value;
        out.error += v.error;
    }
    return out;
}

ShadowValue outline_inside_cone(Outline o, const PolygonCone& cone, const Vec3& x, const Vec3& n,
                                const std::array<Circle, 2>& rims) {
    for (int k = 0; k < cone.count && o.n > 0; ++k)
        o = cut_outline(o, cone.f[static_cast<std::size_t>(k)], x, rims);
    if (o.n == 0) return {};
    const ContourValue c = integrate_outline(o, x, n, rims);
    return {std::abs(c.value) / (2.0 * kPi), c.error / (2.0 * kPi)};
}

}  // namespace radiosa
