#include "haarcast/render/backend_names.h"
#include "haarcast/net/protocol.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <google/protobuf/unknown_field_set.h>

namespace haarcast::net {
namespace {

ProtocolError error(v1::ErrorCode code, std::string message, bool fatal) {
  return ProtocolError{code, std::move(message), fatal};
}

bool finite(const v1::Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }
glm::dvec3 toGlm(const v1::Vec3& v) { return {v.x(), v.y(), v.z()}; }

// "a, b, c" (at most `most` items, then "… (n in all)").
// Shortest form: "170", "0.5", not std::to_string's "170.000000".
std::string numberText(double v) {
  std::ostringstream text;
  text << v;
  return text.str();
}

std::string joined(const std::vector<std::string>& items, std::size_t most = 24) {
  std::string out;
  for (std::size_t i = 0; i < items.size() && i < most; ++i) out += (i ? ", " : "") + items[i];
  if (items.size() > most) out += ", … (" + std::to_string(items.size()) + " in all)";
  return out.empty() ? "none" : out;
}

// The wire names of the per-pixel methods, with their numbers.
std::string wireMethodNames() {
  std::string out;
  for (const RotationMethod m : kAllPixelMethods) {
    out += (out.empty() ? "" : ", ") + v1::RotationMethod_Name(toWire(m)) + " = " + std::to_string(toWire(m));
  }
  return out;
}

std::optional<RotationMethod> methodFromWire(v1::RotationMethod m) {
  switch (m) {
    case v1::ROTATION_METHOD_HAAR: return RotationMethod::Haar;
    case v1::ROTATION_METHOD_SPATIAL: return RotationMethod::Spatial;
    case v1::ROTATION_METHOD_MATRIX: return RotationMethod::Matrix;
    case v1::ROTATION_METHOD_TABLE: return RotationMethod::Table;
    case v1::ROTATION_METHOD_FUSED: return RotationMethod::Fused;
    case v1::ROTATION_METHOD_SPLITSUM: return RotationMethod::Splitsum;
    default: return std::nullopt;
  }
}

// A frame size within the limits (and even for H.264 when `encoding` says
// so): Hello's and RenderSettings' alike.
std::optional<ProtocolError> checkSize(std::uint32_t w, std::uint32_t h, const Limits& limits,
                                       std::optional<FrameEncoding> encoding, bool fatal) {
  if (w == 0 || h == 0 || w > static_cast<std::uint32_t>(limits.maxWidth) ||
      h > static_cast<std::uint32_t>(limits.maxHeight)) {
    return error(v1::ERROR_CODE_BAD_RESOLUTION,
                 "resolution " + std::to_string(w) + "x" + std::to_string(h) + " is outside 1x1.." +
                     std::to_string(limits.maxWidth) + "x" + std::to_string(limits.maxHeight),
                 fatal);
  }
  if (static_cast<std::size_t>(w) * h > limits.maxPixels) {
    return error(v1::ERROR_CODE_BAD_RESOLUTION,
                 "resolution " + std::to_string(w) + "x" + std::to_string(h) + " is " +
                     std::to_string(static_cast<std::size_t>(w) * h) + " pixels, over the server's " +
                     std::to_string(limits.maxPixels) + " per session (max-session-pixels)",
                 fatal);
  }
  if (encoding == FrameEncoding::H264 && (w % 2 != 0 || h % 2 != 0)) {
    // 4:2:0 halves both dimensions: a size the encoder cannot take is
    // refused here, before any frame is rendered.
    return error(v1::ERROR_CODE_BAD_RESOLUTION,
                 "resolution " + std::to_string(w) + "x" + std::to_string(h) +
                     " is odd: ENCODING_H264 needs an even width and height",
                 fatal);
  }
  return std::nullopt;
}

// Validates settings into a copy; only a fully valid change is applied.
std::optional<ProtocolError> mergeSettings(SessionConfig& config, const v1::RenderSettings& s, const Limits& limits,
                                           const Catalog& catalog, bool fatal) {
  SessionConfig next = config;
  if (s.method() != v1::ROTATION_METHOD_UNSPECIFIED) {
    const auto m = methodFromWire(s.method());
    if (!m) {
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   "unknown rotation method " + std::to_string(s.method()) + " (valid: " + wireMethodNames() + ")", fatal);
    }
    next.method = *m;
  }
  if (s.level() != 0) {
    if (s.level() < static_cast<std::uint32_t>(limits.minLevel) || s.level() > static_cast<std::uint32_t>(limits.maxLevel)) {
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   std::string(s.level_mode() == v1::LEVEL_MODE_AUTO ? "level cap " : "level ") + std::to_string(s.level()) +
                       " is outside " + std::to_string(limits.minLevel) + ".." + std::to_string(limits.maxLevel),
                   fatal);
    }
    next.level = static_cast<int>(s.level());
  }
  // A level alone is a fixed level (as before level_mode); a mode with
  // level 0 keeps the level in effect, as the level or as the cap.
  switch (s.level_mode()) {
    case v1::LEVEL_MODE_UNSPECIFIED:
      if (s.level() != 0) next.automaticLevel = false;
      break;
    case v1::LEVEL_MODE_FIXED: next.automaticLevel = false; break;
    case v1::LEVEL_MODE_AUTO: next.automaticLevel = true; break;
    default:
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   "unknown level_mode " + std::to_string(s.level_mode()) + " (valid: FIXED = 1, AUTO = 2)", fatal);
  }
  if (s.light_coefficients() != 0) {
    if (s.light_coefficients() > limits.maxLightCoefficients) {
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   "light_coefficients " + std::to_string(s.light_coefficients()) + " is over the limit " +
                       std::to_string(limits.maxLightCoefficients),
                   fatal);
    }
    next.lightCoefficients = s.light_coefficients();
  }
  if (s.backend() != v1::BACKEND_UNSPECIFIED) {
    const std::optional<Backend> backend = s.backend() == v1::BACKEND_CPU      ? std::optional(Backend::Cpu)
                                           : s.backend() == v1::BACKEND_VULKAN ? std::optional(Backend::Vulkan)
                                                                               : std::nullopt;
    if (!backend) {
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   "unknown backend " + std::to_string(s.backend()) + " (this server enables " +
                       joined(catalog.backendNames()) + ")",
                   fatal);
    }
    // Only the operator's backends: a `--backend cpu` server never builds a
    // Vulkan renderer for a client that asks for one.
    if (!catalog.offersBackend(*backend)) {
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   "backend " + std::string(backendName(*backend)) + " is not enabled on this server (it enables " +
                       joined(catalog.backendNames()) + ")",
                   fatal);
    }
    next.backend = *backend;
  }
  // H.264 fields: 0 = unchanged. Accepted for any encoding (they take
  // effect with ENCODING_H264), checked against h264_encoder.h's ranges.
  if (s.h264_bitrate_kbps() != 0) {
    if (s.h264_bitrate_kbps() < static_cast<std::uint32_t>(kMinH264BitrateKbps) ||
        s.h264_bitrate_kbps() > static_cast<std::uint32_t>(kMaxH264BitrateKbps)) {
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   "h264_bitrate_kbps " + std::to_string(s.h264_bitrate_kbps()) + " is outside " +
                       std::to_string(kMinH264BitrateKbps) + ".." + std::to_string(kMaxH264BitrateKbps),
                   fatal);
    }
    next.h264BitrateKbps = static_cast<int>(s.h264_bitrate_kbps());
  }
  if (s.h264_keyframe_interval() != 0) {
    if (s.h264_keyframe_interval() > static_cast<std::uint32_t>(kMaxH264KeyframeInterval)) {
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   "h264_keyframe_interval " + std::to_string(s.h264_keyframe_interval()) + " is outside 1.." +
                       std::to_string(kMaxH264KeyframeInterval),
                   fatal);
    }
    next.h264KeyframeInterval = static_cast<int>(s.h264_keyframe_interval());
  }
  if (s.width() != 0 || s.height() != 0) {
    if (s.width() == 0 || s.height() == 0) {
      return error(v1::ERROR_CODE_BAD_RESOLUTION,
                   "resolution " + std::to_string(s.width()) + "x" + std::to_string(s.height()) +
                       ": set both width and height, or neither (0 = unchanged)",
                   fatal);
    }
    if (auto e = checkSize(s.width(), s.height(), limits, config.encoding, fatal)) return e;
    next.width = static_cast<int>(s.width());
    next.height = static_cast<int>(s.height());
  }
  switch (s.exposure_mode()) {
    case v1::EXPOSURE_MODE_UNSPECIFIED: break;  // unchanged (a Hello starts with auto)
    case v1::EXPOSURE_MODE_AUTO: next.autoExposure = true; break;
    case v1::EXPOSURE_MODE_FIXED:
      if (!(std::abs(s.exposure_stops()) <= render::kMaxExposureStops)) {
        return error(v1::ERROR_CODE_BAD_SETTINGS,
                     "exposure_stops " + std::to_string(s.exposure_stops()) + " is outside ±" +
                         std::to_string(static_cast<int>(render::kMaxExposureStops)),
                     fatal);
      }
      next.autoExposure = false;
      next.exposureStops = s.exposure_stops();
      break;
    default:
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   "unknown exposure_mode " + std::to_string(s.exposure_mode()) + " (valid: AUTO, FIXED)", fatal);
  }
  switch (s.tone_curve()) {
    case v1::TONE_CURVE_UNSPECIFIED: break;  // unchanged (a Hello starts with Reinhard)
    case v1::TONE_CURVE_REINHARD: next.tone = render::ToneCurve::Reinhard; break;
    case v1::TONE_CURVE_ACES: next.tone = render::ToneCurve::Aces; break;
    case v1::TONE_CURVE_AGX: next.tone = render::ToneCurve::Agx; break;
    default:
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   "unknown tone_curve " + std::to_string(s.tone_curve()) + " (valid: REINHARD, ACES, AGX)", fatal);
  }
  config = std::move(next);
  return std::nullopt;
}

