#include "surfaces/disk.h"

#include <algorithm>
#include <cmath>

#include "surfaces/registry.h"

namespace radiosa {

DiskSurface::DiskSurface(const Vec3& center, const Vec3& unit_normal, double radius, double inner_radius,
                         const AngleRange& angles)
    : m_center(center),
      m_frame(azimuth_frame(unit_normal)),
      m_radius(radius),
      m_inner(inner_radius),
      m_angles(angles) {
    // dP/ds x dP/dt = -rho span (R - r0) normal: the front is the normal's side.
    m_orientation = -1.0;
}

Vec3 DiskSurface::point(double s, double t) const {
    return m_center + rho(t) * m_frame.radial(m_angles.at(s));
}

void DiskSurface::partials(double s, double t, Vec3* dPds, Vec3* dPdt) const {
    const double phi = m_angles.at(s);
    *dPds = (rho(t) * m_angles.span) * m_frame.tangent(phi);
    *dPdt = (m_radius - m_inner) * m_frame.radial(phi);
}

std::optional<SurfaceHit> DiskSurface::intersect(const Ray& ray, double t_min, double t_max,
                                                 HitSide side) const {
    const Vec3& n = m_frame.axis;
    const double denom = glm::dot(n, ray.dir);
    if (denom == 0.0) return std::nullopt;  // parallel: a grazing ray sees no area
    const bool front = denom < 0.0;
    if (side == HitSide::FrontOnly && !front) return std::nullopt;
    const double dist = glm::dot(n, m_center - ray.origin) / denom;
    if (!(dist > t_min && dist < t_max)) return std::nullopt;
    const Vec3 q = ray.at(dist) - m_center;
    const double x = glm::dot(q, m_frame.e1), y = glm::dot(q, m_frame.e2);
    const double r = std::hypot(x, y);
    constexpr double kEdge = 1e-12;
    if (r > m_radius * (1.0 + kEdge) || r < m_inner * (1.0 - kEdge)) return std::nullopt;
    const auto s = m_angles.param(std::atan2(y, x));
    if (!s) return std::nullopt;
    const double t = std::clamp((r - m_inner) / (m_radius - m_inner), 0.0, 1.0);
    return SurfaceHit{dist, *s, t, front};
}

double DiskSurface::area(double s0, double s1, double t0, double t1) const {
    const double r0 = rho(t0), r1 = rho(t1);
    return 0.5 * m_angles.span * (s1 - s0) * (r1 - r0) * (r1 + r0);
}

BoundingSphere DiskSurface::bound(double s0, double s1, double t0, double t1) const {
    // The annular sector is the convex hull of its inner and outer arcs.
    const double phi0 = m_angles.at(s0), phi1 = m_angles.at(s1);
    return enclosing(arc_ball(m_frame, m_center, rho(t0), phi0, phi1),
                     arc_ball(m_frame, m_center, rho(t1), phi0, phi1));
}

std::pair<double, double> DiskSurface::linear_range(const Vec3& a, double s0, double s1, double t0,
                                                    double t1) const {
    const auto [gmin, gmax] = radial_range(m_frame, a, m_angles.at(s0), m_angles.at(s1));
    const double r0 = rho(t0), r1 = rho(t1), c = glm::dot(a, m_center);
    return {c + std::min(r0 * gmin, r1 * gmin), c + std::max(r0 * gmax, r1 * gmax)};
}

bool DiskSurface::patch_contour(double s0, double s1, double t0, double t1,
                                std::vector<ContourPiece>* out) const {
    // Counter-clockwise about the normal: the outer arc, in along phi1, the inner arc back, out
    // along phi0. Whole rings have no radial edges (they would cancel).
    const double p0 = m_angles.at(s0), p1 = m_angles.at(s1), r0 = rho(t0), r1 = rho(t1);
    const bool ring = m_angles.full() && s0 == 0.0 && s1 == 1.0;
    auto arc = [&](double r, double from, double to) {
        ContourPiece c;
        c.arc = true;
        c.center = m_center;
        c.e1 = m_frame.e1;
        c.e2 = m_frame.e2;
        c.radius = r;
        c.from = from;
        c.to = to;
        return c;
    };
    auto segment = [&](double phi, double from, double to) {
        ContourPiece c;
        c.a = m_center + from * m_frame.radial(phi);
        c.b = m_center + to * m_frame.radial(phi);
        return c;
    };
    out->clear();
    out->push_back(arc(r1, p0, p1));
    if (!ring) out->push_back(segment(p1, r1, r0));
    if (r0 > 0.0) out->push_back(arc(r0, p1, p0));
    if (!ring) out->push_back(segment(p0, r0, r1));
    return true;
}

double DiskSurface::max_distance_from_line(const Vec3& p, const Vec3& u, double s0, double s1, double t0,
                                           double t1) const {
    if (!(m_frame.along_axis(u) && m_frame.on_axis(m_center, p, m_radius)))
        return Surface::max_distance_from_line(p, u, s0, s1, t0, t1);
    return rho(t1);
}

double DiskSurface::max_distance_from_point(const Vec3& p, double s0, double s1, double t0, double t1) const {
    if (!m_frame.on_axis(m_center, p, m_radius)) return Surface::max_distance_from_point(p, s0, s1, t0, t1);
    return std::hypot(glm::dot(p - m_center, m_frame.axis), rho(t1));
}

bool DiskSurface::faces_ball(double, double, double, double, const BoundingSphere& b, bool back) const {
    const double d = glm::dot(m_frame.axis, b.center - m_center);
    return (back ? -d : d) - b.radius >= -1e-12 * m_radius;
}

void DiskSurface::write_key(ByteWriter& w) const {
    for (int k = 0; k < 3; ++k) w.f64(m_center[k]);
    for (int k = 0; k < 3; ++k) w.f64(m_frame.axis[k]);
    w.f64(m_radius);
    w.f64(m_inner);
    w.f64(m_angles.phi0);
    w.f64(m_angles.span);
}

namespace {

// center, normal (front side), radius > 0, inner_radius in [0, radius) (default 0: a full
// disk), angles_deg (default [0, 360]: a sector otherwise).
std::shared_ptr<const Surface> read_disk(YamlMap& m, const std::string& name) {
    const Vec3 center = m.vec3("center");
    const Vec3 normal = read_direction(m, "normal");
    const double radius = read_length(m, "radius");
    double inner = 0.0;
    if (m.has("inner_radius")) {
        inner = read_length(m, "inner_radius", true);
        if (!(inner < radius))
            throw Error(m.key_loc("inner_radius"), "disk '" + name +
                                                       "': inner_radius must be smaller than radius (" +
                                                       m.required("radius").Scalar() + ")");
    }
    return std::make_shared<DiskSurface>(center, normal, radius, inner, read_angles_deg(m));
}

}  // namespace

extern const SurfaceType kDiskType;
const SurfaceType kDiskType = {
    .name = "disk",
    .key_id = 2,
    .keys = "center, normal, radius, inner_radius, angles_deg",
    .read = read_disk,
    .example = {{"center", "[0, 0, 0]"},
                {"normal", "[0, 0, 1]"},
                {"radius", "1"},
                {"inner_radius", "0.2"},
                {"angles_deg", "[0, 360]"}},
    .variants = {{"center", "[0.5, 0, 0]"},
                 {"center", "[0, 0, 0.5]"},
                 {"normal", "[0, 1, 1]"},
                 {"normal", "[0, 0, -1]"},
                 {"radius", "1.5"},
                 {"inner_radius", "0.3"},
                 {"angles_deg", "[10, 360]"},
                 {"angles_deg", "[0, 180]"}},
};

}  // namespace radiosa
