#include "haarcast/gpu/buffer.h"
#include "haarcast/gpu/compute.h"

#include "haarcast/core/check.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

namespace haarcast::gpu {
namespace {

const char* useName(MemoryUse use) {
  switch (use) {
    case MemoryUse::Host: return "host-visible";
    case MemoryUse::Readback: return "readback";
    case MemoryUse::DeviceInput: return "device input";
    case MemoryUse::DeviceOnly: return "device-only";
  }
  return "?";
}

void checkRange(const char* what, std::size_t bytes, std::size_t offset, VkDeviceSize size) {
  if (offset > size || bytes > size - offset) {
    throw std::out_of_range(std::string(what) + " of " + std::to_string(bytes) + " bytes at " + std::to_string(offset) +
                            " passes the end of a " + std::to_string(size) + "-byte buffer");
  }
}

}  // namespace

// ---- Buffer ------------------------------------------------------------

Buffer::Buffer(Context& context, VkDeviceSize bytes, VkBufferUsageFlags usage, MemoryUse use) : context_(&context) {
  size_ = std::max<VkDeviceSize>(4, (bytes + 3) / 4 * 4);
  VkBufferCreateInfo b{};
  b.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  b.size = size_;
  b.usage = usage;
  b.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkDevice device = context.device();
  vkCheck(vkCreateBuffer(device, &b, nullptr, &buffer_), "vkCreateBuffer");
  try {
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(device, buffer_, &req);
    const std::optional<MemoryPlacement> placement =
        chooseMemory(context.memoryProperties(), req.memoryTypeBits, use, context.directInputs());
    if (!placement) {
      throw std::runtime_error(std::string("no Vulkan memory type for a ") + useName(use) + " buffer among type bits " +
                               std::to_string(req.memoryTypeBits) + " on " + context.info().name);
    }
    // A buffer whose address a shader or an acceleration-structure build
    // reads (ray_tracing.h) needs memory allocated for device addresses.
    const bool addressed = (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) != 0;
    memory_ = context.allocate(req.size, placement->type, addressed ? VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT : 0);
    staged_ = placement->staged;
    vkCheck(vkBindBufferMemory(device, buffer_, memory_, 0), "vkBindBufferMemory");
    if (placement->mapped) vkCheck(vkMapMemory(device, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
  } catch (...) {
    release();
    throw;
  }
}

Buffer::~Buffer() { release(); }

VkDeviceAddress Buffer::deviceAddress() const {
  HC_CHECK_NE(buffer_, VK_NULL_HANDLE);
  VkBufferDeviceAddressInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO;
  info.buffer = buffer_;
  return vkGetBufferDeviceAddress(context_->device(), &info);
}

Buffer::Buffer(Buffer&& other) noexcept
    : context_(std::exchange(other.context_, nullptr)),
      buffer_(std::exchange(other.buffer_, VK_NULL_HANDLE)),
      memory_(std::exchange(other.memory_, VK_NULL_HANDLE)),
      size_(std::exchange(other.size_, 0)),
      mapped_(std::exchange(other.mapped_, nullptr)),
      staged_(std::exchange(other.staged_, false)) {}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(other.size_, 0);
    mapped_ = std::exchange(other.mapped_, nullptr);
    staged_ = std::exchange(other.staged_, false);
  }
  return *this;
}

void Buffer::release() {
  if (!context_) return;
  VkDevice device = context_->device();
  if (mapped_) vkUnmapMemory(device, memory_);
  if (buffer_) vkDestroyBuffer(device, buffer_, nullptr);
  context_->free(memory_);
  mapped_ = nullptr;
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  staged_ = false;
  context_ = nullptr;
}

void Buffer::write(const void* data, std::size_t bytes, std::size_t offset) {
  checkRange("Buffer::write", bytes, offset, size_);
  if (!mapped_ && bytes) throw std::logic_error("Buffer::write: the buffer is not host-visible (upload it with BufferUpload)");
  if (bytes) std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
}

void Buffer::read(void* data, std::size_t bytes, std::size_t offset) const {
  checkRange("Buffer::read", bytes, offset, size_);
  if (!mapped_ && bytes) throw std::logic_error("Buffer::read: the buffer is not host-visible");
  if (bytes) std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
}

void readBack(Context& context, const Buffer& source, void* data, std::size_t bytes, std::size_t offset) {
  if (source.mapped() || bytes == 0) {
    source.read(data, bytes, offset);
    return;
  }
  if (offset > source.size() || bytes > source.size() - offset) {
    throw std::out_of_range("readBack: " + std::to_string(bytes) + " bytes at " + std::to_string(offset) +
                            " pass the end of a buffer of " + std::to_string(source.size()));
  }
  Buffer copy(context, bytes, kStorageUsage, MemoryUse::Readback);
  context.submit([&](VkCommandBuffer cb) {
    computeBarrier(cb);  // after whatever wrote the source, in this queue
    const VkBufferCopy region{offset, 0, bytes};
    vkCmdCopyBuffer(cb, source.handle(), copy.handle(), 1, &region);
    computeBarrier(cb);  // before the host reads
  });
  copy.read(data, bytes);
}

// ---- TexelView ---------------------------------------------------------

TexelView::TexelView(Context& context, const Buffer& buffer, VkFormat format, std::size_t texelBytes)
    : context_(&context) {
  VkFormatProperties properties{};
  vkGetPhysicalDeviceFormatProperties(context.physicalDevice(), format, &properties);
  if (!(properties.bufferFeatures & VK_FORMAT_FEATURE_UNIFORM_TEXEL_BUFFER_BIT)) {
    throw std::runtime_error(context.info().name + " cannot read format " + std::to_string(format) +
                             " from a uniform texel buffer");
  }
  const std::uint64_t texels = buffer.size() / texelBytes;
  if (texels > context.properties().limits.maxTexelBufferElements) {
    throw std::runtime_error("a texel buffer of " + std::to_string(texels) + " texels exceeds " + context.info().name +
                             "'s maxTexelBufferElements (" +
                             std::to_string(context.properties().limits.maxTexelBufferElements) + ")");
  }
  VkBufferViewCreateInfo v{};
  v.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
  v.buffer = buffer.handle();
  v.format = format;
  v.offset = 0;
  v.range = VK_WHOLE_SIZE;
  vkCheck(vkCreateBufferView(context.device(), &v, nullptr, &view_), "vkCreateBufferView");
}

TexelView::~TexelView() { release(); }

TexelView::TexelView(TexelView&& other) noexcept
    : context_(std::exchange(other.context_, nullptr)), view_(std::exchange(other.view_, VK_NULL_HANDLE)) {}

TexelView& TexelView::operator=(TexelView&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    view_ = std::exchange(other.view_, VK_NULL_HANDLE);
  }
  return *this;
}

