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

}  // namespace radiosa
