// Reads sequence files. The format is documented in docs/sequences.md.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "scene/camera_yaml.h"
#include "scene/scene.h"
#include "schedule/sequence.h"
#include "util/yaml_reader.h"

namespace radiosa {

namespace {

double non_negative_time(const YAML::Node& n, const std::string& file, const std::string& what) {
    const double t = yaml_number(n, file, what);
    if (t < 0.0) throw Error(loc_of(n, file), what + " must be >= 0, got " + n.Scalar());
    return t;
}

std::vector<CameraKey> read_keys(YamlMap& cam, const std::string& file) {
    const YAML::Node list = cam.required("keys");
    if (!list.IsSequence() || list.size() == 0)
        throw Error(
            loc_of(list, file),
            "camera keys must be a non-empty list of {time_s, distance, theta_deg, phi_deg | position, ...}");
    std::vector<CameraKey> keys;
    double last_end = -1.0;
    for (std::size_t k = 0; k < list.size(); ++k) {
        const std::string what = "camera key " + std::to_string(k + 1);
        YamlMap m(list[k], file, what);
        CameraKey key;
        const YAML::Node tn = m.required("time_s");
        key.time_s = non_negative_time(tn, file, "time_s");
        if (key.time_s <= last_end)
            throw Error(loc_of(tn, file), what + ": time_s " + tn.Scalar() +
                                              " must be later than the previous key's time (and hold)");
        if (auto h = m.optional("hold_s")) key.hold_s = non_negative_time(*h, file, "hold_s");
        key.cut = m.boolean_or("cut", false);
        if (k == 0 && key.cut) throw Error(m.key_loc("cut"), "the first camera key cannot be a cut");
        std::optional<OrbitParams> orbit;
        key.camera = read_camera_fields(m, &orbit);
        if (orbit) {
            key.orbit = true;
            key.distance = orbit->distance;
            key.theta_deg = orbit->theta_deg;
            key.phi_deg = orbit->phi_deg;
        }
        m.reject_unknown_keys(
            "time_s, hold_s, cut, distance, theta_deg, phi_deg | position, look_at, up, fov_deg");
        last_end = key.time_s + key.hold_s;
        keys.push_back(key);
    }
    return keys;
}

Rgb read_value(const YAML::Node& n, const std::string& file, EventProperty prop) {
    const std::string what = prop == EventProperty::Emission ? "emission" : "reflectance";
    const Vec3 v = yaml_vec3(n, file, what, "[r, g, b]");
    for (int c = 0; c < 3; ++c) {
        if (v[c] < 0.0) throw Error(loc_of(n[c], file), what + " must be >= 0, got " + n[c].Scalar());
        if (prop == EventProperty::Reflectance && v[c] > 1.0)
            throw Error(loc_of(n[c], file), "reflectance must be in [0, 1], got " + n[c].Scalar());
    }
    return v;
}

// The surfaces an event's `surface` names: the one of that name, or else every front surface one
// entry of several made (a Bezier file's patches, a mesh's faces: "<name>.<k>", not "....back").
std::vector<int> named_surfaces(const Scene& scene, const std::string& name) {
    if (const int k = scene.find_surface(name); k >= 0) return {k};
    std::vector<int> parts;
    for (int k = 0; k < static_cast<int>(scene.surfaces.size()); ++k) {
        const SurfaceDesc& d = scene.surfaces[k];
        if (d.name.starts_with(name + ".") && !d.name.ends_with(".back") &&
            (parts.empty() || d.entry == scene.surfaces[parts[0]].entry))
            parts.push_back(k);
    }
    return parts;
}

// translate: [x, y, z] and/or rotate_deg: {axis: [x, y, z], angle: a, about: [x, y, z]}.
void read_motion(YamlMap& m, const std::string& what, SequenceEvent* ev) {
    const std::string& file = ev->loc.file;
    if (m.has("translate")) ev->translate = m.vec3("translate");
    if (auto r = m.optional("rotate_deg")) {
        YamlMap rm(*r, file, what + ": rotate_deg");
        EventRotation rot;
        const YAML::Node an = rm.required("axis");
        rot.axis = yaml_vec3(an, file, "axis");
        const double len = glm::length(rot.axis);
        if (!(len > 0.0) || !std::isfinite(len))
            throw Error(loc_of(an, file), what + ": rotate_deg axis must be a non-zero vector [x, y, z]");
        const YAML::Node angle = rm.required("angle");
        rot.angle_deg = yaml_number(angle, file, "angle");
        if (!(std::abs(rot.angle_deg) <= 1e6))
            throw Error(loc_of(angle, file),
                        what + ": rotate_deg angle must be in [-1e6, 1e6] degrees, got " + angle.Scalar());
        if (rm.has("about")) rot.about = rm.vec3("about");
        rm.reject_unknown_keys("axis, angle, about");
        ev->rotate = rot;
    }
}

// One event per surface it names (an entry of several surfaces gives several).
std::vector<SequenceEvent> read_event(const YAML::Node& node, std::size_t index, const std::string& file,
                                      const Scene* scene) {
    const std::string what = "event " + std::to_string(index + 1);
    YamlMap m(node, file, what);
    SequenceEvent ev;
    ev.loc = m.loc();
    const YAML::Node tn = m.required("time_s");
    if (tn.IsSequence()) {
        if (tn.size() != 2) throw Error(loc_of(tn, file), what + ": time_s is a time or a ramp [start, end]");
        ev.t0 = non_negative_time(tn[0], file, "time_s[0]");
        ev.t1 = non_negative_time(tn[1], file, "time_s[1]");
        if (!(ev.t1 > ev.t0))
            throw Error(loc_of(tn[1], file), what + ": a ramp must end after it starts, got [" +
                                                 tn[0].Scalar() + ", " + tn[1].Scalar() + "]");
    } else {
        ev.t0 = ev.t1 = non_negative_time(tn, file, "time_s");
    }
    const YAML::Node sn = m.required("surface");
    const std::string name = yaml_string(sn, file, "surface");
    std::vector<int> targets;
    if (scene) {
        targets = named_surfaces(*scene, name);
        ev.surface = targets.empty() ? -1 : targets[0];
        if (ev.surface < 0) {
            std::string known;
            for (const auto& s : scene->surfaces) known += (known.empty() ? "" : ", ") + s.name;
            throw Error(loc_of(sn, file), what + ": no surface named '" + name + "' in " + scene->file +
                                              " (it has " + known + ")");
        }
    }
    if (auto p = m.optional("patch")) {
        if (!p->IsSequence() || p->size() != 2)
            throw Error(loc_of(*p, file), what + ": patch must be [i, j] (0-based indices along s and t)");
        const long long i = yaml_integer((*p)[0], file, "patch[0]"),
                        j = yaml_integer((*p)[1], file, "patch[1]");
        for (const int k : targets) {
            const SurfaceDesc& s = scene->surfaces[k];
            if (i < 0 || i >= s.ns || j < 0 || j >= s.nt)
                throw Error(loc_of(*p, file), what + ": surface '" + name + "' has patches [0.." +
                                                  std::to_string(s.ns - 1) + ", 0.." +
                                                  std::to_string(s.nt - 1) + "], not [" + std::to_string(i) +
                                                  ", " + std::to_string(j) + "]");
        }
        ev.patch = std::make_pair(static_cast<int>(i), static_cast<int>(j));
    }
    const bool e = m.has("emission"), r = m.has("reflectance"),
               moves = m.has("translate") || m.has("rotate_deg");
    if (int(e) + int(r) + int(moves) != 1)
        throw Error(m.loc(), what +
                                 ": give exactly one of emission, reflectance or a motion (translate "
                                 "and/or rotate_deg)");
    if (moves) {
        ev.property = EventProperty::Motion;
        read_motion(m, what, &ev);
        if (ev.patch) throw Error(m.key_loc("patch"), what + ": a motion moves a whole surface; drop patch");
        // A two-sided surface's back moves with it.
        if (scene) {
            const std::size_t fronts = targets.size();
            for (std::size_t k = 0; k < fronts; ++k)
                if (const int twin = scene->surfaces[static_cast<std::size_t>(targets[k])].twin; twin >= 0)
                    targets.push_back(twin);
        }
        m.reject_unknown_keys("time_s, surface, translate, rotate_deg");
    } else {
        ev.property = e ? EventProperty::Emission : EventProperty::Reflectance;
        ev.value = read_value(m.required(e ? "emission" : "reflectance"), file, ev.property);
        m.reject_unknown_keys("time_s, surface, patch, emission | reflectance | translate, rotate_deg");
    }
    if (targets.size() <= 1) return {ev};
    std::vector<SequenceEvent> out;
    for (const int k : targets) {
        ev.surface = k;
        out.push_back(ev);
    }
    return out;
}

// One rotation axis and centre per surface: a ramp then only turns the angle, which is what
// "from the displacement it has to the one given" means without ambiguity (a ramp between two
// different axes has no single natural path).
void check_rotations(const std::vector<SequenceEvent>& events, const Scene* scene) {
    for (std::size_t a = 0; a < events.size(); ++a) {
        if (!events[a].rotate) continue;
        for (std::size_t b = a + 1; b < events.size(); ++b) {
            if (!events[b].rotate || events[b].surface != events[a].surface) continue;
            const EventRotation &ra = *events[a].rotate, &rb = *events[b].rotate;
            if (ra.axis == rb.axis && ra.about == rb.about) continue;
            const std::string name =
                scene ? scene->surfaces[static_cast<std::size_t>(events[b].surface)].name : "the surface";
            throw Error(events[b].loc, "'" + name +
                                           "' already rotates about another axis or centre (event at " +
                                           events[a].loc.to_string() +
                                           "); give every rotation of one surface the same axis and about");
        }
    }
}

}  // namespace

std::string sequence_scene_path(const std::string& path) {
    const YAML::Node root = load_yaml_string(read_input_file(path), path);
    if (!root.IsMap() || !root["scene"]) return "";
    const std::string rel = yaml_string(root["scene"], path, "scene");
    return (std::filesystem::path(path).parent_path() / rel).lexically_normal().string();
}

Sequence parse_sequence(const std::string& yaml_text, const std::string& filename, const Scene* scene) {
    const YAML::Node root = load_yaml_string(yaml_text, filename);
    YamlMap top(root, filename, "sequence file");
    Sequence seq;
    seq.file = filename;
    if (auto s = top.optional("scene"))
        seq.scene_path = (std::filesystem::path(filename).parent_path() / yaml_string(*s, filename, "scene"))
                             .lexically_normal()
                             .string();
    const YAML::Node fn = top.required("fps");
    seq.fps = yaml_number(fn, filename, "fps");
    if (!(seq.fps > 0.0 && seq.fps <= 240.0))
        throw Error(loc_of(fn, filename), "fps must be in (0, 240], got " + fn.Scalar());

    if (auto im = top.optional("image")) {
        YamlMap m(*im, filename, "image");
        auto read = [&](const char* key, int hi) -> std::optional<int> {
            auto n = m.optional(key);
            if (!n) return std::nullopt;
            const long long v = yaml_integer(*n, filename, key);
            if (v < 1 || v > hi)
                throw Error(loc_of(*n, filename), std::string(key) + " must be in [1, " + std::to_string(hi) +
                                                      "], got " + n->Scalar());
            return static_cast<int>(v);
        };
        seq.width = read("width", 16384);
        seq.height = read("height", 16384);
        seq.samples = read("samples", 16);
        m.reject_unknown_keys("width, height, samples");
    }
    YamlMap cam(top.required("camera"), filename, "camera");
    if (auto in = cam.optional("interpolation")) {
        const std::string v = yaml_string(*in, filename, "interpolation");
        if (v == "spline")
            seq.interpolation = CameraInterpolation::Spline;
        else if (v == "constant-speed")
            seq.interpolation = CameraInterpolation::ConstantSpeed;
        else
            throw Error(loc_of(*in, filename),
                        "interpolation must be spline or constant-speed, got '" + v + "'");
    }
    seq.keys = read_keys(cam, filename);
    cam.reject_unknown_keys("interpolation, keys");

    if (auto ev = top.optional("events")) {
        if (!ev->IsSequence())
            throw Error(loc_of(*ev, filename),
                        "events must be a list of {time_s, surface, [patch], emission | reflectance}");
        for (std::size_t k = 0; k < ev->size(); ++k)
            for (SequenceEvent& e : read_event((*ev)[k], k, filename, scene))
                seq.events.push_back(std::move(e));
        std::stable_sort(seq.events.begin(), seq.events.end(),
                         [](const SequenceEvent& a, const SequenceEvent& b) { return a.t0 < b.t0; });
        check_rotations(seq.events, scene);
    }

    // Default length: up to and including the last key (and its hold) or event end.
    double end = seq.keys.back().time_s + seq.keys.back().hold_s;
    for (const auto& e : seq.events) end = std::max(end, e.t1);
    double duration = end + 1.0 / seq.fps;
    if (auto d = top.optional("duration_s")) {
        duration = yaml_number(*d, filename, "duration_s");
        if (!(duration > 0.0))
            throw Error(loc_of(*d, filename), "duration_s must be > 0, got " + d->Scalar());
    }
    const double frames = std::round(duration * seq.fps);
    if (frames > kMaxFrames) {
        // The count can be far beyond any integer type (a time of 1e60 s): print it as a double.
        const std::string count =
            frames < 1e15 ? fmt::format("{:.0f}", frames) : fmt::format("{:.3g}", frames);
        throw Error(top.loc(), "the sequence has " + count + " frames; the limit is " +
                                   std::to_string(kMaxFrames) + " (lower fps or duration_s)");
    }
    seq.frames = std::max(1, static_cast<int>(frames));
    top.reject_unknown_keys("scene, fps, duration_s, image, camera, events");
    return seq;
}

Sequence load_sequence(const std::string& path, const Scene* scene) {
    return parse_sequence(read_input_file(path), path, scene);
}

}  // namespace radiosa
