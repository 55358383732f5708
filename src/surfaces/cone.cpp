#include "surfaces/cone.h"

#include <algorithm>
#include <cmath>

#include "surfaces/registry.h"

namespace radiosa {

FrustumSurface::FrustumSurface(const Vec3& base, const Vec3& axis, double radius, double top_radius,
                               const AngleRange& angles, bool inward)
    : m_base(base),
      m_frame(azimuth_frame(glm::normalize(axis))),
      m_length(glm::length(axis)),
      m_r0(radius),
      m_r1(top_radius),
      m_angles(angles) {
    // dP/ds x dP/dt = span r(t) (L radial - (r1 - r0) axis_hat): outward.
    m_orientation = inward ? -1.0 : 1.0;
}

Vec3 FrustumSurface::point(double s, double t) const {
    return m_base + (t * m_length) * m_frame.axis + r(t) * m_frame.radial(m_angles.at(s));
}

void FrustumSurface::partials(double s, double t, Vec3* dPds, Vec3* dPdt) const {
    const double phi = m_angles.at(s);
    *dPds = (r(t) * m_angles.span) * m_frame.tangent(phi);
    *dPdt = m_length * m_frame.axis + (m_r1 - m_r0) * m_frame.radial(phi);
}

std::optional<SurfaceHit> FrustumSurface::intersect(const Ray& ray, double t_min, double t_max,
                                                    HitSide side) const {
    // In the frame (e1, e2, axis) from the base: x^2 + y^2 = (r0 + k z)^2, k = (r1 - r0) / L.
    const Vec3 q = ray.origin - m_base;
    const Vec3 o = m_frame.local(q), d = m_frame.local(ray.dir);
    const double ox = o.x, oy = o.y, oz = o.z, dx = d.x, dy = d.y, dz = d.z;
    const double k = (m_r1 - m_r0) / m_length;
    const double rho0 = m_r0 + k * oz, h = std::hypot(ox, oy);
    const double A = dx * dx + dy * dy - k * k * dz * dz;
    const double B = ox * dx + oy * dy - k * dz * rho0;
    const double C = (h - rho0) * (h + rho0);  // keeps precision for origins on the surface
    double roots[2];
    int n = 0;
    if (A == 0.0) {
        if (B == 0.0) return std::nullopt;
        roots[n++] = -C / (2.0 * B);
    } else {
        const double disc = B * B - A * C;
        if (disc < 0.0) return std::nullopt;
        const double qq = -(B + std::copysign(std::sqrt(disc), B));
        roots[n++] = qq / A;
        roots[n++] = qq != 0.0 ? C / qq : qq / A;
        if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
    }
    constexpr double kEdge = 1e-12;
    for (int i = 0; i < n; ++i) {
        const double dist = roots[i];
        if (!(dist > t_min && dist < t_max)) continue;
        const double z = oz + dist * dz;
        if (z < -kEdge * m_length || z > m_length * (1.0 + kEdge)) continue;
        const double x = ox + dist * dx, y = oy + dist * dy;
        const auto s = m_angles.param(std::atan2(y, x));
        if (!s) continue;
        const double phi = std::atan2(y, x);
        const Vec3 out = m_length * m_frame.radial(phi) - (m_r1 - m_r0) * m_frame.axis;
        const bool front = m_orientation * glm::dot(out, ray.dir) < 0.0;
        if (side == HitSide::FrontOnly && !front) continue;
        return SurfaceHit{dist, *s, std::clamp(z / m_length, 0.0, 1.0), front};
    }
    return std::nullopt;
}

double FrustumSurface::area(double s0, double s1, double t0, double t1) const {
    const double slant = std::hypot(m_length, m_r1 - m_r0);
    return m_angles.span * (s1 - s0) * slant * (t1 - t0) * 0.5 * (r(t0) + r(t1));
}

BoundingSphere FrustumSurface::bound(double s0, double s1, double t0, double t1) const {
    // The patch is the convex hull of its two rims' arcs (its generators are straight).
    const double phi0 = m_angles.at(s0), phi1 = m_angles.at(s1);
    return enclosing(arc_ball(m_frame, m_base + (t0 * m_length) * m_frame.axis, r(t0), phi0, phi1),
                     arc_ball(m_frame, m_base + (t1 * m_length) * m_frame.axis, r(t1), phi0, phi1));
}

std::pair<double, double> FrustumSurface::linear_range(const Vec3& a, double s0, double s1, double t0,
                                                       double t1) const {
    const auto [gmin, gmax] = radial_range(m_frame, a, m_angles.at(s0), m_angles.at(s1));
    double lo = 0.0, hi = 0.0;
    for (const double t : {t0, t1}) {
        const double c = glm::dot(a, m_base + (t * m_length) * m_frame.axis);
        const double l = c + r(t) * gmin, u = c + r(t) * gmax;
        lo = t == t0 ? l : std::min(lo, l);
        hi = t == t0 ? u : std::max(hi, u);
    }
    return {lo, hi};
}

bool FrustumSurface::patch_contour(double s0, double s1, double t0, double t1,
                                   std::vector<ContourPiece>* out) const {
    // (tangent, axis, radial) is right-handed: about the outward normal (which a cone tilts
    // toward its narrow end) the boundary runs along the lower rim in +phi, up the generator at
    // phi1, back along the upper rim, down at phi0. A rim of radius 0 (the apex) is left out.
    const double p0 = m_angles.at(s0), p1 = m_angles.at(s1);
    const bool ring = m_angles.full() && s0 == 0.0 && s1 == 1.0;
    auto arc = [&](double t, double from, double to) {
        ContourPiece c;
        c.arc = true;
        c.center = m_base + (t * m_length) * m_frame.axis;
        c.e1 = m_frame.e1;
        c.e2 = m_frame.e2;
        c.radius = r(t);
        c.from = from;
        c.to = to;
        return c;
    };
    auto generator = [&](double s, double from, double to) {
        ContourPiece c;
        c.a = point(s, from);
        c.b = point(s, to);
        return c;
    };
    out->clear();
    if (r(t0) > 0.0) out->push_back(arc(t0, p0, p1));
    if (!ring) out->push_back(generator(s1, t0, t1));
    if (r(t1) > 0.0) out->push_back(arc(t1, p1, p0));
    if (!ring) out->push_back(generator(s0, t1, t0));
    if (m_orientation < 0.0) {
        std::reverse(out->begin(), out->end());
        for (ContourPiece& c : *out) {
            std::swap(c.a, c.b);
            std::swap(c.from, c.to);
        }
    }
    return true;
}

std::optional<ConvexSolid> FrustumSurface::convex_solid() const {
    return ConvexSolid{true, m_base, m_frame.axis, m_r0, (m_r1 - m_r0) / m_length};
}

double FrustumSurface::max_distance_from_line(const Vec3& p, const Vec3& u, double s0, double s1, double t0,
                                              double t1) const {
    if (!(m_frame.along_axis(u) && m_frame.on_axis(m_base, p, m_r0)))
        return Surface::max_distance_from_line(p, u, s0, s1, t0, t1);
    return std::max(r(t0), r(t1));
}

double FrustumSurface::max_distance_from_point(const Vec3& p, double s0, double s1, double t0,
                                               double t1) const {
    if (!m_frame.on_axis(m_base, p, std::max(m_r0, m_r1)))
        return Surface::max_distance_from_point(p, s0, s1, t0, t1);
    const double h = glm::dot(p - m_base, m_frame.axis);
    // The squared distance (t L - h)^2 + r(t)^2 is convex in t.
    return std::max(std::hypot(t0 * m_length - h, r(t0)), std::hypot(t1 * m_length - h, r(t1)));
}

bool FrustumSurface::faces_ball(double s0, double s1, double, double, const BoundingSphere& b,
                                bool back) const {
    if ((m_orientation < 0.0) != back) return false;
    // The tangent plane along the generator at azimuth phi holds the whole generator; its outward
    // normal is h radial(phi) - (r1 - r0) axis, h the height. With d = c - base, the ball lies in
    // front of every such plane of the patch when, for every azimuth,
    //   h (d . radial(phi)) - (r1 - r0) (d . axis) - r0 h > r_b |(h, r1 - r0)|
    // (for a cylinder: d . radial(phi) - r_b > R, outside the tube).
    const Vec3 d = b.center - m_base;
    const double lo = radial_range(m_frame, d, m_angles.at(s0), m_angles.at(s1)).first;
    const double h = m_length, dr = m_r1 - m_r0;
    const double margin = 1e-12 * std::max({m_r0, m_r1, h}) * h;
    return h * lo - dr * glm::dot(d, m_frame.axis) - m_r0 * h > b.radius * std::hypot(h, dr) + margin;
}

void FrustumSurface::write_key(ByteWriter& w) const {
    for (int k = 0; k < 3; ++k) w.f64(m_base[k]);
    for (int k = 0; k < 3; ++k) w.f64(m_length * m_frame.axis[k]);
    w.f64(m_r0);
    w.f64(m_r1);
    w.f64(m_angles.phi0);
    w.f64(m_angles.span);
    w.u8(m_orientation < 0.0 ? 1 : 0);
}

// base: the centre of the base rim; axis: from it to the centre of the top rim (its length is
// the height); radius > 0 at the base; facing: outward | inward; angles_deg: an azimuth range;
// for a cone, top_radius >= 0 at the top (0: up to its apex).
std::shared_ptr<const Surface> read_frustum(YamlMap& m, bool cone) {
    const Vec3 base = m.vec3("base");
    double length = 0.0;
    const Vec3 axis = read_direction(m, "axis", &length);
    const double radius = read_length(m, "radius");
    const double top_radius = cone ? read_length(m, "top_radius", true) : radius;
    const bool inward = read_facing_inward(m);
    return std::make_shared<FrustumSurface>(base, length * axis, radius, top_radius, read_angles_deg(m),
                                            inward);
}

namespace {

std::shared_ptr<const Surface> read_cone(YamlMap& m, const std::string&) { return read_frustum(m, true); }

}  // namespace

extern const SurfaceType kConeType;
const SurfaceType kConeType = {
    .name = "cone",
    .key_id = 4,
    .keys = "base, axis, radius, top_radius, facing, angles_deg",
    .read = read_cone,
    .example = {{"base", "[0, 0, 0]"},
                {"axis", "[0, 0, 1]"},
                {"radius", "1"},
                {"top_radius", "0.5"},
                {"facing", "outward"},
                {"angles_deg", "[0, 360]"}},
    .variants = {{"base", "[0.5, 0, 0]"},
                 {"base", "[0, 0, 0.5]"},
                 {"axis", "[0, 0, 2]"},
                 {"axis", "[0, 1, 1]"},
                 {"radius", "1.5"},
                 {"top_radius", "0"},
                 {"facing", "inward"},
                 {"angles_deg", "[0, 90]"}},
};

}  // namespace radiosa
