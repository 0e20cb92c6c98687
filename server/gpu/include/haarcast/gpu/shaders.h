// The SPIR-V of shaders/, compiled by glslang at build time and embedded in
// the binary (shaders/CMakeLists.txt generates the definitions).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace haarcast::gpu {

// The words of the shader compiled from shaders/<name>, e.g.
// "rotate_spatial.comp"; empty when there is no such shader.
std::span<const std::uint32_t> embeddedShader(std::string_view name);

// Every embedded shader's name, in file-name order.
std::vector<std::string_view> embeddedShaderNames();

}  // namespace haarcast::gpu
