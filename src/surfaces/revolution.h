#pragma once
// Pieces shared by the surfaces of revolution (disk, cylinder, cone, sphere): the azimuth frame
// about an axis, azimuth ranges (`angles_deg`), `facing`, and exact bounds of circular arcs.
#include <optional>
#include <string>
#include <utility>

#include "util/math.h"
#include "util/yaml_reader.h"

namespace radiosa {

// A right-handed frame (e1, e2, axis): azimuth phi points along cos(phi) e1 + sin(phi) e2,
// counter-clockwise about the axis. e1 is +x projected onto the plane normal to the axis, or +y
// when the axis lies within about 25 degrees of +-x.
struct AzimuthFrame {
    Vec3 e1, e2, axis;
    Vec3 radial(double phi) const { return std::cos(phi) * e1 + std::sin(phi) * e2; }
    Vec3 tangent(double phi) const { return -std::sin(phi) * e1 + std::cos(phi) * e2; }
    // v in the frame's coordinates (along e1, e2, axis).
    Vec3 local(const Vec3& v) const { return Vec3(glm::dot(v, e1), glm::dot(v, e2), glm::dot(v, axis)); }
    // Whether p lies on the axis through `origin` (to 1e-14 of `size`), and whether the unit
    // vector u runs along it: the cases where distances from a point or line are exact.
    bool on_axis(const Vec3& origin, const Vec3& p, double size) const {
        const Vec3 q = p - origin;
        return glm::length(q - glm::dot(q, axis) * axis) <= 1e-14 * size;
    }
    bool along_axis(const Vec3& u) const { return glm::length(glm::cross(u, axis)) <= 1e-14; }
};
AzimuthFrame azimuth_frame(const Vec3& unit_axis);

// An azimuth range [phi0, phi0 + span], span in (0, 2 pi].
struct AngleRange {
    double phi0 = 0.0;
    double span = 2.0 * kPi;
    bool full() const { return span >= 2.0 * kPi; }
    double at(double s) const { return phi0 + span * s; }
    // The parameter s in [0, 1] of azimuth phi, or nullopt when phi lies outside the range.
    std::optional<double> param(double phi) const;
};

// The range of amp * cos(x - phase) over [lo, hi] (amp >= 0).
std::pair<double, double> cosine_range(double amp, double phase, double lo, double hi);
// The range of g . radial(phi) over phi in [phi0, phi1].
std::pair<double, double> radial_range(const AzimuthFrame& f, const Vec3& g, double phi0, double phi1);

// A ball holding the arc center + r radial(phi), phi in [phi0, phi1] (exact for spans up to pi).
BoundingSphere arc_ball(const AzimuthFrame& f, const Vec3& center, double r, double phi0, double phi1);
// The smallest ball holding both balls (and so their convex hull).
BoundingSphere enclosing(const BoundingSphere& a, const BoundingSphere& b);

// Readers for the keys the surfaces of revolution share; bad values throw at their file:line:col.
// angles_deg: [a0, a1] with a0 < a1 <= a0 + 360 (default [0, 360]).
AngleRange read_angles_deg(YamlMap& m);
// facing: outward (default) | inward; true for inward.
bool read_facing_inward(YamlMap& m);
// A number > 0 (or >= 0 when zero_ok).
double read_length(YamlMap& m, const std::string& key, bool zero_ok = false);
// A non-zero vector, normalised; its length is returned in *length when asked.
Vec3 read_direction(YamlMap& m, const std::string& key, double* length = nullptr);

}  // namespace radiosa
