// RayScene on Embree 3: one child scene per distinct Mesh, placed by instance
// geometries in a top-level scene, so that moving an object rebuilds only the
// (tiny) top level; every scene on the process's one Embree device.
#include "haarcast/render/embree_scene.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

#include <embree3/rtcore.h>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "haarcast/core/check.h"

namespace haarcast {
namespace {

// Embree reports an error twice: as a code that rtcGetDeviceError returns
// (per thread, cleared on read) and as a message passed to the error callback
// on the thread that caused it. The callback only records the message — it
// must not throw through Embree's C interface — and check() turns the pair
// into an exception at the call site, which knows the call's name.
thread_local std::string tEmbreeMessage;

void recordEmbreeError(void* /*userPtr*/, RTCError /*code*/, const char* message) {
  tEmbreeMessage = message ? message : "";
}

const char* errorName(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE: return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN: return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT: return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION: return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY: return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU: return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED: return "RTC_ERROR_CANCELLED";
  }
  return "unknown RTCError";
}

// Throws if the last Embree call on this thread failed. `device` may be null
// (rtcNewDevice's own failure is reported on the null device).
void check(RTCDevice device, const char* call) {
  const RTCError code = rtcGetDeviceError(device);
  if (code == RTC_ERROR_NONE) return;
  std::string what = std::string("Embree: ") + call + " failed: " + errorName(code) + " (" +
                     std::to_string(static_cast<int>(code)) + ")";
  if (!tEmbreeMessage.empty()) what += ": " + tEmbreeMessage;
  tEmbreeMessage.clear();
  throw std::runtime_error(what);
}

// A null handle from a constructor-like call is a failure even if Embree did
// not set an error code (it always should).
template <typename Handle>
Handle checked(RTCDevice device, Handle handle, const char* call) {
  check(device, call);
  if (!handle) throw std::runtime_error(std::string("Embree: ") + call + " returned null");
  return handle;
}

struct DeviceDeleter {
  void operator()(RTCDeviceTy* d) const { rtcReleaseDevice(d); }
};
struct SceneDeleter {
  void operator()(RTCSceneTy* s) const { rtcReleaseScene(s); }
};
using DeviceHandle = std::unique_ptr<RTCDeviceTy, DeviceDeleter>;
using SceneHandle = std::unique_ptr<RTCSceneTy, SceneDeleter>;

std::atomic<std::uint64_t> gDevicesCreated{0};  // constant-initialised: counts from the first static on

// The process's Embree device, made on the first RayScene and shared by
// every one after it. A device is thread-safe (scenes may be built and
// traced from many threads at once), and each device brings its own task
// scheduler and memory accounting, so one per scene cost a device per
// renderer. Error codes stay per thread (Embree keeps one per thread and
// device) and the callback runs on the failing thread, so tEmbreeMessage
// still pairs with the code check() reads. Each RayScene retains the device
// (Embree counts references): this static's release at exit destroys it only
// once the last scene is gone.
RTCDevice sharedDevice() {
  static const DeviceHandle device = [] {
    // A failed rtcNewDevice reports its error on the null device; the
    // static is then tried again by the next scene.
    DeviceHandle d(rtcNewDevice(nullptr));
    check(nullptr, "rtcNewDevice");
    if (!d) throw std::runtime_error("Embree: rtcNewDevice returned null");
    ++gDevicesCreated;
    rtcSetDeviceErrorFunction(d.get(), recordEmbreeError, nullptr);
    check(d.get(), "rtcSetDeviceErrorFunction");
    return d;
  }();
  return device.get();
}

void checkTransform(const glm::mat4& m, std::size_t object) {
  const std::string who = "RayScene: object " + std::to_string(object) + ": ";
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(m[c][r])) throw std::invalid_argument(who + "transform has a non-finite entry");
    }
  }
  // Embree instances are affine; a projective row would be silently dropped.
  if (m[0][3] != 0.0f || m[1][3] != 0.0f || m[2][3] != 0.0f || m[3][3] != 1.0f) {
    throw std::invalid_argument(who + "transform is not affine (last row must be 0 0 0 1)");
  }
  // A singular linear part flattens the mesh and leaves no normal transform.
  const double det = glm::determinant(glm::dmat3(glm::mat3(m)));
  if (!(std::abs(det) > 0.0)) throw std::invalid_argument(who + "transform is singular");
}

// The inverse transpose of the linear part: what carries normals.
glm::mat3 normalMatrix(const glm::mat4& m) { return glm::transpose(glm::inverse(glm::mat3(m))); }

}  // namespace

