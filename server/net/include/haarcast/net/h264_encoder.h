// The H.264 frame encoder of one session (ENCODING_H264): libavcodec with
// libx264, software encoding (datacenter GPUs such as the H100 have no video
// encoder), tuned for interactive streaming:
//
//   - one Annex-B access unit out per frame in (tune=zerolatency: no
//     lookahead, no B-frames, no frame threads), so a Frame message always
//     carries the picture of its own pose; a frame held back is a broken
//     invariant (std::logic_error naming the counts), never a silent delay;
//   - SPS and PPS in band before every IDR, so a decoder that starts at any
//     keyframe can decode; the first frame, the first after a size or
//     settings change and the one after requestKeyframe() are IDRs, and one
//     comes every `keyframeInterval` frames;
//   - rate control: constant quality (CRF kH264Crf) under a cap, the VBV
//     maxrate `bitrateKbps` with one second of buffer: a still view costs
//     little, a moving one never more than the cap;
//   - colour: the tonemapped sRGB RGBA8 image (row 0 at the top) → YUV 4:2:0
//     with the BT.709 matrix, limited range (Y 16..235, Cb/Cr 16..240); the
//     SPS's VUI says so (primaries BT.709, transfer sRGB), and the decoders
//     (client/cli/h264_decoder, client/web/h264_decoder.js) use the same;
//   - even width and height only (4:2:0 halves both): an odd size is refused
//     with std::invalid_argument, as are settings outside their ranges.
//
// Not thread-safe: one session's frames are encoded in order, one at a time.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace haarcast::net {

inline constexpr int kDefaultH264BitrateKbps = 4000;   // the encoder's own default (a session's follows its size)
inline constexpr int kMinH264BitrateKbps = 100;
inline constexpr int kMaxH264BitrateKbps = 50000;      // Welcome.limits.max_h264_bitrate_kbps
inline constexpr int kDefaultH264KeyframeInterval = 120;  // frames; 4 s at 30 fps
inline constexpr int kMaxH264KeyframeInterval = 10000;
inline constexpr int kH264Crf = 23;  // x264's default quality; the cap above bounds the bits
// x264's speed preset. Measured on one core (thread CPU time, 120 frames of
// an orbiting shaded disc over a gradient, with and without ±8 levels of
// per-pixel noise): ultrafast 0.26–0.47 ms at 256², 1.0–1.9 ms at 512²;
// veryfast 0.6–1.6 ms and 2.4–5.3 ms, for 10–35 % fewer bytes. Both are far
// inside a 30 fps budget; bandwidth is what a session is charged for, so
// veryfast (CABAC, 8×8 transform: High profile).
inline constexpr const char* kH264Preset = "veryfast";

// The bitrate cap of a session that sets none: it follows the frame size
// and rate, kH264DefaultBitsPerPixel bits per pixel per frame (a still view
// costs far less: constant quality under the cap), within
// kMinDefaultH264BitrateKbps..kMaxDefaultH264BitrateKbps. 0.1 bit per pixel
// gives 2.8 Mbit/s at 1280×720 and 6.2 Mbit/s at 1920×1080, 30 fps: the
// rates streaming services ask for at those sizes.
inline constexpr double kH264DefaultBitsPerPixel = 0.1;
inline constexpr int kMinDefaultH264BitrateKbps = 1000;
inline constexpr int kMaxDefaultH264BitrateKbps = 20000;
int defaultH264BitrateKbps(int width, int height, double fps);

struct H264Settings {
  int width = 0;   // even, 2..io::kMaxImageDimension
  int height = 0;  // even
  int bitrateKbps = kDefaultH264BitrateKbps;           // kMinH264BitrateKbps..kMaxH264BitrateKbps
  int keyframeInterval = kDefaultH264KeyframeInterval;  // 1..kMaxH264KeyframeInterval
  double fps = 30.0;  // the session's frame rate cap: how rate control turns kbit/s into bits per frame
  std::string preset = kH264Preset;  // an x264 preset name ("ultrafast", "veryfast", …)

  bool operator==(const H264Settings&) const = default;
};

// Throws std::invalid_argument naming the field, its value and the valid
// range. The encoder calls it; the protocol layer can too, to answer a
// Hello or RenderSettings with BAD_RESOLUTION / BAD_SETTINGS before any work.
void validateH264Settings(const H264Settings& settings);

struct H264AccessUnit {
  std::string annexB;     // NAL units with 00 00 00 01 start codes: a Frame's `data`
  bool keyframe = false;  // an IDR, preceded by SPS and PPS
  std::int64_t index = 0; // frames encoded since the last (re)start, from 0
};

class H264Encoder {
 public:
  explicit H264Encoder(const H264Settings& settings);
  ~H264Encoder();
  H264Encoder(const H264Encoder&) = delete;
  H264Encoder& operator=(const H264Encoder&) = delete;

  // Encodes one frame: rgba8 holds width·height·4 bytes, row 0 at the top.
  // A size that differs from the settings' restarts the encoder at that size
  // (the result is a keyframe). Throws std::runtime_error naming the
  // libavcodec call and its AVERROR text.
  H264AccessUnit encode(const std::vector<std::uint8_t>& rgba8, int width, int height);

  // The next encode() returns a keyframe (a client joined or lost the stream).
  void requestKeyframe() { keyframeRequested_ = true; }

  // New settings take effect at the next frame, which is then a keyframe;
  // the same settings change nothing. Throws like validateH264Settings.
  void reconfigure(const H264Settings& settings);

  const H264Settings& settings() const { return settings_; }

 private:
  struct Codec;  // the libavcodec and libswscale state
  void open();

  H264Settings settings_;
  std::unique_ptr<Codec> codec_;
  bool keyframeRequested_ = false;
};

// The NAL unit types an Annex-B buffer holds, in order (5 = IDR slice,
// 7 = SPS, 8 = PPS, 1 = non-IDR slice, 6 = SEI): for tests and for the
// clients' key/delta decision.
std::vector<int> h264NalTypes(const std::string& annexB);

}  // namespace haarcast::net
