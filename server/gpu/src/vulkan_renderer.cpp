#include "haarcast/gpu/vulkan_renderer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>

#include "haarcast/core/fused.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/gpu/rotation_data.h"
#include "haarcast/gpu/shaders.h"
#include "haarcast/render/shading.h"
#include "haarcast/render/tonemap.h"

namespace haarcast::gpu {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

constexpr VkFormat kNormalFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kIdsFormat = VK_FORMAT_R32G32B32A32_UINT;
constexpr VkFormat kPositionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr std::size_t kRotatedBudget = 256u << 20;  // bytes of rotated coefficients per batch, at most
constexpr std::size_t kFusedScratchBudget = 256u << 20;  // bytes of `fused` scratch in global memory, at most
constexpr std::size_t kFusedPlanesBudget = 256u << 20;   // bytes of vertex visibility in pixel form, at most

std::uint32_t groupsOf(std::size_t items, std::uint32_t local) {
  return static_cast<std::uint32_t>((items + local - 1) / local);
}

struct Push16 {
  std::uint32_t first = 0, count = 0, pad0 = 0, pad1 = 0;
};

// An image with its memory and view.
struct Image {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
};

}  // namespace

struct VulkanRenderer::Impl {
  render::RenderOptions options;
  VulkanRendererLimits limits;
  render::PreparedScene prepared;
  Context context;
  int level = 0;
  std::size_t coefficients = 0;  // N = 4^level
  std::string methodName;

  // ---- Scene data, uploaded once --------------------------------------------
  std::vector<ObjectInfo> objectInfo;
  std::vector<std::uint32_t> triangleCount;
  std::size_t vertexCount = 0, totalTriangles = 0;
  std::vector<std::size_t> visibilityBlocks;  // per global vertex, for the bytes-read count
  std::size_t rotationBytesPerChannel = 0;    // coefficient bytes one rotation reads (per object: same level)
  std::vector<std::size_t> methodBytesPerChannel;  // per object: method data one rotation reads
  Buffer slices, methodData, positions, normals, triangles, visibility, background;
  Buffer objects, light, frameParams, thresholds;
  // `fused`: the slices in pixel form (texels), the light in pixel form per
  // frame (in `light`), the pixel-centre directions and the workgroups' scratch.
  bool fused = false;
  Buffer directions, scratch;
  std::uint32_t fusedGroups = 0;     // the most workgroups of the fused dispatch
  std::uint32_t fusedLocal = 0;      // its local size
  bool fusedShared = false;          // scratch in shared memory (else in `scratch`)
  bool fusedVertexPlanes = false;    // visibility uploaded per vertex in pixel form (else as lists)

  // ---- Pipelines ---------------------------------------------------------------
  std::unique_ptr<ComputePipeline> rotate, rotationInput, tripleProduct, tonemap, fusedPass;
  VkRenderPass renderPass = VK_NULL_HANDLE;
  VkDescriptorSetLayout gbufferSetLayout = VK_NULL_HANDLE;
  VkPipelineLayout gbufferLayout = VK_NULL_HANDLE;
  VkPipeline gbufferPipeline = VK_NULL_HANDLE;
  VkDescriptorPool gbufferPool = VK_NULL_HANDLE;
  VkDescriptorSet gbufferSet = VK_NULL_HANDLE;

  // ---- Per resolution --------------------------------------------------------
  int width = 0, height = 0;
  std::size_t batch = 0, maxBatches = 0, lastBatches = 0;
  Image normalImage, idsImage, positionImage, depthImage;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  Buffer gbufIds, gbufNormals, gbufPositions, samples, shade, counter, radiance, rgba8, rotated;
  // Stage timing: timestamps around each stage's submission on GPUs; on a
  // CPU device (lavapipe), the host's wall time of the submission, because
  // lavapipe's timestamps do not wait for compute dispatches (measured: 0.8 s
  // of timestamps in a 3.8 s submission). On a CPU device, host time is device time.
  bool useTimestamps = false;
  static constexpr std::uint32_t kMaxTimedStages = 8;
  VkQueryPool queries = VK_NULL_HANDLE;

  void createFusedPipeline(std::uint32_t local);
  render::Frame renderFused(const render::FrameRequest& request);
  Impl(const render::Scene& scene, const render::RenderOptions& o, const VulkanOptions& vulkan,
       const render::RenderProgress& progress, const VulkanRendererLimits& l);
  ~Impl();
  void uploadScene();
  void createGraphicsPipeline();
  void ensureResolution(int w, int h);
  void releaseResolution();
  Image createImage(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect);
  void destroyImage(Image& image);
  render::Frame render(const render::FrameRequest& request);
  const render::Pose& poseOf(const render::FrameRequest& request, std::size_t i) const;
  glm::dmat4 frameViewProjection(const render::FrameRequest& request) const;
  // The frame's uniforms (camera, light turn, exposure, the fused dispatch's
  // workgroup count) and the sRGB thresholds of its exposure.
  void uploadFrameUniforms(const render::FrameRequest& request);
  // Auto exposure: the frame was tonemapped on the device with
  // provisionalStops(); measure the lit object pixels (mapped radiance and
  // ids) and, when the exposure they call for differs, tonemap again on the
  // host (the same thresholds, so the same bytes the device would give).
  void finishExposure(const render::FrameRequest& request, render::Frame& frame);
  void recordGBuffer(VkCommandBuffer cb, const render::FrameRequest& request, const glm::dmat4& viewProj);
  // The stages of a frame, in order: with timestamps, recorded into one
  // command buffer (a timestamp after each) and submitted once; otherwise
  // (a CPU device) one submission per stage, timed on the host.
  void runStages(const std::vector<std::pair<const char*, std::function<void(VkCommandBuffer)>>>& stages,
                 render::Frame& frame);
};

// ------------------------------------------------------------------ setup

