// The scripted pose path the client plays: the camera orbiting the target,
// object 0 spinning, the light turning — from flags, or from a JSON file
// that lists poses explicitly. Pure: no sockets, tested on its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "haarcast/proto/haarcast.pb.h"

namespace haarcast::client {

// Every sweep is the total over the whole run, so pose i of N sits at
// t = i/N of it and a 360° sweep loops without repeating its first pose.
struct OrbitSweep {
  double orbitDegrees = 360.0;  // camera azimuth about +Y, from +Z toward +X
  double spinDegrees = 0.0;     // object `spinObject` about its Y axis
  std::uint32_t spinObject = 0;
  double lightDegrees = 0.0;    // the environment about world +Y
  // At azimuth 0 these reproduce the built-in default scene's camera, eye
  // (0, 0.85, 4.8) looking at the origin, 45° field of view.
  double distance = 4.8747;
  double elevationDegrees = 10.042;
  double fovYDegrees = 45.0;
};

class PosePath {
 public:
  static PosePath orbit(const OrbitSweep& sweep);
  // {"poses": [{"camera": {"eye": [x,y,z], "target": [...], "up": [...],
  //   "fov_y_degrees": f}, "objects": [{"object": 0, "rotate_degrees": [...],
  //   "translate": [...]}], "light_rotate_degrees": [...]}, ...]}. Every
  // field of a pose is optional (absent = unchanged). Throws
  // std::invalid_argument naming the file, the pose index and the field.
  static PosePath fromJson(const nlohmann::json& document, const std::string& source);
  static PosePath fromFile(const std::string& path);

  // How many poses the path has by itself: the file's pose count, or 0 for
  // a sweep, which can be cut into any number.
  std::size_t naturalLength() const { return poses_.size(); }

  // Pose i of a run of `total` (sequence and client time are left to the
  // caller). File paths cycle when the run is longer than the file.
  v1::PoseUpdate at(std::size_t index, std::size_t total) const;

 private:
  std::optional<OrbitSweep> sweep_;
  std::vector<v1::PoseUpdate> poses_;
};

}  // namespace haarcast::client
