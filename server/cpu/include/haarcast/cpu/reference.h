// The Monte Carlo reference: the truth that "truth PSNR" is measured against
// (DESIGN.md "Measurements"). It estimates, at each pixel's first hit, the
// same integral as renderCpu,
//
//   L_o = ∫ L_env(ω) ρ(ω, ωₒ) cos θᵢ V(ω) dω,
//
// with everything renderCpu shares held fixed and nothing band-limited:
// - camera: renderCpu's pixel rays (pixel centres, same fov and aspect);
// - shading normal: the barycentric blend of the hit triangle's vertex
//   normals, normalised; ρ is evaluated in renderCpu's local frame (+Y = the
//   shading normal, the view direction at φ = 0); cos θᵢ ≤ 0 contributes 0;
// - light: Environment::radiance per direction (full resolution), the object
//   frame being the pose's rotation of the world (L_obj(ω) = L_world(R ω));
// - visibility V(ω): traced at the hit point itself (not interpolated from
//   vertices), the ray starting at the hit point moved along the shading
//   normal by an offset (below). ReferenceOptions::occlusion says against what:
//   · scene (the default): every object of the scene, each posed by its
//     pose, in the world frame: objects shadow each other and a ground
//     object;
//   · self: the hit object alone, in its object frame (what renderCpu's
//     per-vertex visibility holds);
//   · none: V = 1, nothing occludes (with scene, it marks shadowed pixels).
//   The offset. self: shadowOffset × the mesh's bounding radius, object
//   frame (visibility.cpp's rule, with the hit point in place of the
//   vertex). scene: in world units,
//
//     offset = max(shadowOffset × r_min, 2⁻¹⁷ × m),
//
//   r_min the smallest world bounding radius of the scene's objects, m the
//   largest coordinate magnitude of the hit point (in the world, or in the
//   object frame times the pose's scale, whichever is larger). Why r_min and
//   not the hit object's radius: a ray leaving a large ground plane (a
//   radius of tens of units) would otherwise start a millimetre-scale
//   distance above it and pass under the contact shadow of a small object
//   standing on it; the offset stays a length below the smallest feature
//   that can occlude. Why the floor: the ray's origin is a float, rounded by
//   up to half an ulp of its largest coordinate, and Embree's intersection
//   is exact to about as much, so the offset never falls under 64 ulps
//   (2⁻¹⁷ relative): no ray re-hits the surface it leaves, whatever the
//   sizes (50 units from the origin under a 1 mm ball, 1e-4 × its radius is
//   1.7e-7, under the rounding's 2e-6, and a third of the ground's rays would
//   re-hit it). With one object, or objects of one size near the origin,
//   this is the self rule in world units;
// - background: Environment::radiance along the pixel ray, or black.
//
// On a faceted mesh the hit point lies on a flat triangle while the shading
// normal is interpolated, so directions between the triangle's plane and the
// shading horizon can hit the neighbouring facets. The reference keeps that
// (it is what a ray tracer sees); per-vertex visibility, taken at vertices on
// the surface, does not. The effect is a sliver of width ≈ the facet angle at
// the shading horizon, where cos θᵢ is small: ≈ 0.1–0.5% of a Lambert
// surface's radiance on the 32–64-segment built-in spheres.
//
// Sampling (one "sample" = one direction from each strategy in use):
// - environment: a piecewise-constant distribution over a lat-long table of
//   the environment (environmentTableWidth × width/2 cells; each cell holds
//   the largest channel-mean radiance on a 3×3 lattice that includes its
//   edges, plus a floor of 1e-3 × the mean so that no direction has zero
//   density). A cell is chosen by its value × its exact solid angle, then a
//   direction uniformly in solid angle inside it (uniform in cos θ and φ),
//   so the density is piecewise constant in solid angle:
//   p(ω) = value(cell)/Σ value·ΔΩ — the usual p(u, v)/(2π² sin θ) with the
//   sin θ taken exactly over each cell. The cell maximum, not the mean,
//   keeps f/p bounded where the radiance changes inside a cell (a small
//   sun's limb), which would otherwise make fireflies.
// - brdf: a data-driven importance sampler valid for any isotropic BRDF
//   (analytic or MERL): per object, for brdfTableThetaOut view elevations
//   (cell centres of [0, π/2]), a table over the half vector h of the cell
//   maxima of mean(ρ)·cos θᵢ·4(ωₒ·h) (brdfTableWidth × brdfTableWidth/4
//   cells); ωᵢ = the reflection of ωₒ about h, with density p(h)/(4 ωₒ·h).
//   In h a glossy lobe sits near the normal whatever θₒ, so a pixel mixing
//   the two tables nearest its θₒ (linearly) loses little. The whole is
//   mixed with cosine sampling (probability 0.1, "defensive" sampling) so
//   that every direction with cos θᵢ > 0 has non-zero density.
// - cosine: cos θᵢ/π about the shading normal.
// Strategies are combined by multiple importance sampling with the power
// heuristic (β = 2; Veach 1997, §9.2), one sample per strategy. Every
// strategy alone is unbiased; Mis (environment + brdf) is the default. The
// single strategies exist for tests and diagnosis. Within a pass, the two
// dimensions that pick each strategy's cell are Latin-hypercube stratified
// over the pass's samples (how many land on the sun no longer varies).
//
// Progressive estimation and the stopping rule: passes of samplesPerPass
// samples per pixel go alternately to two independent half-images A (even
// passes) and B (odd passes). After each pair of passes
//
//   halfError = sqrt(mean((A − B)²)) / mean((A + B)/2)
//
// over the colour channels of every object pixel (background pixels are
// exact): the relative RMS difference of the halves. Since A and B are
// independent with equal counts, the averaged output (A + B)/2 has an RMS
// error of about halfError/2 relative to its mean. Rendering stops when
// halfError ≤ tolerance or when another pair would pass maxSamples; the
// output is the average of all samples.
//
// Deterministic given the seed, whatever the thread count: pixel i in pass k
// draws from its own PCG32 stream (state from seed and k, stream from i).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "haarcast/io/image.h"
#include "haarcast/render/scene.h"

