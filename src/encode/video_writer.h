#pragma once
// H.264 in MP4 with FFmpeg's libav (libavcodec/libavformat/libswscale): 8-bit sRGB frames in,
// yuv420p BT.709 out, constant frame rate. Written under a temporary name and renamed by
// finish(); a writer destroyed without finish() removes its temporary file. Every libav call
// is checked: a failure throws Error naming the call and the file. A build with
// -DRADIOSA_VIDEO=OFF has no libav: every function here then throws Error (no_video.cpp).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace radiosa::media {

struct VideoOptions {
    int width = 0, height = 0;  // both even (yuv420p)
    double fps = 30.0;
    int crf = 18;  // x264 constant rate factor: 0 lossless ... 51 worst; 18 ~ visually lossless
    const char* preset = "medium";
};

class VideoWriter {
public:
    VideoWriter(const std::filesystem::path& path, const VideoOptions& options);
    ~VideoWriter();
    VideoWriter(const VideoWriter&) = delete;
    VideoWriter& operator=(const VideoWriter&) = delete;

    // rgb: width*height*3 bytes, sRGB, top row first.
    void add_frame(const std::vector<std::uint8_t>& rgb);
    void finish();
    int frames() const { return m_frames; }

private:
    struct Impl;
    std::unique_ptr<Impl> m;
    int m_frames = 0;
};

// Throws Error when an MP4 of this size cannot be written to `path` (odd size, bad directory).
void check_video_output(const std::filesystem::path& path, int width, int height);

// What libavformat reads back from a video file (for tests and checks).
struct VideoProbe {
    int frames = 0;           // decoded frames
    double duration_s = 0.0;  // container duration
    double fps = 0.0;         // stream average frame rate
    int width = 0, height = 0;
    std::string codec;
};
VideoProbe probe_video(const std::filesystem::path& path);

}  // namespace radiosa::media
