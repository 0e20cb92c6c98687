// The wire protocol without sockets: parsing client messages, validating a
// Hello and later settings against the server's limits and catalogue, and
// turning pose updates into render requests. Pure functions over bytes and
// messages, so every rule here is tested without a network (and the session
// code in render_session.cpp applies them; ws_session.cpp only moves bytes
// and timers).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "haarcast/core/rotation.h"
#include "haarcast/net/encode.h"
#include "haarcast/net/h264_encoder.h"
#include "haarcast/proto/haarcast.pb.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"

namespace haarcast::net {

inline constexpr std::uint32_t kProtocolVersion = 1;
inline constexpr const char* kServerVersion = "haarcast 0.1.0";

// The renderer backends a session may run on (haarcast/backends/backends.h
// builds them, render/backend_names.h names them); the operator enables a
// subset of those the build has (Catalog::backends).
enum class Backend { Cpu, Vulkan };
inline constexpr Backend kAllBackends[] = {Backend::Cpu, Backend::Vulkan};
std::string_view backendName(Backend backend);                 // "cpu", "vulkan"
std::optional<Backend> parseBackend(std::string_view name);    // nullopt: not a backend name

// What the server allows; every limit is a clear Error when exceeded.
struct Limits {
  int maxWidth = 2048;
  int maxHeight = 2048;
  // width × height of one session's frames (serve: --max-session-pixels, the
  // render service's per-session budget): a Hello over it is refused at once
  // instead of failing every frame.
  std::size_t maxPixels = 2048u * 2048u;
  double maxFps = 60.0;
  double defaultFps = 30.0;
  int minLevel = render::kMinRenderLevel;
  int maxLevel = 6;  // ≤ render::kMaxRenderLevel; a level-7 scene takes minutes to prepare
  std::size_t maxLightCoefficients = 4096;
  std::size_t maxMessageBytes = 64 * 1024;  // client → server; poses are ~100 bytes
  int maxBadMessages = 3;  // non-fatal BAD_MESSAGE errors before the server closes
};

// Server-side defaults for what a Hello leaves unset.
struct Defaults {
  int width = 256;
  int height = 256;
  FrameEncoding encoding = FrameEncoding::Jpeg;
  int jpegQuality = 85;
  RotationMethod method = RotationMethod::Haar;
  int level = 5;                // fixed: the level; automatic: the cap
  bool automaticLevel = false;  // RenderSettings.level_mode AUTO (render::RenderOptions::automaticLevel)
  std::size_t lightCoefficients = 256;
  Backend backend = Backend::Cpu;
};

// What the server offers: scene names (with their object counts, so that
// per-object materials can be checked before anything is built), material
// specs, backends.
struct Catalog {
  struct SceneEntry {
    std::string name;
    std::vector<std::string> defaultMaterials;  // per object, as the scene names them
    render::Camera camera;                      // the scene's own view
    std::vector<render::Pose> poses;            // per object
    std::vector<std::string> objectNames;       // per object (SceneInfo); empty = "object <i>"
  };
  // A mesh a client may choose (SceneChoice.mesh): its "mesh scene" (the
  // mesh on a ground) for each up axis, since the up axis moves the ground
  // and so the scene's poses, and the up axis guessed from its bounds.
  struct MeshEntry {
    std::string name;  // the file's stem
    render::UpAxis guessedUp = render::UpAxis::Y;
    SceneEntry upY, upZ;  // objects: the mesh, then "ground"
    const SceneEntry& scene(render::UpAxis up) const { return up == render::UpAxis::Z ? upZ : upY; }
  };
  std::vector<SceneEntry> scenes;             // the first is the default
  std::vector<std::string> materials;         // offered specs: "lambert", "phong:64", MERL names …
  std::vector<Backend> backends;              // those the operator enabled
  std::vector<std::string> probes;            // probe names a SceneChoice may name (serve --data)
  std::vector<MeshEntry> meshes;              // meshes a SceneChoice may name (serve --data)