VulkanRenderer::Impl::Impl(const render::Scene& scene, const render::RenderOptions& o, const VulkanOptions& vulkan,
                           const render::RenderProgress& progress, const VulkanRendererLimits& l)
    : options(o), limits(l), prepared(), context(vulkan) {
  render::checkRenderOptions(options);
  if (options.antialias) {
    throw std::invalid_argument("antialiasing is drawn by the CPU backend only: the Vulkan backend takes one sample per pixel");
  }
  fused = options.method == RotationMethod::Fused;
  if (fused) {
    checkFusedLevel(options.level);  // 2–7: its scratch need not fit in shared memory
  } else if (options.level < kMinGpuLevel || options.level > kMaxGpuLevel) {
    throw std::invalid_argument("the Vulkan backend takes map levels " + std::to_string(kMinGpuLevel) + " to " +
                                std::to_string(kMaxGpuLevel) + " (got " + std::to_string(options.level) +
                                "): a rotation workgroup keeps one map in shared memory, and a level-6 map is the "
                                "16 KiB every Vulkan device guarantees");
  }
  methodName = std::string(haarcast::methodName(options.method));
  const std::string shader = fused ? "fused.comp" : "rotate_" + methodName + ".comp";
  if (embeddedShader(shader).empty()) {
    throw std::invalid_argument("rotation method \"" + methodName + "\" has no Vulkan shader in this build (shaders/" +
                                shader + " is missing)");
  }
  level = options.level;
  coefficients = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  prepared = render::prepareScene(scene, options, progress);
  uploadScene();
  createGraphicsPipeline();
  useTimestamps = context.timestampsSupported() && context.properties().limits.timestampComputeAndGraphics &&
                  context.info().type != "cpu";
  if (useTimestamps) {
    VkQueryPoolCreateInfo q{};
    q.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    q.queryType = VK_QUERY_TYPE_TIMESTAMP;
    q.queryCount = kMaxTimedStages + 1;
    vkCheck(vkCreateQueryPool(context.device(), &q, nullptr, &queries), "vkCreateQueryPool");
  }
}

VulkanRenderer::Impl::~Impl() {
  VkDevice device = context.device();
  vkDeviceWaitIdle(device);  // best effort in a destructor
  releaseResolution();
  if (queries) vkDestroyQueryPool(device, queries, nullptr);
  if (gbufferPool) vkDestroyDescriptorPool(device, gbufferPool, nullptr);
  if (gbufferPipeline) vkDestroyPipeline(device, gbufferPipeline, nullptr);
  if (gbufferLayout) vkDestroyPipelineLayout(device, gbufferLayout, nullptr);
  if (gbufferSetLayout) vkDestroyDescriptorSetLayout(device, gbufferSetLayout, nullptr);
  if (renderPass) vkDestroyRenderPass(device, renderPass, nullptr);
}

void VulkanRenderer::Impl::uploadScene() {
  const std::size_t objectCount = prepared.objects.size();
  const auto T = static_cast<std::size_t>(options.thetaSamples);
  const std::size_t n = coefficients;

  // Slices: global slice s = object's base + t, channel c at (s·3 + c)·N
  // (the rotation contract's binding 1).
  std::vector<float> sliceData;
  std::vector<std::uint32_t> method;
  std::vector<glm::vec4> pos, nor;
  std::vector<std::uint32_t> tri;
  std::vector<SparseHaar> vis;
  objectInfo.resize(objectCount);
  for (std::size_t k = 0; k < objectCount; ++k) {
    const render::PreparedObject& p = prepared.objects[k];
    ObjectInfo& info = objectInfo[k];
    if (static_cast<std::size_t>(p.table.thetaSamples()) != T || p.table.level() != level) {
      throw std::logic_error("Vulkan backend: object " + p.name + " has a slice table unlike the options");
    }
    info.thetaSamples = static_cast<std::uint32_t>(T);
    if (fused) {
      // The slices in pixel form, RGB0 texels (core PixelSlices), slice s at s·N texels.
      const PixelSlices pixelSlices = PixelSlices::synthesize(p.table);
      info.sliceBase = static_cast<std::uint32_t>(sliceData.size() / (shared::kTexelFloats * n));
      sliceData.insert(sliceData.end(), pixelSlices.texels().begin(), pixelSlices.texels().end());
      setFusedSkip(info, level, pixelSlices.lastNonZeroRow());
    } else {
      info.sliceBase = static_cast<std::uint32_t>(sliceData.size() / (3 * n));
      for (std::size_t t = 0; t < T; ++t) {
        for (int c = 0; c < 3; ++c) {
          const auto coeffs = p.table.slice(c, static_cast<int>(t)).coefficients();
          sliceData.insert(sliceData.end(), coeffs.begin(), coeffs.end());
        }
      }
    }
    const std::size_t before = method.size();
    info.methodBase = options.method == RotationMethod::Spatial || fused
                          ? static_cast<std::uint32_t>(method.size())
                          : appendRotationData(options.method, p.table, info.sliceBase, method, options.rotator);
    const std::size_t blockWords = method.size() - before;
    // Bytes of method data one rotation of one channel reads: haar reads its
    // map's differences ((2M−1)·M words); table reads one copy instead of the
    // slice; matrix reads two of its K elevation matrices.
    std::size_t methodBytes = 0;
    const std::size_t m = static_cast<std::size_t>(mapSize(level));
    switch (options.method) {
      case RotationMethod::Haar: methodBytes = (2 * m - 1) * m * 4; break;
      case RotationMethod::Table: methodBytes = 0; break;
      case RotationMethod::Matrix: {
        const std::size_t matrices = std::max<std::size_t>(1, method.size() > before ? method[before] : 1);
        methodBytes = 2 * (blockWords * 4) / matrices;
        break;
      }
      case RotationMethod::Spatial:
      case RotationMethod::Fused: break;
    }
    methodBytesPerChannel.push_back(methodBytes);

    info.vertexBase = static_cast<std::uint32_t>(pos.size());
    info.triangleBase = static_cast<std::uint32_t>(tri.size() / 3);
    const Mesh& mesh = *p.mesh;
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
      pos.emplace_back(mesh.positions[v], 1.0f);
      nor.emplace_back(mesh.normals[v], 0.0f);
    }
    for (const glm::uvec3& t : mesh.triangles) {
      tri.push_back(info.vertexBase + t.x);
      tri.push_back(info.vertexBase + t.y);
      tri.push_back(info.vertexBase + t.z);
    }
    triangleCount.push_back(static_cast<std::uint32_t>(mesh.triangles.size()));
    if (p.visibility.size() != mesh.positions.size()) {
      throw std::logic_error("Vulkan backend: object " + p.name + " has " + std::to_string(p.visibility.size()) +
                             " visibility maps for " + std::to_string(mesh.positions.size()) + " vertices");
    }
    vis.insert(vis.end(), p.visibility.begin(), p.visibility.end());
  }
  vertexCount = pos.size();
  totalTriangles = tri.size() / 3;
  rotationBytesPerChannel = n * sizeof(float);  // the slice, or for table the copy that replaces it

  auto upload = [&](Buffer& b, const void* data, std::size_t bytes) {
    b = Buffer(context, bytes);
    b.write(data, bytes);
  };
  if (fused) {
    visibilityBlocks.resize(vis.size());
    for (std::size_t v = 0; v < vis.size(); ++v) visibilityBlocks[v] = vis[v].size();
    const std::size_t planeBytes = vis.size() * n * sizeof(float);
    fusedVertexPlanes = !limits.fusedVisibilityLists &&
                        planeBytes <= std::min<std::size_t>(kFusedPlanesBudget,
                                                            context.properties().limits.maxStorageBufferRange);
    if (fusedVertexPlanes) {
      // Every vertex's visibility in pixel form (synthesised once here):
      // fused.comp blends three of them per direction.
      visibility = Buffer(context, planeBytes);
      for (std::size_t v = 0; v < vis.size(); ++v) {
        const SphereMap pixelsOf = inverseHaar(vis[v].toDense());
        visibility.write(pixelsOf.values().data(), n * sizeof(float), v * n * sizeof(float));
      }
    } else {
      // The lists as they are: a (first, count) header per vertex, then
      // (index, value bits) entries; fused.comp merges and synthesises them.
      const std::vector<std::uint32_t> words = packVisibilityEntries(vis, level);
      upload(visibility, words.data(), words.size() * sizeof(std::uint32_t));
    }
  } else {
    const std::vector<glm::uvec4> visPacked = packSparseLists(vis, level);
    visibilityBlocks.resize(vis.size());
    for (std::size_t v = 0; v < vis.size(); ++v) visibilityBlocks[v] = visPacked[v].y;
    upload(visibility, visPacked.data(), visPacked.size() * sizeof(glm::uvec4));
  }
  upload(slices, sliceData.data(), sliceData.size() * sizeof(float));
  if (method.empty()) method.push_back(0u);  // spatial: a 4-byte dummy (the contract)
  upload(methodData, method.data(), method.size() * sizeof(std::uint32_t));
  upload(positions, pos.data(), pos.size() * sizeof(glm::vec4));
  upload(normals, nor.data(), nor.size() * sizeof(glm::vec4));
  upload(triangles, tri.data(), tri.size() * sizeof(std::uint32_t));

  // Backdrop maps, [channel][row][col].
  std::vector<float> bg;
  for (const SphereMap& map : prepared.background) bg.insert(bg.end(), map.values().begin(), map.values().end());
  upload(background, bg.data(), bg.size() * sizeof(float));

  objects = Buffer(context, objectCount * sizeof(ObjectInfo));
  // The light: per object and channel a header and at most (N − 1)/3 blocks;
  // for `fused` its pixel form, three planes of N floats per object.
  light = Buffer(context, fused ? objectCount * 3 * n * sizeof(float)
                                : objectCount * 3 * (1 + (n - 1) / 3) * sizeof(glm::uvec4));
  frameParams = Buffer(context, sizeof(FrameParams));
  thresholds = Buffer(context, 256 * sizeof(float));

  const auto lvl = static_cast<std::uint32_t>(level);
  // Constant 2 is rotate_spatial.comp's local size (the other methods'
  // shaders fix theirs and ignore it): on a CPU device fewer invocations per
  // workgroup make each barrier cheaper (docs/gpu.md, "Performance").
  std::uint32_t local = context.info().type == "cpu" ? 64u : 256u;
  if (limits.spatialLocalSize) local = limits.spatialLocalSize;
  rotationInput = std::make_unique<ComputePipeline>(context, "rotation_input.comp", 8, 0);
  tonemap = std::make_unique<ComputePipeline>(context, "tonemap.comp", 6, 0);
  if (fused) {
    createFusedPipeline(local);
    return;
  }
  rotate = std::make_unique<ComputePipeline>(
      context, "rotate_" + methodName + ".comp", 4, 16,
      std::vector<SpecConstant>{{0, lvl}, {1, static_cast<std::uint32_t>(T)}, {2, local}});
  tripleProduct = std::make_unique<ComputePipeline>(context, "triple_product.comp", 5, 16,
                                                    std::vector<SpecConstant>{{0, lvl}});
}

