// The core side of the encode stage: finds the plugin once, forwards to it, and computes what
// needs no image library (frame names, sRGB bytes).
#include "encode/encode.h"

#include <dlfcn.h>
#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <mutex>

#include "encode/backend.h"
#include "util/error.h"

namespace radiosa {

namespace {

constexpr const char* kPluginName = "libradiosa_encode.so";

// The plugin beside the running executable (build/radiosa -> build/libradiosa_encode.so).
std::filesystem::path plugin_path() {
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? std::filesystem::path(kPluginName) : exe.parent_path() / kPluginName;
}

const EncodeBackend& load_backend() {
    // A process that links the plugin (the test binary) already has it: use that copy.
    using Entry = const EncodeBackend* (*)();
    auto entry = reinterpret_cast<Entry>(dlsym(RTLD_DEFAULT, "radiosa_encode_backend"));
    const std::filesystem::path path = plugin_path();
    if (!entry) {
        void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);  // never closed
        if (!handle)
            throw Error(
                fmt::format("cannot load the image and video writers ({}); rebuild radiosa with "
                            "'cmake --build build', which builds it beside the executable",
                            dlerror()));
        entry = reinterpret_cast<Entry>(dlsym(handle, "radiosa_encode_backend"));
    }
    const EncodeBackend* b = entry ? entry() : nullptr;
    if (!b || b->version != kEncodeBackendVersion)
        throw Error(path.string() + " is from another build of radiosa; rebuild with 'cmake --build build'");
    return *b;
}

const EncodeBackend& backend() {
    static std::once_flag once;
    static const EncodeBackend* b = nullptr;
    std::call_once(once, [] { b = &load_backend(); });  // a failed load throws and is retried
    return *b;
}

}  // namespace

void check_image_output(const std::string& path) { backend().check_image_output(path); }

void check_sequence_output(const std::string& path, int width, int height) {
    backend().check_sequence_output(path, width, height);
}

void write_image(const Image& image, const std::string& path, double exposure_stops) {
    backend().write_image(image, path, exposure_stops);
}

std::unique_ptr<FrameSink> make_frame_sink(const std::string& path, int width, int height,
                                           const SinkOptions& options) {
    return backend().make_frame_sink(path, width, height, options);
}

void write_indexed_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& index,
                       const std::vector<Colour8>& palette) {
    backend().write_indexed_png(path, width, height, index, palette);
}

void write_gif(const std::string& path, int width, int height, double fps,
               const std::vector<Colour8>& palette, const std::vector<std::vector<std::uint8_t>>& frames) {
    backend().write_gif(path, width, height, fps, palette, frames);
}

std::string frame_path(const std::string& pattern, int frame) {
    char buf[4096];
    std::snprintf(buf, sizeof buf, pattern.c_str(), frame);  // a runtime printf pattern: fmt cannot take it
    return buf;
}

unsigned char encode_srgb8(double v) {
    v = std::clamp(v, 0.0, 1.0);  // also maps NaN-free overexposure to white
    const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
    return static_cast<unsigned char>(std::lround(255.0 * s));
}

std::vector<unsigned char> to_srgb8(const Image& image, double exposure) {
    const double scale = std::exp2(exposure);
    std::vector<unsigned char> px(image.rgb.size());
    for (std::size_t i = 0; i < px.size(); ++i) px[i] = encode_srgb8(image.rgb[i] * scale);
    return px;
}

}  // namespace radiosa
