#include "scene/camera.h"

#include <cmath>

namespace radiosa {

Vec3 orbit_position(const Vec3& look_at, double distance, double theta_deg, double phi_deg) {
    const double th = deg_to_rad(theta_deg), ph = deg_to_rad(phi_deg);
    return look_at + distance * Vec3(std::sin(ph) * std::cos(th), std::sin(ph) * std::sin(th), std::cos(ph));
}

}  // namespace radiosa
