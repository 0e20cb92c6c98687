#include "haarcast/net/h264_encoder.h"

#include <mutex>
#include <stdexcept>
#include <string>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/dict.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libavutil/log.h>
#include <libavutil/rational.h>
#include <libswscale/swscale.h>
}

namespace haarcast::net {
namespace {

std::string averrorText(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

// A libavcodec or libswscale call that returned an error: the message names
// the call and libavutil's text for the code.
[[noreturn]] void throwAv(const char* call, int code) {
  throw std::runtime_error(std::string("h264: ") + call + " failed: " + averrorText(code) + " (" +
                           std::to_string(code) + ")");
}

// libx264 reports every open and close (CPU flags, a line of statistics per
// frame type) on stderr through av_log; one per session would drown the
// server's own session lines. Errors still come through.
void quietLibav() {
  static std::once_flag once;
  std::call_once(once, [] { av_log_set_level(AV_LOG_ERROR); });
}

}  // namespace

struct H264Encoder::Codec {
  AVCodecContext* context = nullptr;
  SwsContext* toYuv = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  std::int64_t index = 0;  // frames sent since open: the pts

  ~Codec() {
    sws_freeContext(toYuv);
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&context);
  }
};

H264Encoder::H264Encoder(const H264Settings& settings) : settings_(settings) {
  validateH264Settings(settings_);
  open();
}

H264Encoder::~H264Encoder() = default;

void H264Encoder::open() {
  quietLibav();
  codec_.reset();  // the previous stream's state goes first: no two x264 instances per session
  auto c = std::make_unique<Codec>();
  const AVCodec* x264 = avcodec_find_encoder_by_name("libx264");
  if (!x264) {
    throw std::runtime_error("h264: this libavcodec has no libx264 encoder (Debian's libavcodec59 has it)");
  }
  c->context = avcodec_alloc_context3(x264);
  c->frame = av_frame_alloc();
  c->packet = av_packet_alloc();
  if (!c->context || !c->frame || !c->packet) throw std::runtime_error("h264: out of memory allocating the encoder");

  AVCodecContext* ctx = c->context;
  ctx->width = settings_.width;
  ctx->height = settings_.height;
  ctx->pix_fmt = AV_PIX_FMT_YUV420P;
  const AVRational rate = av_d2q(settings_.fps, 1000);
  ctx->framerate = rate;
  ctx->time_base = av_inv_q(rate);
  ctx->gop_size = settings_.keyframeInterval;
  ctx->max_b_frames = 0;  // a B-frame waits for a later frame: latency
  // One thread: sessions are encoded in parallel by the server's pool, so a
  // session's cost stays one core at most; x264's frame threads would also
  // delay output by a frame per thread.
  ctx->thread_count = 1;
  // The cap: VBV maxrate with one second of buffer; quality is CRF below it.
  ctx->rc_max_rate = std::int64_t{settings_.bitrateKbps} * 1000;
  ctx->rc_buffer_size = settings_.bitrateKbps * 1000;
  ctx->color_range = AVCOL_RANGE_MPEG;
  ctx->colorspace = AVCOL_SPC_BT709;
  ctx->color_primaries = AVCOL_PRI_BT709;
  ctx->color_trc = AVCOL_TRC_IEC61966_2_1;  // the frames are sRGB-encoded (render/tonemap.h)

  AVDictionary* options = nullptr;
  av_dict_set(&options, "preset", settings_.preset.c_str(), 0);
  av_dict_set(&options, "tune", "zerolatency", 0);
  av_dict_set_int(&options, "crf", kH264Crf, 0);
  av_dict_set_int(&options, "forced-idr", 1, 0);  // a requested keyframe is an IDR, not an open-GOP I
  // No scene-cut keyframes: keyframes come at the interval and on request
  // only, so their cost is the session's choice.
  av_dict_set(&options, "x264-params", "scenecut=0:repeat-headers=1", 0);
  const int opened = avcodec_open2(ctx, x264, &options);
  AVDictionaryEntry* unused = av_dict_get(options, "", nullptr, AV_DICT_IGNORE_SUFFIX);
  const std::string unusedName = unused ? unused->key : "";
  av_dict_free(&options);
  if (opened < 0) throwAv(("avcodec_open2(libx264, preset " + settings_.preset + ")").c_str(), opened);
  if (!unusedName.empty()) throw std::logic_error("h264: libx264 did not take the option \"" + unusedName + "\"");

  c->frame->format = AV_PIX_FMT_YUV420P;
  c->frame->width = settings_.width;
  c->frame->height = settings_.height;
  c->frame->color_range = AVCOL_RANGE_MPEG;
  c->frame->colorspace = AVCOL_SPC_BT709;
  if (const int e = av_frame_get_buffer(c->frame, 0); e < 0) throwAv("av_frame_get_buffer", e);

  // RGBA (full range by nature) → BT.709 limited-range YUV 4:2:0; accurate
  // rounding so a flat grey stays flat.
  c->toYuv = sws_getContext(settings_.width, settings_.height, AV_PIX_FMT_RGBA, settings_.width, settings_.height,
                            AV_PIX_FMT_YUV420P, SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INP, nullptr,
                            nullptr, nullptr);
  if (!c->toYuv) throw std::runtime_error("h264: sws_getContext(RGBA → YUV420P) failed");
  const int* bt709 = sws_getCoefficients(SWS_CS_ITU709);
  if (const int e = sws_setColorspaceDetails(c->toYuv, bt709, 1, bt709, 0, 0, 1 << 16, 1 << 16); e < 0) {
    throwAv("sws_setColorspaceDetails(BT.709, limited range)", e);
  }
  codec_ = std::move(c);
  keyframeRequested_ = true;  // a new stream starts with SPS, PPS and an IDR
}

void H264Encoder::reconfigure(const H264Settings& settings) {
  if (settings == settings_) return;
  validateH264Settings(settings);
  settings_ = settings;
  open();
}

H264AccessUnit H264Encoder::encode(const std::vector<std::uint8_t>& rgba8, int width, int height) {
  if (width != settings_.width || height != settings_.height) {
    H264Settings resized = settings_;
    resized.width = width;
    resized.height = height;
    reconfigure(resized);  // validates: an odd or out-of-range size throws here
  }
  const std::size_t expected = std::size_t(width) * std::size_t(height) * 4;
  if (rgba8.size() != expected) {
    throw std::invalid_argument("h264: RGBA8 buffer holds " + std::to_string(rgba8.size()) + " bytes, " +
                                std::to_string(width) + "x" + std::to_string(height) + " needs " +
                                std::to_string(expected));
  }
  if (!codec_) open();  // a failed restart left none: try again, or throw the same error
  Codec& c = *codec_;
  if (const int e = av_frame_make_writable(c.frame); e < 0) throwAv("av_frame_make_writable", e);
  const std::uint8_t* src[1] = {rgba8.data()};
  const int srcStride[1] = {width * 4};
  const int rows = sws_scale(c.toYuv, src, srcStride, 0, height, c.frame->data, c.frame->linesize);
  if (rows != height) {
    throw std::logic_error("h264: sws_scale wrote " + std::to_string(rows) + " rows, the frame has " +
                           std::to_string(height));
  }
  c.frame->pts = c.index;
  c.frame->pict_type = keyframeRequested_ ? AV_PICTURE_TYPE_I : AV_PICTURE_TYPE_NONE;
  keyframeRequested_ = false;

  if (const int e = avcodec_send_frame(c.context, c.frame); e < 0) throwAv("avcodec_send_frame", e);
  const std::int64_t sent = ++c.index;
  const int received = avcodec_receive_packet(c.context, c.packet);
  if (received == AVERROR(EAGAIN)) {
    // zerolatency promises one access unit per frame in; a held frame would
    // show the client an older pose than the Frame message names.
    throw std::logic_error("h264: libx264 held frame " + std::to_string(sent - 1) + " back (frames sent " +
                           std::to_string(sent) + ", access units out " + std::to_string(sent - 1) +
                           "); tune=zerolatency must emit one per frame");
  }
  if (received < 0) throwAv("avcodec_receive_packet", received);
  H264AccessUnit out;
  out.annexB.assign(reinterpret_cast<const char*>(c.packet->data), static_cast<std::size_t>(c.packet->size));
  out.keyframe = (c.packet->flags & AV_PKT_FLAG_KEY) != 0;
  out.index = sent - 1;
  av_packet_unref(c.packet);
  const int extra = avcodec_receive_packet(c.context, c.packet);
  if (extra != AVERROR(EAGAIN)) {
    av_packet_unref(c.packet);
    throw std::logic_error("h264: libx264 returned a second access unit for frame " + std::to_string(out.index) +
                           " (receive_packet → " + averrorText(extra) + "); one per frame expected");
  }
  return out;
}

}  // namespace haarcast::net
