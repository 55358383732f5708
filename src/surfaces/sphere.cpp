#include "surfaces/sphere.h"

#include <algorithm>
#include <cmath>

#include "surfaces/registry.h"
#include "surfaces/revolution.h"

namespace radiosa {

SphereSurface::SphereSurface(const Vec3& center, double radius, bool inward)
    : m_center(center), m_radius(radius) {
    m_orientation = inward ? -1.0 : 1.0;
}

Vec3 SphereSurface::point(double s, double t) const {
    const double phi = 2.0 * kPi * s, theta = kPi * (1.0 - t);
    const double st = std::sin(theta);
    return m_center + m_radius * Vec3(st * std::cos(phi), st * std::sin(phi), std::cos(theta));
}

void SphereSurface::partials(double s, double t, Vec3* dPds, Vec3* dPdt) const {
    // dP/ds x dP/dt = 2 pi^2 R^2 sin(theta) r_hat: outward, vanishing at the poles.
    const double phi = 2.0 * kPi * s, theta = kPi * (1.0 - t);
    const double sp = std::sin(phi), cp = std::cos(phi), st = std::sin(theta), ct = std::cos(theta);
    *dPds = (2.0 * kPi * m_radius) * Vec3(-st * sp, st * cp, 0.0);
    *dPdt = (-kPi * m_radius) * Vec3(ct * cp, ct * sp, -st);
}

std::optional<SurfaceHit> SphereSurface::intersect(const Ray& ray, double t_min, double t_max,
                                                   HitSide side) const {
    // |o + t d - c|^2 = R^2, solved in the cancellation-free form.
    const Vec3 oc = ray.origin - m_center;
    const double a = glm::dot(ray.dir, ray.dir);
    const double b = glm::dot(oc, ray.dir);
    // c = |oc|^2 - R^2 computed as (|oc| - R)(|oc| + R) keeps precision near the surface.
    const double loc = glm::length(oc);
    const double c = (loc - m_radius) * (loc + m_radius);
    // Discriminant via the perpendicular distance (Hearn & Baker / Ray Tracing Gems ch. 7).
    const Vec3 perp = oc - (b / a) * ray.dir;
    const double disc = a * (m_radius * m_radius - glm::dot(perp, perp));
    if (disc < 0.0) return std::nullopt;
    const double q = -(b + std::copysign(std::sqrt(disc), b));
    double roots[2] = {c / q, q / a};
    if (q == 0.0) roots[0] = roots[1] = 0.0;
    if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
    for (double dist : roots) {
        if (!(dist > t_min && dist < t_max)) continue;
        const Vec3 x = ray.at(dist);
        const Vec3 out = x - m_center;
        const bool front = m_orientation * glm::dot(out, ray.dir) < 0.0;
        if (side == HitSide::FrontOnly && !front) continue;
        const Vec3 u = out / m_radius;
        double phi = std::atan2(u.y, u.x);
        if (phi < 0.0) phi += 2.0 * kPi;
        const double theta = std::acos(std::clamp(u.z, -1.0, 1.0));
        const double s = std::clamp(phi / (2.0 * kPi), 0.0, 1.0);
        const double t = std::clamp(1.0 - theta / kPi, 0.0, 1.0);
        return SurfaceHit{dist, s, t, front};
    }
    return std::nullopt;
}

double SphereSurface::area(double s0, double s1, double t0, double t1) const {
    // R^2 (phi1 - phi0)(cos theta(t1) - cos theta(t0)), theta = pi (1 - t).
    const double dphi = 2.0 * kPi * (s1 - s0);
    return m_radius * m_radius * dphi * (std::cos(kPi * (1.0 - t1)) - std::cos(kPi * (1.0 - t0)));
}

std::pair<double, double> SphereSurface::linear_range(const Vec3& a, double s0, double s1, double t0,
                                                      double t1) const {
    // a . (P - c) / R = sin(theta) A(phi) + a_z cos(theta), A(phi) = a_x cos(phi) + a_y sin(phi),
    // with sin(theta) >= 0: for each theta the extremes take A's extremes over the azimuths.
    const double rho = std::hypot(a.x, a.y);
    const auto [amin, amax] = cosine_range(rho, std::atan2(a.y, a.x), 2.0 * kPi * s0, 2.0 * kPi * s1);
    const double th0 = kPi * (1.0 - t1), th1 = kPi * (1.0 - t0);
    // g(theta) = A sin(theta) + a_z cos(theta) = |(A, a_z)| cos(theta - atan2(A, a_z)).
    const double lo = cosine_range(std::hypot(amin, a.z), std::atan2(amin, a.z), th0, th1).first;
    const double hi = cosine_range(std::hypot(amax, a.z), std::atan2(amax, a.z), th0, th1).second;
    const double c = glm::dot(a, m_center);
    return {c + m_radius * lo, c + m_radius * hi};
}

BoundingSphere SphereSurface::bound(double, double, double, double) const {
    // Conservative: the whole sphere. Only used to cull pairs and occluders, so a loose
    // bound costs a little time, never accuracy.
    return {m_center, m_radius};
}

void SphereSurface::write_key(ByteWriter& w) const {
    for (int k = 0; k < 3; ++k) w.f64(m_center[k]);
    w.f64(m_radius);
    w.u8(m_orientation < 0.0 ? 1 : 0);
}

namespace {

// center: [x, y, z]; radius > 0; facing: outward (default) | inward (the concave side is lit
// and visible: a dome or a room). Parametrised by azimuth 2 pi s around +z from +x and polar
// angle pi (1 - t) from +z (t = 0 the south pole, t = 1 the north pole).
std::shared_ptr<const Surface> read_sphere(YamlMap& m, const std::string&) {
    const Vec3 center = m.vec3("center");
    const double radius = read_length(m, "radius");
    const bool inward = read_facing_inward(m);
    return std::make_shared<SphereSurface>(center, radius, inward);
}

}  // namespace

extern const SurfaceType kSphereType;
const SurfaceType kSphereType = {
    .name = "sphere",
    .key_id = 1,
    .keys = "center, radius, facing",
    .read = read_sphere,
    .example = {{"center", "[0, 0, 0]"}, {"radius", "1"}, {"facing", "outward"}},
    .variants = {{"center", "[0.5, 0, 0]"},
                 {"center", "[0, 0.5, 0]"},
                 {"center", "[0, 0, 0.5]"},
                 {"radius", "1.5"},
                 {"facing", "inward"}},
};

}  // namespace radiosa
