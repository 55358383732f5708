#pragma once
// Basic numeric types shared by every stage: double precision throughout.
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace radiosa {

using Vec3 = glm::dvec3;
using Mat3 = glm::dmat3;  // column-major: m[k] is column k
// Linear RGB triple: reflectance, emission and radiosity per colour channel.
using Rgb = glm::dvec3;

inline constexpr double kPi = 3.14159265358979323846;

inline double deg_to_rad(double deg) { return deg * kPi / 180.0; }

// A ray or segment: points are origin + t * dir. `dir` need not be unit length
// (segments use dir = b - a and t in (0, 1)).
struct Ray {
    Vec3 origin;
    Vec3 dir;
    Vec3 at(double t) const { return origin + t * dir; }
};

// A unit vector at right angles to the unit vector a (the same one for the same a).
inline Vec3 unit_across(const Vec3& a) {
    return glm::normalize(std::abs(a.x) < 0.9 ? glm::cross(a, Vec3(1, 0, 0)) : glm::cross(a, Vec3(0, 1, 0)));
}

struct BoundingSphere {
    Vec3 center{0.0};
    double radius = 0.0;
};

}  // namespace radiosa