struct RayScene::Impl {
  // Declared in this order so that scenes are released before the device.
  DeviceHandle device;
  std::vector<SceneHandle> meshScenes;  // one per distinct Mesh
  SceneHandle top;
  std::vector<glm::mat3> normalMatrices;  // per object
  // Per object: its mesh's own scene and the world → object transform, for
  // the rays that ask what the object alone blocks (occludedByObjectFrom).
  std::vector<RTCScene> objectScenes;
  std::vector<glm::mat4> worldToObject;
  // What occlusion queries trace: the mesh's own scene when the scene is one
  // object at the identity (a mesh's visibility against itself), else the
  // top level. Skipping the instance level takes about a fifth off a
  // visibility ray (the bunny at level 7), and an identity transform carries
  // a ray exactly, so the answers are the same. intersect() keeps the top
  // level: its hits name their instance.
  RTCScene occlusionScene = nullptr;

  void chooseOcclusionScene(const glm::mat4& onlyTransform) {
    occlusionScene = normalMatrices.size() == 1 && onlyTransform == glm::mat4(1.0f)
                         ? meshScenes.front().get()
                         : top.get();
  }

  RTCScene meshScene(const Mesh& mesh) {
    SceneHandle scene(checked(device.get(), rtcNewScene(device.get()), "rtcNewScene"));
    // ROBUST: watertight traversal, so that a visibility ray cannot slip
    // through the shared edge of two triangles of a closed mesh. HIGH: the
    // meshes are static and traced by millions of rays; spatial splits pay.
    rtcSetSceneFlags(scene.get(), RTC_SCENE_FLAG_ROBUST);
    check(device.get(), "rtcSetSceneFlags");
    rtcSetSceneBuildQuality(scene.get(), RTC_BUILD_QUALITY_HIGH);
    check(device.get(), "rtcSetSceneBuildQuality");

    RTCGeometry geom = checked(device.get(), rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE), "rtcNewGeometry");
    // From here the geometry must be released on every path; the scene keeps
    // its own reference once attached.
    try {
      // Embree-owned buffers (padded as its SIMD loads need): the Mesh need
      // not outlive the scene.
      auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
          geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.positions.size()));
      check(device.get(), "rtcSetNewGeometryBuffer(vertex)");
      auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), mesh.triangles.size()));
      check(device.get(), "rtcSetNewGeometryBuffer(index)");
      if (!vertices || !indices) throw std::runtime_error("Embree: rtcSetNewGeometryBuffer returned null");
      for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        vertices[3 * i + 0] = mesh.positions[i].x;
        vertices[3 * i + 1] = mesh.positions[i].y;
        vertices[3 * i + 2] = mesh.positions[i].z;
      }
      for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
        indices[3 * i + 0] = mesh.triangles[i].x;
        indices[3 * i + 1] = mesh.triangles[i].y;
        indices[3 * i + 2] = mesh.triangles[i].z;
      }
      rtcCommitGeometry(geom);
      check(device.get(), "rtcCommitGeometry(mesh)");
      // ID 0: the only geometry, so a hit's geomID is always 0 and primID is
      // the triangle index of the Mesh.
      rtcAttachGeometryByID(scene.get(), geom, 0);
      check(device.get(), "rtcAttachGeometryByID(mesh)");
    } catch (...) {
      rtcReleaseGeometry(geom);
      throw;
    }
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene.get());
    check(device.get(), "rtcCommitScene(mesh)");
    meshScenes.push_back(std::move(scene));
    return meshScenes.back().get();
  }

  void attachInstance(RTCScene child, const glm::mat4& objectToWorld, unsigned id) {
    RTCGeometry geom = checked(device.get(), rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_INSTANCE), "rtcNewGeometry");
    try {
      rtcSetGeometryInstancedScene(geom, child);
      check(device.get(), "rtcSetGeometryInstancedScene");
      rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &objectToWorld[0][0]);
      check(device.get(), "rtcSetGeometryTransform");
      rtcCommitGeometry(geom);
      check(device.get(), "rtcCommitGeometry(instance)");
      // The instance's ID is the object index: a hit's instID[0] names it.
      rtcAttachGeometryByID(top.get(), geom, id);
      check(device.get(), "rtcAttachGeometryByID(instance)");
    } catch (...) {
      rtcReleaseGeometry(geom);
      throw;
    }
    rtcReleaseGeometry(geom);
  }
};