void VulkanRenderer::Impl::createFusedPipeline(std::uint32_t local) {
  // The pixel-centre directions, as core fused builds them (double → float).
  const std::vector<glm::vec4> dirs = pixelCentreDirections(level);
  directions = Buffer(context, dirs.size() * sizeof(glm::vec4));
  directions.write(dirs.data(), dirs.size() * sizeof(glm::vec4));

  // Scratch: in shared memory where the device has room for it (and the
  // reduction's vec3 per invocation), else a slice of a global buffer per
  // workgroup, whose size bounds the workgroups in flight.
  const VkPhysicalDeviceLimits& lim = context.properties().limits;
  const std::size_t floats = fusedScratchFloats(level, fusedVertexPlanes);
  fusedLocal = limits.fusedLocalSize ? limits.fusedLocalSize : local;
  fusedShared = !limits.fusedGlobalScratch &&
                floats * sizeof(float) + fusedLocal * 4 * sizeof(float) <= lim.maxComputeSharedMemorySize;
  const std::size_t maxGroups = lim.maxComputeWorkGroupCount[0];
  if (fusedShared) {
    fusedGroups = static_cast<std::uint32_t>(std::min<std::size_t>(maxGroups, 1u << 16));
    scratch = Buffer(context, sizeof(float));
  } else {
    const std::size_t budget = std::min<std::size_t>(kFusedScratchBudget, lim.maxStorageBufferRange);
    fusedGroups = static_cast<std::uint32_t>(std::clamp<std::size_t>(budget / (floats * sizeof(float)), 1, maxGroups));
    scratch = Buffer(context, std::size_t{fusedGroups} * floats * sizeof(float));
  }
  if (limits.fusedGroups) fusedGroups = std::min(fusedGroups, limits.fusedGroups);
  fusedPass = std::make_unique<ComputePipeline>(
      context, "fused.comp", 10, 0,
      std::vector<SpecConstant>{{0, static_cast<std::uint32_t>(level)},
                                {2, fusedLocal},
                                {3, fusedShared ? static_cast<std::uint32_t>(floats) : 1u},
                                {4, options.interpolateSlices ? 1u : 0u},
                                {5, fusedVertexPlanes ? 1u : 0u}});
}

