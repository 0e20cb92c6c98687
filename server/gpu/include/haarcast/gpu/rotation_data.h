// Host-side packing of the per-method data of the rotation shaders: kRotateMethodDataBinding
// (`uint methodData[]`) of shaders/rotate_<method>.comp. One block per object,
// appended to one word vector; the block's first word offset is the object's
// RotationSample::methodBase. Floats are stored as their bits
// (uintBitsToFloat in the shaders). All offsets are in 32-bit words.
//
// Layouts (M = 2^n map side, N = M², T = the object's θ slices, slice t of
// channel c being the object's global slice sliceBase + t in kRotateSlicesBinding):
//
//  haar, variant refined (RotatorOptions{}) — the rotate_haar.comp step (1)
//  data: f's exact differences across every pixel boundary, per slice and
//  channel, derived at load time from the coefficients by
//  refinedPixelDifferences (core/rotate_haar.h), not stored assets.
//  (2M−1)·M words per map, 2× the map itself: at level 5, 8 KiB per map,
//  384 KiB for a 48-map table (16 θ × 3 channels).
//    [0] sliceBase  [1] 0 (refined)  [2..3] 0
//    [4 + (t·3 + c)·(2M−1)·M …]  fT[(M−1)·M] then fP[M·M], row-major
//
//  haar, variant faithful — the seed as written: the finest details as
//  derivative samples and ∫f dω for the scaling coefficient, also derived at
//  load time (1 + M²/2 words per map, half the map).
//    [0] sliceBase  [1] 1 (faithful)  [2..3] 0
//    [4 + 2^l − 1 + i]  verticalDetailMoment(n, l, i), l < n, i < 2^l
//    [4 + (M−1) + (t·3 + c)·(1 + M²/2) …]  ∫f dω, then ∂f/∂θ ≈ −v/Δθ and
//    ∂f/∂φ ≈ −h/Δφ at the (M/2)² block centres, row-major
//
//  table — the CPU table rotator's pre-rotated copies (tableCopies), per
//  channel: N words per copy, T·3·Kβ·Kγ copies.
//    [0] sliceBase  [1] Kβ (elevations)  [2] Kγ (spins)  [3] 0
//    [4 + (((t·3 + c)·Kβ + k)·Kγ + j)·N …]  slice t, channel c rotated by (0, β_k, γ_j)
//
//  matrix — the CPU matrix rotator's elevation matrices (elevationMatrixViews).
//  They depend on the level only, not on the slices, so one set serves every
//  channel and slice of the object.
//    [0] K  [1..3] 0  [4 + k] offset of matrix k from the block start
//    matrix k: rowStart[N + 1] (entry indices), then entries as
//              (column, value bits) pairs
//
//  spatial — no data; the block is empty and methodBase is where the next
//  block would start.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/rotation.h"

namespace haarcast::gpu {

// Map levels the rotation shaders accept: at level 6 their shared memory
// reaches the 16 KiB that every Vulkan device offers (the table and matrix
// shaders use exactly 16 KiB there, haar 10.7 KiB).
inline constexpr int kMinRotationLevel = 1;
inline constexpr int kMaxRotationLevel = 6;

// Appends one object's block for `method` to methodData and returns its
// methodBase. The table and matrix data come from CPU rotators built here
// with `options` on the table's channel slices; for haar, options picks the
// variant, refined or faithful, which the shader reads from the block.
// Throws std::invalid_argument naming the problem: a level outside
// [kMinRotationLevel, kMaxRotationLevel], the haar variant local, a haar
// start level other than the finest (the shader starts from the finest
// level), or a buffer that would pass 2^32 words.
std::uint32_t appendRotationData(RotationMethod method, const BrdfSliceTable& table, std::uint32_t sliceBase,
                                 std::vector<std::uint32_t>& methodData, const RotatorOptions& options = {});

// The same for table or matrix from CPU rotators already built, one per
// channel on table.channelSlices(c), so that the GPU uses exactly their
// copies or matrices. Throws std::invalid_argument unless all three share one
// method, table or matrix, and the table's level and slice count.
std::uint32_t appendRotationData(const std::array<const SliceRotator*, 3>& channelRotators, const BrdfSliceTable& table,
                                 std::uint32_t sliceBase, std::vector<std::uint32_t>& methodData);

}  // namespace haarcast::gpu
