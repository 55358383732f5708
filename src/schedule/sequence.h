#pragma once
// An animation sequence (cameras/*.yaml with a `camera: {keys: ...}` timeline): a frame rate,
// camera keys with holds and cuts, and light/colour events. Plain data plus its evaluation
// at a time; the format is documented in docs/sequences.md.
#include <optional>
#include <string>
#include <vector>

#include "scene/camera.h"
#include "scene/scene.h"

namespace radiosa {

struct Scene;
class SceneGeometry;

enum class CameraInterpolation {
    Spline,        // cubic Hermite through the keys, Catmull-Rom tangents (time-weighted)
    ConstantSpeed  // piecewise linear: constant angular speed along an orbit
};

struct CameraKey {
    double time_s = 0.0;
    double hold_s = 0.0;  // stays at this key for hold_s after time_s
    bool cut = false;     // jump to this key at time_s instead of moving towards it
    // The paper's form (distance D, theta, phi around look_at), when given that way; these
    // are then what is interpolated, so an orbit stays an orbit.
    bool orbit = false;
    double distance = 6.0, theta_deg = 0.0, phi_deg = 90.0;
    CameraDesc camera;  // always filled (eye from the orbit form when orbit)
};

enum class EventProperty { Emission, Reflectance, Motion };

// A motion event's rotation: angle_deg degrees about `axis` through the point `about` (scene
// coordinates, where the surface stands in the scene file).
struct EventRotation {
    Vec3 axis{0.0, 0.0, 1.0};
    double angle_deg = 0.0;
    Vec3 about{0.0};
};

struct SequenceEvent {
    double t0 = 0.0, t1 = 0.0;  // a set when t0 == t1, else a linear ramp over [t0, t1]
    int surface = -1;
    std::optional<std::pair<int, int>> patch;  // (is, it); the whole surface when absent
    EventProperty property = EventProperty::Emission;
    Rgb value{0.0};
    // Motion: the surface's displacement from its place in the scene file (not an increment):
    // the rotation first, then the translation; either may be absent (that part is unchanged).
    std::optional<Vec3> translate;
    std::optional<EventRotation> rotate;
    FileLoc loc;
};

struct Sequence {
    std::string file;
    std::string scene_path;  // resolved against the sequence file's directory; "" if not given
    double fps = 30.0;
    int frames = 1;
    CameraInterpolation interpolation = CameraInterpolation::Spline;
    // Optional `image:` block: the size and sampling the sequence is meant for (the command
    // line's --width/--height/--samples win).
    std::optional<int> width, height, samples;
    std::vector<CameraKey> keys;        // sorted by time, at least one
    std::vector<SequenceEvent> events;  // sorted by start time (stable)

    double frame_time(int f) const { return f / fps; }
    CameraDesc camera_at(double t) const;
    // The scene's materials with every event applied as it stands at time t.
    Materials materials_at(const Materials& base, const SceneGeometry& geometry, double t) const;
    // Every surface's displacement at time t from its place in the scene file (the identity for
    // a surface no motion event has reached): applied after the surface's own transform.
    std::vector<Similarity> motion_at(int surface_count, double t) const;
    bool has_motion() const;
};

inline constexpr int kMaxFrames = 100000;

// Surface and patch names in events are resolved against `scene`.
Sequence parse_sequence(const std::string& yaml_text, const std::string& filename, const Scene* scene);
Sequence load_sequence(const std::string& path, const Scene* scene);
// The scene a sequence file names (`scene:`), resolved against its directory; "" if none.
std::string sequence_scene_path(const std::string& path);

}  // namespace radiosa
