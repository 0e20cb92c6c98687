// The G-buffer pass: its render pass and graphics pipeline, and the
// recording of one frame's raster with the resolved frame's projection
// (render::ResolvedFrame::viewProjection, render::CameraRays' pinhole).

#include <array>
#include <stdexcept>

#include "haarcast/gpu/shaders.h"

#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

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
  gbufferSetLayout = createStorageSetLayout(device, shared::kGBufferBindings, VK_SHADER_STAGE_VERTEX_BIT);
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

  allocateStorageSet(device, gbufferSetLayout, shared::kGBufferBindings, gbufferPool, gbufferSet);
  std::array<VkDescriptorBufferInfo, shared::kGBufferBindings> infos{};
  infos[shared::kGBufferPositionsBinding] = {positions.handle(), 0, VK_WHOLE_SIZE};
  infos[shared::kGBufferNormalsBinding] = {normals.handle(), 0, VK_WHOLE_SIZE};
  infos[shared::kGBufferTrianglesBinding] = {triangles.handle(), 0, VK_WHOLE_SIZE};
  std::array<VkWriteDescriptorSet, shared::kGBufferBindings> writes{};
  for (std::uint32_t i = 0; i < shared::kGBufferBindings; ++i) {
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = gbufferSet;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  vkUpdateDescriptorSets(device, shared::kGBufferBindings, writes.data(), 0, nullptr);
}

// Every object rasterised into `t`, then the attachments copied to the
// storage buffers the compute passes read. The projection is the frame's at
// any scale: at twice the resolution the pixel centres land on the
// sub-samples (shared_layout.h).
void VulkanRenderer::Impl::rasterise(VkCommandBuffer cb, const render::ResolvedFrame& resolved,
                                     const GBufferTarget& t, const Buffer& ids,
                                     const Buffer& normalsOut, const Buffer* positionsOut) {
  std::array<VkClearValue, 4> clear{};
  clear[3].depthStencil = {0.0f, 0};  // reversed Z: 0 is infinitely far
  VkRenderPassBeginInfo rb{};
  rb.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rb.renderPass = renderPass;
  rb.framebuffer = t.framebuffer;
  rb.renderArea = {{0, 0}, {t.width, t.height}};
  rb.clearValueCount = 4;
  rb.pClearValues = clear.data();
  vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
  const VkViewport viewport{0.0f, 0.0f, static_cast<float>(t.width), static_cast<float>(t.height), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, {t.width, t.height}};
  vkCmdSetViewport(cb, 0, 1, &viewport);
  vkCmdSetScissor(cb, 0, 1, &scissor);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, gbufferPipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, gbufferLayout, 0, 1, &gbufferSet, 0, nullptr);
  for (std::size_t i = 0; i < prepared.objects.size(); ++i) {
    GBufferPush push;
    push.objectToClip = glm::mat4(resolved.viewProjection * resolved.objects[i].objectToWorld);
    push.objectId = static_cast<std::uint32_t>(i);
    push.triangleBase = objectInfo[i].triangleBase;
    vkCmdPushConstants(cb, gbufferLayout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof push,
                       &push);
    vkCmdDraw(cb, 3 * triangleCount[i], 1, 0, 0);
  }
  vkCmdEndRenderPass(cb);
  markPart(cb, positionsOut ? "raster" : "sub-sample raster");
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {t.width, t.height, 1};
  vkCmdCopyImageToBuffer(cb, t.normal.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, normalsOut.handle(), 1, &region);
  vkCmdCopyImageToBuffer(cb, t.ids.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, ids.handle(), 1, &region);
  if (positionsOut) {
    vkCmdCopyImageToBuffer(cb, t.position.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, positionsOut->handle(), 1,
                           &region);
  }
}

void VulkanRenderer::Impl::recordGBuffer(VkCommandBuffer cb, const render::ResolvedFrame& resolved) {
  rasterise(cb, resolved, target, gbufIds, gbufNormals, &gbufPositions);
  markPart(cb, "copies");
  if (options.antialias) {
    rasterise(cb, resolved, subTarget, subIds, subNormals, nullptr);
    markPart(cb, "sub-sample copies");
  }
}

}  // namespace haarcast::gpu
