// Visibility sampled where it changes: `fused` blends its per-vertex bits
// across each triangle (visibility_bits.h), and a blend cannot place an edge
// of visibility inside a triangle. Where a triangle's corners disagree — a
// slab whose vertices lie under a pillar, the floor of a slot, a face one of
// whose corners sits in another face's shadow — the blend smears a dark band
// across the whole triangle. So the mesh is refined there before it is
// drawn: every edge whose two ends see different skies is split at its
// midpoint, new vertices get their own bits, and the test runs again on the
// new edges, a few rounds.
//
// The refined mesh draws exactly as the original: a midpoint lies on its
// edge, so the new triangles tile the old ones in their planes, and its
// normal is the normalised mean of the edge's two (the shading normal the
// blend gives there, up to length). Splits are decided per edge by position,
// not by index, so the triangles on both sides of an edge (also across a
// crease, where each face has its own vertices) split it alike and no
// T-junction opens a crack. A triangle with one, two or three split edges
// becomes two, three or four (the red–green templates).
//
// Disagreement of an edge (a, b): the share of the cosine-weighted
// hemisphere about their mean normal n on which exactly one of them sees
// out, (1/π) Σ_ω [bit_a(ω) ≠ bit_b(ω)] max(0, n·ω) ΔΩ — light-independent,
// so one refinement serves every environment and rotation.
#pragma once

#include <cstddef>
#include <functional>

#include "haarcast/core/mesh.h"
#include "haarcast/core/visibility_bits.h"
#include "haarcast/render/visibility.h"

namespace haarcast {

struct RefineOptions {
  int rounds = 4;             // split rounds; 0 = no refinement
  double threshold = 0.04;    // an edge splits above this disagreement, in (0, 1]
  double minEdge = 1.0 / 64;  // × the mesh's bounding radius: no shorter edge splits
  // The refined mesh has at most max(growth × the mesh's vertices, floor)
  // vertices: the most disagreeing edges split first when it would be more.
  double growth = 2.0;
  std::size_t floor = 32768;
};

// Throws std::invalid_argument naming the bad option.
void checkRefineOptions(const RefineOptions& options);

struct RefinedVisibility {
  Mesh mesh;           // the original's vertices first, then the added ones
  VisibilityBits bits; // one point per vertex of `mesh`
  int rounds = 0;      // rounds that split something
};

// Refines `mesh` (with normals) whose vertices' bits are `bits` (computed
// against `occluders` under `options`, as computeVisibilityBits does); the
// added vertices' bits are cast against the same occluders. progress(done,
// total) counts vertices against the budget, refineVertexBudget: done is
// every vertex with bits so far (the mesh's own, then each round's added
// ones), so it never goes back from one round to the next; the last call
// is (budget, budget), however many rounds stopped short of it.
RefinedVisibility refineVisibility(const RayScene& occluders, const Mesh& mesh, VisibilityBits bits,
                                   const VisibilityOptions& options, const RefineOptions& refine,
                                   const std::function<void(std::size_t done, std::size_t total)>& progress = {});

// The most vertices refinement may give a mesh of `vertices`: max(growth ×
// vertices, floor), and never fewer than it has.
std::size_t refineVertexBudget(std::size_t vertices, const RefineOptions& refine);

// The same against the mesh alone: bits computed, then refined; one
// progress over both, against the budget.
RefinedVisibility computeRefinedVisibility(const Mesh& mesh, const VisibilityOptions& options,
                                           const RefineOptions& refine,
                                           const std::function<void(std::size_t done, std::size_t total)>& progress = {});

// An edge's disagreement (above) for two points' words at `level` about the
// unit normal n.
double visibilityDisagreement(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b, int level,
                              const glm::vec3& n);

}  // namespace haarcast
