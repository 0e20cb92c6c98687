// How far a render is from the truth, over the object's pixels (linear RGB),
// in whole and split into the pixels the scene's objects shadow and the rest
// (docs/evaluation.md "Shadows"):
//
//   truth PSNR     10·log10(peak²/MSE), peak = the truth's maximum (DESIGN.md)
//   relative L2    sqrt(Σ(a − r)² / Σr²)
//   brightness     Σa / Σr (1 = as bright as the truth)
//
// a the render, r the truth, sums over the object pixels' channels. A group
// (shadowed, lit) also gets its fraction of the object's pixels and its share
// of the object's squared error Σ(a − r)².
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

namespace haarcast::app {

// The relative drop in luminance that marks a pixel as shadowed.
inline constexpr double kShadowThreshold = 0.02;

// Rec. 709 luminance of a linear RGB triple.
inline double luminance(const float* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

// 1 where mask is set and luminance(occluded) < (1 − threshold)·luminance(unoccluded):
// the truth with the scene's occlusion against the truth with none. rgb
// spans hold 3 floats per pixel. Throws std::invalid_argument on mismatched sizes.
std::vector<std::uint8_t> shadowedPixels(std::span<const float> occluded, std::span<const float> unoccluded,
                                         std::span<const std::uint8_t> mask, double threshold = kShadowThreshold);

struct GroupError {
  std::size_t pixels = 0;
  double pixelFraction = 0.0;  // of the object's pixels
  double errorShare = 0.0;     // of the object's Σ(a − r)²; 0 when that is 0
  double relativeL2 = 0.0;     // within the group; 0 when the group is empty or black
  double brightness = 0.0;     // Σa/Σr within the group; 0 when empty or black
};

struct TruthError {
  double psnr = 0.0;  // capped at 300 dB (an exact match)
  double mse = 0.0;
  double relativeL2 = 0.0;
  double brightness = 0.0;
  GroupError shadowed, lit;
};

// `test` against `truth` over `mask`; `shadowed` splits the object's pixels
// (empty: everything is lit). Throws std::invalid_argument on mismatched
// sizes or an empty mask.
TruthError compareWithTruth(std::span<const float> truth, std::span<const float> test,
                            std::span<const std::uint8_t> mask, std::span<const std::uint8_t> shadowed);

nlohmann::json toJson(const TruthError& e);

// Pixels drawn much darker than the truth where the truth is mostly lit
// (docs/evaluation.md "Shadows"): of `mask`'s pixels whose truth keeps more
// than `keptShare` of its unoccluded luminance (the light it would get with
// nothing occluding), those whose render is more than `darker` below the
// truth in luminance. A render that takes a lit region for a shadow shows
// here, however little it weighs in relative L2.
inline constexpr double kDarkKeptShare = 0.5;
inline constexpr double kDarkDrop = 0.2;

struct DarkPixels {
  std::size_t eligible = 0;       // mask pixels that keep more than keptShare of their open light
  std::size_t dark = 0;           // of those, drawn more than `darker` below the truth
  double worstRatio = 1.0;        // the smallest render / truth luminance among the eligible (1 when none)
  std::size_t worstPixel = 0;     // where it is (row-major); 0 when none
  std::vector<std::size_t> where; // the dark pixels (row-major), in order
};

// Throws std::invalid_argument on mismatched sizes.
DarkPixels darkPixels(std::span<const float> truth, std::span<const float> unoccluded, std::span<const float> test,
                      std::span<const std::uint8_t> mask, double keptShare = kDarkKeptShare, double darker = kDarkDrop);

nlohmann::json toJson(const DarkPixels& d);

}  // namespace haarcast::app
