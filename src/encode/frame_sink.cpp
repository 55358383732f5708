// Part of the encode plugin: the sequence outputs (.mp4 through libav, numbered images through
// OpenImageIO).
#include "encode/frame_sink.h"

#include <cctype>
#include <cmath>
#include <cstdio>

#include "encode/image_io.h"
#include "encode/video_writer.h"
#include "util/error.h"

namespace radiosa::media {

namespace {

bool is_video(const std::string& path) {
    return path.size() > 4 && (path.ends_with(".mp4") || path.ends_with(".MP4"));
}

class VideoSink : public FrameSink {
public:
    VideoSink(const std::string& path, int w, int h, const SinkOptions& o) : m_exposure(o.exposure) {
        VideoOptions vo;
        vo.width = w;
        vo.height = h;
        vo.fps = o.fps;
        vo.crf = o.crf;
        m_writer = std::make_unique<VideoWriter>(path, vo);
    }
    void write(int, const Image& image) override { m_writer->add_frame(to_srgb8(image, m_exposure)); }
    void finish() override { m_writer->finish(); }

private:
    double m_exposure;
    std::unique_ptr<VideoWriter> m_writer;
};

class ImageSequenceSink : public FrameSink {
public:
    ImageSequenceSink(std::string pattern, double exposure)
        : m_pattern(std::move(pattern)), m_exposure(exposure) {}
    void write(int frame, const Image& image) override {
        media::write_image(image, frame_path(m_pattern, frame), m_exposure);
    }
    void finish() override {}

private:
    std::string m_pattern;
    double m_exposure;
};

}  // namespace

void check_sequence_output(const std::string& path, int width, int height) {
    if (is_video(path)) {
        check_video_output(path, width, height);
        return;
    }
    // Exactly one conversion, %d or %0Nd with one digit N, and no other '%'.
    const std::size_t at = path.find('%');
    bool ok = at != std::string::npos && path.size() < 4000;
    std::size_t end = at + 1;
    if (ok && path[end] == '0') ++end;
    if (ok && end < path.size() && std::isdigit(static_cast<unsigned char>(path[end]))) ++end;
    ok = ok && end < path.size() && path[end] == 'd' && path.find('%', end) == std::string::npos;
    if (!ok)
        throw Error(path +
                    ": a sequence is written as a video (.mp4) or as numbered images with one %d or %04d "
                    "in the name, e.g. out/frames/%04d.png");
    check_image_output(frame_path(path, 0));
}

std::unique_ptr<FrameSink> make_frame_sink(const std::string& path, int w, int h, const SinkOptions& o) {
    check_sequence_output(path, w, h);
    if (is_video(path)) return std::make_unique<VideoSink>(path, w, h, o);
    return std::make_unique<ImageSequenceSink>(path, o.exposure);
}

}  // namespace radiosa::media
