#include "render/camera.h"

#include <cmath>

namespace radiosa {

PinholeCamera::PinholeCamera(const CameraDesc& d, int width, int height)
    : m_eye(d.eye), m_width(width), m_height(height) {
    m_forward = glm::normalize(d.look_at - d.eye);
    Vec3 right = glm::cross(m_forward, d.up);
    if (glm::length(right) < 1e-9 * glm::length(d.up)) {
        // Looking along `up` (phi = 0 or 180 deg): any perpendicular will do; take the
        // world axis least aligned with the view direction.
        const Vec3 alt = std::abs(m_forward.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
        right = glm::cross(m_forward, alt);
    }
    m_right = glm::normalize(right);
    m_up = glm::cross(m_right, m_forward);
    m_tan_half = std::tan(0.5 * deg_to_rad(d.fov_deg));
}

Ray PinholeCamera::ray(double px, double py) const {
    const double aspect = double(m_width) / m_height;
    const double x = (2.0 * px / m_width - 1.0) * m_tan_half * aspect;
    const double y = (1.0 - 2.0 * py / m_height) * m_tan_half;
    return Ray{m_eye, glm::normalize(m_forward + x * m_right + y * m_up)};
}

}  // namespace radiosa
