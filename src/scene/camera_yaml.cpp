// Reads camera files. The format is documented in docs/scene-format.md ("Camera files").
#include "scene/camera_yaml.h"

namespace radiosa {

CameraDesc read_camera_fields(YamlMap& m, std::optional<OrbitParams>* orbit_out) {
    const std::string& filename = m.file();
    CameraDesc cam;
    cam.loc = m.loc();
    if (m.has("look_at")) cam.look_at = m.vec3("look_at");
    const bool orbit = m.has("distance") || m.has("theta_deg") || m.has("phi_deg");
    if (orbit && m.has("position"))
        throw Error(m.key_loc("position"),
                    m.what() + ": give either distance/theta_deg/phi_deg or position, not both");
    if (orbit) {
        const YAML::Node dn = m.required("distance");
        OrbitParams o;
        o.distance = yaml_number(dn, filename, "distance");
        if (!(o.distance > 0.0))
            throw Error(loc_of(dn, filename), "distance must be > 0, got " + dn.Scalar());
        o.theta_deg = m.number("theta_deg");
        o.phi_deg = m.number("phi_deg");
        cam.eye = orbit_position(cam.look_at, o.distance, o.theta_deg, o.phi_deg);
        if (orbit_out) *orbit_out = o;
    } else {
        cam.eye = m.vec3("position");
    }
    if (m.has("up")) cam.up = m.vec3("up");
    if (auto f = m.optional("fov_deg")) {
        cam.fov_deg = yaml_number(*f, filename, "fov_deg");
        if (!(cam.fov_deg > 0.0 && cam.fov_deg < 180.0))
            throw Error(loc_of(*f, filename), "fov_deg must be in (0, 180), got " + f->Scalar());
    }
    const double dist = glm::length(cam.look_at - cam.eye);
    if (!(dist > 0.0)) throw Error(cam.loc, m.what() + ": position and look_at coincide");
    if (!(glm::length(cam.up) > 0.0)) throw Error(cam.loc, m.what() + ": up must not be the zero vector");
    return cam;
}

CameraDesc parse_camera(const std::string& yaml_text, const std::string& filename) {
    const YAML::Node root = load_yaml_string(yaml_text, filename);
    YamlMap top(root, filename, "camera file");
    if (top.has("fps"))
        throw Error(top.loc(), "this is a sequence file (it has fps); pass it with --sequence, not --camera");
    YamlMap m(top.required("camera"), filename, "camera");
    top.reject_unknown_keys("camera");
    const CameraDesc cam = read_camera_fields(m, nullptr);
    m.reject_unknown_keys("distance, theta_deg, phi_deg | position, look_at, up, fov_deg");
    return cam;
}

CameraDesc load_camera(const std::string& path) { return parse_camera(read_input_file(path), path); }

}  // namespace radiosa
