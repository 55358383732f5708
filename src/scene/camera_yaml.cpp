// Reads camera files. The format is documented in README.md ("Camera files").
#include <cmath>

#include "scene/camera.h"
#include "scene/yaml_reader.h"

namespace radiosa {

Vec3 orbit_position(const Vec3& look_at, double distance, double theta_deg, double phi_deg) {
    const double th = deg_to_rad(theta_deg), ph = deg_to_rad(phi_deg);
    return look_at + distance * Vec3(std::sin(ph) * std::cos(th), std::sin(ph) * std::sin(th), std::cos(ph));
}

CameraDesc parse_camera(const std::string& yaml_text, const std::string& filename) {
    const YAML::Node root = load_yaml_string(yaml_text, filename);
    YamlMap top(root, filename, "camera file");
    YamlMap m(top.required("camera"), filename, "camera");
    top.reject_unknown_keys("camera");

    CameraDesc cam;
    cam.loc = m.loc();
    if (m.has("look_at")) cam.look_at = m.vec3("look_at");
    const bool orbit = m.has("distance") || m.has("theta_deg") || m.has("phi_deg");
    if (orbit && m.has("position"))
        throw Error(m.key_loc("position"), "camera: give either distance/theta_deg/phi_deg or position, not both");
    if (orbit) {
        const YAML::Node dn = m.required("distance");
        const double d = yaml_number(dn, filename, "distance");
        if (!(d > 0.0)) throw Error(loc_of(dn, filename), "distance must be > 0, got " + dn.Scalar());
        cam.eye = orbit_position(cam.look_at, d, m.number("theta_deg"), m.number("phi_deg"));
    } else {
        cam.eye = m.vec3("position");
    }
    if (m.has("up")) cam.up = m.vec3("up");
    if (auto f = m.optional("fov_deg")) {
        cam.fov_deg = yaml_number(*f, filename, "fov_deg");
        if (!(cam.fov_deg > 0.0 && cam.fov_deg < 180.0))
            throw Error(loc_of(*f, filename), "fov_deg must be in (0, 180), got " + f->Scalar());
    }
    m.reject_unknown_keys("distance, theta_deg, phi_deg | position, look_at, up, fov_deg");

    const double dist = glm::length(cam.look_at - cam.eye);
    if (!(dist > 0.0)) throw Error(cam.loc, "camera: position and look_at coincide");
    if (!(glm::length(cam.up) > 0.0)) throw Error(cam.loc, "camera: up must not be the zero vector");
    return cam;
}

CameraDesc load_camera(const std::string& path) { return parse_camera(read_input_file(path), path); }

}  // namespace radiosa
