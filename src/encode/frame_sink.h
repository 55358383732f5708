#pragma once
// Where the frames of a sequence go; the kind follows the -o path:
//   *.mp4                      H.264 video (VideoWriter)
//   a pattern with %d / %04d   one image per frame, e.g. out/frames/%04d.png or %04d.exr
#include <memory>
#include <string>

#include "render/raycast.h"

namespace radiosa {

struct SinkOptions {
    double fps = 30.0;
    double exposure = 0.0;  // stops, one for the whole sequence
    int crf = 18;
};

class FrameSink {
public:
    virtual ~FrameSink() = default;
    virtual void write(int frame, const Image& image) = 0;
    // Completes the output (renames the video into place); not calling it leaves nothing.
    virtual void finish() = 0;
};

// Throws Error, before any work, when `path` is not a usable sequence output.
void check_sequence_output(const std::string& path, int width, int height);
std::unique_ptr<FrameSink> make_frame_sink(const std::string& path, int width, int height, const SinkOptions& options);

// "out/%04d.png", 7 -> "out/0007.png" (the pattern is checked by check_sequence_output).
std::string frame_path(const std::string& pattern, int frame);

// 8-bit sRGB bytes of a linear image after exposure, as in PNG outputs.
std::vector<unsigned char> to_srgb8(const Image& image, double exposure);

}  // namespace radiosa
