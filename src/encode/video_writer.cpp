#include "encode/video_writer.h"

#include <cstdint>
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <cmath>
#include <string>

#include "encode/av_error.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace radiosa::media {

namespace fs = std::filesystem;

struct VideoWriter::Impl {
    fs::path path;
    AtomicFile file;
    AVFormatContext* fmt = nullptr;
    AVCodecContext* ctx = nullptr;
    AVStream* stream = nullptr;
    AVFrame* frame = nullptr;
    AVPacket* packet = nullptr;
    SwsContext* sws = nullptr;
    bool io_open = false;
    bool finished = false;

    explicit Impl(const fs::path& p) : path(p), file(p) {}
    ~Impl() {
        if (sws) sws_freeContext(sws);
        av_frame_free(&frame);
        av_packet_free(&packet);
        avcodec_free_context(&ctx);
        if (fmt && io_open) avio_closep(&fmt->pb);
        avformat_free_context(fmt);
    }

    // Moves every packet the encoder has ready into the file.
    void drain() {
        for (;;) {
            const int r = avcodec_receive_packet(ctx, packet);
            if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
            av_check(r, "avcodec_receive_packet", path);
            packet->duration = 1;  // libx264 leaves it 0; one frame in the codec time base
            av_packet_rescale_ts(packet, ctx->time_base, stream->time_base);
            packet->stream_index = stream->index;
            av_check(av_interleaved_write_frame(fmt, packet), "av_interleaved_write_frame", path);
        }
    }
};

void check_video_output(const fs::path& path, int width, int height) {
    check_output_path(path);
    if (width % 2 || height % 2)
        throw Error(path.string() + ": H.264 in yuv420p needs an even width and height, got " +
                    std::to_string(width) + "x" + std::to_string(height) + " (use --width/--height)");
}

VideoWriter::VideoWriter(const fs::path& path, const VideoOptions& o) : m(std::make_unique<Impl>(path)) {
    check_video_output(path, o.width, o.height);
    av_log_set_level(AV_LOG_ERROR);  // libx264's statistics are not for our users
    const std::string temp = m->file.temp_path().string();
    av_check(avformat_alloc_output_context2(&m->fmt, nullptr, "mp4", temp.c_str()),
             "avformat_alloc_output_context2", path);
    const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
    if (!codec) codec = avcodec_find_encoder(AV_CODEC_ID_H264);
    if (!codec) throw Error(path.string() + ": avcodec_find_encoder: this FFmpeg has no H.264 encoder");
    m->stream = avformat_new_stream(m->fmt, nullptr);
    if (!m->stream) throw Error(path.string() + ": avformat_new_stream failed");
    m->ctx = avcodec_alloc_context3(codec);
    if (!m->ctx) throw Error(path.string() + ": avcodec_alloc_context3 failed");

    // The frame rate as a rational: exact for integer rates, 1/1000 resolution otherwise.
    const AVRational rate = std::abs(o.fps - std::round(o.fps)) < 1e-9
                                ? AVRational{static_cast<int>(std::round(o.fps)), 1}
                                : AVRational{static_cast<int>(std::round(o.fps * 1000)), 1000};
    m->ctx->width = o.width;
    m->ctx->height = o.height;
    m->ctx->time_base = av_inv_q(rate);
    m->ctx->framerate = rate;
    m->ctx->pix_fmt = AV_PIX_FMT_YUV420P;
    m->ctx->gop_size = std::max(1, static_cast<int>(std::round(o.fps * 2)));
    m->ctx->color_primaries = AVCOL_PRI_BT709;
    m->ctx->color_trc = AVCOL_TRC_BT709;
    m->ctx->colorspace = AVCOL_SPC_BT709;
    m->ctx->color_range = AVCOL_RANGE_MPEG;
    if (m->fmt->oformat->flags & AVFMT_GLOBALHEADER) m->ctx->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    if (std::string(codec->name) == "libx264") {
        av_check(av_opt_set(m->ctx->priv_data, "preset", o.preset, 0), "av_opt_set(preset)", path);
        av_check(av_opt_set(m->ctx->priv_data, "crf", std::to_string(o.crf).c_str(), 0), "av_opt_set(crf)",
                 path);
    }
    av_check(avcodec_open2(m->ctx, codec, nullptr), "avcodec_open2", path);
    av_check(avcodec_parameters_from_context(m->stream->codecpar, m->ctx), "avcodec_parameters_from_context",
             path);
    m->stream->time_base = m->ctx->time_base;
    m->stream->avg_frame_rate = rate;
    av_check(avio_open(&m->fmt->pb, temp.c_str(), AVIO_FLAG_WRITE), "avio_open", path);
    m->io_open = true;
    av_check(avformat_write_header(m->fmt, nullptr), "avformat_write_header", path);

    m->frame = av_frame_alloc();
    m->packet = av_packet_alloc();
    if (!m->frame || !m->packet) throw Error(path.string() + ": av_frame_alloc/av_packet_alloc failed");
    m->frame->format = AV_PIX_FMT_YUV420P;
    m->frame->width = o.width;
    m->frame->height = o.height;
    m->frame->color_primaries = AVCOL_PRI_BT709;
    m->frame->color_trc = AVCOL_TRC_BT709;
    m->frame->colorspace = AVCOL_SPC_BT709;
    m->frame->color_range = AVCOL_RANGE_MPEG;
    av_check(av_frame_get_buffer(m->frame, 0), "av_frame_get_buffer", path);

    m->sws = sws_getContext(o.width, o.height, AV_PIX_FMT_RGB24, o.width, o.height, AV_PIX_FMT_YUV420P,
                            SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr, nullptr, nullptr);
    if (!m->sws) throw Error(path.string() + ": sws_getContext failed");
    // swscale defaults to BT.601; the stream is tagged BT.709, so convert with BT.709.
    const int* bt709 = sws_getCoefficients(SWS_CS_ITU709);
    av_check(sws_setColorspaceDetails(m->sws, bt709, 1, bt709, 0, 0, 1 << 16, 1 << 16),
             "sws_setColorspaceDetails", path);
}

