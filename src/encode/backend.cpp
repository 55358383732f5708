// The encode plugin's entry point: libradiosa_encode.so, built from this file, image_io.cpp,
// frame_sink.cpp, video_writer.cpp (or no_video.cpp) and palette_av.cpp, and loaded by
// encode/encode.cpp on the first image or video a command writes.
#include "encode/backend.h"

#include "encode/frame_sink.h"
#include "encode/image_io.h"
#include "encode/palette_av.h"

namespace radiosa::media {
namespace {

void write_gif(const std::string& path, int width, int height, double fps,
               const std::vector<Colour8>& palette, const std::vector<std::vector<std::uint8_t>>& frames) {
    GifWriter gif(path, width, height, fps, palette);
    for (const auto& f : frames) gif.add_frame(f);
    gif.finish();
}

const EncodeBackend kBackend = {
    .version = kEncodeBackendVersion,
    .check_image_output = check_image_output,
    .check_sequence_output = check_sequence_output,
    .write_image = write_image,
    .make_frame_sink = make_frame_sink,
    .write_indexed_png = write_indexed_png,
    .write_gif = write_gif,
};

}  // namespace
}  // namespace radiosa::media

extern "C" const radiosa::EncodeBackend* radiosa_encode_backend() { return &radiosa::media::kBackend; }