void VulkanRenderer::Impl::createGraphicsPipeline() {
  VkDevice device = context.device();
  VkFormatProperties depth{};
  vkGetPhysicalDeviceFormatProperties(context.physicalDevice(), kDepthFormat, &depth);
  if (!(depth.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT)) {
    throw std::runtime_error(context.info().name + " cannot use VK_FORMAT_D32_SFLOAT as a depth attachment");
  }

  // Render pass: three colour attachments and depth, cleared, then read by
  // transfers (copied into buffers for the compute passes).
  std::array<VkAttachmentDescription, 4> att{};
  const VkFormat formats[4] = {kNormalFormat, kIdsFormat, kPositionFormat, kDepthFormat};
  for (std::size_t i = 0; i < 4; ++i) {
    att[i].format = formats[i];
    att[i].samples = VK_SAMPLE_COUNT_1_BIT;
    att[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    att[i].storeOp = i < 3 ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att[i].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    att[i].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att[i].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    att[i].finalLayout = i < 3 ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  }
  const VkAttachmentReference colour[3] = {{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
                                           {1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
                                           {2, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}};
  const VkAttachmentReference depthRef{3, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 3;
  subpass.pColorAttachments = colour;
  subpass.pDepthStencilAttachment = &depthRef;
  std::array<VkSubpassDependency, 2> deps{};
  // Earlier transfers (last frame's copies) before this frame's writes …
  deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  deps[0].dstSubpass = 0;
  deps[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  deps[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT;
  deps[0].srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT;
  // … and the attachments written before the copies read them.
  deps[1].srcSubpass = 0;
  deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo rp{};
  rp.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  rp.attachmentCount = static_cast<std::uint32_t>(att.size());
  rp.pAttachments = att.data();
  rp.subpassCount = 1;
  rp.pSubpasses = &subpass;
  rp.dependencyCount = static_cast<std::uint32_t>(deps.size());
  rp.pDependencies = deps.data();
  vkCheck(vkCreateRenderPass(device, &rp, nullptr, &renderPass), "vkCreateRenderPass");

  // Set 0: positions, normals, triangles (vertex stage storage buffers).
  gbufferSetLayout = createStorageSetLayout(device, 3, VK_SHADER_STAGE_VERTEX_BIT);
  VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(GBufferPush)};
  VkPipelineLayoutCreateInfo pl{};
  pl.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &gbufferSetLayout;
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &range;
  vkCheck(vkCreatePipelineLayout(device, &pl, nullptr, &gbufferLayout), "vkCreatePipelineLayout");

  VkShaderModule vert = createShaderModule(context, "gbuffer.vert");
  VkShaderModule frag = VK_NULL_HANDLE;
  try {
    frag = createShaderModule(context, "gbuffer.frag");
    std::array<VkPipelineShaderStageCreateInfo, 2> stages{};
    stages[0].sType = stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vert;
    stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = frag;
    stages[1].pName = "main";
    VkPipelineVertexInputStateCreateInfo vi{};
    vi.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    VkPipelineInputAssemblyStateCreateInfo ia{};
    ia.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo vp{};
    vp.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    vp.viewportCount = 1;
    vp.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo rs{};
    rs.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.cullMode = VK_CULL_MODE_NONE;  // rays hit back faces too (Embree, the CPU G-buffer)
    rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    rs.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{};
    ms.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;  // one sample at the pixel centre, like a primary ray
    VkPipelineDepthStencilStateCreateInfo ds{};
    ds.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    ds.depthTestEnable = VK_TRUE;
    ds.depthWriteEnable = VK_TRUE;
    ds.depthCompareOp = VK_COMPARE_OP_GREATER;  // reversed Z: depth = near / distance
    std::array<VkPipelineColorBlendAttachmentState, 3> blend{};
    for (auto& a : blend) {
      a.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                         VK_COLOR_COMPONENT_A_BIT;
    }
    VkPipelineColorBlendStateCreateInfo cb{};
    cb.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    cb.attachmentCount = 3;
    cb.pAttachments = blend.data();
    const VkDynamicState dynamic[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dy{};
    dy.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
    dy.dynamicStateCount = 2;
    dy.pDynamicStates = dynamic;
    VkGraphicsPipelineCreateInfo gp{};
    gp.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    gp.stageCount = 2;
    gp.pStages = stages.data();
    gp.pVertexInputState = &vi;
    gp.pInputAssemblyState = &ia;
    gp.pViewportState = &vp;
    gp.pRasterizationState = &rs;
    gp.pMultisampleState = &ms;
    gp.pDepthStencilState = &ds;
    gp.pColorBlendState = &cb;
    gp.pDynamicState = &dy;
    gp.layout = gbufferLayout;
    gp.renderPass = renderPass;
    vkCheck(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &gp, nullptr, &gbufferPipeline),
            "vkCreateGraphicsPipelines");
  } catch (...) {
    vkDestroyShaderModule(device, vert, nullptr);
    if (frag) vkDestroyShaderModule(device, frag, nullptr);
    throw;
  }
  vkDestroyShaderModule(device, vert, nullptr);
  vkDestroyShaderModule(device, frag, nullptr);

  allocateStorageSet(device, gbufferSetLayout, 3, gbufferPool, gbufferSet);
  const VkDescriptorBufferInfo infos[3] = {{positions.handle(), 0, VK_WHOLE_SIZE},
                                           {normals.handle(), 0, VK_WHOLE_SIZE},
                                           {triangles.handle(), 0, VK_WHOLE_SIZE}};
  std::array<VkWriteDescriptorSet, 3> writes{};
  for (std::uint32_t i = 0; i < 3; ++i) {
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = gbufferSet;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  vkUpdateDescriptorSets(device, 3, writes.data(), 0, nullptr);
}

Image VulkanRenderer::Impl::createImage(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect) {
  VkDevice device = context.device();
  Image out;
  VkImageCreateInfo ic{};
  ic.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ic.imageType = VK_IMAGE_TYPE_2D;
  ic.format = format;
  ic.extent = {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height), 1};
  ic.mipLevels = 1;
  ic.arrayLayers = 1;
  ic.samples = VK_SAMPLE_COUNT_1_BIT;
  ic.tiling = VK_IMAGE_TILING_OPTIMAL;
  ic.usage = usage;
  ic.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  vkCheck(vkCreateImage(device, &ic, nullptr, &out.image), "vkCreateImage");
  try {
    VkMemoryRequirements req{};
    vkGetImageMemoryRequirements(device, out.image, &req);
    out.memory = context.allocate(req.size, context.memoryType(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT));
    vkCheck(vkBindImageMemory(device, out.image, out.memory, 0), "vkBindImageMemory");
    VkImageViewCreateInfo vc{};
    vc.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vc.image = out.image;
    vc.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vc.format = format;
    vc.subresourceRange = {aspect, 0, 1, 0, 1};
    vkCheck(vkCreateImageView(device, &vc, nullptr, &out.view), "vkCreateImageView");
  } catch (...) {
    destroyImage(out);
    throw;
  }
  return out;
}

void VulkanRenderer::Impl::destroyImage(Image& image) {
  VkDevice device = context.device();
  if (image.view) vkDestroyImageView(device, image.view, nullptr);
  if (image.image) vkDestroyImage(device, image.image, nullptr);
  context.free(image.memory);
  image = Image{};
}

void VulkanRenderer::Impl::releaseResolution() {
  VkDevice device = context.device();
  if (framebuffer) vkDestroyFramebuffer(device, framebuffer, nullptr);
  framebuffer = VK_NULL_HANDLE;
  for (Image* i : {&normalImage, &idsImage, &positionImage, &depthImage}) destroyImage(*i);
  for (Buffer* b : {&gbufIds, &gbufNormals, &gbufPositions, &samples, &shade, &counter, &radiance, &rgba8, &rotated}) {
    *b = Buffer();
  }
  width = height = 0;
  batch = maxBatches = 0;
}

void VulkanRenderer::Impl::ensureResolution(int w, int h) {
  if (w == width && h == height) return;
  releaseResolution();
  width = w;
  height = h;
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  constexpr VkImageUsageFlags colourUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  normalImage = createImage(kNormalFormat, colourUsage, VK_IMAGE_ASPECT_COLOR_BIT);
  idsImage = createImage(kIdsFormat, colourUsage, VK_IMAGE_ASPECT_COLOR_BIT);
  positionImage = createImage(kPositionFormat, colourUsage, VK_IMAGE_ASPECT_COLOR_BIT);
  depthImage = createImage(kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT);
  const VkImageView views[4] = {normalImage.view, idsImage.view, positionImage.view, depthImage.view};
  VkFramebufferCreateInfo fb{};
  fb.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
  fb.renderPass = renderPass;
  fb.attachmentCount = 4;
  fb.pAttachments = views;
  fb.width = static_cast<std::uint32_t>(w);
  fb.height = static_cast<std::uint32_t>(h);
  fb.layers = 1;
  vkCheck(vkCreateFramebuffer(context.device(), &fb, nullptr, &framebuffer), "vkCreateFramebuffer");

  gbufIds = Buffer(context, pixels * sizeof(glm::uvec4));
  gbufNormals = Buffer(context, pixels * sizeof(glm::vec4));
  gbufPositions = Buffer(context, pixels * sizeof(glm::vec4));
  samples = Buffer(context, pixels * sizeof(RotationSample));
  shade = Buffer(context, pixels * sizeof(ShadeSample));
  // The covered-pixel count and `fused`'s indirect dispatch arguments.
  counter = Buffer(context, sizeof(CoverageCounter),
                   VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                       VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  radiance = Buffer(context, pixels * sizeof(glm::vec4));
  rgba8 = Buffer(context, pixels * sizeof(std::uint32_t));

  rotationInput->bind({&frameParams, &objects, &gbufIds, &gbufNormals, &triangles, &samples, &shade, &counter});
  tonemap->bind({&frameParams, &gbufIds, &radiance, &background, &rgba8, &thresholds});
  if (fused) {
    fusedPass->bind({&samples, &shade, &objects, &slices, &light, &visibility, &directions, &scratch, &radiance, &counter});
    return;
  }

  // The batch: as many covered pixels as the rotated buffer holds within the
  // budget, the device's storage-buffer range and one dispatch's group count.
  const VkPhysicalDeviceLimits& lim = context.properties().limits;
  const std::size_t perSample = 3 * coefficients * sizeof(float);
  const std::size_t range = std::min<std::size_t>(kRotatedBudget, lim.maxStorageBufferRange);
  batch = std::min({pixels, range / perSample, static_cast<std::size_t>(lim.maxComputeWorkGroupCount[0]),
                    static_cast<std::size_t>(lim.maxComputeWorkGroupCount[0]) * 64 / 3});
  if (limits.batchSamples) batch = std::min(batch, limits.batchSamples);
  batch = std::max<std::size_t>(batch, 1);
  maxBatches = (pixels + batch - 1) / batch;
  rotated = Buffer(context, batch * perSample);


  rotate->bind({&samples, &slices, &methodData, &rotated});
  tripleProduct->bind({&shade, &rotated, &light, &visibility, &radiance});
}

// ------------------------------------------------------------------ a frame

namespace {

// Clip coordinates of a world point for render::CameraRays' pinhole: x right,
// y down (Vulkan's framebuffer has row 0 at the top, as the image does), and
// reversed, infinite-far Z (depth = near / distance, greatest wins), whose
// float precision does not depend on the scene's depth range.
glm::dmat4 viewProjection(const render::Camera& camera, int width, int height, double nearPlane) {
  const CameraBasis basis = cameraBasis(camera);
  const glm::dvec3 &f = basis.forward, &r = basis.right, &u = basis.up;
  const double tanHalf = render::verticalTanHalf(camera, width, height);
  const double aspect = static_cast<double>(width) / height;
  const glm::dvec3& e = camera.eye;
  glm::dmat4 m(0.0);  // m[column][row]
  const double sx = 1.0 / (tanHalf * aspect), sy = -1.0 / tanHalf;
  for (int c = 0; c < 3; ++c) {
    m[c][0] = sx * r[c];
    m[c][1] = sy * u[c];
    m[c][2] = 0.0;
    m[c][3] = f[c];
  }
  m[3][0] = -sx * glm::dot(r, e);
  m[3][1] = -sy * glm::dot(u, e);
  m[3][2] = nearPlane;
  m[3][3] = -glm::dot(f, e);
  return m;
}

}  // namespace

const render::Pose& VulkanRenderer::Impl::poseOf(const render::FrameRequest& request, std::size_t i) const {
  return request.poses.empty() ? prepared.objects[i].pose : request.poses[i];
}

glm::dmat4 VulkanRenderer::Impl::frameViewProjection(const render::FrameRequest& request) const {
  // Near plane: a fraction of the nearest object's bounding-sphere distance.
  double nearest = std::numeric_limits<double>::infinity(), farthest = 0.0;
  for (std::size_t i = 0; i < prepared.objects.size(); ++i) {
    const Bounds b = prepared.objects[i].mesh->bounds();
    const glm::dvec3 centre = glm::dvec3(poseOf(request, i).objectToWorld() * glm::dvec4(b.centre(), 1.0));
    const double radius = b.radius() * poseOf(request, i).scale;
    const double d = glm::length(centre - request.camera.eye);
    nearest = std::min(nearest, d - radius);
    farthest = std::max(farthest, d + radius);
  }
  const double nearPlane = nearest > 0.0 ? std::max(0.5 * nearest, 1e-6 * farthest) : 1e-6 * std::max(farthest, 1.0);
  return viewProjection(request.camera, request.width, request.height, nearPlane);
}

// The G-buffer: every object rasterised, then the attachments copied to the
// storage buffers the compute passes read.
void VulkanRenderer::Impl::recordGBuffer(VkCommandBuffer cb, const render::FrameRequest& request,
                                         const glm::dmat4& viewProj) {
  std::array<VkClearValue, 4> clear{};
  clear[3].depthStencil = {0.0f, 0};  // reversed Z: 0 is infinitely far
  VkRenderPassBeginInfo rb{};
  rb.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rb.renderPass = renderPass;
  rb.framebuffer = framebuffer;
  rb.renderArea = {{0, 0}, {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)}};
  rb.clearValueCount = 4;
  rb.pClearValues = clear.data();
  vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
  const VkViewport viewport{0.0f, 0.0f, static_cast<float>(width), static_cast<float>(height), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)}};
  vkCmdSetViewport(cb, 0, 1, &viewport);
  vkCmdSetScissor(cb, 0, 1, &scissor);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, gbufferPipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, gbufferLayout, 0, 1, &gbufferSet, 0, nullptr);
  for (std::size_t i = 0; i < prepared.objects.size(); ++i) {
    GBufferPush push;
    push.objectToClip = glm::mat4(viewProj * poseOf(request, i).objectToWorld());
    push.objectId = static_cast<std::uint32_t>(i);
    push.triangleBase = objectInfo[i].triangleBase;
    vkCmdPushConstants(cb, gbufferLayout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof push,
                       &push);
    vkCmdDraw(cb, 3 * triangleCount[i], 1, 0, 0);
  }
  vkCmdEndRenderPass(cb);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height), 1};
  vkCmdCopyImageToBuffer(cb, normalImage.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, gbufNormals.handle(), 1, &region);
  vkCmdCopyImageToBuffer(cb, idsImage.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, gbufIds.handle(), 1, &region);
  vkCmdCopyImageToBuffer(cb, positionImage.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, gbufPositions.handle(), 1,
                         &region);
}

