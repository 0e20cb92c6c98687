// libFuzzer target: the wire protocol without a socket. Each input is a
// sequence of client messages (a 2-byte little-endian length before each),
// driven through what the server does with them: parseClientMessage, then a
// Hello → configFromHello, and after a valid Hello settings → applySettings,
// a scene choice → applySceneChoice, a pose → applyPose and frameRequest, as
// protocol.h describes. A message that is refused is a ProtocolError value;
// an exception, a crash or a sanitizer report is a finding.
//
// ProtocolDriver::apply is the one place a session's handling of a message
// goes: when a socketless render session exists, it replaces the body of
// apply (construct it in ProtocolDriver, hand it each parsed message) and the
// rest of this file stays as it is.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <variant>

#include "haarcast/net/protocol.h"

namespace haarcast::net {
namespace {

Catalog fuzzCatalog() {
  Catalog c;
  render::Pose turned;
  turned.rotateDegrees = {30.0, 0.0, 0.0};
  c.scenes.push_back({"default", {"phong:64", "lambert"}, render::Camera{}, {render::Pose{}, turned}, {"ball", "ring"}});
  c.scenes.push_back({"other", {"ggx:0.3"}, render::Camera{}, {render::Pose{}}, {}});
  c.materials = {"lambert", "phong:64", "ggx:0.3", "steel.binary"};
  c.backends = {Backend::Cpu, Backend::Vulkan};
  return c;
}

class ProtocolDriver {
 public:
  void apply(const v1::ClientMessage& message) {
    switch (message.body_case()) {
      case v1::ClientMessage::kHello: {
        auto result = configFromHello(message.hello(), limits_, defaults_, catalog_);
        if (auto* config = std::get_if<SessionConfig>(&result)) {
          config_ = *config;
          const Catalog::SceneEntry* scene = catalog_.findScene(config_->scene);
          if (scene == nullptr) __builtin_trap();  // a Hello's config names an offered scene
          pose_ = initialPose(scene->camera, scene->poses);
        }
        break;
      }
      case v1::ClientMessage::kSettings:
        if (config_) applySettings(*config_, message.settings(), limits_, catalog_);
        break;
      case v1::ClientMessage::kScene:
        if (config_ && !applySceneChoice(*config_, message.scene(), catalog_)) {
          const Catalog::SceneEntry* scene = catalog_.findScene(config_->scene);
          if (scene == nullptr) __builtin_trap();
          pose_ = initialPose(scene->camera, scene->poses);
        }
        break;
      case v1::ClientMessage::kPose:
        if (config_ && pose_) {
          applyPose(*pose_, message.pose());
          const render::FrameRequest request = frameRequest(*pose_, *config_);
          (void)request;
        }
        break;
      default:
        break;
    }
    if (config_) {
      // Every config the rules accept stays within the limits.
      if (config_->width < 1 || config_->width > limits_.maxWidth || config_->height < 1 ||
          config_->height > limits_.maxHeight || config_->level < limits_.minLevel ||
          config_->level > limits_.maxLevel) {
        __builtin_trap();
      }
      // The messages a session answers with are built from the config.
      (void)config_->rendererKey();
      (void)sceneInfo(*config_, catalog_).SerializeAsString();
      (void)settingsToWire(*config_).SerializeAsString();
    }
  }

 private:
  Limits limits_;
  Defaults defaults_;
  Catalog catalog_ = fuzzCatalog();
  std::optional<SessionConfig> config_;
  std::optional<PoseState> pose_;
};

}  // namespace
}  // namespace haarcast::net

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  haarcast::net::ProtocolDriver driver;
  std::size_t at = 0;
  while (size - at >= 2) {
    const std::size_t length = data[at] | (static_cast<std::size_t>(data[at + 1]) << 8);
    at += 2;
    const std::size_t take = length < size - at ? length : size - at;
    const auto parsed =
        haarcast::net::parseClientMessage(std::string_view(reinterpret_cast<const char*>(data + at), take));
    at += take;
    if (const auto* message = std::get_if<haarcast::v1::ClientMessage>(&parsed)) driver.apply(*message);
  }
  return 0;
}
