// `fused`'s "light" stage on the device (shaders/light.comp,
// core/shared_light.h): each object's light in its own frame, made every
// frame inside the frame's one submission from the rest maps uploaded once.
// The host's share is a push block per object (its rest map, its ground).

#include <map>
#include <optional>
#include <utility>

#include "haarcast/core/check.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/sphere_map.h"
#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

void VulkanRenderer::Impl::createFusedLight(const DirectionTable& directionTable) {
  // The rest map at each object's turn level (render::lightTurnLevel), once
  // per level, RGB0 texels in the map's row-major order; the level's
  // directions and solid angles are in the direction table.
  std::vector<glm::vec4> rest;
  std::map<int, std::uint32_t> baseOf;
  lightRestOf.clear();
  for (const render::PreparedObject& p : prepared.objects) {
    const int turn = render::lightTurnLevel(p.level);
    auto [at, added] = baseOf.try_emplace(turn, static_cast<std::uint32_t>(rest.size()));
    if (added) {
      const std::array<SphereMap, 3>& maps = prepared.restLightAt(turn);
      for (std::size_t i = 0; i < maps[0].pixelCount(); ++i)
        rest.emplace_back(maps[0].values()[i], maps[1].values()[i], maps[2].values()[i], 0.0f);
    }
    LightPush& of = lightRestOf.emplace_back();
    of.restBase = at->second;
    of.restLevel = static_cast<std::uint32_t>(turn);
    of.restDirections = directionTable.base[static_cast<std::size_t>(turn)];
  }
  lightRestMaps = Buffer(context, rest.size() * sizeof(glm::vec4), kStorageUsage, MemoryUse::DeviceInput);
  BufferUpload up(context, lightRestMaps);
  up.write(rest.data(), rest.size() * sizeof(glm::vec4));
  up.submit();
  lightPass = std::make_unique<ComputePipeline>(context, "light.comp", shared::kLightBindings, sizeof(LightPush));
  lightPass->bind({{shared::kLightObjectsBinding, &objects},
                   {shared::kLightRestBinding, &lightRestMaps},
                   {shared::kLightDirectionsBinding, &directions},
                   {shared::kLightTexelsBinding, &light}});
}

void VulkanRenderer::Impl::recordFusedLight(VkCommandBuffer cb, const render::ResolvedFrame& resolved) {
  const std::size_t objectCount = prepared.objects.size();
  HC_CHECK_EQ(resolved.objects.size(), objectCount);
  HC_CHECK_EQ(lightRestOf.size(), objectCount);
  // The ground's normal in the world (renderer.cpp resolveFrame's).
  std::optional<glm::dvec3> groundNormal;
  if (prepared.ground) groundNormal = resolved.objects[*prepared.ground].rotation * glm::dvec3(0.0, 1.0, 0.0);
  lightMadeFor.resize(objectCount);
  lightMaking.assign(objectCount, std::nullopt);
  std::vector<LightPush> pushes(objectCount);
  std::vector<bool> make(objectCount);
  lightsMadeLastFrame = 0;
  for (std::size_t i = 0; i < objectCount; ++i) {
    // Everything the object's texels depend on that a request changes.
    const render::FusedLightCache::Key key{resolved.lightRotation, resolved.objects[i].rotation, groundNormal};
    make[i] = !(lightMadeFor[i] == key);
    if (make[i]) {
      lightMadeFor[i].reset();  // until its frame has run: the buffer may hold either light
      lightMaking[i] = key;
      ++lightsMadeLastFrame;
    }
    const render::PreparedObject& p = prepared.objects[i];
    LightPush& push = pushes[i];
    push = lightRestOf[i];
    push.object = static_cast<std::uint32_t>(i);
    if (groundNormal && !p.ground) {
      push.groundUp = glm::vec4(glm::vec3(glm::transpose(resolved.objects[i].rotation) * *groundNormal), 1.0f);
    }
    if (p.ground) push.albedo = glm::vec4(glm::vec3(p.groundAlbedo / kPi), 0.0f);
  }
  // Every turned object's texels, then what is made from them: the cells'
  // power and centroids, the ground's flat radiance (the ground's every
  // frame: its ObjectInfo is written by the host each frame).
  for (LightPush& push : pushes) {
    if (!make[push.object]) continue;
    push.phase = shared::kLightPhaseTexels;
    const std::size_t m = static_cast<std::size_t>(mapSize(prepared.objects[push.object].level));
    lightPass->dispatch(cb, {groupsOf(m * m, shared::kLocalSize), 1, 1}, &push, sizeof push);
  }
  computeBarrier(cb);
  for (LightPush& push : pushes) {
    const render::PreparedObject& p = prepared.objects[push.object];
    const std::size_t m = static_cast<std::size_t>(mapSize(p.level));
    if (make[push.object] && objectInfo[push.object].sumTolerance > 0.0f) {
      push.phase = shared::kLightPhaseCells;
      lightPass->dispatch(cb, {groupsOf(m * m / shared::kCellDirections, shared::kLocalSize), 1, 1}, &push, sizeof push);
    }
    if (p.ground) {
      push.phase = shared::kLightPhaseGround;
      lightPass->dispatch(cb, {1, 1, 1}, &push, sizeof push);
    }
  }
}

void VulkanRenderer::Impl::fusedLightMade() {
  for (std::size_t i = 0; i < lightMaking.size(); ++i)
    if (lightMaking[i]) lightMadeFor[i] = std::exchange(lightMaking[i], std::nullopt);
}

}  // namespace haarcast::gpu