VideoWriter::~VideoWriter() = default;

void VideoWriter::add_frame(const std::vector<std::uint8_t>& rgb) {
    const int w = m->ctx->width, h = m->ctx->height;
    if (rgb.size() != static_cast<std::size_t>(w) * h * 3)
        throw Error(m->path.string() + ": frame size does not match the video");
    av_check(av_frame_make_writable(m->frame), "av_frame_make_writable", m->path);
    const std::uint8_t* src[1] = {rgb.data()};
    const int stride[1] = {3 * w};
    av_check(sws_scale(m->sws, src, stride, 0, h, m->frame->data, m->frame->linesize), "sws_scale", m->path);
    m->frame->pts = m_frames++;
    av_check(avcodec_send_frame(m->ctx, m->frame), "avcodec_send_frame", m->path);
    m->drain();
}

void VideoWriter::finish() {
    if (m->finished) return;
    av_check(avcodec_send_frame(m->ctx, nullptr), "avcodec_send_frame(flush)", m->path);
    m->drain();
    av_check(av_write_trailer(m->fmt), "av_write_trailer", m->path);
    av_check(avio_closep(&m->fmt->pb), "avio_closep", m->path);
    m->io_open = false;
    m->file.commit();
    m->finished = true;
}

VideoProbe probe_video(const fs::path& path) {
    VideoProbe p;
    AVFormatContext* fmt = nullptr;
    av_check(avformat_open_input(&fmt, path.c_str(), nullptr, nullptr), "avformat_open_input", path);
    struct Closer {
        AVFormatContext** f;
        ~Closer() { avformat_close_input(f); }
    } closer{&fmt};
    av_check(avformat_find_stream_info(fmt, nullptr), "avformat_find_stream_info", path);
    const int si = av_check(av_find_best_stream(fmt, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0),
                            "av_find_best_stream", path);
    const AVStream* st = fmt->streams[si];
    p.duration_s = fmt->duration > 0 ? fmt->duration / static_cast<double>(AV_TIME_BASE) : 0.0;
    p.fps = av_q2d(st->avg_frame_rate);
    p.width = st->codecpar->width;
    p.height = st->codecpar->height;
    p.codec = avcodec_get_name(st->codecpar->codec_id);
    AVPacket* pkt = av_packet_alloc();
    while (av_read_frame(fmt, pkt) >= 0) {
        if (pkt->stream_index == si) ++p.frames;
        av_packet_unref(pkt);
    }
    av_packet_free(&pkt);
    return p;
}

}  // namespace radiosa::media
