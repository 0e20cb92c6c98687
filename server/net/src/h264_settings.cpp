// The H.264 settings' rules and the Annex-B scan: pure, built with or
// without libavcodec (HAARCAST_H264), so the protocol checks a session's
// H.264 settings and the tests read NAL types in every build.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "haarcast/io/image.h"
#include "haarcast/net/h264_encoder.h"

namespace haarcast::net {
namespace {

// Shortest form: "4096", "0.01", not std::to_string's "4096.000000".
std::string numberText(double v) {
  std::ostringstream text;
  text << v;
  return text.str();
}

void checkRange(const char* field, double value, double lo, double hi) {
  if (!(value >= lo && value <= hi)) {
    throw std::invalid_argument("h264: " + std::string(field) + " " + numberText(value) + " is outside " +
                                numberText(lo) + ".." + numberText(hi));
  }
}

}  // namespace

int defaultH264BitrateKbps(int width, int height, double fps) {
  const double pixels = static_cast<double>(std::max(width, 0)) * static_cast<double>(std::max(height, 0));
  const double rate = std::isfinite(fps) && fps > 0.0 ? fps : 30.0;
  const double kbps = std::round(kH264DefaultBitsPerPixel * pixels * rate / 1000.0);
  return static_cast<int>(std::clamp(kbps, static_cast<double>(kMinDefaultH264BitrateKbps),
                                     static_cast<double>(kMaxDefaultH264BitrateKbps)));
}

void validateH264Settings(const H264Settings& s) {
  checkRange("width", s.width, 2, io::kMaxImageDimension);
  checkRange("height", s.height, 2, io::kMaxImageDimension);
  // 4:2:0 halves both dimensions: the chroma planes of an odd size would
  // need cropping information libavcodec's libx264 wrapper cannot write.
  if (s.width % 2 != 0 || s.height % 2 != 0) {
    throw std::invalid_argument("h264: frame size " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                                " is odd; H.264 (4:2:0) needs an even width and height");
  }
  checkRange("bitrate (kbit/s)", s.bitrateKbps, kMinH264BitrateKbps, kMaxH264BitrateKbps);
  checkRange("keyframe interval (frames)", s.keyframeInterval, 1, kMaxH264KeyframeInterval);
  checkRange("fps", s.fps, 0.01, 1000.0);
  if (s.preset.empty()) throw std::invalid_argument("h264: the x264 preset is empty (e.g. ultrafast, veryfast)");
}

std::vector<int> h264NalTypes(const std::string& annexB) {
  std::vector<int> types;
  const auto* b = reinterpret_cast<const unsigned char*>(annexB.data());
  for (std::size_t i = 0; i + 3 < annexB.size(); ++i) {
    if (b[i] == 0 && b[i + 1] == 0 && b[i + 2] == 1) {
      types.push_back(b[i + 3] & 0x1f);  // nal_unit_type: the low five bits of the NAL header (H.264 §7.3.1)
      i += 2;
    }
  }
  return types;
}

}  // namespace haarcast::net
