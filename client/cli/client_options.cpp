#include "haarcast/client/client_options.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <google/protobuf/descriptor.h>

#include "haarcast/wire/encoding_name.h"


namespace haarcast::client {

namespace {

std::uint32_t parseDimension(std::string_view text, const std::string& whole) {
  std::uint32_t value = 0;
  const auto* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end) {
    throw std::invalid_argument("--size must be WIDTHxHEIGHT, e.g. 256x256 (got \"" + whole + "\")");
  }
  // The largest side is the server's (Welcome.limits; its refusal names the
  // range), so here only the form is checked.
  if (value == 0) throw std::invalid_argument("--size: each side must be at least 1 (got \"" + whole + "\")");
  return value;
}

bool isUnreserved(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' ||
         c == '_' || c == '.' || c == '~';
}

}  // namespace

WsUrl parseWsUrl(const std::string& url) {
  const std::string scheme = "ws://";
  if (url.rfind("wss://", 0) == 0) {
    throw std::invalid_argument("URL \"" + url +
                                "\": wss:// is not supported; haarcast speaks plain ws:// (put TLS in a proxy)");
  }
  if (url.rfind(scheme, 0) != 0) {
    throw std::invalid_argument("URL \"" + url + "\" must start with ws:// (e.g. ws://127.0.0.1:8080)");
  }
  const std::string rest = url.substr(scheme.size());
  const auto slash = rest.find_first_of("/?");
  const std::string authority = rest.substr(0, slash);
  std::string target = slash == std::string::npos ? "" : rest.substr(slash);
  if (target.empty() || target[0] == '?') target = "/ws" + target;

  WsUrl out;
  if (!authority.empty() && authority[0] == '[') {  // [IPv6]:port
    const auto close = authority.find(']');
    if (close == std::string::npos) throw std::invalid_argument("URL \"" + url + "\": unterminated [IPv6] host");
    out.host = authority.substr(1, close - 1);
    if (close + 1 < authority.size()) {
      if (authority[close + 1] != ':') throw std::invalid_argument("URL \"" + url + "\": junk after ]");
      out.port = authority.substr(close + 2);
    }
  } else {
    const auto colon = authority.rfind(':');
    out.host = authority.substr(0, colon);
    if (colon != std::string::npos) out.port = authority.substr(colon + 1);
  }
  if (out.host.empty()) throw std::invalid_argument("URL \"" + url + "\" has no host");
  if (out.port.empty()) out.port = "80";
  unsigned port = 0;
  auto [ptr, ec] = std::from_chars(out.port.data(), out.port.data() + out.port.size(), port);
  if (ec != std::errc() || ptr != out.port.data() + out.port.size() || port == 0 || port > 65535) {
    throw std::invalid_argument("URL \"" + url + "\": port \"" + out.port + "\" is not in 1..65535");
  }
  out.target = target;
  return out;
}

std::string withTokenQuery(const std::string& target, const std::string& token) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string encoded;
  for (char c : token) {
    if (isUnreserved(c)) {
      encoded += c;
    } else {
      const auto byte = static_cast<unsigned char>(c);
      encoded += '%';
      encoded += kHex[byte >> 4];
      encoded += kHex[byte & 15];
    }
  }
  return target + (target.find('?') == std::string::npos ? "?" : "&") + "token=" + encoded;
}

Size parseSize(const std::string& text) {
  const auto x = text.find_first_of("xX");
  if (x == std::string::npos) {
    throw std::invalid_argument("--size must be WIDTHxHEIGHT, e.g. 256x256 (got \"" + text + "\")");
  }
  const std::string_view view(text);
  return {parseDimension(view.substr(0, x), text), parseDimension(view.substr(x + 1), text)};
}

v1::Encoding parseEncoding(const std::string& name) {
  // The wire names (wire::encodingName), and the spellings people also type.
  if (name == "jpg") return v1::ENCODING_JPEG;
  if (name == "rgba8") return v1::ENCODING_RAW_RGBA8;
  if (name == "h.264") return v1::ENCODING_H264;
  if (const auto encoding = wire::encodingFromName(name); encoding && *encoding != v1::ENCODING_UNSPECIFIED) {
    return *encoding;
  }
  throw std::invalid_argument("--encoding must be jpeg, png, raw, exr or h264 (got \"" + name + "\")");
}

std::string encodingFileExtension(v1::Encoding encoding) {
  switch (encoding) {
    case v1::ENCODING_JPEG: return ".jpg";
    case v1::ENCODING_PNG: return ".png";
    // Raw frames are written as PAM (netpbm P7, RGB_ALPHA): the same bytes
    // behind a 60-byte header that records the size, so any viewer opens them.
    case v1::ENCODING_RAW_RGBA8: return ".pam";
    case v1::ENCODING_EXR: return ".exr";
    // Decoded by the session's FrameDecoder and written as PNG (encodePng).
    case v1::ENCODING_H264: return ".png";
    default: return ".bin";
  }
}