RayScene::RayScene(std::vector<Instance> instances) : impl_(std::make_unique<Impl>()) {
  if (instances.empty()) throw std::invalid_argument("RayScene: no instances");
  for (std::size_t i = 0; i < instances.size(); ++i) {
    if (!instances[i].mesh) throw std::invalid_argument("RayScene: object " + std::to_string(i) + " has no mesh");
    instances[i].mesh->validate();
    checkTransform(instances[i].objectToWorld, i);
  }
  if (instances.size() > RTC_INVALID_GEOMETRY_ID) throw std::invalid_argument("RayScene: too many instances");

  Impl& s = *impl_;
  RTCDevice device = sharedDevice();
  rtcRetainDevice(device);
  s.device.reset(device);  // released with the scene
  check(device, "rtcRetainDevice");

  s.top.reset(checked(s.device.get(), rtcNewScene(s.device.get()), "rtcNewScene"));
  rtcSetSceneFlags(s.top.get(), RTC_SCENE_FLAG_ROBUST);
  check(s.device.get(), "rtcSetSceneFlags");

  std::unordered_map<const Mesh*, RTCScene> built;
  for (std::size_t i = 0; i < instances.size(); ++i) {
    const Mesh* mesh = instances[i].mesh;
    auto it = built.find(mesh);
    if (it == built.end()) it = built.emplace(mesh, s.meshScene(*mesh)).first;
    s.attachInstance(it->second, instances[i].objectToWorld, static_cast<unsigned>(i));
    s.normalMatrices.push_back(normalMatrix(instances[i].objectToWorld));
    s.objectScenes.push_back(it->second);
    s.worldToObject.push_back(glm::inverse(instances[i].objectToWorld));
  }
  rtcCommitScene(s.top.get());
  check(s.device.get(), "rtcCommitScene(top)");
  s.chooseOcclusionScene(instances.front().objectToWorld);
}

std::uint64_t RayScene::devicesCreated() { return gDevicesCreated.load(); }

RayScene::~RayScene() = default;
RayScene::RayScene(RayScene&&) noexcept = default;
RayScene& RayScene::operator=(RayScene&&) noexcept = default;

std::size_t RayScene::objectCount() const { return impl_->normalMatrices.size(); }

namespace {

RTCRay toEmbree(const Ray& r) {
  RTCRay e{};
  e.org_x = r.origin.x;
  e.org_y = r.origin.y;
  e.org_z = r.origin.z;
  e.dir_x = r.direction.x;
  e.dir_y = r.direction.y;
  e.dir_z = r.direction.z;
  e.tnear = r.tnear;
  e.tfar = r.tfar;
  e.time = 0.0f;
  e.mask = ~0u;
  e.id = 0;
  e.flags = 0;
  return e;
}

}  // namespace

Hit RayScene::hitOf(unsigned object, unsigned triangle, float u, float v, float t, const glm::vec3& ng) const {
  Hit hit;
  hit.object = object;
  hit.triangle = triangle;
  hit.u = u;
  hit.v = v;
  hit.t = t;
  // Embree gives Ng in the mesh's (object) frame, unnormalised.
  const glm::vec3 n = impl_->normalMatrices[object] * ng;
  const float len = glm::length(n);
  if (len > 0.0f) hit.geometricNormal = n / len;
  return hit;
}

