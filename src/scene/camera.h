#pragma once
// A still camera as read from a camera file (cameras/*.yaml).
#include <string>

#include "util/error.h"
#include "util/math.h"

namespace radiosa {

struct CameraDesc {
    Vec3 eye{6.0, 0.0, 0.0};
    Vec3 look_at{0.0};
    Vec3 up{0.0, 0.0, 1.0};
    double fov_deg = 50.0;  // vertical field of view
    FileLoc loc;
};

// The paper's camera: looks at `look_at` from distance D at azimuth theta (from +x towards
// +y, about +z) and polar angle phi (from +z). theta = 0, phi = 90 deg puts the eye on +x.
Vec3 orbit_position(const Vec3& look_at, double distance, double theta_deg, double phi_deg);

CameraDesc load_camera(const std::string& path);
CameraDesc parse_camera(const std::string& yaml_text, const std::string& filename);

}  // namespace radiosa
