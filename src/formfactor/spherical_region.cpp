#include "formfactor/spherical_region.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "util/gauss_kronrod.h"

namespace radiosa {

namespace {

// The circle where a cut's plane meets the sphere: centre, radius, an orthonormal basis of its
// plane, and the unit normal and offset of the cut.
struct Circle {
    Vec3 c, e1, e2, n;
    double rho, d;
    Vec3 at(double a) const { return c + rho * (std::cos(a) * e1 + std::sin(a) * e2); }
    Vec3 tangent(double a) const { return rho * (-std::sin(a) * e1 + std::cos(a) * e2); }
};

struct Arc {
    const Circle* circle;
    double a, b;   // angles, a < b
    double sense;  // +1: run from a to b, -1: from b to a
};

// The arcs bounding the region, each oriented counter-clockwise about the front normal.
// Returns false when the cuts leave nothing; `circles` owns what the arcs point to.
bool boundary(const SphericalRegion& r, std::vector<Circle>* circles, std::vector<Arc>* arcs) {
    const double R = r.radius;
    circles->clear();
    arcs->clear();
    for (const HalfSpace& h : r.cuts) {
        const double len = glm::length(h.normal);
        if (!(len > 0.0)) {
            if (h.offset > 0.0) return false;
            continue;
        }
        Circle k;
        k.n = h.normal / len;
        k.d = h.offset / len;
        const double height = k.d - glm::dot(k.n, r.center);
        if (height >= R * (1.0 - 1e-13)) return false;  // at most a point is left
        if (height <= -R * (1.0 - 1e-13)) continue;     // at most a point is cut off
        // A cut in the plane of an earlier one repeats it (same side) or leaves only that plane.
        bool repeat = false;
        for (const Circle& o : *circles) {
            const double same = glm::length(o.n - k.n), opposite = glm::length(o.n + k.n);
            if (same < 1e-14 && std::abs(o.d - k.d) < 1e-14 * R) repeat = true;
            if (opposite < 1e-14 && std::abs(o.d + k.d) < 1e-14 * R) return false;
        }
        if (repeat) continue;
        k.c = r.center + height * k.n;
        k.rho = std::sqrt(std::max(0.0, R * R - height * height));
        const Vec3 helper = std::abs(k.n.x) < 0.6 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
        k.e1 = glm::normalize(glm::cross(helper, k.n));
        k.e2 = glm::cross(k.n, k.e1);
        circles->push_back(k);
    }
    auto inside = [&](const Vec3& y, std::size_t skip) {
        for (std::size_t m = 0; m < circles->size(); ++m)
            if (m != skip && glm::dot((*circles)[m].n, y) < (*circles)[m].d) return false;
        return true;
    };
    std::vector<double> cuts;
    for (std::size_t k = 0; k < circles->size(); ++k) {
        const Circle& ck = (*circles)[k];
        cuts.clear();
        for (std::size_t m = 0; m < circles->size(); ++m) {
            if (m == k) continue;
            const Circle& cm = (*circles)[m];
            const double A = ck.rho * glm::dot(cm.n, ck.e1), B = ck.rho * glm::dot(cm.n, ck.e2),
                         C = cm.d - glm::dot(cm.n, ck.c);
            const double M = std::hypot(A, B);
            if (!(M > 0.0) || std::abs(C) >= M) continue;
            const double mid = std::atan2(B, A), half = std::acos(C / M);
            for (double a : {mid - half, mid + half}) {
                a = std::fmod(a, 2 * kPi);
                cuts.push_back(a < 0.0 ? a + 2 * kPi : a);
            }
        }
        // The sense that keeps the region (n . y >= d) on the left of the front normal.
        const Vec3 front = r.front * (ck.at(0.0) - r.center);
        const double sense = glm::dot(glm::cross(front, ck.tangent(0.0)), ck.n) >= 0.0 ? 1.0 : -1.0;
        if (cuts.empty()) {
            if (inside(ck.at(0.0), k)) arcs->push_back({&ck, 0.0, 2 * kPi, sense});
            continue;
        }
        std::sort(cuts.begin(), cuts.end());
        for (std::size_t q = 0; q < cuts.size(); ++q) {
            const double a = cuts[q], b = q + 1 < cuts.size() ? cuts[q + 1] : cuts[0] + 2 * kPi;
            if (b - a <= 0.0) continue;
            if (inside(ck.at(0.5 * (a + b)), k)) arcs->push_back({&ck, a, b, sense});
        }
    }
    return true;
}

// The contour integral of n . (r x dr) / |r|^2 along the circle from angle a to b, r = y - x, by
// adaptive Gauss-Kronrod. Near x the integrand peaks over a width of x's distance from the
// circle, which no node of a wide interval may see: the arc is cut into pieces that grow
// geometrically away from the circle's point y* nearest x, each no longer than its distance
// from x. And y - x is taken as (y* - x) + (y - y*), the second term by half-angle formulas:
// free of the cancellation that would cost digits at small distances.
ContourValue arc_by_quadrature(const Circle& k, const Vec3& n, const Vec3& base, double nearest, double a,
                               double b, double tol) {
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
std::optional<ContourValue> arc_closed_form(const Circle& k, const Vec3& x, const Vec3& n, const Vec3& base,
                                            double a, double b) {
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

}  // namespace

void add_patch_cuts(SphericalRegion* r, double s0, double s1, double t0, double t1) {
    const Vec3& c = r->center;
    const double R = r->radius;
    const double phi0 = 2 * kPi * s0, phi1 = 2 * kPi * s1;
    const double theta_min = kPi * (1.0 - t1), theta_max = kPi * (1.0 - t0);
    const Vec3 z(0, 0, 1);
    r->cuts.push_back({z, c.z + R * std::cos(theta_max)});
    r->cuts.push_back({-z, -(c.z + R * std::cos(theta_min))});
    const Vec3 m0(-std::sin(phi0), std::cos(phi0), 0.0), m1(std::sin(phi1), -std::cos(phi1), 0.0);
    r->cuts.push_back({m0, glm::dot(m0, c)});
    r->cuts.push_back({m1, glm::dot(m1, c)});
}

ContourValue point_to_spherical_region(const Vec3& x, const Vec3& n, const SphericalRegion& region,
                                       double tol_f) {
    ContourValue out;
    std::vector<Circle> circles;
    std::vector<Arc> arcs;
    circles.reserve(region.cuts.size());
    if (!boundary(region, &circles, &arcs)) return out;
    // No boundary: the region is empty unless no cut met the sphere (then it is all of it).
    if (circles.empty()) out.valid = false;
    if (arcs.empty()) return out;
    // Each arc's share of the tolerance, on the contour's scale (2 pi for a form factor of 1).
    const double tol = tol_f * 2 * kPi / static_cast<double>(arcs.size());
    const double R = region.radius, eps = std::numeric_limits<double>::epsilon();
    double sum = 0.0, err = 0.0;
    for (const Arc& arc : arcs) {
        const Circle& k = *arc.circle;
        const Vec3 in_plane = x - k.c - glm::dot(x - k.c, k.n) * k.n;
        const double nearest = std::atan2(glm::dot(in_plane, k.e2), glm::dot(in_plane, k.e1));
        const Vec3 base = k.at(nearest) - x;  // from x to the circle's point nearest it
        const std::optional<ContourValue> closed = arc_closed_form(k, x, n, base, arc.a, arc.b);
        const ContourValue v = closed ? *closed : arc_by_quadrature(k, n, base, nearest, arc.a, arc.b, tol);
        sum += arc.sense * v.value;
        // Each arc sees x through its own rounding of y* - x: the value moves by about that
        // rounding over x's distance from the circle, times the arc's share.
        err += v.error + 4 * eps * (glm::length(x - region.center) + R) /
                             std::max(glm::length(base), eps * R) * std::abs(v.value);
    }
    out.value = -sum / (2 * kPi);
    out.error = err / (2 * kPi);
    return out;
}

ContourValue spherical_region_area(const SphericalRegion& region, const Vec3& away, double tol) {
    // Seen from `away` on the sphere, the region's front must face inward: a copy only if it
    // does not already (the form factors' inner loop passes inward regions).
    if (region.front > 0.0) {
        SphericalRegion inward = region;
        inward.front = -1.0;
        return spherical_region_area(inward, away, tol);
    }
    const Vec3 n = glm::normalize(region.center - away);
    ContourValue f = point_to_spherical_region(away, n, region, tol);
    const double scale = 4 * kPi * region.radius * region.radius;
    f.value *= scale;
    f.error *= scale;
    return f;
}

}  // namespace radiosa