void VulkanRenderer::Impl::runStages(
    const std::vector<std::pair<const char*, std::function<void(VkCommandBuffer)>>>& stages, render::Frame& frame) {
  if (!useTimestamps) {
    for (const auto& [name, record] : stages) {
      const auto t = Clock::now();
      context.submit([&](VkCommandBuffer cb) {
        record(cb);
        computeBarrier(cb);
      });
      frame.stages.push_back({name, since(t)});
    }
    return;
  }
  const auto count = static_cast<std::uint32_t>(stages.size());
  if (count > kMaxTimedStages) throw std::logic_error("runStages: more stages than timestamp queries");
  context.submit([&](VkCommandBuffer cb) {
    vkCmdResetQueryPool(cb, queries, 0, count + 1);
    vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 0);
    for (std::uint32_t i = 0; i < count; ++i) {
      stages[i].second(cb);
      computeBarrier(cb);
      vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, i + 1);
    }
  });
  std::array<std::uint64_t, kMaxTimedStages + 1> ticks{};
  vkCheck(vkGetQueryPoolResults(context.device(), queries, 0, count + 1, (count + 1) * sizeof(std::uint64_t), ticks.data(),
                                sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
  // Only timestampValidBits of a tick count; differences are taken modulo that.
  const std::uint64_t mask = context.timestampValidBits() >= 64 ? ~std::uint64_t{0}
                                                                 : (std::uint64_t{1} << context.timestampValidBits()) - 1;
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint64_t delta = (ticks[i + 1] - ticks[i]) & mask;
    frame.stages.push_back({stages[i].first, static_cast<double>(delta) * context.timestampPeriodNs() * 1e-9});
  }
}

