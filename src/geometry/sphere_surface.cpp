#include <algorithm>
#include <cmath>

#include "geometry/surface.h"
#include "scene/scene.h"

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

BoundingSphere SphereSurface::bound(double, double, double, double) const {
    // Conservative: the whole sphere. Only used to cull pairs and occluders, so a loose
    // bound costs a little time, never accuracy.
    return {m_center, m_radius};
}

std::unique_ptr<Surface> make_surface(const SurfaceDesc& d) {
    switch (d.type) {
        case SurfaceType::Quad:
            return std::make_unique<QuadSurface>(d.corners[0], d.corners[1], d.corners[2], d.corners[3]);
        case SurfaceType::Sphere:
            return std::make_unique<SphereSurface>(d.center, d.radius, d.inward);
    }
    return nullptr;
}

}  // namespace radiosa
