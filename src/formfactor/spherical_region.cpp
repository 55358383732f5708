#include "formfactor/spherical_region.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "formfactor/circle_arc.h"

namespace radiosa {

namespace {

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

}  // namespace

void add_patch_cuts(SphericalRegion* r, const Surface& s, double s0, double s1, double t0, double t1) {
    const auto [phi0, theta_max] = s.sphere_angles(s0, t0);
    const auto [phi1, theta_min] = s.sphere_angles(s1, t1);
    add_patch_cuts(r, phi0, phi1, theta_min, theta_max);
}

void add_patch_cuts(SphericalRegion* r, double phi0, double phi1, double theta_min, double theta_max) {
    const Vec3& c = r->center;
    const double R = r->radius;
    const Vec3 x = r->axes[0], y = r->axes[1], z = r->axes[2];
    const double cz = glm::dot(z, c);
    r->cuts.push_back({z, cz + R * std::cos(theta_max)});
    r->cuts.push_back({-z, -(cz + R * std::cos(theta_min))});
    const Vec3 m0 = -std::sin(phi0) * x + std::cos(phi0) * y, m1 = std::sin(phi1) * x - std::cos(phi1) * y;
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
        const double nearest = k.nearest_angle(x);
        const Vec3 base = k.at(nearest) - x;  // from x to the circle's point nearest it
        const ContourValue v = circle_arc_integral(k, x, n, nearest, arc.a, arc.b, tol);
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
