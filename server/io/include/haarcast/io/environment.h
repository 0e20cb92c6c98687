// Light probes: loading HDR environment images in the usual probe layouts,
// turning them into haarcast's lat-long convention, and filtering them into
// the level-n maps that the Haar transform takes (DESIGN.md "Maps").
//
// Orientation. haarcast's world is the probe's own frame: +Y up, and the
// direction the probe's centre looks at is −Z (Debevec's convention for both
// of his layouts, and HDRShop's). No rotation is applied; an application that
// wants the environment turned rotates the light, as it does per object.
//
// Lat-long probes (equirectangular, width = 2·height). Point (u, v) ∈ [0, 1]²
// of the image (u to the right, v down) is seen in direction
//     θ = π·v (from +Y: the top row looks up),
//     d = (−sin θ sin 2πu, cos θ, sin θ cos 2πu),
// so the centre column u = ½ looks down −Z, u = ¾ looks toward +X, u = ¼
// toward −X, and the left and right edges meet at +Z, behind the viewer. This
// is the picture a viewer at the centre sees, not mirrored: facing −Z with +Y
// up, +X is on the right. The USC ICT probe pages describe this layout
// (centre −Z "forward", top edge straight up); its handedness is the one that
// agrees with Debevec's angular maps, whose (u, v) = (Dx·r, Dy·r) also puts +X
// on the right. Comparing with haarcast's
// d = (sin θ sin φ, cos θ, sin θ cos φ) gives sin φ = −sin 2πu and
// cos φ = cos 2πu, that is
//     φ = 2π·(1 − u):
// haarcast's φ runs from +Z toward +X, which for a viewer inside the sphere is
// leftward. In pixels, haarcast's column j (φ_j = (j + ½)2π/W) is the probe's
// column W − 1 − j: the conversion is an exact left-right mirror, with no
// resampling and no half-pixel shift.
//
// Angular maps (Debevec's light-probe layout, width = height). Image point
// (u, v) ∈ [−1, 1]² (u to the right, v up, the image's corners at ±1), at
// r = √(u² + v²) ≤ 1, is seen in direction
//     d = (u·sin(πr)/r, v·sin(πr)/r, −cos(πr)):
// the angle from the forward direction −Z is π·r, so the centre looks down
// −Z, the circle r = ½ is the sideways great circle (u = ½, v = 0 is +X,
// u = 0, v = ½ is +Y) and the rim r = 1 is +Z. This agrees with the lat-long
// layout above: the two are the same environment in the same frame.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "haarcast/core/sphere_map.h"
#include "haarcast/io/image.h"

namespace haarcast::io {

enum class ProbeLayout { Auto, LatLong, Angular };

// "auto", "latlong", "angular" (for command lines and requests); throws
// std::invalid_argument naming the text otherwise.
ProbeLayout parseProbeLayout(std::string_view name);
const char* probeLayoutName(ProbeLayout layout);

// Direction seen at point (u, v) ∈ [0, 1]² of a lat-long probe (file comment).
glm::dvec3 latLongProbeDirection(double u, double v);

// Direction seen at point (u, v) ∈ [−1, 1]² of an angular map, or nullopt
// outside the unit disc (file comment).
std::optional<glm::dvec3> angularProbeDirection(double u, double v);

// The angular-map point (u, v) at which direction `d` (any length > 0) is
// seen; +Z, the whole rim, is given as (1, 0).
glm::dvec2 directionToAngularProbe(const glm::dvec3& d);

// A lat-long probe, in the usual layout, as a haarcast lat-long image: the
// left-right mirror derived in the file comment.
RgbImage latLongProbeToHaarcast(const RgbImage& probe);

// Resamples an N×N angular map to a 2N×N haarcast lat-long image. N rows
// resolve θ twice as finely as the angular map resolves angle at its centre
// (2π/N per pixel), so nothing is lost there; toward the rim the angular map
// is denser, and each output pixel averages supersampling² stratified
// (equal-area) bilinear lookups. Lookups use only pixels whose centres lie in
// the disc, so the black corners of real probes do not bleed in. Measured:
// ∫ L dω of the angular map kept to 6e-5 (grace, 256²) and 2e-5 (grace EXR,
// 512²); about 0.4 s for a 1024² map on one core.
RgbImage angularProbeToLatLong(const RgbImage& angular, int supersampling = 2);

// Reads an environment image (any format readImage reads) and returns it as a
// haarcast lat-long image: row 0 is θ = 0 (+Y), column j is at
// φ = (j + ½)·2π/width from +Z toward +X. Auto takes width = 2·height as
// lat-long and width = height as angular, and refuses anything else. Pixel
// values that are not finite (NaN, ±inf) make it throw: a probe with them
// would poison every Haar coefficient it touches. Errors are
// std::runtime_error starting with the path.
RgbImage loadEnvironment(const std::string& path, ProbeLayout layout = ProbeLayout::Auto);

// ∫ L dω of each channel of a haarcast lat-long image of any size, with the
// exact solid angle of each pixel row, (cos θ⁻ − cos θ⁺)·2π/width.
std::array<double, 3> latLongIntegral(const RgbImage& latlong);

// One level-n map per channel (R, G, B). Each map pixel is the solid-angle
// weighted average of the image over the pixel's footprint — an area
// average, not a point sample — computed separably, since both grids are
// products of a θ interval and a φ interval:
//   pixel = Σ_ab L_ab · w_θ(a) · w_φ(b) / (Σ_a w_θ(a) · Σ_b w_φ(b)),
// with w_θ(a) = ∫ k_a(θ) sin θ dθ and w_φ(b) = ∫ k_b(φ) dφ over the pixel.
// Along an axis where the map is no finer than the image (the usual case:
// a 1024×512 or 256×128 probe into a level 5–7 map), k is the image pixel's
// box and the weights are exact overlaps, so every image pixel's energy
// L·ΔΩ is shared out exactly and ∫ L dω is preserved to float rounding for
// any ratio of sizes, fractional ones included. Along an axis where the map
// is finer than the image, k is the linear (tent) kernel between pixel
// centres — the image is reconstructed bilinearly, φ wrapping, θ clamped at
// the poles like SphereMap — integrated by `supersampling` equal-measure
// sub-intervals per map pixel; that path preserves a constant exactly and
// ∫ L dω to second order (the tent's sin θ-weighted area is not quite its
// row's solid angle near the poles).
// Measured relative change of ∫ L dω: ≤ 1e-8 (float rounding) for grace
// (1024×512 EXR), the five 256×128 ICT probes and three 1k Poly Haven
// probes at levels 5–7; 2e-5–1.6e-4 for the 256×128 probes upsampled to
// levels 8–9; 0.16 % for a 32×16 image of random spikes upsampled.
// Throws std::invalid_argument for a bad level (checkLevel), an empty or
// malformed image, or supersampling outside [1, 64].
std::array<SphereMap, 3> environmentToMaps(const RgbImage& latlong, int level, int supersampling = 4);

// loadEnvironment followed by environmentToMaps; the level is checked first.
std::array<SphereMap, 3> loadEnvironmentMaps(const std::string& path, int level,
                                             ProbeLayout layout = ProbeLayout::Auto, int supersampling = 4);

}  // namespace haarcast::io