std::optional<ProtocolError> mergeScene(SessionConfig& config, const v1::SceneChoice& choice, const Catalog& catalog,
                                        bool fatal) {
  const Catalog::SceneEntry* scene = catalog.findScene(choice.scene());
  if (!scene) {
    return error(v1::ERROR_CODE_UNKNOWN_SCENE,
                 "unknown scene \"" + choice.scene() + "\" (this server offers " + joined(catalog.sceneNames()) + ")", fatal);
  }
  // Probe, mesh and up: names the catalog offers, never paths (as materials).
  const std::vector<std::string>& probes = catalog.probes;
  if (!choice.probe().empty() && std::find(probes.begin(), probes.end(), choice.probe()) == probes.end()) {
    return error(v1::ERROR_CODE_UNKNOWN_SCENE,
                 "unknown probe \"" + choice.probe() + "\" (this server offers " + joined(probes) + ")", fatal);
  }
  const Catalog::MeshEntry* mesh = nullptr;
  if (!choice.mesh().empty()) {
    mesh = catalog.findMesh(choice.mesh());
    if (!mesh) {
      return error(v1::ERROR_CODE_UNKNOWN_SCENE,
                   "unknown mesh \"" + choice.mesh() + "\" (this server offers " + joined(catalog.meshNames()) + ")", fatal);
    }
  }
  render::UpAxis up = mesh ? mesh->guessedUp : render::UpAxis::Y;
  if (!choice.up().empty()) {
    if (choice.up() != "y" && choice.up() != "z") {
      return error(v1::ERROR_CODE_BAD_SETTINGS, "unknown up \"" + choice.up() + "\" (valid: y, z)", fatal);
    }
    if (!mesh) {
      return error(v1::ERROR_CODE_BAD_SETTINGS,
                   "up \"" + choice.up() + "\" applies to a mesh, and no mesh is chosen (SceneChoice.mesh)", fatal);
    }
    up = render::parseUpAxis(choice.up());
  }
  // The objects drawn: the mesh scene's, else the scene's. Materials chosen
  // before are kept while the objects stay the same ones.
  const Catalog::SceneEntry& objects = mesh ? mesh->scene(up) : *scene;
  const bool sameObjects = mesh ? mesh->name == config.mesh : scene->name == config.scene && config.mesh.empty();
  std::vector<std::string> materials = sameObjects && !config.materials.empty() ? config.materials : objects.defaultMaterials;
  // Sorted for a deterministic first error.
  std::map<std::uint32_t, std::string> sorted(choice.object_materials().begin(), choice.object_materials().end());
  for (const auto& [object, spec] : sorted) {
    if (object >= materials.size()) {
      return error(v1::ERROR_CODE_UNKNOWN_MATERIAL,
                   "object " + std::to_string(object) + " does not exist: " + (mesh ? "mesh" : "scene") + " \"" +
                       (mesh ? mesh->name : scene->name) + "\" has " +
                       std::to_string(materials.size()) + " objects",
                   fatal);
    }
    // Only offered specs: a client must never make the server open a path.
    if (!catalog.offersMaterial(spec)) {
      return error(v1::ERROR_CODE_UNKNOWN_MATERIAL,
                   "material \"" + spec + "\" is not offered by this server (it offers " + joined(catalog.materials) + ")",
                   fatal);
    }
    materials[object] = spec;
  }
  config.scene = scene->name;
  config.probe = choice.probe();
  config.mesh = mesh ? mesh->name : "";
  config.up = up;
  config.materials = std::move(materials);
  return std::nullopt;
}

}  // namespace

