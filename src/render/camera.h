#pragma once
#include "scene/camera.h"
#include "util/math.h"

namespace radiosa {

// Pinhole camera generating primary rays for an image of width x height pixels.
class PinholeCamera {
public:
    PinholeCamera(const CameraDesc& desc, int width, int height);
    // (px, py) in pixels, (0, 0) the top-left corner of the image.
    Ray ray(double px, double py) const;
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
