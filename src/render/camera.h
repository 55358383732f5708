#pragma once
#include "scene/camera.h"
#include "util/math.h"

namespace radiosa {

// Pinhole camera generating primary rays for an image of width x height pixels.
class PinholeCamera {
public:
    PinholeCamera(const CameraDesc& desc, int width, int height);
    // (px, py) in pixels, (0, 0) the top-left corner of the image. Inline: an image makes one
    // per sample.
    Ray ray(double px, double py) const {
        const double aspect = double(m_width) / m_height;
        const double x = (2.0 * px / m_width - 1.0) * m_tan_half * aspect;
        const double y = (1.0 - 2.0 * py / m_height) * m_tan_half;
        return Ray{m_eye, glm::normalize(m_forward + x * m_right + y * m_up)};
    }
    // The rays of pixels x0 .. x1 - 1 of row y, n x n samples each (pixel by pixel, then sample
    // row sy, then column sx): out[r] is ray(x + (sx + 0.5) / n, y + (sy + 0.5) / n) bit for bit,
    // computed a few at a time in arrays the compiler puts in SIMD lanes. At most kRowRays rays.
    static constexpr int kRowRays = 64;
    void row_rays(int y, int x0, int x1, int n, Ray* out) const;
    const Vec3& eye() const { return m_eye; }
    const Vec3& forward() const { return m_forward; }
    // Focal length in pixels (distance to an image plane where pixels are unit squares).
    double focal_pixels() const { return 0.5 * m_height / m_tan_half; }

private:
    Vec3 m_eye, m_forward, m_right, m_up;
    double m_tan_half = 1.0;
    int m_width = 1, m_height = 1;
};

}  // namespace radiosa