void TexelView::release() {
  if (context_ && view_) vkDestroyBufferView(context_->device(), view_, nullptr);
  context_ = nullptr;
  view_ = VK_NULL_HANDLE;
}

// ---- BufferUpload ------------------------------------------------------

BufferUpload::BufferUpload(Context& context, Buffer& target) : context_(&context), target_(&target) {
  if (target.staged()) staging_ = Buffer(context, target.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUse::Host);
}

void BufferUpload::write(const void* data, std::size_t bytes, std::size_t offset) {
  if (!target_) throw std::logic_error("BufferUpload::write without a target buffer");
  if (!staged()) {
    target_->write(data, bytes, offset);
    return;
  }
  staging_.write(data, bytes, offset);
  if (!bytes) return;
  if (dirtyBegin_ == dirtyEnd_) {
    dirtyBegin_ = offset;
    dirtyEnd_ = offset + bytes;
  } else {
    dirtyBegin_ = std::min(dirtyBegin_, offset);
    dirtyEnd_ = std::max(dirtyEnd_, offset + bytes);
  }
}

void BufferUpload::record(VkCommandBuffer cb) {
  if (!pending()) return;
  const VkBufferCopy region{dirtyBegin_, dirtyBegin_, dirtyEnd_ - dirtyBegin_};
  vkCmdCopyBuffer(cb, staging_.handle(), target_->handle(), 1, &region);
  dirtyBegin_ = dirtyEnd_ = 0;
}

void BufferUpload::submit() { submitUploads(*context_, std::span<BufferUpload>(this, 1)); }

void submitUploads(Context& context, std::span<BufferUpload> uploads) {
  if (std::none_of(uploads.begin(), uploads.end(), [](const BufferUpload& u) { return u.pending(); })) return;
  context.submit([&](VkCommandBuffer cb) {
    for (BufferUpload& u : uploads) u.record(cb);
    VkMemoryBarrier m{};
    m.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    m.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    m.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &m, 0, nullptr,
                         0, nullptr);
  });
}

}  // namespace haarcast::gpu