std::optional<FrameEncoding> fromWire(v1::Encoding e) {
  switch (e) {
    case v1::ENCODING_JPEG: return FrameEncoding::Jpeg;
    case v1::ENCODING_PNG: return FrameEncoding::Png;
    case v1::ENCODING_RAW_RGBA8: return FrameEncoding::RawRgba8;
    case v1::ENCODING_EXR: return FrameEncoding::Exr;
    case v1::ENCODING_H264: return FrameEncoding::H264;
    default: return std::nullopt;
  }
}

const Catalog::SceneEntry* Catalog::findScene(std::string_view name) const {
  if (scenes.empty()) return nullptr;
  if (name.empty()) return &scenes.front();
  for (const auto& s : scenes) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

const Catalog::MeshEntry* Catalog::findMesh(std::string_view name) const {
  for (const auto& m : meshes) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

std::vector<std::string> Catalog::meshNames() const {
  std::vector<std::string> names;
  for (const auto& m : meshes) names.push_back(m.name);
  return names;
}

const Catalog::SceneEntry* sceneEntry(const SessionConfig& config, const Catalog& catalog) {
  if (!config.mesh.empty()) {
    const Catalog::MeshEntry* mesh = catalog.findMesh(config.mesh);
    return mesh ? &mesh->scene(config.up) : nullptr;
  }
  return catalog.findScene(config.scene);
}

std::string_view upAxisName(render::UpAxis up) { return up == render::UpAxis::Z ? "z" : "y"; }

std::vector<std::string> Catalog::sceneNames() const {
  std::vector<std::string> names;
  for (const auto& s : scenes) names.push_back(s.name);
  return names;
}

bool Catalog::offersMaterial(std::string_view spec) const {
  return std::find(materials.begin(), materials.end(), spec) != materials.end();
}

bool Catalog::offersBackend(Backend backend) const {
  return std::find(backends.begin(), backends.end(), backend) != backends.end();
}

std::vector<std::string> Catalog::backendNames() const {
  std::vector<std::string> names;
  for (const Backend b : backends) names.emplace_back(backendName(b));
  return names;
}

std::string_view backendName(Backend backend) {
  switch (backend) {
    case Backend::Cpu: return render::kCpuBackend;
    case Backend::Vulkan: return render::kVulkanBackend;
  }
  return "?";
}

std::optional<Backend> parseBackend(std::string_view name) {
  for (const Backend b : kAllBackends) {
    if (backendName(b) == name) return b;
  }
  return std::nullopt;
}

std::string SessionConfig::rendererKey() const {
  std::ostringstream key;
  // Probe, mesh and up change what is drawn: another renderer. The up axis
  // counts only with a mesh (it is Y, and means nothing, without one).
  key << "scene=" << scene << ";probe=" << probe << ";mesh=" << mesh << ";up=" << (mesh.empty() ? "" : upAxisName(up))
      << ";materials=";
  for (const auto& m : materials) key << m << ',';
  key << ";level=" << (automaticLevel ? "auto:" : "") << level << ";method=" << methodName(method)
      << ";backend=" << backendName(backend);
  return key.str();
}

std::variant<v1::ClientMessage, ProtocolError> parseClientMessage(std::string_view bytes) {
  v1::ClientMessage message;
  if (bytes.size() > static_cast<std::size_t>(INT32_MAX) ||
      !message.ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) {
    return error(v1::ERROR_CODE_BAD_MESSAGE,
                 "not a ClientMessage: " + std::to_string(bytes.size()) + " bytes that do not parse (garbage or truncated)",
                 false);
  }
  if (message.body_case() == v1::ClientMessage::BODY_NOT_SET) {
    // Name the unknown field, if any: a newer client's message type.
    const auto& unknown = message.GetReflection()->GetUnknownFields(message);
    if (unknown.field_count() > 0) {
      return error(v1::ERROR_CODE_BAD_MESSAGE,
                   "unknown message type: ClientMessage field " + std::to_string(unknown.field(0).number()) +
                       " is not one this server knows",
                   false);
    }
    return error(v1::ERROR_CODE_BAD_MESSAGE, "empty ClientMessage: no message type set", false);
  }
  return message;
}

std::variant<SessionConfig, ProtocolError> configFromHello(const v1::Hello& hello, const Limits& limits,
                                                          const Defaults& defaults, const Catalog& catalog) {
  if (hello.protocol_version() != kProtocolVersion) {
    return error(v1::ERROR_CODE_UNSUPPORTED_VERSION,
                 "protocol version " + std::to_string(hello.protocol_version()) + " is not supported (server speaks " +
                     std::to_string(kProtocolVersion) + ")",
                 true);
  }
  SessionConfig c;
  const std::uint32_t w = hello.width() ? hello.width() : static_cast<std::uint32_t>(defaults.width);
  const std::uint32_t h = hello.height() ? hello.height() : static_cast<std::uint32_t>(defaults.height);
  // 0 × 0 is a mistake, not "default": both or neither must be given.
  if ((hello.width() == 0) != (hello.height() == 0)) {
    return error(v1::ERROR_CODE_BAD_RESOLUTION,
                 "resolution " + std::to_string(hello.width()) + "x" + std::to_string(hello.height()) +
                     " is outside 1x1.." + std::to_string(limits.maxWidth) + "x" + std::to_string(limits.maxHeight),
                 true);
  }
  if (auto e = checkSize(w, h, limits, std::nullopt, true)) return *e;
  c.width = static_cast<int>(w);
  c.height = static_cast<int>(h);
  if (hello.encoding() == v1::ENCODING_UNSPECIFIED) {
    c.encoding = defaults.encoding;
  } else if (const auto e = fromWire(hello.encoding())) {
    c.encoding = *e;
  } else {
    return error(v1::ERROR_CODE_BAD_SETTINGS, "unknown encoding " + std::to_string(hello.encoding()) +
                     " (valid: JPEG = 1, PNG = 2, RAW_RGBA8 = 3, EXR = 4, H264 = 5)", true);
  }
  if (!std::isfinite(hello.fps_cap()) || hello.fps_cap() < 0.0) {
    return error(v1::ERROR_CODE_BAD_SETTINGS, "fps_cap must be a finite number ≥ 0 (0 = server default)", true);
  }
  c.fps = hello.fps_cap() == 0.0 ? std::min(limits.defaultFps, limits.maxFps) : std::min(hello.fps_cap(), limits.maxFps);
  if (hello.jpeg_quality() > 100) {
    return error(v1::ERROR_CODE_BAD_SETTINGS,
                 "jpeg_quality " + std::to_string(hello.jpeg_quality()) + " is outside 1..100", true);
  }
  c.jpegQuality = hello.jpeg_quality() ? static_cast<int>(hello.jpeg_quality()) : defaults.jpegQuality;
  c.method = defaults.method;
  c.level = defaults.level;
  c.automaticLevel = defaults.automaticLevel;
  c.lightCoefficients = defaults.lightCoefficients;
  c.backend = defaults.backend;
  if (auto e = mergeScene(c, hello.scene(), catalog, true)) return *e;
  if (auto e = mergeSettings(c, hello.settings(), limits, catalog, true)) return *e;
  if (c.encoding == FrameEncoding::H264) {
    // 4:2:0 halves both dimensions: a resolution the encoder cannot take is
    // refused here, before any renderer is built.
    if (c.width % 2 != 0 || c.height % 2 != 0) {
      return error(v1::ERROR_CODE_BAD_RESOLUTION,
                   "resolution " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                       " is odd: ENCODING_H264 needs an even width and height",
                   true);
    }
    try {
      validateH264Settings(h264Settings(c));
    } catch (const std::invalid_argument& e) {
      return error(v1::ERROR_CODE_BAD_SETTINGS, e.what(), true);
    }
  }
  return c;
}

std::optional<ProtocolError> applySettings(SessionConfig& config, const v1::RenderSettings& settings,
                                           const Limits& limits, const Catalog& catalog) {
  return mergeSettings(config, settings, limits, catalog, false);
}

std::optional<ProtocolError> applySceneChoice(SessionConfig& config, const v1::SceneChoice& choice,
                                              const Catalog& catalog) {
  return mergeScene(config, choice, catalog, false);
}

PoseState initialPose(const render::Camera& camera, const std::vector<render::Pose>& poses) {
  PoseState s;
  s.camera = camera;
  s.poses = poses;
  return s;
}

namespace {
// Rotations a pose may carry, in degrees per axis: any angle is within one
// turn of zero, and past this a double has no fraction of a degree left.
constexpr double kMaxPoseDegrees = 1e6;

bool withinDegrees(const v1::Vec3& v) {
  return std::abs(v.x()) <= kMaxPoseDegrees && std::abs(v.y()) <= kMaxPoseDegrees && std::abs(v.z()) <= kMaxPoseDegrees;
}
}  // namespace

std::optional<ProtocolError> applyPose(PoseState& state, const v1::PoseUpdate& update) {
  if (update.sequence() <= state.sequence) return std::nullopt;  // stale
  PoseState next = state;
  if (update.has_camera()) {
    const auto& c = update.camera();
    if (!finite(c.eye()) || !finite(c.target()) || !finite(c.up()) || !std::isfinite(c.fov_y_degrees())) {
      return error(v1::ERROR_CODE_BAD_MESSAGE, "pose " + std::to_string(update.sequence()) + ": camera has a non-finite number", false);
    }
    if (c.has_eye()) next.camera.eye = toGlm(c.eye());
    if (c.has_target()) next.camera.target = toGlm(c.target());
    if (c.has_up()) next.camera.up = toGlm(c.up());
    if (c.fov_y_degrees() != 0.0) {
      // The renderer's range (render/renderer.h), the one definition.
      if (!(c.fov_y_degrees() >= render::kMinFovDegrees && c.fov_y_degrees() <= render::kMaxFovDegrees)) {
        return error(v1::ERROR_CODE_BAD_MESSAGE,
                     "pose " + std::to_string(update.sequence()) + ": fov_y_degrees " + numberText(c.fov_y_degrees()) +
                         " is outside " + numberText(render::kMinFovDegrees) + ".." +
                         numberText(render::kMaxFovDegrees),
                     false);
      }
      next.camera.fovYDegrees = c.fov_y_degrees();
    }
    if (glm::length(next.camera.target - next.camera.eye) < 1e-9) {
      return error(v1::ERROR_CODE_BAD_MESSAGE, "pose " + std::to_string(update.sequence()) + ": camera eye equals target", false);
    }
  }
  for (const auto& o : update.objects()) {
    if (o.object() >= next.poses.size()) {
      return error(v1::ERROR_CODE_BAD_MESSAGE,
                   "pose " + std::to_string(update.sequence()) + ": object " + std::to_string(o.object()) +
                       " does not exist (the scene has " + std::to_string(next.poses.size()) + ")",
                   false);
    }
    if (!finite(o.rotate_degrees()) || !finite(o.translate())) {
      return error(v1::ERROR_CODE_BAD_MESSAGE, "pose " + std::to_string(update.sequence()) + ": object " +
                                                   std::to_string(o.object()) + " has a non-finite number", false);
    }
    if (o.has_rotate_degrees() && !withinDegrees(o.rotate_degrees())) {
      return error(v1::ERROR_CODE_BAD_MESSAGE, "pose " + std::to_string(update.sequence()) + ": object " +
                                                   std::to_string(o.object()) + " rotation is outside ±" +
                                                   std::to_string(static_cast<long long>(kMaxPoseDegrees)) + "°",
                   false);
    }
    if (o.has_rotate_degrees()) next.poses[o.object()].rotateDegrees = toGlm(o.rotate_degrees());
    if (o.has_translate()) next.poses[o.object()].translate = toGlm(o.translate());
  }
  if (update.has_light_rotate_degrees()) {
    if (!finite(update.light_rotate_degrees()) || !withinDegrees(update.light_rotate_degrees())) {
      return error(v1::ERROR_CODE_BAD_MESSAGE, "pose " + std::to_string(update.sequence()) +
                                                   ": light rotation is not finite or outside ±" +
                                                   std::to_string(static_cast<long long>(kMaxPoseDegrees)) + "°",
                   false);
    }
    next.lightRotateDegrees = toGlm(update.light_rotate_degrees());
  }
  // The renderer's own check of what the pose would become, now: a pose it
  // refuses must not be kept, or every later update (a camera-only one too)
  // inherits the bad part and fails to render.
  render::FrameRequest probe;
  probe.width = probe.height = 1;
  probe.camera = next.camera;
  probe.poses = next.poses;
  try {
    render::checkFrameRequest(probe, next.poses.size());
  } catch (const std::invalid_argument& e) {
    return error(v1::ERROR_CODE_BAD_MESSAGE,
                 "pose " + std::to_string(update.sequence()) + ": " + e.what() + " (the previous pose stays)", false);
  }
  next.sequence = update.sequence();
  next.clientTimeMs = std::isfinite(update.client_time_ms()) ? update.client_time_ms() : 0.0;
  state = std::move(next);
  return std::nullopt;
}

render::FrameRequest frameRequest(const PoseState& pose, const SessionConfig& config) {
  render::FrameRequest r;
  r.width = config.width;
  r.height = config.height;
  r.camera = pose.camera;
  r.poses = pose.poses;
  render::Pose light;
  light.rotateDegrees = pose.lightRotateDegrees;
  r.lightRotation = light.rotation();
  r.lightCoefficients = config.lightCoefficients;
  r.exposure.automatic = config.autoExposure;
  r.exposure.stops = config.exposureStops;
  r.tone = config.tone;
  return r;
}

v1::Encoding toWire(FrameEncoding encoding) {
  switch (encoding) {
    case FrameEncoding::Jpeg: return v1::ENCODING_JPEG;
    case FrameEncoding::Png: return v1::ENCODING_PNG;
    case FrameEncoding::RawRgba8: return v1::ENCODING_RAW_RGBA8;
    case FrameEncoding::Exr: return v1::ENCODING_EXR;
    case FrameEncoding::H264: return v1::ENCODING_H264;
  }
  return v1::ENCODING_UNSPECIFIED;
}

v1::RotationMethod toWire(RotationMethod method) {
  switch (method) {
    case RotationMethod::Haar: return v1::ROTATION_METHOD_HAAR;
    case RotationMethod::Spatial: return v1::ROTATION_METHOD_SPATIAL;
    case RotationMethod::Matrix: return v1::ROTATION_METHOD_MATRIX;
    case RotationMethod::Table: return v1::ROTATION_METHOD_TABLE;
    case RotationMethod::Fused: return v1::ROTATION_METHOD_FUSED;
    case RotationMethod::Splitsum: return v1::ROTATION_METHOD_SPLITSUM;
  }
  return v1::ROTATION_METHOD_UNSPECIFIED;
}

v1::Backend toWire(Backend backend) {
  switch (backend) {
    case Backend::Cpu: return v1::BACKEND_CPU;
    case Backend::Vulkan: return v1::BACKEND_VULKAN;
  }
  return v1::BACKEND_UNSPECIFIED;
}

v1::ToneCurve toWire(render::ToneCurve tone) {
  switch (tone) {
    case render::ToneCurve::Reinhard: return v1::TONE_CURVE_REINHARD;
    case render::ToneCurve::Aces: return v1::TONE_CURVE_ACES;
    case render::ToneCurve::Agx: return v1::TONE_CURVE_AGX;
  }
  return v1::TONE_CURVE_UNSPECIFIED;
}

v1::RenderSettings settingsToWire(const SessionConfig& config) {
  v1::RenderSettings s;
  s.set_method(toWire(config.method));
  s.set_level(static_cast<std::uint32_t>(config.level));
  s.set_level_mode(config.automaticLevel ? v1::LEVEL_MODE_AUTO : v1::LEVEL_MODE_FIXED);
  s.set_light_coefficients(static_cast<std::uint32_t>(config.lightCoefficients));
  s.set_backend(toWire(config.backend));
  s.set_exposure_mode(config.autoExposure ? v1::EXPOSURE_MODE_AUTO : v1::EXPOSURE_MODE_FIXED);
  s.set_exposure_stops(config.exposureStops);
  s.set_tone_curve(toWire(config.tone));
  s.set_width(static_cast<std::uint32_t>(config.width));
  s.set_height(static_cast<std::uint32_t>(config.height));
  if (config.encoding == FrameEncoding::H264) {
    s.set_h264_bitrate_kbps(static_cast<std::uint32_t>(h264Settings(config).bitrateKbps));
    s.set_h264_keyframe_interval(static_cast<std::uint32_t>(config.h264KeyframeInterval));
  }
  return s;
}

H264Settings h264Settings(const SessionConfig& config) {
  H264Settings s;
  s.width = config.width;
  s.height = config.height;
  s.bitrateKbps = config.h264BitrateKbps > 0 ? config.h264BitrateKbps
                                             : defaultH264BitrateKbps(config.width, config.height, config.fps);
  s.keyframeInterval = config.h264KeyframeInterval;
  s.fps = config.fps;
  return s;
}

v1::ServerLimits limitsToWire(const Limits& limits) {
  v1::ServerLimits l;
  l.set_min_level(static_cast<std::uint32_t>(limits.minLevel));
  l.set_max_level(static_cast<std::uint32_t>(limits.maxLevel));
  l.set_max_width(static_cast<std::uint32_t>(limits.maxWidth));
  l.set_max_height(static_cast<std::uint32_t>(limits.maxHeight));
  l.set_max_pixels(limits.maxPixels);
  l.set_max_fps(limits.maxFps);
  l.set_max_light_coefficients(static_cast<std::uint32_t>(limits.maxLightCoefficients));
  l.set_max_exposure_stops(render::kMaxExposureStops);
  l.set_max_h264_bitrate_kbps(static_cast<std::uint32_t>(kMaxH264BitrateKbps));
  return l;
}

v1::SceneInfo sceneInfo(const SessionConfig& config, const Catalog& catalog, const std::vector<int>& objectLevels) {
  v1::SceneInfo info;
  info.set_name(config.scene);
  info.set_probe(config.probe);
  info.set_mesh(config.mesh);
  if (!config.mesh.empty()) info.set_up(std::string(upAxisName(config.up)));
  const Catalog::SceneEntry* scene = sceneEntry(config, catalog);
  const auto vec = [](v1::Vec3* out, const glm::dvec3& v) {
    out->set_x(v.x);
    out->set_y(v.y);
    out->set_z(v.z);
  };
  if (scene) {
    auto* camera = info.mutable_camera();
    vec(camera->mutable_eye(), scene->camera.eye);
    vec(camera->mutable_target(), scene->camera.target);
    vec(camera->mutable_up(), scene->camera.up);
    camera->set_fov_y_degrees(scene->camera.fovYDegrees);
  }
  for (std::size_t i = 0; i < config.materials.size(); ++i) {
    auto* o = info.add_objects();
    o->set_index(static_cast<std::uint32_t>(i));
    const bool named = scene && i < scene->objectNames.size() && !scene->objectNames[i].empty();
    o->set_name(named ? scene->objectNames[i] : "object " + std::to_string(i));
    o->set_material(config.materials[i]);
    if (i < objectLevels.size()) o->set_level(static_cast<std::uint32_t>(objectLevels[i]));
    if (scene && i < scene->poses.size()) {
      auto* pose = o->mutable_pose();
      pose->set_object(static_cast<std::uint32_t>(i));
      vec(pose->mutable_rotate_degrees(), scene->poses[i].rotateDegrees);
      vec(pose->mutable_translate(), scene->poses[i].translate);
    }
  }
  return info;
}

std::string serialize(const v1::ServerMessage& message) {
  std::string bytes;
  message.SerializeToString(&bytes);
  return bytes;
}


}  // namespace haarcast::net