namespace haarcast::render {

enum class ReferenceSampling {
  Mis,          // environment + brdf, power heuristic (default)
  MisCosine,    // environment + cosine, power heuristic
  Environment,  // environment only
  Brdf,         // brdf tables (with their defensive cosine part) only
  Cosine,       // cosine only
};

// "mis", "mis-cosine", "environment", "brdf", "cosine"; nullopt otherwise.
std::optional<ReferenceSampling> parseReferenceSampling(const std::string& name);

// What occludes a shadow ray (see the file comment).
enum class ReferenceOcclusion {
  Scene,  // every object of the scene, posed, world frame (default)
  Self,   // the hit object alone, object frame
  None,   // nothing: V = 1
};

// "scene", "self", "none"; nullopt otherwise.
std::optional<ReferenceOcclusion> parseReferenceOcclusion(const std::string& name);
const char* referenceOcclusionName(ReferenceOcclusion occlusion);

struct ReferenceOptions {
  int width = 128;
  int height = 128;
  int samplesPerPass = 16;         // per pixel, per pass; ≥ 1
  int maxSamples = 4096;           // per pixel, both halves; ≥ 2·samplesPerPass
  double tolerance = 0.01;         // stop when halfError ≤ tolerance; 0 = run to maxSamples
  bool environmentBackground = true;
  std::uint64_t seed = 1;
  unsigned threads = 0;            // 0 = hardware concurrency
  ReferenceSampling sampling = ReferenceSampling::Mis;
  int environmentTableWidth = 1024;  // environment sampling table: width × width/2 cells; even, 8..8192
  int brdfTableThetaOut = 32;      // view elevations tabulated for brdf sampling; 1..256
  int brdfTableWidth = 256;        // φ cells of each brdf table (θ_h gets width/4); multiple of 4, 8..2048
  float shadowOffset = 1e-4f;      // × a bounding radius (see the file comment), as VisibilityOptions::offset
  ReferenceOcclusion occlusion = ReferenceOcclusion::Scene;
};

// Throws std::invalid_argument naming the bad option.
void checkReferenceOptions(const ReferenceOptions& options);

struct ReferenceResult {
  io::RgbImage image;                    // linear radiance, the average of all samples
  std::vector<std::uint8_t> objectMask;  // 1 where an object was hit
  std::vector<std::uint8_t> groundMask;  // 1 where a ground (SceneObject::ground) was hit
  int samples = 0;                       // per pixel, both halves together
  double halfError = 0.0;                // at the end (see the file comment)
  double seconds = 0.0;                  // wall time, tables included
};

// progress(samples, halfError) after every pair of passes, on the calling
// thread; may be empty. Throws std::invalid_argument for bad options or an
// empty scene.
ReferenceResult renderReference(const Scene& scene, const ReferenceOptions& options,
                                const std::function<void(int samples, double error)>& progress = {});

}  // namespace haarcast::render
