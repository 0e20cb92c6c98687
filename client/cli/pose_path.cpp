#include "haarcast/client/pose_path.h"

#include <cmath>
#include <fstream>
#include <numbers>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace haarcast::client {

namespace {

void setVec3(v1::Vec3* out, double x, double y, double z) {
  out->set_x(x);
  out->set_y(y);
  out->set_z(z);
}

// A JSON [x, y, z] of numbers, or a clear error naming where it was.
void readVec3(const nlohmann::json& value, v1::Vec3* out, const std::string& where) {
  if (!value.is_array() || value.size() != 3 || !value[0].is_number() || !value[1].is_number() ||
      !value[2].is_number()) {
    throw std::invalid_argument(where + ": expected [x, y, z] numbers, got " + value.dump());
  }
  setVec3(out, value[0].get<double>(), value[1].get<double>(), value[2].get<double>());
}

void rejectUnknownKeys(const nlohmann::json& object, std::initializer_list<const char*> known,
                       const std::string& where) {
  for (const auto& [key, unused] : object.items()) {
    bool ok = false;
    for (const char* k : known) ok = ok || key == k;
    // A typo ("rotate_degree") would otherwise silently do nothing.
    if (!ok) throw std::invalid_argument(where + ": unknown key \"" + key + "\"");
  }
}

}  // namespace

PosePath PosePath::orbit(const OrbitSweep& sweep) {
  if (!(sweep.distance > 0.0) || !std::isfinite(sweep.distance)) {
    throw std::invalid_argument("--distance must be a positive number (got " + std::to_string(sweep.distance) + ")");
  }
  if (!(sweep.fovYDegrees > 0.0 && sweep.fovYDegrees < 180.0)) {
    throw std::invalid_argument("--fov must be in (0, 180) degrees (got " + std::to_string(sweep.fovYDegrees) + ")");
  }
  if (!(std::abs(sweep.elevationDegrees) < 90.0)) {
    // At ±90° the view direction is parallel to the up vector.
    throw std::invalid_argument("--elevation must be in (-90, 90) degrees (got " +
                                std::to_string(sweep.elevationDegrees) + ")");
  }
  PosePath path;
  path.sweep_ = sweep;
  return path;
}

PosePath PosePath::fromJson(const nlohmann::json& document, const std::string& source) {
  if (!document.is_object() || !document.contains("poses") || !document["poses"].is_array()) {
    throw std::invalid_argument(source + ": expected an object with a \"poses\" array");
  }
  const auto& poses = document["poses"];
  if (poses.empty()) throw std::invalid_argument(source + ": \"poses\" is empty");
  PosePath path;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto& p = poses[i];
    const std::string where = source + ": poses[" + std::to_string(i) + "]";
    if (!p.is_object()) throw std::invalid_argument(where + ": expected an object");
    rejectUnknownKeys(p, {"camera", "objects", "light_rotate_degrees"}, where);
    v1::PoseUpdate pose;
    if (p.contains("camera")) {
      const auto& c = p["camera"];
      if (!c.is_object()) throw std::invalid_argument(where + ".camera: expected an object");
      rejectUnknownKeys(c, {"eye", "target", "up", "fov_y_degrees"}, where + ".camera");
      auto* camera = pose.mutable_camera();
      // Unset camera fields take the scene camera's usual values, because a
      // Camera message replaces the whole camera.
      setVec3(camera->mutable_eye(), 0.0, 0.4, 3.2);
      setVec3(camera->mutable_up(), 0.0, 1.0, 0.0);
      setVec3(camera->mutable_target(), 0.0, 0.0, 0.0);
      camera->set_fov_y_degrees(35.0);
      if (c.contains("eye")) readVec3(c["eye"], camera->mutable_eye(), where + ".camera.eye");
      if (c.contains("target")) readVec3(c["target"], camera->mutable_target(), where + ".camera.target");
      if (c.contains("up")) readVec3(c["up"], camera->mutable_up(), where + ".camera.up");
      if (c.contains("fov_y_degrees")) {
        if (!c["fov_y_degrees"].is_number()) throw std::invalid_argument(where + ".camera.fov_y_degrees: expected a number");
        camera->set_fov_y_degrees(c["fov_y_degrees"].get<double>());
      }
    }
    if (p.contains("objects")) {
      const auto& objects = p["objects"];
      if (!objects.is_array()) throw std::invalid_argument(where + ".objects: expected an array");
      for (std::size_t j = 0; j < objects.size(); ++j) {
        const auto& o = objects[j];
        const std::string ow = where + ".objects[" + std::to_string(j) + "]";
        if (!o.is_object()) throw std::invalid_argument(ow + ": expected an object");
        rejectUnknownKeys(o, {"object", "rotate_degrees", "translate"}, ow);
        auto* object = pose.add_objects();
        if (o.contains("object")) {
          if (!o["object"].is_number_unsigned()) throw std::invalid_argument(ow + ".object: expected an index ≥ 0");
          object->set_object(o["object"].get<std::uint32_t>());
        }
        if (o.contains("rotate_degrees")) readVec3(o["rotate_degrees"], object->mutable_rotate_degrees(), ow + ".rotate_degrees");
        if (o.contains("translate")) readVec3(o["translate"], object->mutable_translate(), ow + ".translate");
      }
    }
    if (p.contains("light_rotate_degrees")) {
      readVec3(p["light_rotate_degrees"], pose.mutable_light_rotate_degrees(), where + ".light_rotate_degrees");
    }
    path.poses_.push_back(std::move(pose));
  }
  return path;
}

PosePath PosePath::fromFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("--path: cannot open \"" + path + "\"");
  nlohmann::json document;
  try {
    in >> document;
  } catch (const nlohmann::json::parse_error& e) {
    throw std::invalid_argument("--path: \"" + path + "\" is not valid JSON: " + e.what());
  }
  return fromJson(document, path);
}

v1::PoseUpdate PosePath::at(std::size_t index, std::size_t total) const {
  if (!sweep_) return poses_.at(index % poses_.size());
  const OrbitSweep& s = *sweep_;
  const double t = total == 0 ? 0.0 : static_cast<double>(index % total) / static_cast<double>(total);
  constexpr double kRad = std::numbers::pi / 180.0;
  const double azimuth = s.orbitDegrees * t * kRad;
  const double elevation = s.elevationDegrees * kRad;

  v1::PoseUpdate pose;
  auto* camera = pose.mutable_camera();
  // The shared direction convention: azimuth from +Z toward +X, +Y up.
  setVec3(camera->mutable_eye(), s.distance * std::cos(elevation) * std::sin(azimuth),
          s.distance * std::sin(elevation), s.distance * std::cos(elevation) * std::cos(azimuth));
  setVec3(camera->mutable_target(), 0.0, 0.0, 0.0);
  setVec3(camera->mutable_up(), 0.0, 1.0, 0.0);
  camera->set_fov_y_degrees(s.fovYDegrees);
  // An object pose replaces the object's whole rotation, so a run without a
  // spin leaves the scene's own object poses alone.
  if (s.spinDegrees != 0.0) {
    auto* object = pose.add_objects();
    object->set_object(s.spinObject);
    setVec3(object->mutable_rotate_degrees(), 0.0, s.spinDegrees * t, 0.0);
  }
  setVec3(pose.mutable_light_rotate_degrees(), 0.0, s.lightDegrees * t, 0.0);
  return pose;
}

}  // namespace haarcast::client
