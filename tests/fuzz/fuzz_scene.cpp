// libFuzzer target: the scene and camera readers on arbitrary bytes. Bad input must end in
// radiosa::Error (one clear message); anything else — a crash, a sanitizer report, another
// exception type escaping — is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "geometry/scene_geometry.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const radiosa::Scene scene = radiosa::parse_scene(text, "fuzz.yaml");
        if (scene.patch_count() <= 2000) {
            const radiosa::SceneGeometry geometry(scene);  // every accepted scene must build
            (void)geometry.scale();
        }
    } catch (const radiosa::Error&) {
    }
    try {
        (void)radiosa::parse_camera(text, "fuzz.yaml");
    } catch (const radiosa::Error&) {
    }
    return 0;
}