  const SceneEntry* findScene(std::string_view name) const;  // "" = the default
  const MeshEntry* findMesh(std::string_view name) const;    // nullptr: not offered
  std::vector<std::string> meshNames() const;
  std::vector<std::string> sceneNames() const;
  bool offersMaterial(std::string_view spec) const;
  bool offersBackend(Backend backend) const;
  std::vector<std::string> backendNames() const;
};

struct ProtocolError {
  v1::ErrorCode code = v1::ERROR_CODE_UNSPECIFIED;
  std::string message;
  bool fatal = false;
};

// Everything a session renders with. Changing scene, probe, mesh, up,
// materials, level, method or backend selects another renderer
// (rendererKey()).
struct SessionConfig {
  int width = 0;
  int height = 0;
  FrameEncoding encoding = FrameEncoding::Jpeg;
  int jpegQuality = 85;
  double fps = 30.0;
  std::string scene;                   // a Catalog scene name
  std::string probe;                   // a Catalog probe replacing the scene's environment; "": none
  std::string mesh;                    // a Catalog mesh scene replacing the scene's objects; "": none
  render::UpAxis up = render::UpAxis::Y;  // the mesh's up axis (chosen, else guessed); Y without a mesh
  std::vector<std::string> materials;  // per object, offered specs
  RotationMethod method = RotationMethod::Haar;
  int level = 5;                // fixed: the level; automatic: the cap
  bool automaticLevel = false;  // each object its own level (render/object_levels.h)
  std::size_t lightCoefficients = 256;
  Backend backend = Backend::Cpu;
  bool autoExposure = true;   // else exposureStops
  double exposureStops = 0.0;
  render::ToneCurve tone = render::ToneCurve::Reinhard;
  // ENCODING_H264 only (h264_encoder.h has the ranges). A bitrate of 0:
  // none set, the cap follows the size (defaultH264BitrateKbps).
  int h264BitrateKbps = 0;
  int h264KeyframeInterval = kDefaultH264KeyframeInterval;

  // Identifies the prepared renderer this config needs; equal keys share one.
  std::string rendererKey() const;
};

// A binary WebSocket message → ClientMessage. Garbage, a truncated message
// and an empty or unknown oneof are BAD_MESSAGE, naming which.
std::variant<v1::ClientMessage, ProtocolError> parseClientMessage(std::string_view bytes);

// The session's config from its Hello, or the first thing wrong with it
// (version, resolution, fps, quality, encoding, scene, materials, settings).
// Every error here is fatal: the session has nothing to render.
std::variant<SessionConfig, ProtocolError> configFromHello(const v1::Hello& hello, const Limits& limits,
                                                          const Defaults& defaults, const Catalog& catalog);

// Settings or scene changes mid-session. On error the config is unchanged
// (the errors are not fatal: the session goes on with what it had).
std::optional<ProtocolError> applySettings(SessionConfig& config, const v1::RenderSettings& settings,
                                           const Limits& limits, const Catalog& catalog);
std::optional<ProtocolError> applySceneChoice(SessionConfig& config, const v1::SceneChoice& choice,
                                              const Catalog& catalog);

// The objects, poses and camera a config draws: its mesh's scene when it
// has a mesh, else its scene's (nullptr: neither is in the catalog).
const Catalog::SceneEntry* sceneEntry(const SessionConfig& config, const Catalog& catalog);
// "y" or "z", as SceneChoice.up and SceneInfo.up say it.
std::string_view upAxisName(render::UpAxis up);

// The view a session has asked for so far: every PoseUpdate field it set.
struct PoseState {
  std::uint64_t sequence = 0;  // of the last update applied; 0 = none yet
  render::Camera camera;
  std::vector<render::Pose> poses;  // per object
  glm::dvec3 lightRotateDegrees{0.0};
  double clientTimeMs = 0.0;
};

// The scene's own view, for a session that has sent no pose yet.
PoseState initialPose(const render::Camera& camera, const std::vector<render::Pose>& poses);

// Applies an update. Returns nothing and leaves the state unchanged for an
// update whose sequence is not newer (stale: the latest pose wins). An
// object index out of range, a non-finite number, a rotation past ±1e6°, or
// a result the renderer would refuse (render::checkFrameRequest: the fov,
// the eye's distance, a pose whose numbers overflow) is BAD_MESSAGE (not
// fatal) and nothing of the update is applied: the last valid pose stays.
std::optional<ProtocolError> applyPose(PoseState& state, const v1::PoseUpdate& update);

// The render request for a pose under a config (exposure: the config's mode;
// the session adds the previous frame's exposure for auto).
render::FrameRequest frameRequest(const PoseState& pose, const SessionConfig& config);

// Wire enums ↔ ours.
v1::Encoding toWire(FrameEncoding encoding);
std::optional<FrameEncoding> fromWire(v1::Encoding encoding);  // nullopt: UNSPECIFIED or unknown
v1::RotationMethod toWire(RotationMethod method);
v1::Backend toWire(Backend backend);
v1::ToneCurve toWire(render::ToneCurve tone);
v1::RenderSettings settingsToWire(const SessionConfig& config);
v1::ServerLimits limitsToWire(const Limits& limits);
// The H.264 encoder settings of a config (size, bitrate, keyframe interval,
// fps); meaningful for ENCODING_H264. A config that set no bitrate gets
// defaultH264BitrateKbps of its size and fps.
H264Settings h264Settings(const SessionConfig& config);
// The config's scene, its objects (named by the catalog) and their materials.
// objectLevels: each object's map level where the renderer is ready
// (render::Renderer::objectLevels), else empty (SceneInfo.Object.level 0).
v1::SceneInfo sceneInfo(const SessionConfig& config, const Catalog& catalog, const std::vector<int>& objectLevels = {});

// Serialised ServerMessages (the builders of each message: messages.h).
std::string serialize(const v1::ServerMessage& message);

}  // namespace haarcast::net
