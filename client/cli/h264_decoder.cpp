#include "haarcast/client/h264_decoder.h"

#include <mutex>
#include <stdexcept>
#include <string>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libavutil/log.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}

namespace haarcast::client {

namespace {

[[noreturn]] void throwAv(const std::string& call, int code, const std::string& hint = "") {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  throw std::runtime_error("H.264: " + call + " failed: " + text + " (" + std::to_string(code) + ")" + hint);
}

}  // namespace

struct H264Decoder::Codec {
  AVCodecContext* context = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  SwsContext* toRgba = nullptr;

  ~Codec() {
    sws_freeContext(toRgba);
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&context);
  }
};

H264Decoder::H264Decoder() : codec_(std::make_unique<Codec>()) {
  // libavcodec logs every damaged slice on stderr; the errors that matter
  // come back from decode() as exceptions with the frame's number.
  static std::once_flag quiet;  // --clients N decoders start on several threads
  std::call_once(quiet, [] { av_log_set_level(AV_LOG_FATAL); });
  const AVCodec* h264 = avcodec_find_decoder(AV_CODEC_ID_H264);
  if (!h264) throw std::runtime_error("H.264: this libavcodec has no h264 decoder");
  codec_->context = avcodec_alloc_context3(h264);
  codec_->packet = av_packet_alloc();
  codec_->frame = av_frame_alloc();
  if (!codec_->context || !codec_->packet || !codec_->frame) throw std::runtime_error("H.264: out of memory");
  // One thread and low delay: frame threads would hold each picture back by
  // a frame per thread, and the stream has no B-frames to reorder.
  codec_->context->thread_count = 1;
  codec_->context->flags |= AV_CODEC_FLAG_LOW_DELAY;
  if (const int e = avcodec_open2(codec_->context, h264, nullptr); e < 0) throwAv("avcodec_open2(h264)", e);
}

H264Decoder::~H264Decoder() = default;

wire::Rgba8Image H264Decoder::decode(std::span<const std::uint8_t> annexB, std::uint32_t width, std::uint32_t height) {
  const std::string which = "frame " + std::to_string(frames_ + 1);
  if (annexB.empty()) throw std::runtime_error("H.264 " + which + " is empty");
  Codec& c = *codec_;
  // av_packet's data is not const, but the decoder only reads it.
  c.packet->data = const_cast<std::uint8_t*>(annexB.data());
  c.packet->size = static_cast<int>(annexB.size());
  const int sent = avcodec_send_packet(c.context, c.packet);
  av_packet_unref(c.packet);
  // Before the first picture, a failure most likely means the stream did
  // not start at a keyframe: the message says how to recover.
  const std::string hint = frames_ == 0 ? "; the stream must start at a keyframe (SPS, PPS, IDR): ask for one "
                                          "with PoseUpdate.keyframe"
                                        : "";
  if (sent < 0) throwAv("avcodec_send_packet(" + which + ")", sent, hint);
  const int got = avcodec_receive_frame(c.context, c.frame);
  if (got == AVERROR(EAGAIN)) throw std::runtime_error("H.264 " + which + " gave no picture" + hint);
  if (got < 0) throwAv("avcodec_receive_frame(" + which + ")", got, hint);
  ++frames_;

  const AVFrame& f = *c.frame;
  if (static_cast<std::uint32_t>(f.width) != width || static_cast<std::uint32_t>(f.height) != height) {
    const std::string decoded = std::to_string(f.width) + "x" + std::to_string(f.height);
    av_frame_unref(c.frame);
    throw std::runtime_error("H.264 " + which + " decodes to " + decoded + " but the Frame message says " +
                             std::to_string(width) + "x" + std::to_string(height));
  }
  c.toRgba = sws_getCachedContext(c.toRgba, f.width, f.height, static_cast<AVPixelFormat>(f.format), f.width,
                                  f.height, AV_PIX_FMT_RGBA, SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT,
                                  nullptr, nullptr, nullptr);
  if (!c.toRgba) {
    av_frame_unref(c.frame);
    const char* name = av_get_pix_fmt_name(static_cast<AVPixelFormat>(f.format));
    throw std::runtime_error(std::string("H.264: sws_getContext(") + (name ? name : "unknown pixel format") +
                             " → RGBA) failed");
  }
  // The matrix and range the stream's VUI states (sws_getCoefficients takes
  // the AVColorSpace numbers; unspecified reads as BT.601).
  const int* matrix = sws_getCoefficients(f.colorspace);
  const int fullRange = f.color_range == AVCOL_RANGE_JPEG ? 1 : 0;
  if (const int e = sws_setColorspaceDetails(c.toRgba, matrix, fullRange, matrix, 1, 0, 1 << 16, 1 << 16); e < 0) {
    av_frame_unref(c.frame);
    throwAv("sws_setColorspaceDetails", e);
  }
  wire::Rgba8Image out{width, height, std::vector<std::uint8_t>(std::size_t{width} * height * 4)};
  std::uint8_t* dst[1] = {out.pixels.data()};
  const int dstStride[1] = {static_cast<int>(width * 4)};
  const int rows = sws_scale(c.toRgba, f.data, f.linesize, 0, f.height, dst, dstStride);
  av_frame_unref(c.frame);
  if (rows != static_cast<int>(height)) {
    throw std::runtime_error("H.264: sws_scale wrote " + std::to_string(rows) + " rows of " + std::to_string(height));
  }
  return out;
}

}  // namespace haarcast::client