void checkH264Options(v1::Encoding encoding, const Size& size, const H264Options& options) {
  if (encoding != v1::ENCODING_H264) {
    const char* flag = options.bitrateKbps != 0 ? "--bitrate" : options.keyframeInterval != 0 ? "--keyframe-interval" : nullptr;
    if (flag) {
      throw std::invalid_argument(std::string(flag) + " applies to --encoding h264 only (got --encoding " +
                                  std::string(wire::encodingName(encoding)) + ")");
    }
    return;
  }
  if (size.width % 2 != 0 || size.height % 2 != 0) {
    throw std::invalid_argument("--encoding h264 needs an even width and height (4:2:0 chroma), got --size " +
                                std::to_string(size.width) + "x" + std::to_string(size.height));
  }
}

Exposure parseExposure(const std::string& text) {
  if (text == "auto") return {};
  try {
    std::size_t used = 0;
    const double stops = std::stod(text, &used);
    if (used == text.size() && std::isfinite(stops)) return {v1::EXPOSURE_MODE_FIXED, stops};
  } catch (const std::logic_error&) {
  }
  throw std::invalid_argument("--exposure must be auto or a number of stops, e.g. -1.5 (got \"" + text + "\")");
}

LevelRequest parseLevel(const std::string& text) {
  // The range is the server's (Welcome.limits); it refuses a level outside
  // it by name, so only the form is checked here.
  const std::string valid = "--level must be N, auto or auto:N, N a map level the server serves (got \"" + text + "\")";
  auto number = [&](const std::string& digits) -> std::uint32_t {
    if (digits.empty() || digits.size() > 2 ||
        !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c) != 0; })) {
      throw std::invalid_argument(valid);
    }
    const auto n = static_cast<std::uint32_t>(std::stoul(digits));
    if (n == 0) throw std::invalid_argument(valid);
    return n;
  };
  if (text.empty() || text == "0") return {};
  if (text == "auto") return {0, v1::LEVEL_MODE_AUTO};
  if (text.rfind("auto:", 0) == 0) return {number(text.substr(5)), v1::LEVEL_MODE_AUTO};
  return {number(text), v1::LEVEL_MODE_FIXED};
}

namespace {

// A wire enum's values by their names as users type them: the value's name
// after the enum's prefix, in lower case ("ROTATION_METHOD_FUSED" → "fused"),
// UNSPECIFIED left out. The proto is the one table, as for the browser
// client, which reads the same enums from the same file.
std::vector<std::pair<std::string, int>> wireNames(const google::protobuf::EnumDescriptor* e, std::string_view prefix) {
  std::vector<std::pair<std::string, int>> names;
  for (int i = 0; i < e->value_count(); ++i) {
    const google::protobuf::EnumValueDescriptor* v = e->value(i);
    if (v->number() == 0) continue;
    std::string name = v->name().substr(prefix.size());
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    names.emplace_back(std::move(name), v->number());
  }
  return names;
}

// "a, b or c".
std::string choiceList(const std::vector<std::pair<std::string, int>>& names) {
  std::string list;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) list += i + 1 == names.size() ? " or " : ", ";
    list += names[i].first;
  }
  return list;
}

// The value named `name` ("" → 0, unspecified); else invalid_argument naming
// the flag and every valid name.
int parseWireName(const std::vector<std::pair<std::string, int>>& names, const std::string& name, const char* flag) {
  if (name.empty()) return 0;
  for (const auto& [n, value] : names) {
    if (n == name) return value;
  }
  throw std::invalid_argument(std::string(flag) + " must be " + choiceList(names) + " (got \"" + name + "\")");
}

const std::vector<std::pair<std::string, int>>& methodNames() {
  static const auto names = wireNames(v1::RotationMethod_descriptor(), "ROTATION_METHOD_");
  return names;
}

const std::vector<std::pair<std::string, int>>& toneNames() {
  static const auto names = wireNames(v1::ToneCurve_descriptor(), "TONE_CURVE_");
  return names;
}

}  // namespace

v1::RotationMethod parseMethod(const std::string& name) {
  return static_cast<v1::RotationMethod>(parseWireName(methodNames(), name, "--method"));
}

v1::ToneCurve parseToneCurve(const std::string& name) {
  return static_cast<v1::ToneCurve>(parseWireName(toneNames(), name, "--tone"));
}

std::string methodName(v1::RotationMethod method) {
  for (const auto& [name, value] : methodNames()) {
    if (value == method) return name;
  }
  return "default";
}

}  // namespace haarcast::client
