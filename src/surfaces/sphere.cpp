#include "surfaces/sphere.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "surfaces/registry.h"
#include "surfaces/revolution.h"
#include "surfaces/sphere_hit.h"
#include "util/angles.h"

namespace radiosa {

SphereSurface::SphereSurface(const Vec3& center, double radius, bool inward, const AngleRange& angles,
                             double theta_top, double theta_bottom)
    : m_center(center), m_radius(radius), m_angles(angles), m_top(theta_top), m_bottom(theta_bottom) {
    m_orientation = inward ? -1.0 : 1.0;
}

SphereSurface::Trig SphereSurface::trig(double s, double t) const {
    const double phi = m_angles.at(s), th = theta(t);
    return {std::sin(phi), std::cos(phi), std::sin(th), std::cos(th)};
}

Vec3 SphereSurface::point_of(const Trig& a) const {
    return m_center + m_radius * Vec3(a.st * a.cp, a.st * a.sp, a.ct);
}

void SphereSurface::partials_of(const Trig& a, Vec3* dPds, Vec3* dPdt) const {
    // dP/ds x dP/dt = span (theta_bottom - theta_top) R^2 sin(theta) r_hat: outward, vanishing at
    // the poles.
    *dPds = (m_angles.span * m_radius) * Vec3(-a.st * a.sp, a.st * a.cp, 0.0);
    *dPdt = (-(m_bottom - m_top) * m_radius) * Vec3(a.ct * a.cp, a.ct * a.sp, -a.st);
}

Vec3 SphereSurface::point(double s, double t) const { return point_of(trig(s, t)); }

void SphereSurface::partials(double s, double t, Vec3* dPds, Vec3* dPdt) const {
    partials_of(trig(s, t), dPds, dPdt);
}

void SphereSurface::point_and_normal(double s, double t, Vec3* x, Vec3* n) const {
    const Trig a = trig(s, t);
    Vec3 ds, dt;
    partials_of(a, &ds, &dt);
    *x = point_of(a);
    *n = normal_of(ds, dt);
}

std::optional<SurfaceHit> SphereSurface::intersect(const Ray& ray, double t_min, double t_max,
                                                   HitSide side) const {
    double roots[2];
    if (!sphere_roots(ray, m_center, m_radius, roots)) return std::nullopt;
    for (double dist : roots) {
        if (!(dist > t_min && dist < t_max)) continue;
        const Vec3 x = ray.at(dist);
        const Vec3 out = x - m_center;
        const bool front = m_orientation * glm::dot(out, ray.dir) < 0.0;
        if (side == HitSide::FrontOnly && !front) continue;
        const Vec3 u = out / m_radius;
        if (auto h = hit_at_angles(dist, std::atan2(u.y, u.x), std::acos(std::clamp(u.z, -1.0, 1.0)), front))
            return h;
    }
    return std::nullopt;
}

std::optional<SurfaceHit> SphereSurface::hit_at_angles(double dist, double phi, double th, bool front) const {
    const auto s = m_angles.param(phi);
    if (!s) return std::nullopt;
    const double t = (m_bottom - th) / (m_bottom - m_top);
    constexpr double kEdge = 1e-12;
    if (t < -kEdge || t > 1.0 + kEdge) return std::nullopt;
    return SurfaceHit{dist, *s, std::clamp(t, 0.0, 1.0), front};
}

void SphereSurface::front_hits(std::size_t n, const Ray* const* rays, const double* dist, const double* limit,
                               std::optional<SurfaceHit>* out) const {
    // A whole sphere: intersect()'s hit is its first front root in range, at dist, whose
    // angles are found here for many rays at once.
    if (!whole_sphere()) return Surface::front_hits(n, rays, dist, limit, out);
    constexpr std::size_t kBatch = 64;
    double x[kBatch], y[kBatch], z[kBatch], phi[kBatch], th[kBatch];
    bool front[kBatch];
    for (std::size_t first = 0; first < n; first += kBatch) {
        const std::size_t m = std::min(kBatch, n - first);
        for (std::size_t i = 0; i < m; ++i) {
            const Ray& ray = *rays[first + i];
            const Vec3 o = ray.at(dist[first + i]) - m_center;
            front[i] = m_orientation * glm::dot(o, ray.dir) < 0.0;
            x[i] = o.x;  // the azimuth needs no division by the radius
            y[i] = o.y;
            z[i] = o.z / m_radius;
        }
        atan2_acos(m, y, x, z, phi, th);
        for (std::size_t i = 0; i < m; ++i)
            out[first + i] = front[i] ? hit_at_angles(dist[first + i], phi[i], th[i], true) : std::nullopt;
    }
}

bool SphereSurface::blocks(const Ray& ray, double t_min, double t_max) const {
    // A whole sphere: every point of it has parameters (the azimuth range is 2 pi, the polar
    // one [0, pi]), so a root in range is a hit, as intersect() would find.
    if (!whole_sphere()) return Surface::blocks(ray, t_min, t_max);
    double roots[2];
    if (!sphere_roots(ray, m_center, m_radius, roots)) return false;
    return (roots[0] > t_min && roots[0] < t_max) || (roots[1] > t_min && roots[1] < t_max);
}

std::optional<double> SphereSurface::front_distance(const Ray& ray, double t_min, double t_max) const {
    // A whole sphere: every point has parameters (as in blocks()), so intersect()'s first root
    // in range on the front side is its hit; no angles needed.
    if (!whole_sphere()) return Surface::front_distance(ray, t_min, t_max);
    const double d = sphere_front_distance(ray, m_center, m_radius, m_orientation, t_min, t_max);
    return d < std::numeric_limits<double>::infinity() ? std::optional<double>(d) : std::nullopt;
}

double SphereSurface::area(double s0, double s1, double t0, double t1) const {
    // R^2 (phi1 - phi0)(cos theta(t1) - cos theta(t0)).
    const double dphi = m_angles.span * (s1 - s0);
    return m_radius * m_radius * dphi * (std::cos(theta(t1)) - std::cos(theta(t0)));
}

std::pair<double, double> SphereSurface::linear_range(const Vec3& a, double s0, double s1, double t0,
                                                      double t1) const {
    // a . (P - c) / R = sin(theta) A(phi) + a_z cos(theta), A(phi) = a_x cos(phi) + a_y sin(phi),
    // with sin(theta) >= 0: for each theta the extremes take A's extremes over the azimuths.
    const double rho = std::hypot(a.x, a.y);
    const auto [amin, amax] = cosine_range(rho, std::atan2(a.y, a.x), m_angles.at(s0), m_angles.at(s1));
    const double th0 = theta(t1), th1 = theta(t0);
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
    if (!(whole_sphere() && m_angles.phi0 == 0.0)) {  // whole spheres keep the keys they always had
        w.u8(0x50);
        w.f64(m_angles.phi0);
        w.f64(m_angles.span);
        w.f64(m_top);
        w.f64(m_bottom);
    }
}

namespace {

// center: [x, y, z]; radius > 0; facing: outward (default) | inward (the concave side is lit
// and visible: a dome or a room); angles_deg: an azimuth range about +z from +x (default
// [0, 360]); polar_deg: [from, to] polar angles from +z, 0 <= from < to <= 180 (default [0, 180]).
// Parametrised by azimuth over the range and polar angle falling from `to` at t = 0 to `from` at
// t = 1 (whole spheres: t = 0 the south pole, t = 1 the north pole).
std::shared_ptr<const Surface> read_sphere(YamlMap& m, const std::string&) {
    const Vec3 center = m.vec3("center");
    const double radius = read_length(m, "radius");
    const bool inward = read_facing_inward(m);
    const AngleRange angles = read_angles_deg(m);
    double top = 0.0, bottom = kPi;
    if (const auto polar = m.optional("polar_deg")) {
        if (!polar->IsSequence() || polar->size() != 2)
            throw Error(loc_of(*polar, m.file()),
                        "polar_deg must be a list of 2 numbers [from, to] in degrees");
        const double p0 = yaml_number((*polar)[0], m.file(), "polar_deg[0]");
        const double p1 = yaml_number((*polar)[1], m.file(), "polar_deg[1]");
        if (!(p0 >= 0.0 && p0 < p1 && p1 <= 180.0))
            throw Error(loc_of(*polar, m.file()), "polar_deg [from, to] needs 0 <= from < to <= 180, got [" +
                                                      (*polar)[0].Scalar() + ", " + (*polar)[1].Scalar() +
                                                      "]");
        top = p0 == 0.0 ? 0.0 : deg_to_rad(p0);
        bottom = p1 == 180.0 ? kPi : deg_to_rad(p1);
    }
    return std::make_shared<SphereSurface>(center, radius, inward, angles, top, bottom);
}

}  // namespace

extern const SurfaceType kSphereType;
const SurfaceType kSphereType = {
    .name = "sphere",
    .key_id = 1,
    .keys = "center, radius, facing, angles_deg, polar_deg",
    .read = read_sphere,
    .example = {{"center", "[0, 0, 0]"},
                {"radius", "1"},
                {"facing", "outward"},
                {"angles_deg", "[0, 360]"},
                {"polar_deg", "[0, 180]"}},
    .variants = {{"center", "[0.5, 0, 0]"},
                 {"center", "[0, 0.5, 0]"},
                 {"center", "[0, 0, 0.5]"},
                 {"radius", "1.5"},
                 {"facing", "inward"},
                 {"angles_deg", "[0, 180]"},
                 {"angles_deg", "[30, 390]"},
                 {"polar_deg", "[0, 90]"},
                 {"polar_deg", "[10, 180]"}},
};

}  // namespace radiosa
