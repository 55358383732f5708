// libFuzzer target: the sequence reader on arbitrary bytes, against the seed scene, and the
// evaluation of every accepted sequence at a few times.
#include <cstddef>
#include <cstdint>
#include <string>

#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "schedule/sequence.h"
#include "util/error.h"

namespace {
const radiosa::Scene& seed() {
    static const radiosa::Scene s = radiosa::load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    return s;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const radiosa::SceneGeometry geometry(seed());
    static const radiosa::Materials base = radiosa::patch_materials(seed());
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const radiosa::Sequence seq = radiosa::parse_sequence(text, "fuzz.yaml", &seed());
        for (int f : {0, seq.frames / 2, seq.frames - 1}) {
            const double t = seq.frame_time(f);
            (void)seq.camera_at(t);
            (void)seq.materials_at(base, geometry, t);
        }
    } catch (const radiosa::Error&) {
    }
    return 0;
}
