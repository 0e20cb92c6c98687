// Storage buffers and how host data gets into them.
//
// A Buffer's memory follows its MemoryUse (memory.h): Host buffers are
// host-visible, coherent and mapped for their whole life; DeviceInput
// buffers are device-local, mapped only where the host sees all of
// device-local memory (CPU devices, integrated GPUs, resizable BAR) and
// otherwise filled through a staging buffer (BufferUpload); DeviceOnly
// buffers are device-local and never mapped.
//
//   gpu::Buffer slices(ctx, bytes, gpu::kStorageUsage, gpu::MemoryUse::DeviceInput);
//   gpu::BufferUpload up(ctx, slices);   // staging only where `slices` is not mapped
//   up.write(data, bytes);
//   up.submit();                         // or up.record(cb) inside a frame's command buffer
#pragma once

#include <cstddef>
#include <span>

#include <vulkan/vulkan.h>

#include "haarcast/gpu/context.h"
#include "haarcast/gpu/memory.h"

namespace haarcast::gpu {

// Storage, and both ends of transfers (uploads, fills, readback copies).
inline constexpr VkBufferUsageFlags kStorageUsage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
// The same, also readable as a uniform texel buffer (TexelView).
inline constexpr VkBufferUsageFlags kTexelUsage = kStorageUsage | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;

class Buffer {
 public:
  Buffer() = default;
  // bytes is rounded up to 4 and to at least 4 (Vulkan forbids empty buffers).
  // Throws std::runtime_error when the device has no memory type for `use`.
  Buffer(Context& context, VkDeviceSize bytes, VkBufferUsageFlags usage = kStorageUsage, MemoryUse use = MemoryUse::Host);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  // Its address on the device; the buffer needs
  // VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT (and the device, ray tracing:
  // context.h), which also allocates its memory for device addresses.
  VkDeviceAddress deviceAddress() const;
  // The host mapping, or null when the host cannot see the memory.
  void* mapped() const { return mapped_; }
  // Host data reaches it only through a staging buffer (BufferUpload).
  bool staged() const { return staged_; }

  // Byte copies in and out of the mapping; throw std::out_of_range when the
  // range passes the end and std::logic_error when there is no mapping.
  void write(const void* data, std::size_t bytes, std::size_t offset = 0);
  void read(void* data, std::size_t bytes, std::size_t offset = 0) const;
  template <class T>
  void upload(std::span<const T> values, std::size_t offset = 0) {
    write(values.data(), values.size_bytes(), offset);
  }
  template <class T>
  void download(std::span<T> values, std::size_t offset = 0) const {
    read(values.data(), values.size_bytes(), offset);
  }

 private:
  void release();
  Context* context_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
  bool staged_ = false;
};

// Bytes of any buffer to the host: from its mapping where it has one, else
// copied through a temporary Readback buffer in one submission of its own.
// For tests and inspection, not for a frame's path (which keeps its
// Readback copies and records their copies in the frame's own submission).
void readBack(Context& context, const Buffer& source, void* data, std::size_t bytes, std::size_t offset = 0);

// Host data into a buffer: straight into its mapping where it has one, else
// into a staging buffer (host-visible, the target's size, allocated once
// here) whose written range record() copies over. Keep one for the life of
// a buffer that is written every frame, so that frames allocate nothing.
// The target must outlive it and stay where it is.
class BufferUpload {
 public:
  BufferUpload() = default;
  BufferUpload(Context& context, Buffer& target);

  bool staged() const { return target_ && target_->staged(); }
  // Staged bytes written and not yet recorded.
  bool pending() const { return staged() && dirtyBegin_ != dirtyEnd_; }
  void write(const void* data, std::size_t bytes, std::size_t offset = 0);
  // Records the copy of the bytes written since the last record() (nothing
  // for a mapped target). The caller puts a barrier between it and the
  // passes that read the target (computeBarrier).
  void record(VkCommandBuffer cb);
  // Records into a command buffer of its own, with a barrier that makes the
  // copy visible to every later command, submits and waits.
  void submit();

 private:
  Context* context_ = nullptr;
  Buffer* target_ = nullptr;
  Buffer staging_;
  std::size_t dirtyBegin_ = 0, dirtyEnd_ = 0;  // bytes of staging_ written since the last record()
};

// A buffer seen as an array of texels of one format (a VkBufferView over the
// whole buffer), which a shader reads as a uniform texel buffer
// (samplerBuffer, texelFetch). The buffer needs kTexelUsage and must outlive
// the view. Throws std::runtime_error when the device cannot read the format
// from a texel buffer or the buffer holds more texels than
// maxTexelBufferElements allows.
class TexelView {
 public:
  TexelView() = default;
  TexelView(Context& context, const Buffer& buffer, VkFormat format, std::size_t texelBytes);
  ~TexelView();
  TexelView(TexelView&& other) noexcept;
  TexelView& operator=(TexelView&& other) noexcept;
  TexelView(const TexelView&) = delete;
  TexelView& operator=(const TexelView&) = delete;

  VkBufferView handle() const { return view_; }

 private:
  void release();
  Context* context_ = nullptr;
  VkBufferView view_ = VK_NULL_HANDLE;
};

// submit() for several uploads in one command buffer (the prepare step's).
void submitUploads(Context& context, std::span<BufferUpload> uploads);

}  // namespace haarcast::gpu
