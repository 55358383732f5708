#pragma once
// The table of writers the encode plugin (libradiosa_encode.so) hands to the program: the
// one interface between the core and the OpenImageIO / libav code (encode/encode.h).
#include "encode/encode.h"

namespace radiosa {

// Bumped whenever the table changes: a plugin from another build is refused, not called.
inline constexpr int kEncodeBackendVersion = 1;

struct EncodeBackend {
    int version;
    void (*check_image_output)(const std::string& path);
    void (*check_sequence_output)(const std::string& path, int width, int height);
    void (*write_image)(const Image& image, const std::string& path, double exposure_stops);
    std::unique_ptr<FrameSink> (*make_frame_sink)(const std::string& path, int width, int height,
                                                  const SinkOptions& options);
    void (*write_indexed_png)(const std::string& path, int width, int height,
                              const std::vector<std::uint8_t>& index, const std::vector<Colour8>& palette);
    void (*write_gif)(const std::string& path, int width, int height, double fps,
                      const std::vector<Colour8>& palette,
                      const std::vector<std::vector<std::uint8_t>>& frames);
};

}  // namespace radiosa

// The plugin's one exported entry point.
extern "C" const radiosa::EncodeBackend* radiosa_encode_backend();
