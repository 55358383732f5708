#pragma once
// Reading a camera from a YAML mapping, shared by camera files and sequence keys.
#include "scene/camera.h"
#include "util/yaml_reader.h"

namespace radiosa {

struct OrbitParams {
    double distance = 6.0, theta_deg = 0.0, phi_deg = 90.0;
};

// Reads distance/theta_deg/phi_deg or position, and look_at, up, fov_deg from `m` (the caller
// rejects unknown keys). Sets *orbit to the orbit parameters when given in that form.
CameraDesc read_camera_fields(YamlMap& m, std::optional<OrbitParams>* orbit);

}  // namespace radiosa
