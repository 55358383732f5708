#pragma once
// What the rest of radiosa asks of the encode stage: stills (.png 8-bit sRGB, .exr linear
// float), sequences (H.264 .mp4, or numbered images such as out/frames/%04d.png) and palette
// outputs (.gif, indexed .png).
//
// The writers need OpenImageIO and FFmpeg's libav, which load ~260 shared libraries. They live
// in a plugin, libradiosa_encode.so beside the executable, loaded on the first call here, so
// that commands writing no image (formfactors, cache, accuracy) start in milliseconds
// (docs/architecture.md). Every function below throws Error on bad output paths or failed
// writes; a missing plugin is an Error that says how to rebuild it.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "encode/palette.h"
#include "render/image.h"

namespace radiosa {

struct SinkOptions {
    double fps = 30.0;
    double exposure = 0.0;  // stops, one for the whole sequence
    int crf = 18;
};

// Where the frames of a sequence go; the kind follows the path (.mp4, or a %d pattern).
class FrameSink {
public:
    virtual ~FrameSink() = default;
    virtual void write(int frame, const Image& image) = 0;
    // Completes the output (renames the video into place); not calling it leaves nothing.
    virtual void finish() = 0;
};

// Throw Error, before any work, when `path` is not a usable output.
void check_image_output(const std::string& path);
void check_sequence_output(const std::string& path, int width, int height);

// .exr: linear radiosity, 32-bit float, unscaled. Others (.png, .jpg, .tif): 8-bit sRGB of
// radiosity * 2^exposure clamped to [0, 1]: radiosity 1.0 is display white at exposure 0.
void write_image(const Image& image, const std::string& path, double exposure_stops);
std::unique_ptr<FrameSink> make_frame_sink(const std::string& path, int width, int height,
                                           const SinkOptions& options);
// Palette outputs: one indexed PNG, or a GIF of all frames (libav builds only).
void write_indexed_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& index,
                       const std::vector<Colour8>& palette);
void write_gif(const std::string& path, int width, int height, double fps,
               const std::vector<Colour8>& palette, const std::vector<std::vector<std::uint8_t>>& frames);

// ---- computed here, no plugin needed ----

// "out/%04d.png", 7 -> "out/0007.png" (the pattern is checked by check_sequence_output).
std::string frame_path(const std::string& pattern, int frame);
// 8-bit sRGB encoding of one linear value after exposure, and of a whole image.
unsigned char encode_srgb8(double linear);
std::vector<unsigned char> to_srgb8(const Image& image, double exposure);

}  // namespace radiosa