// `fused`: G-buffer → rotation input (compaction, indirect arguments) →
// fused (vkCmdDispatchIndirect, no readback of the count) → tonemap.
namespace {
double provisionalStops(const render::ExposureControl& exposure) {
  return exposure.automatic ? exposure.previousStops.value_or(0.0) : exposure.stops;
}
}  // namespace

void VulkanRenderer::Impl::uploadFrameUniforms(const render::FrameRequest& request) {
  const double stops = provisionalStops(request.exposure);
  FrameParams params = makeFrameParams(request.camera, request.width, request.height, request.lightRotation, stops,
                                       options.environmentBackground, prepared.background[0].level());
  params.fusedGroups = fusedGroups;
  frameParams.write(&params, sizeof params);
  const std::array<float, 256> encoding = render::tonemapThresholds(stops);
  thresholds.write(encoding.data(), sizeof encoding);
}

void VulkanRenderer::Impl::finishExposure(const render::FrameRequest& request, render::Frame& frame) {
  const double provisional = provisionalStops(request.exposure);
  frame.exposureStops = provisional;
  if (!request.exposure.automatic) return;
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  io::RgbImage linear = frame.image;
  if (linear.rgb.empty()) {
    linear = io::makeImage(width, height);
    const auto* rad = static_cast<const glm::vec4*>(radiance.mapped());
    for (std::size_t p = 0; p < pixels; ++p) {
      for (std::size_t c = 0; c < 3; ++c) linear.rgb[3 * p + c] = rad[p][static_cast<int>(c)];
    }
  }
  frame.logAverageLuminance = render::frameLogAverage(linear, frame.objectMask);
  frame.exposureStops = render::applyExposure(request.exposure, frame.logAverageLuminance);
  if (frame.exposureStops != provisional) frame.rgba8 = render::tonemapRgba8(linear, frame.exposureStops);
}

