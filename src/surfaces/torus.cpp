#include "surfaces/torus.h"

#include <algorithm>
#include <cmath>

#include "surfaces/registry.h"
#include "util/polynomial.h"

namespace radiosa {

TorusSurface::TorusSurface(const Vec3& center, const Vec3& unit_axis, double major, double minor,
                           const AngleRange& angles, bool inward)
    : m_center(center), m_frame(azimuth_frame(unit_axis)), m_R(major), m_r(minor), m_angles(angles) {
    m_orientation = inward ? -1.0 : 1.0;
}

Vec3 TorusSurface::point(double s, double t) const {
    const double v = 2.0 * kPi * t;
    return m_center + (m_R + m_r * std::cos(v)) * m_frame.radial(m_angles.at(s)) +
           (m_r * std::sin(v)) * m_frame.axis;
}

void TorusSurface::partials(double s, double t, Vec3* dPds, Vec3* dPdt) const {
    const double u = m_angles.at(s), v = 2.0 * kPi * t;
    *dPds = (m_angles.span * (m_R + m_r * std::cos(v))) * m_frame.tangent(u);
    *dPdt = (2.0 * kPi * m_r) * (-std::sin(v) * m_frame.radial(u) + std::cos(v) * m_frame.axis);
}

std::optional<SurfaceHit> TorusSurface::intersect(const Ray& ray, double t_min, double t_max,
                                                  HitSide side) const {
    // In the frame (e1, e2, axis) about the centre, from the ray's point nearest the centre
    // (keeps the coefficients small): with p = o + x d, |d| = 1, o . d = 0,
    // (|p|^2 + R^2 - r^2)^2 = 4 R^2 (p_x^2 + p_y^2) is x^4 + (2k - 4R^2 a) x^2 - 8R^2 b x + k^2 - 4R^2 c.
    const double len = glm::length(ray.dir);
    const Vec3 d = ray.dir / len;
    const double shift = glm::dot(m_center - ray.origin, d);
    const Vec3 o = ray.origin + shift * d - m_center;
    const double reach = m_R + m_r;
    if (glm::dot(o, o) >= reach * reach) return std::nullopt;
    const Vec3 ol = m_frame.local(o), dl = m_frame.local(d);
    const double a = dl.x * dl.x + dl.y * dl.y, b = ol.x * dl.x + ol.y * dl.y, c = ol.x * ol.x + ol.y * ol.y;
    const double k = glm::dot(ol, ol) + (m_R - m_r) * (m_R + m_r), R2 = m_R * m_R;
    if (!(std::max(-reach, t_min * len - shift) < std::min(reach, t_max * len - shift))) return std::nullopt;
    // The roots over the whole chord through the torus's ball, then those in (t_min, t_max):
    // a root's last bits do not depend on the range asked for (a BVH and a loop over the
    // surfaces ask with different t_max and must find the same hit).
    const double coeffs[5] = {k * k - 4.0 * R2 * c, -8.0 * R2 * b, 2.0 * k - 4.0 * R2 * a, 0.0, 1.0};
    double roots[4];
    const int count = real_roots(coeffs, 5, -reach, reach, roots);
    for (int q = 0; q < count; ++q) {
        const double x = roots[q];
        const double dist = (x + shift) / len;
        if (!(dist > t_min && dist < t_max)) continue;
        const Vec3 p = ol + x * dl;
        const double rho = std::hypot(p.x, p.y), phi = std::atan2(p.y, p.x);
        const auto s = m_angles.param(phi);
        if (!s) continue;
        const Vec3 out = (rho - m_R) * m_frame.radial(phi) + p.z * m_frame.axis;
        const double margin = end_margin(ray, glm::normalize(out), reach);
        if (!(dist > t_min + margin && dist < t_max - margin)) continue;  // a segment's end, surface.h
        const bool front = m_orientation * glm::dot(out, ray.dir) < 0.0;
        if (side == HitSide::FrontOnly && !front) continue;
        double v = std::atan2(p.z, rho - m_R) / (2.0 * kPi);
        if (v < 0.0) v += 1.0;
        return SurfaceHit{dist, *s, std::clamp(v, 0.0, 1.0), front};
    }
    return std::nullopt;
}

double TorusSurface::area(double s0, double s1, double t0, double t1) const {
    const double v0 = 2.0 * kPi * t0, v1 = 2.0 * kPi * t1;
    return m_r * m_angles.span * (s1 - s0) * (m_R * (v1 - v0) + m_r * (std::sin(v1) - std::sin(v0)));
}

BoundingSphere TorusSurface::bound(double s0, double s1, double, double) const {
    // Every point lies within r of the centre circle's arc.
    const BoundingSphere arc = arc_ball(m_frame, m_center, m_R, m_angles.at(s0), m_angles.at(s1));
    return {arc.center, arc.radius + m_r};
}

std::pair<double, double> TorusSurface::linear_range(const Vec3& a, double s0, double s1, double t0,
                                                     double t1) const {
    // a . P = a . center + g R + r (g cos v + h sin v), g = a . radial(u) over [g0, g1], h = a . axis:
    // linear in g, so each extreme lies at g0 or g1, and for fixed g it is a cosine in v.
    const double v0 = 2.0 * kPi * t0, v1 = 2.0 * kPi * t1;
    const auto [g0, g1] = radial_range(m_frame, a, m_angles.at(s0), m_angles.at(s1));
    const double h = glm::dot(a, m_frame.axis), base = glm::dot(a, m_center);
    double lo = 1e300, hi = -1e300;
    for (const double g : {g0, g1}) {
        const auto [c0, c1] = cosine_range(m_r * std::hypot(g, h), std::atan2(h, g), v0, v1);
        lo = std::min(lo, g * m_R + c0);
        hi = std::max(hi, g * m_R + c1);
    }
    return {base + lo, base + hi};
}

bool TorusSurface::patch_contour(double s0, double s1, double t0, double t1,
                                 std::vector<ContourPiece>* out) const {
    // About dP/ds x dP/dt (outward): along t0 in +u, up the tube at u1, back along t1, down at u0.
    const double u0 = m_angles.at(s0), u1 = m_angles.at(s1), v0 = 2.0 * kPi * t0, v1 = 2.0 * kPi * t1;
    auto around_axis = [&](double v, double from, double to) {
        ContourPiece c;
        c.arc = true;
        c.center = m_center + (m_r * std::sin(v)) * m_frame.axis;
        c.e1 = m_frame.e1;
        c.e2 = m_frame.e2;
        c.radius = m_R + m_r * std::cos(v);
        c.from = from;
        c.to = to;
        return c;
    };
    auto around_tube = [&](double u, double from, double to) {
        ContourPiece c;
        c.arc = true;
        c.center = m_center + m_R * m_frame.radial(u);
        c.e1 = m_frame.radial(u);
        c.e2 = m_frame.axis;
        c.radius = m_r;
        c.from = from;
        c.to = to;
        return c;
    };
    out->clear();
    out->push_back(around_axis(v0, u0, u1));
    out->push_back(around_tube(u1, v0, v1));
    out->push_back(around_axis(v1, u1, u0));
    out->push_back(around_tube(u0, v1, v0));
    if (m_orientation < 0.0) {
        std::reverse(out->begin(), out->end());
        for (ContourPiece& c : *out) std::swap(c.from, c.to);
    }
    return true;
}

bool TorusSurface::on_convex_hull(double, double, double t0, double t1) const {
    return (t0 >= 0.0 && t1 <= 0.25) || (t0 >= 0.75 && t1 <= 1.0);
}

bool TorusSurface::faces_ball(double s0, double s1, double t0, double t1, const BoundingSphere& b,
                              bool back) const {
    if ((m_orientation < 0.0) != back || !on_convex_hull(s0, s1, t0, t1)) return false;
    // n . (c - P) = cos v (A(u) - R) + h sin v - r, A(u) = d . radial(u), h = d . axis, d = c -
    // center: with cos v >= 0 least at the least A, then a cosine in v.
    const Vec3 d = b.center - m_center;
    const double a = radial_range(m_frame, d, m_angles.at(s0), m_angles.at(s1)).first - m_R;
    const double h = glm::dot(d, m_frame.axis);
    const double least =
        cosine_range(std::hypot(a, h), std::atan2(h, a), 2.0 * kPi * t0, 2.0 * kPi * t1).first - m_r;
    return least > b.radius + 1e-12 * (m_R + m_r + glm::length(d));
}

void TorusSurface::write_key(ByteWriter& w) const {
    for (int k = 0; k < 3; ++k) w.f64(m_center[k]);
    for (int k = 0; k < 3; ++k) w.f64(m_frame.axis[k]);
    w.f64(m_R);
    w.f64(m_r);
    w.f64(m_angles.phi0);
    w.f64(m_angles.span);
    w.u8(m_orientation < 0.0 ? 1 : 0);
}

namespace {

// center, axis (a direction), major_radius > minor_radius > 0, facing, angles_deg.
std::shared_ptr<const Surface> read_torus(YamlMap& m, const std::string& name) {
    const Vec3 center = m.vec3("center");
    const Vec3 axis = read_direction(m, "axis");
    const double major = read_length(m, "major_radius");
    const double minor = read_length(m, "minor_radius");
    if (!(minor < major))
        throw Error(m.key_loc("minor_radius"),
                    "torus '" + name +
                        "': minor_radius must be smaller than major_radius (a horn or spindle torus "
                        "passes through itself)");
    const bool inward = read_facing_inward(m);
    return std::make_shared<TorusSurface>(center, axis, major, minor, read_angles_deg(m), inward);
}

}  // namespace

extern const SurfaceType kTorusType;
const SurfaceType kTorusType = {
    .name = "torus",
    .key_id = 5,
    .keys = "center, axis, major_radius, minor_radius, facing, angles_deg",
    .read = read_torus,
    .example = {{"center", "[0, 0, 0]"},
                {"axis", "[0, 0, 1]"},
                {"major_radius", "1"},
                {"minor_radius", "0.25"},
                {"facing", "outward"},
                {"angles_deg", "[0, 360]"}},
    .variants = {{"center", "[0.5, 0, 0]"},
                 {"center", "[0, 0, 0.5]"},
                 {"axis", "[0, 1, 1]"},
                 {"major_radius", "1.5"},
                 {"minor_radius", "0.5"},
                 {"facing", "inward"},
                 {"angles_deg", "[0, 90]"}},
};

}  // namespace radiosa
