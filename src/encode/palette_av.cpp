// Indexed PNG frames and GIF animations through libav's png and gif encoders (built only with
// RADIOSA_VIDEO=ON; see encode/no_video.cpp).
#include "encode/palette_av.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
}

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "encode/av_error.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace radiosa::media {

namespace {

// An encoder context for PAL8 frames with `codec_id`, and one reusable frame.
struct Pal8Encoder {
    AVCodecContext* ctx = nullptr;
    AVFrame* frame = nullptr;
    AVPacket* packet = nullptr;
    std::string path;
    Pal8Encoder(AVCodecID id, int w, int h, AVRational time_base, const std::vector<Colour8>& palette,
                std::string p, bool global_header)
        : path(std::move(p)) {
        av_log_set_level(AV_LOG_ERROR);
        const AVCodec* codec = avcodec_find_encoder(id);
        if (!codec) throw Error(path + ": avcodec_find_encoder: no " + avcodec_get_name(id) + " encoder");
        ctx = avcodec_alloc_context3(codec);
        frame = av_frame_alloc();
        packet = av_packet_alloc();
        if (!ctx || !frame || !packet) throw Error(path + ": libav allocation failed");
        ctx->width = w;
        ctx->height = h;
        ctx->pix_fmt = AV_PIX_FMT_PAL8;
        ctx->time_base = time_base;
        if (global_header) ctx->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
        av_check(avcodec_open2(ctx, codec, nullptr), "avcodec_open2", path);
        frame->format = AV_PIX_FMT_PAL8;
        frame->width = w;
        frame->height = h;
        av_check(av_frame_get_buffer(frame, 0), "av_frame_get_buffer", path);
        auto* pal = reinterpret_cast<std::uint32_t*>(frame->data[1]);
        for (int k = 0; k < 256; ++k) {
            const Colour8 c = k < static_cast<int>(palette.size()) ? palette[k] : Colour8{0, 0, 0};
            pal[k] = 0xff000000u | (std::uint32_t(c[0]) << 16) | (std::uint32_t(c[1]) << 8) | c[2];
        }
    }
    ~Pal8Encoder() {
        av_frame_free(&frame);
        av_packet_free(&packet);
        avcodec_free_context(&ctx);
    }
    void send(const std::vector<std::uint8_t>* index, std::int64_t pts) {
        if (!index) {
            av_check(avcodec_send_frame(ctx, nullptr), "avcodec_send_frame(flush)", path);
            return;
        }
        av_check(av_frame_make_writable(frame), "av_frame_make_writable", path);
        for (int y = 0; y < ctx->height; ++y)
            std::copy_n(index->data() + static_cast<std::size_t>(y) * ctx->width, ctx->width,
                        frame->data[0] + static_cast<std::size_t>(y) * frame->linesize[0]);
        frame->pts = pts;
        av_check(avcodec_send_frame(ctx, frame), "avcodec_send_frame", path);
    }
    // Calls `take` for every packet ready.
    template <class F>
    void drain(F take) {
        for (;;) {
            const int r = avcodec_receive_packet(ctx, packet);
            if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
            av_check(r, "avcodec_receive_packet", path);
            take(packet);
            av_packet_unref(packet);
        }
    }
};

}  // namespace

void write_indexed_png(const std::string& path, int w, int h, const std::vector<std::uint8_t>& index,
                       const std::vector<Colour8>& palette) {
    Pal8Encoder enc(AV_CODEC_ID_PNG, w, h, AVRational{1, 1}, palette, path, false);
    std::string bytes;
    auto take = [&](AVPacket* p) { bytes.append(reinterpret_cast<const char*>(p->data), p->size); };
    enc.send(&index, 0);
    enc.drain(take);
    enc.send(nullptr, 0);
    enc.drain(take);
    write_text_file(path, bytes);
}

struct GifWriter::Impl {
    std::string path;
    AtomicFile file;
    AVFormatContext* fmt = nullptr;
    AVStream* stream = nullptr;
    std::unique_ptr<Pal8Encoder> enc;
    bool io_open = false;
    double fps;
    std::int64_t frames = 0;
    Impl(const std::string& p, double f) : path(p), file(p), fps(f) {}
    ~Impl() {
        enc.reset();
        if (fmt && io_open) avio_closep(&fmt->pb);
        avformat_free_context(fmt);
    }
    void drain() {
        enc->drain([&](AVPacket* p) {
            av_packet_rescale_ts(p, enc->ctx->time_base, stream->time_base);
            p->stream_index = stream->index;
            av_check(av_interleaved_write_frame(fmt, p), "av_interleaved_write_frame", path);
        });
    }
};

GifWriter::GifWriter(const std::string& path, int w, int h, double fps, const std::vector<Colour8>& palette)
    : m(std::make_unique<Impl>(path, fps)) {
    {
        check_output_path(path);
        const std::string temp = m->file.temp_path().string();
        av_check(avformat_alloc_output_context2(&m->fmt, nullptr, "gif", temp.c_str()),
                 "avformat_alloc_output_context2", path);
        m->stream = avformat_new_stream(m->fmt, nullptr);
        if (!m->stream) throw Error(path + ": avformat_new_stream failed");
        // GIF delays are in centiseconds.
        m->enc = std::make_unique<Pal8Encoder>(AV_CODEC_ID_GIF, w, h, AVRational{1, 100}, palette, path,
                                               (m->fmt->oformat->flags & AVFMT_GLOBALHEADER) != 0);
        av_check(avcodec_parameters_from_context(m->stream->codecpar, m->enc->ctx),
                 "avcodec_parameters_from_context", path);
        m->stream->time_base = AVRational{1, 100};
        av_check(avio_open(&m->fmt->pb, temp.c_str(), AVIO_FLAG_WRITE), "avio_open", path);
        m->io_open = true;
        av_check(avformat_write_header(m->fmt, nullptr), "avformat_write_header", path);
    }
}

GifWriter::~GifWriter() = default;

void GifWriter::add_frame(const std::vector<std::uint8_t>& index) {
    m->enc->send(&index, static_cast<std::int64_t>(std::llround(m->frames * 100.0 / m->fps)));
    ++m->frames;
    m->drain();
}

void GifWriter::finish() {
    m->enc->send(nullptr, 0);
    m->drain();
    av_check(av_write_trailer(m->fmt), "av_write_trailer", m->path);
    av_check(avio_closep(&m->fmt->pb), "avio_closep", m->path);
    m->io_open = false;
    m->file.commit();
}

}  // namespace radiosa::media
