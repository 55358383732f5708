// libFuzzer target: the cache reader on arbitrary bytes, against the seed scene. The checksum
// is repaired and the expected key taken from the input, so that mutations get past the
// integrity checks into the header, size, table and sense checks. A bad file must end in
// CacheFileError; anything else (a crash, a sanitizer report, another exception, an allocation
// beyond the scene's matrix: run with -malloc_limit_mb) is a bug. The same bytes also go
// through `cache verify`'s streaming reader, which has no scene to bound it. Bytes that start
// with the hierarchical-link file's magic go through its reader and verifier instead.
#include <xxhash.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "cache/cache_file.h"
#include "cache/link_file.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"

namespace {

const radiosa::Scene& seed() {
    static const radiosa::Scene scene = radiosa::load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    return scene;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const radiosa::SceneGeometry geometry(seed());
    std::vector<std::uint8_t> bytes(data, data + size);
    if (bytes.size() >= 8) {
        const std::uint64_t sum = XXH3_64bits(bytes.data(), bytes.size() - 8);
        for (int k = 0; k < 8; ++k) bytes[bytes.size() - 8 + k] = static_cast<std::uint8_t>(sum >> (8 * k));
    }
    radiosa::CacheExpectation expect{{}, &geometry, radiosa::FormFactorOptions(), seed().closed};
    if (bytes.size() >= 32) std::memcpy(expect.key.bytes.data(), bytes.data() + 16, 16);
    if (bytes.size() >= 8 && std::memcmp(bytes.data(), "RADHL", 5) == 0) {
        expect.options = radiosa::FormFactorOptions::hierarchical(radiosa::kDefaultLinkTolerance);
        try {
            (void)radiosa::read_link_bytes(bytes, expect);
        } catch (const radiosa::CacheFileError&) {
        }
        try {
            (void)radiosa::verify_link_bytes(bytes);
        } catch (const radiosa::CacheFileError&) {
        }
        return 0;
    }
    try {
        (void)radiosa::read_cache_bytes(bytes, expect);
    } catch (const radiosa::CacheFileError&) {
    }
    try {
        (void)radiosa::verify_cache_bytes(bytes);
    } catch (const radiosa::CacheFileError&) {
    }
    return 0;
}