std::optional<Hit> RayScene::intersect(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray = toEmbree(ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->top.get(), &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  return hitOf(rh.hit.instID[0], rh.hit.primID, rh.hit.u, rh.hit.v, rh.ray.tfar,
               glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
}

void RayScene::intersectFrom(const glm::vec3& origin, float tnear, std::span<const glm::vec3> directions,
                             std::span<std::optional<Hit>> out) const {
  if (directions.size() != out.size()) {
    throw std::invalid_argument("RayScene::intersectFrom: " + std::to_string(directions.size()) + " directions but " +
                                std::to_string(out.size()) + " results");
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  constexpr std::size_t kWidth = 16;  // Embree's widest packet, as occludedFrom
  alignas(64) RTCRayHit16 packet;
  alignas(64) int valid[kWidth];
  for (std::size_t first = 0; first < directions.size(); first += kWidth) {
    const std::size_t n = std::min(kWidth, directions.size() - first);
    for (std::size_t k = 0; k < kWidth; ++k) {
      const bool live = k < n;
      const glm::vec3 d = live ? directions[first + k] : glm::vec3(0.0f, 1.0f, 0.0f);
      valid[k] = live ? -1 : 0;
      packet.ray.org_x[k] = origin.x;
      packet.ray.org_y[k] = origin.y;
      packet.ray.org_z[k] = origin.z;
      packet.ray.dir_x[k] = d.x;
      packet.ray.dir_y[k] = d.y;
      packet.ray.dir_z[k] = d.z;
      packet.ray.tnear[k] = tnear;
      packet.ray.tfar[k] = std::numeric_limits<float>::infinity();
      packet.ray.time[k] = 0.0f;
      packet.ray.mask[k] = ~0u;
      packet.ray.id[k] = static_cast<unsigned>(k);
      packet.ray.flags[k] = 0;
      packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, impl_->top.get(), &context, &packet);
    for (std::size_t k = 0; k < n; ++k) {
      if (packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
        out[first + k] = std::nullopt;
        continue;
      }
      out[first + k] = hitOf(packet.hit.instID[0][k], packet.hit.primID[k], packet.hit.u[k], packet.hit.v[k],
                             packet.ray.tfar[k], glm::vec3(packet.hit.Ng_x[k], packet.hit.Ng_y[k], packet.hit.Ng_z[k]));
    }
  }
}

bool RayScene::occluded(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r = toEmbree(ray);
  rtcOccluded1(impl_->occlusionScene, &context, &r);
  // Embree marks a blocked ray by setting tfar to −∞.
  return r.tfar == -std::numeric_limits<float>::infinity();
}

void RayScene::occludedBatch(std::span<const Ray> rays, std::span<std::uint8_t> out, bool coherent) const {
  if (rays.size() != out.size()) {
    throw std::invalid_argument("RayScene::occludedBatch: " + std::to_string(rays.size()) + " rays but " +
                                std::to_string(out.size()) + " results");
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  // Streams of a fixed size on the stack: no allocation per call, and large
  // enough for Embree to form full packets.
  constexpr std::size_t kChunk = 256;
  std::array<RTCRay, kChunk> chunk;
  for (std::size_t first = 0; first < rays.size(); first += kChunk) {
    const std::size_t n = std::min(kChunk, rays.size() - first);
    for (std::size_t k = 0; k < n; ++k) chunk[k] = toEmbree(rays[first + k]);
    rtcOccluded1M(impl_->occlusionScene, &context, chunk.data(), static_cast<unsigned>(n), sizeof(RTCRay));
    for (std::size_t k = 0; k < n; ++k) {
      out[first + k] = chunk[k].tfar == -std::numeric_limits<float>::infinity() ? 1 : 0;
    }
  }
}

namespace {

// Rays 0 … count−1, ray i from origin(i) along direction(i), t ∈ [tnear, ∞),
// traced as Embree packets of 16, its widest: out[i] = 1 if blocked.
// Neighbouring rays (a 4×4 block of map pixels from one point, or a row of
// points toward one light) share most of their traversal; on the bunny at
// level 7 packets of 16 took 15–20 % off the rays' time against packets of 8
// along a pixel row (AVX-512; about the same either way where Embree runs a
// packet of 16 as two of 8).
//
// Never with the coherent hint (RTC_INTERSECT_CONTEXT_FLAG_COHERENT): with it
// rtcOccluded16 takes Embree's frustum path (occludedCoherent), which in
// Debian's libembree3 3.13.5 (GCC 12, AVX-512 kernels) can loop for ever.
// There the 64-bit mask of rays still to trace, `valid_bits`, is initialised
// by a 16-bit store (`kmovw %k6, 0x640(%rsp)`) and then read and cleared as
// 64 bits (`cmpq`, `tzcnt`, `andn`), so its upper 48 bits are whatever the
// thread's stack held there. Once the 16 real rays are done, a stale bit
// remains: `tzcnt` names a lane past the 16th, its octant is read from beyond
// the vector, no ray matches it, the bit is never cleared and the do-while
// spins. It only happens on CPUs where Embree runs packets of 16 natively
// (AVX-512), only for scenes with instances (our world scenes), and only
// when earlier calls on that thread left a non-zero byte in that slot, which
// depends on what ran there before: the Vulkan backend's host stage (not the
// CPU backend) on one machine, the sanitized build on another.
// RayPackets.OcclusionReturnsWhateverTheStackHolds forces it. The incoherent
// packet path keeps the mask in registers and gives the same answers.
template <class Origin, class Direction>
void occludedPackets(RTCScene scene, std::size_t count, float tnear, const Origin& origin, const Direction& direction,
                     std::span<std::uint8_t> out) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  constexpr std::size_t kWidth = 16;
  alignas(64) RTCRay16 packet;
  alignas(64) int valid[kWidth];
  for (std::size_t k = 0; k < kWidth; ++k) {  // what every ray of every packet shares, set once
    packet.tnear[k] = tnear;
    packet.time[k] = 0.0f;
    packet.mask[k] = ~0u;
    packet.id[k] = static_cast<unsigned>(k);
    packet.flags[k] = 0;
  }
  for (std::size_t first = 0; first < count; first += kWidth) {
    const std::size_t n = std::min(kWidth, count - first);
    for (std::size_t k = 0; k < kWidth; ++k) {
      const bool live = k < n;
      const glm::vec3 o = origin(live ? first + k : first);  // a dead lane copies a live one
      const glm::vec3 d = direction(live ? first + k : first);
      valid[k] = live ? -1 : 0;
      packet.org_x[k] = o.x;
      packet.org_y[k] = o.y;
      packet.org_z[k] = o.z;
      packet.dir_x[k] = d.x;
      packet.dir_y[k] = d.y;
      packet.dir_z[k] = d.z;
      // Embree marks a blocked ray by setting tfar to −∞, so it is reset.
      packet.tfar[k] = std::numeric_limits<float>::infinity();
    }
    rtcOccluded16(valid, scene, &context, &packet);
    for (std::size_t k = 0; k < n; ++k) out[first + k] = packet.tfar[k] == -std::numeric_limits<float>::infinity() ? 1 : 0;
  }
}

}  // namespace

void RayScene::occludedFrom(const glm::vec3& origin, float tnear, std::span<const glm::vec3> directions,
                            std::span<std::uint8_t> out) const {
  if (directions.size() != out.size()) {
    throw std::invalid_argument("RayScene::occludedFrom: " + std::to_string(directions.size()) + " directions but " +
                                std::to_string(out.size()) + " results");
  }
  occludedPackets(impl_->occlusionScene, directions.size(), tnear, [&](std::size_t) { return origin; },
                  [&](std::size_t i) { return directions[i]; }, out);
}

void RayScene::occludedToward(std::span<const glm::vec3> origins, const glm::vec3& direction, float tnear,
                              std::span<std::uint8_t> out) const {
  if (origins.size() != out.size()) {
    throw std::invalid_argument("RayScene::occludedToward: " + std::to_string(origins.size()) + " origins but " +
                                std::to_string(out.size()) + " results");
  }
  occludedPackets(impl_->occlusionScene, origins.size(), tnear, [&](std::size_t i) { return origins[i]; },
                  [&](std::size_t) { return direction; }, out);
}

void RayScene::occludedByObjectFrom(std::size_t object, const glm::vec3& origin, float tnear,
                                    std::span<const glm::vec3> directions, std::span<std::uint8_t> out) const {
  const Impl& s = *impl_;
  HC_CHECK_LT(object, s.objectScenes.size());
  if (directions.size() != out.size()) {
    throw std::invalid_argument("RayScene::occludedByObjectFrom: " + std::to_string(directions.size()) +
                                " directions but " + std::to_string(out.size()) + " results");
  }
  // The rays in the object's own frame: an affine map carries a ray's points
  // o + t·d to o' + t·d', so the same t, and what blocks it, are kept.
  const glm::mat4& toObject = s.worldToObject[object];
  const glm::vec3 o(toObject * glm::vec4(origin, 1.0f));
  const glm::mat3 linear(toObject);
  occludedPackets(s.objectScenes[object], directions.size(), tnear, [&](std::size_t) { return o; },
                  [&](std::size_t i) { return linear * directions[i]; }, out);
}

void RayScene::setTransform(std::size_t object, const glm::mat4& objectToWorld) {
  Impl& s = *impl_;
  if (object >= s.normalMatrices.size()) {
    throw std::out_of_range("RayScene::setTransform: object " + std::to_string(object) + " of " +
                            std::to_string(s.normalMatrices.size()));
  }
  checkTransform(objectToWorld, object);
  RTCGeometry geom = rtcGetGeometry(s.top.get(), static_cast<unsigned>(object));
  check(s.device.get(), "rtcGetGeometry");
  rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &objectToWorld[0][0]);
  check(s.device.get(), "rtcSetGeometryTransform");
  rtcCommitGeometry(geom);
  check(s.device.get(), "rtcCommitGeometry(instance)");
  rtcCommitScene(s.top.get());
  check(s.device.get(), "rtcCommitScene(top)");
  s.normalMatrices[object] = normalMatrix(objectToWorld);
  s.worldToObject[object] = glm::inverse(objectToWorld);
  s.chooseOcclusionScene(objectToWorld);
}

}  // namespace haarcast
