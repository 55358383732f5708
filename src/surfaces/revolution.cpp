#include "surfaces/revolution.h"

#include <algorithm>
#include <cmath>

namespace radiosa {

AzimuthFrame azimuth_frame(const Vec3& a) {
    const Vec3 ref = std::abs(a.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
    const Vec3 e1 = glm::normalize(ref - glm::dot(ref, a) * a);
    return {e1, glm::cross(a, e1), a};
}

std::optional<double> AngleRange::param(double phi) const {
    double d = phi - phi0;
    if (!(std::abs(d) < 2.0 * kPi)) d = std::fmod(d, 2.0 * kPi);  // fmod leaves |d| < 2 pi as it is
    if (d < 0.0) d += 2.0 * kPi;
    constexpr double kSlack = 1e-12;  // a hit on the range's edge despite rounding
    if (d > 2.0 * kPi - kSlack) d = 0.0;
    if (d > span * (1.0 + kSlack)) return std::nullopt;
    return std::clamp(d / span, 0.0, 1.0);
}

std::pair<double, double> cosine_range(double amp, double phase, double lo, double hi) {
    double a = amp * std::cos(lo - phase), b = amp * std::cos(hi - phase);
    std::pair<double, double> r{std::min(a, b), std::max(a, b)};
    // The peaks phase + 2 pi k and troughs phase + pi + 2 pi k inside (lo, hi).
    const double k_max = std::ceil((lo - phase) / (2.0 * kPi));
    if (phase + 2.0 * kPi * k_max < hi) r.second = amp;
    const double k_min = std::ceil((lo - phase - kPi) / (2.0 * kPi));
    if (phase + kPi + 2.0 * kPi * k_min < hi) r.first = -amp;
    return r;
}

std::pair<double, double> radial_range(const AzimuthFrame& f, const Vec3& g, double phi0, double phi1) {
    const double A = glm::dot(g, f.e1), B = glm::dot(g, f.e2);
    return cosine_range(std::hypot(A, B), std::atan2(B, A), phi0, phi1);
}

BoundingSphere arc_ball(const AzimuthFrame& f, const Vec3& center, double r, double phi0, double phi1) {
    const double half = 0.5 * (phi1 - phi0);
    if (half >= 0.5 * kPi) return {center, r};
    // The chord's midpoint; every point of the arc is within r sin(half) of it.
    return {center + r * std::cos(half) * f.radial(phi0 + half), r * std::sin(half)};
}

BoundingSphere enclosing(const BoundingSphere& a, const BoundingSphere& b) {
    const double d = glm::length(b.center - a.center);
    if (d + b.radius <= a.radius) return a;
    if (d + a.radius <= b.radius) return b;
    const double r = 0.5 * (d + a.radius + b.radius);
    const Vec3 c = a.center + ((r - a.radius) / d) * (b.center - a.center);
    return {c, r * (1.0 + 1e-15) + 1e-300};
}

AngleRange read_angles_deg(YamlMap& m) {
    AngleRange r;
    const auto node = m.optional("angles_deg");
    if (!node) return r;
    if (!node->IsSequence() || node->size() != 2)
        throw Error(loc_of(*node, m.file()), "angles_deg must be a list of 2 numbers [from, to] in degrees");
    const double a0 = yaml_number((*node)[0], m.file(), "angles_deg[0]");
    const double a1 = yaml_number((*node)[1], m.file(), "angles_deg[1]");
    if (!(a1 > a0) || a1 - a0 > 360.0)
        throw Error(loc_of(*node, m.file()), "angles_deg [from, to] needs from < to <= from + 360, got [" +
                                                 (*node)[0].Scalar() + ", " + (*node)[1].Scalar() + "]");
    r.phi0 = deg_to_rad(a0);
    r.span = a1 - a0 == 360.0 ? 2.0 * kPi : deg_to_rad(a1 - a0);
    return r;
}

bool read_facing_inward(YamlMap& m) {
    const auto facing = m.optional("facing");
    if (!facing) return false;
    const std::string f = yaml_string(*facing, m.file(), "facing");
    if (f != "outward" && f != "inward")
        throw Error(loc_of(*facing, m.file()), "facing must be 'outward' or 'inward', got '" + f + "'");
    return f == "inward";
}

double read_length(YamlMap& m, const std::string& key, bool zero_ok) {
    const YAML::Node n = m.required(key);
    const double v = yaml_number(n, m.file(), key);
    if (zero_ok ? !(v >= 0.0) : !(v > 0.0))
        throw Error(loc_of(n, m.file()),
                    key + (zero_ok ? " must be >= 0, got " : " must be > 0, got ") + n.Scalar());
    return v;
}

Vec3 read_direction(YamlMap& m, const std::string& key, double* length) {
    const YAML::Node n = m.required(key);
    const Vec3 v = yaml_vec3(n, m.file(), key);
    const double len = glm::length(v);
    if (!(len > 0.0) || !std::isfinite(len))
        throw Error(loc_of(n, m.file()), key + " must be a non-zero vector [x, y, z]");
    if (length) *length = len;
    return v / len;
}

}  // namespace radiosa
