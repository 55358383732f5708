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

void PinholeCamera::row_rays(int y, int x0, int x1, int n, Ray* out) const {
    // ray()'s arithmetic in its order, one operation over all rays at a time: the same values.
    const int count = (x1 - x0) * n * n;
    const double aspect = double(m_width) / m_height;
    double px[kRowRays], vy[kRowRays], dx[kRowRays], dy[kRowRays], dz[kRowRays];
    int r = 0;
    for (int x = x0; x < x1; ++x)
        for (int sy = 0; sy < n; ++sy)
            for (int sx = 0; sx < n; ++sx, ++r) {
                px[r] = x + (sx + 0.5) / n;
                vy[r] = (1.0 - 2.0 * (y + (sy + 0.5) / n) / m_height) * m_tan_half;
            }
    for (int i = 0; i < count; ++i) {
        const double vx = (2.0 * px[i] / m_width - 1.0) * m_tan_half * aspect;
        dx[i] = m_forward.x + vx * m_right.x + vy[i] * m_up.x;
        dy[i] = m_forward.y + vx * m_right.y + vy[i] * m_up.y;
        dz[i] = m_forward.z + vx * m_right.z + vy[i] * m_up.z;
    }
    for (int i = 0; i < count; ++i) {
        // glm::normalize: v * (1 / sqrt(dot(v, v))).
        const double inv = 1.0 / std::sqrt(dx[i] * dx[i] + dy[i] * dy[i] + dz[i] * dz[i]);
        dx[i] *= inv;
        dy[i] *= inv;
        dz[i] *= inv;
    }
    for (int i = 0; i < count; ++i) out[i] = Ray{m_eye, Vec3(dx[i], dy[i], dz[i])};
}

}  // namespace radiosa
