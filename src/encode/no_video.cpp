// The libav-backed writers in a build configured with -DRADIOSA_VIDEO=OFF: each refuses with
// one message naming the file and the way out (encode/features.h). Outputs are checked before
// any work, so a run asking for them fails before anything is computed or written.
#include "encode/features.h"
#include "encode/palette_av.h"
#include "encode/video_writer.h"
#include "util/error.h"

namespace radiosa::media {

namespace {
[[noreturn]] void refuse(const std::string& path) { throw Error(path + ": " + kNoVideoMessage); }
}  // namespace

struct VideoWriter::Impl {};
VideoWriter::VideoWriter(const std::filesystem::path& path, const VideoOptions&) { refuse(path.string()); }
VideoWriter::~VideoWriter() = default;
void VideoWriter::add_frame(const std::vector<std::uint8_t>&) {}
void VideoWriter::finish() {}
void check_video_output(const std::filesystem::path& path, int, int) { refuse(path.string()); }
VideoProbe probe_video(const std::filesystem::path& path) { refuse(path.string()); }

void write_indexed_png(const std::string& path, int, int, const std::vector<std::uint8_t>&,
                       const std::vector<Colour8>&) {
    refuse(path);
}
struct GifWriter::Impl {};
GifWriter::GifWriter(const std::string& path, int, int, double, const std::vector<Colour8>&) { refuse(path); }
GifWriter::~GifWriter() = default;
void GifWriter::add_frame(const std::vector<std::uint8_t>&) {}
void GifWriter::finish() {}

}  // namespace radiosa::media