render::Frame VulkanRenderer::Impl::renderFused(const render::FrameRequest& request) {
  const auto start = Clock::now();
  render::Frame frame;
  frame.width = request.width;
  frame.height = request.height;

  // ---- light (host): resolveFrame, as the CPU backend; its pixel form uploaded
  auto t0 = Clock::now();
  const render::ResolvedFrame resolved = render::resolveFrame(prepared, options, request);
  ensureResolution(request.width, request.height);
  const std::size_t objectCount = prepared.objects.size();
  const std::size_t planeBytes = 3 * coefficients * sizeof(float);
  for (std::size_t i = 0; i < objectCount; ++i) {
    const render::ResolvedObject& o = resolved.objects[i];
    light.write(o.fusedLight.planes.data(), planeBytes, i * planeBytes);
    for (int c = 0; c < 3; ++c) objectInfo[i].rotation[c] = glm::vec4(glm::vec3(o.rotation[c]), 0.0f);
  }
  objects.write(objectInfo.data(), objectInfo.size() * sizeof(ObjectInfo));
  uploadFrameUniforms(request);
  frame.stages.push_back({"light", since(t0)});

  // ---- the device's part: one command buffer (timestamps) or one per stage
  const glm::dmat4 viewProj = frameViewProjection(request);
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  runStages({{"gbuffer", [&](VkCommandBuffer cb) { recordGBuffer(cb, request, viewProj); }},
             {"rotation-input",
              [&](VkCommandBuffer cb) {
                vkCmdFillBuffer(cb, counter.handle(), 0, VK_WHOLE_SIZE, 0u);
                computeBarrier(cb);
                rotationInput->dispatch(cb, {groupsOf(pixels, 64), 1, 1});
              }},
             {"fused",
              [&](VkCommandBuffer cb) {
                fusedPass->dispatchIndirect(cb, counter, offsetof(CoverageCounter, groups));
              }},
             {"tonemap", [&](VkCommandBuffer cb) { tonemap->dispatch(cb, {groupsOf(pixels, 64), 1, 1}); }}},
            frame);

  // ---- Results: RGBA8 always, the linear image only when asked for ----------
  frame.rgba8.resize(pixels * 4);
  rgba8.read(frame.rgba8.data(), frame.rgba8.size());
  frame.objectMask.assign(pixels, 0);
  const auto* ids = static_cast<const glm::uvec4*>(gbufIds.mapped());
  for (std::size_t p = 0; p < pixels; ++p) frame.objectMask[p] = ids[p].x != 0 ? 1 : 0;
  if (request.linearImage) {
    frame.image = io::makeImage(width, height);
    const auto* rad = static_cast<const glm::vec4*>(radiance.mapped());
    for (std::size_t p = 0; p < pixels; ++p) {
      for (std::size_t c = 0; c < 3; ++c) frame.image.rgb[3 * p + c] = rad[p][static_cast<int>(c)];
    }
  }
  finishExposure(request, frame);

  // Coefficient bytes read, counted as the CPU backend counts them: the light
  // lists, and per covered pixel core fusedPixelBytes (one slice or two, the
  // light planes, the three vertices' entries).
  std::size_t bytes = resolved.lightBytes;
  CoverageCounter count{};
  counter.read(&count, sizeof count);
  const auto* rs = static_cast<const RotationSample*>(samples.mapped());
  const auto* sh = static_cast<const ShadeSample*>(shade.mapped());
  for (std::uint32_t i = 0; i < count.covered && i < pixels; ++i) {
    std::size_t entries = 0;
    for (std::uint32_t v : sh[i].vertex) entries += v < visibilityBlocks.size() ? visibilityBlocks[v] : 0;
    const shared::SliceBlend blend =
        shared::sliceBlendAt(rs[i].thetaOut, static_cast<shared::uint>(options.thetaSamples), options.interpolateSlices ? 1u : 0u);
    // With the vertices' pixel forms, three planes of N floats replace the lists.
    bytes += fusedVertexPlanes ? fusedPixelBytes(level, blend.weight != 0.0f && blend.second != blend.first, 0) +
                                     3 * coefficients * sizeof(float)
                               : fusedPixelBytes(level, blend.weight != 0.0f && blend.second != blend.first, entries);
  }
  frame.coefficientBytes = bytes;
  frame.seconds = since(start);
  return frame;
}

render::Frame VulkanRenderer::Impl::render(const render::FrameRequest& request) {
  if (fused) return renderFused(request);
  render::checkFrameRequest(request, prepared.objects.size());
  const auto start = Clock::now();
  ensureResolution(request.width, request.height);
  const std::size_t objectCount = prepared.objects.size();
  auto poseOf = [&](std::size_t i) -> const render::Pose& {
    return request.poses.empty() ? prepared.objects[i].pose : request.poses[i];
  };
  const std::size_t k = request.lightCoefficients ? request.lightCoefficients : options.lightCoefficients;
  render::Frame frame;
  frame.width = request.width;
  frame.height = request.height;
  std::size_t bytes = 0;

  // ---- light (host): the same code as the CPU backend ----------------------
  auto t0 = Clock::now();
  std::vector<SparseHaar> lights;
  lights.reserve(objectCount * 3);
  for (std::size_t i = 0; i < objectCount; ++i) {
    const glm::dmat3 rot = poseOf(i).rotation();
    for (SparseHaar& s : render::lightInObjectFrame(prepared.light, rot, request.lightRotation, k)) {
      lights.push_back(std::move(s));
    }
    for (int c = 0; c < 3; ++c) objectInfo[i].rotation[c] = glm::vec4(glm::vec3(rot[c]), 0.0f);
  }
  const std::vector<glm::uvec4> lightPacked = packSparseLists(lights, level);
  light.write(lightPacked.data(), lightPacked.size() * sizeof(glm::uvec4));
  bytes += (lightPacked.size() - lights.size()) * sizeof(glm::uvec4);
  objects.write(objectInfo.data(), objectInfo.size() * sizeof(ObjectInfo));
  uploadFrameUniforms(request);
  frame.stages.push_back({"light", since(t0)});

  const glm::dmat4 viewProj = frameViewProjection(request);

  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  // Each stage is its own submission, timed as the member comment says.
  auto timed = [&](double& seconds, const std::function<void(VkCommandBuffer)>& record) {
    const auto t = Clock::now();
    context.submit([&](VkCommandBuffer cb) {
      if (useTimestamps) {
        vkCmdResetQueryPool(cb, queries, 0, 2);
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 0);
      }
      record(cb);
      computeBarrier(cb);
      if (useTimestamps) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 1);
    });
    if (!useTimestamps) {
      seconds += since(t);
      return;
    }
    std::uint64_t ticks[2] = {0, 0};
    vkCheck(vkGetQueryPoolResults(context.device(), queries, 0, 2, sizeof ticks, ticks, sizeof(std::uint64_t),
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "vkGetQueryPoolResults");
    if (ticks[1] > ticks[0]) seconds += static_cast<double>(ticks[1] - ticks[0]) * context.timestampPeriodNs() * 1e-9;
  };
  double gbuffer = 0, rotInput = 0, rotation = 0, product = 0, tone = 0;

  // ---- gbuffer ------------------------------------------------------------------
  timed(gbuffer, [&](VkCommandBuffer cb) { recordGBuffer(cb, request, viewProj); });

  // ---- rotation-input -----------------------------------------------------------
  timed(rotInput, [&](VkCommandBuffer cb) {
    vkCmdFillBuffer(cb, counter.handle(), 0, VK_WHOLE_SIZE, 0u);
    computeBarrier(cb);
    rotationInput->dispatch(cb, {groupsOf(pixels, 64), 1, 1});
  });
  std::uint32_t covered = 0;
  counter.read(&covered, sizeof covered);
  if (covered > pixels) throw std::logic_error("rotation-input reported more covered pixels than the frame has");

  // ---- rotation and triple-product, batch by batch --------------------------------
  const std::size_t batches = (covered + batch - 1) / batch;
  lastBatches = batches;
  for (std::size_t b = 0; b < batches; ++b) {
    Push16 push;
    push.first = static_cast<std::uint32_t>(b * batch);
    push.count = static_cast<std::uint32_t>(std::min<std::size_t>(batch, covered - b * batch));
    // The contract: one workgroup per (sample, channel).
    timed(rotation, [&](VkCommandBuffer cb) { rotate->dispatch(cb, {push.count, 3, 1}, &push, sizeof push); });
    timed(product, [&](VkCommandBuffer cb) {
      tripleProduct->dispatch(cb, {groupsOf(3 * std::size_t{push.count}, 64), 1, 1}, &push, sizeof push);
    });
  }

  // ---- tonemap ------------------------------------------------------------------
  timed(tone, [&](VkCommandBuffer cb) { tonemap->dispatch(cb, {groupsOf(pixels, 64), 1, 1}); });

  // ---- Results ---------------------------------------------------------------
  frame.image = io::makeImage(width, height);
  frame.objectMask.assign(pixels, 0);
  frame.rgba8.resize(pixels * 4);
  {
    const auto* rad = static_cast<const glm::vec4*>(radiance.mapped());
    const auto* ids = static_cast<const glm::uvec4*>(gbufIds.mapped());
    for (std::size_t p = 0; p < pixels; ++p) {
      for (std::size_t c = 0; c < 3; ++c) frame.image.rgb[3 * p + c] = rad[p][static_cast<int>(c)];
      frame.objectMask[p] = ids[p].x != 0 ? 1 : 0;
    }
    rgba8.read(frame.rgba8.data(), frame.rgba8.size());
  }
  finishExposure(request, frame);

  frame.stages.push_back({"gbuffer", gbuffer});
  frame.stages.push_back({"rotation-input", rotInput});
  frame.stages.push_back({"rotation", rotation});
  frame.stages.push_back({"triple-product", product});
  frame.stages.push_back({"tonemap", tone});

  // Coefficient bytes read: the light lists (above), and per covered pixel and
  // channel the rotation's data and the three vertices' visibility lists, in
  // the GPU's own formats (16-byte blocks).
  {
    const auto* sh = static_cast<const ShadeSample*>(shade.mapped());
    for (std::uint32_t i = 0; i < covered; ++i) {
      std::size_t visBlocks = 0;
      for (std::uint32_t v : sh[i].vertex) visBlocks += v < visibilityBlocks.size() ? visibilityBlocks[v] : 0;
      const std::size_t object = sh[i].object < objectCount ? sh[i].object : 0;
      bytes += 3 * (rotationBytesPerChannel + methodBytesPerChannel[object] + visBlocks * sizeof(glm::uvec4));
    }
  }
  frame.coefficientBytes = bytes;
  frame.seconds = since(start);
  return frame;
}

// ------------------------------------------------------------------ facade

VulkanRenderer::VulkanRenderer(const render::Scene& scene, const render::RenderOptions& options,
                               const VulkanOptions& vulkan, const render::RenderProgress& progress,
                               const VulkanRendererLimits& limits)
    : impl_(std::make_unique<Impl>(scene, options, vulkan, progress, limits)) {}

VulkanRenderer::~VulkanRenderer() = default;

std::string VulkanRenderer::deviceName() const { return impl_->context.info().name; }
const render::RenderOptions& VulkanRenderer::options() const { return impl_->options; }
std::size_t VulkanRenderer::objectCount() const { return impl_->prepared.objects.size(); }
render::Frame VulkanRenderer::render(const render::FrameRequest& request) { return impl_->render(request); }
Context& VulkanRenderer::context() { return impl_->context; }
const render::PreparedScene& VulkanRenderer::prepared() const { return impl_->prepared; }
std::size_t VulkanRenderer::batchSamples() const { return impl_->batch; }
std::size_t VulkanRenderer::batchesLastFrame() const { return impl_->lastBatches; }

namespace {
template <class T>
std::vector<T> readAll(const Buffer& b, std::size_t count) {
  std::vector<T> out(count);
  if (count) b.read(out.data(), count * sizeof(T));
  return out;
}
}  // namespace

std::vector<glm::uvec4> VulkanRenderer::gbufferIds() const {
  return readAll<glm::uvec4>(impl_->gbufIds, static_cast<std::size_t>(impl_->width) * static_cast<std::size_t>(impl_->height));
}
std::vector<glm::vec4> VulkanRenderer::gbufferNormals() const {
  return readAll<glm::vec4>(impl_->gbufNormals, static_cast<std::size_t>(impl_->width) * static_cast<std::size_t>(impl_->height));
}
std::vector<glm::vec4> VulkanRenderer::gbufferPositions() const {
  return readAll<glm::vec4>(impl_->gbufPositions, static_cast<std::size_t>(impl_->width) * static_cast<std::size_t>(impl_->height));
}
std::vector<RotationSample> VulkanRenderer::rotationSamples() const {
  std::uint32_t covered = 0;
  if (impl_->counter.handle()) impl_->counter.read(&covered, sizeof covered);
  return readAll<RotationSample>(impl_->samples, covered);
}
std::vector<ShadeSample> VulkanRenderer::shadeSamples() const {
  std::uint32_t covered = 0;
  if (impl_->counter.handle()) impl_->counter.read(&covered, sizeof covered);
  return readAll<ShadeSample>(impl_->shade, covered);
}

std::unique_ptr<render::Renderer> makeVulkanRenderer(const render::Scene& scene, const render::RenderOptions& options,
                                                     const VulkanOptions& vulkan, const render::RenderProgress& progress) {
  return std::make_unique<VulkanRenderer>(scene, options, vulkan, progress);
}

}  // namespace haarcast::gpu
