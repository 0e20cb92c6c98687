// refineVisibility (visibility_refine.h): disagreeing edges, midpoints, the
// red–green templates, bits for the new vertices, a few rounds.
#include "haarcast/render/visibility_refine.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "haarcast/core/check.h"
#include "haarcast/core/parallel.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/render/embree_scene.h"

namespace haarcast {
namespace {

// Each map direction and its solid angle over π: the disagreement's weights
// but for the cosine.
struct DirectionTable {
  std::vector<glm::vec3> direction;
  std::vector<float> weight;
  explicit DirectionTable(int level) {
    const int m = mapSize(level);
    for (int i = 0; i < m; ++i) {
      const float w = static_cast<float>(pixelSolidAngle(level, i) / kPi);
      for (int j = 0; j < m; ++j) {
        direction.emplace_back(sphericalToDirection(rowTheta(level, i), colPhi(level, j)));
        weight.push_back(w);
      }
    }
  }
};

double disagreement(const DirectionTable& t, std::span<const std::uint32_t> a, std::span<const std::uint32_t> b,
                    const glm::vec3& n) {
  double sum = 0.0;
  for (std::size_t w = 0; w < a.size(); ++w) {
    std::uint32_t differ = a[w] ^ b[w];
    while (differ) {
      const std::size_t i = w * 32 + static_cast<std::size_t>(std::countr_zero(differ));
      differ &= differ - 1;
      sum += static_cast<double>(t.weight[i] * std::max(0.0f, glm::dot(n, t.direction[i])));
    }
  }
  return sum;
}

glm::vec3 meanNormal(const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 s = a + b;
  const float len = glm::length(s);
  return len > 1e-6f && std::isfinite(len) ? s / len : a;
}

// An edge by its two end positions (bit patterns, lower first): the key on
// which both sides of an edge, crease or not, agree.
struct EdgeKey {
  std::array<std::uint32_t, 6> bits;
  bool operator==(const EdgeKey&) const = default;
};
struct EdgeKeyHash {
  std::size_t operator()(const EdgeKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (const std::uint32_t x : k.bits) h = (h ^ x) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};
EdgeKey edgeKey(const glm::vec3& p, const glm::vec3& q) {
  std::array<std::uint32_t, 3> a{}, b{};
  std::memcpy(a.data(), &p, sizeof a);
  std::memcpy(b.data(), &q, sizeof b);
  if (b < a) std::swap(a, b);
  return {{a[0], a[1], a[2], b[0], b[1], b[2]}};
}

// One split round: the edges to split (by position key), the midpoints made
// for them (by index pair: each side of a crease has its own normal).
struct IndexPairHash {
  std::size_t operator()(const std::pair<std::uint32_t, std::uint32_t>& e) const {
    return std::hash<std::uint64_t>()((static_cast<std::uint64_t>(e.first) << 32) | e.second);
  }
};

std::pair<std::uint32_t, std::uint32_t> ordered(std::uint32_t a, std::uint32_t b) {
  return a < b ? std::pair{a, b} : std::pair{b, a};
}

// Triangles of one refined triangle, winding kept: v the corners, m[k] the
// midpoint of edge k = (v[k], v[k+1]) or kNone.
constexpr std::uint32_t kNone = 0xffffffffu;
void retriangulate(const Mesh& mesh, const std::array<std::uint32_t, 3>& v, const std::array<std::uint32_t, 3>& m,
                   std::vector<glm::uvec3>& out) {
  const int splits = (m[0] != kNone) + (m[1] != kNone) + (m[2] != kNone);
  auto rot = [&](int r, int k) { return v[static_cast<std::size_t>((r + k) % 3)]; };
  auto mid = [&](int r, int k) { return m[static_cast<std::size_t>((r + k) % 3)]; };
  if (splits == 0) {
    out.emplace_back(v[0], v[1], v[2]);
  } else if (splits == 1) {
    int r = 0;
    while (m[static_cast<std::size_t>(r)] == kNone) ++r;
    // Edge r = (a, b) split at m; c opposite.
    const std::uint32_t a = rot(r, 0), b = rot(r, 1), c = rot(r, 2), mm = mid(r, 0);
    out.emplace_back(a, mm, c);
    out.emplace_back(mm, b, c);
  } else if (splits == 2) {
    int k = 0;
    while (m[static_cast<std::size_t>(k)] != kNone) ++k;  // the edge kept whole
    const int r = (k + 1) % 3;  // edges r and r+1 split, r+2 = k whole: (a,b) at m0, (b,c) at m1, (c,a) whole
    const std::uint32_t a = rot(r, 0), b = rot(r, 1), c = rot(r, 2), m0 = mid(r, 0), m1 = mid(r, 1);
    out.emplace_back(m0, b, m1);
    // The quad a, m0, m1, c by its shorter diagonal.
    const float d1 = glm::length(mesh.positions[a] - mesh.positions[m1]);
    const float d2 = glm::length(mesh.positions[m0] - mesh.positions[c]);
    if (d1 <= d2) {
      out.emplace_back(a, m0, m1);
      out.emplace_back(a, m1, c);
    } else {
      out.emplace_back(a, m0, c);
      out.emplace_back(m0, m1, c);
    }
  } else {
    out.emplace_back(v[0], m[0], m[2]);
    out.emplace_back(m[0], v[1], m[1]);
    out.emplace_back(m[2], m[1], v[2]);
    out.emplace_back(m[0], m[1], m[2]);
  }
}

}  // namespace

void checkRefineOptions(const RefineOptions& o) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("visibility refinement: " + what); };
  if (o.rounds < 0 || o.rounds > 16) bad("rounds " + std::to_string(o.rounds) + " is outside [0, 16]");
  if (!(o.threshold > 0.0 && o.threshold <= 1.0)) bad("threshold must be in (0, 1]");
  if (!(o.minEdge > 0.0) || !std::isfinite(o.minEdge)) bad("minimum edge must be finite and positive");
  if (!(o.growth >= 1.0) || !std::isfinite(o.growth)) bad("growth must be finite and at least 1");
}

double visibilityDisagreement(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b, int level,
                              const glm::vec3& n) {
  HC_CHECK_EQ(a.size(), visibilityWordsPerPoint(level));
  HC_CHECK_EQ(b.size(), a.size());
  return disagreement(DirectionTable(level), a, b, n);
}

RefinedVisibility refineVisibility(const RayScene& occluders, const Mesh& mesh, VisibilityBits bits,
                                   const VisibilityOptions& options, const RefineOptions& refine,
                                   const std::function<void(std::size_t done, std::size_t total)>& progress) {
  checkRefineOptions(refine);
  checkVisibilityOptions(options);
  mesh.validate();
  HC_CHECK_EQ(mesh.normals.size(), mesh.positions.size());
  HC_CHECK_EQ(bits.pointCount(), mesh.positions.size());
  HC_CHECK_EQ(bits.level(), options.level);
  RefinedVisibility out{mesh, std::move(bits), 0};
  Mesh& m = out.mesh;
  const DirectionTable table(options.level);
  const double minEdge = refine.minEdge * mesh.bounds().radius();
  const std::size_t maxVertices = refineVertexBudget(mesh.positions.size(), refine);

  for (int round = 0; round < refine.rounds; ++round) {
    // Each position edge's largest disagreement over the index edges on it.
    std::unordered_map<EdgeKey, double, EdgeKeyHash> worst;
    struct Candidate {
      std::uint32_t a, b;
      EdgeKey key;
    };
    std::vector<Candidate> edges;
    std::unordered_map<std::pair<std::uint32_t, std::uint32_t>, char, IndexPairHash> seen;
    for (const glm::uvec3& t : m.triangles) {
      for (int k = 0; k < 3; ++k) {
        const auto e = ordered(t[k], t[(k + 1) % 3]);
        if (!seen.emplace(e, 0).second) continue;
        if (glm::length(m.positions[e.first] - m.positions[e.second]) <= minEdge) continue;
        edges.push_back({e.first, e.second, edgeKey(m.positions[e.first], m.positions[e.second])});
      }
    }
    std::vector<double> score(edges.size());
    parallelFor(edges.size(), [&](std::size_t i) {
      const Candidate& e = edges[i];
      score[i] = disagreement(table, out.bits.point(e.a), out.bits.point(e.b),
                              meanNormal(m.normals[e.a], m.normals[e.b]));
    });
    for (std::size_t i = 0; i < edges.size(); ++i) {
      double& w = worst[edges[i].key];
      w = std::max(w, score[i]);
    }
    // The position edges to split, most disagreeing first, within the budget
    // (each costs a vertex per index edge on it: counted as it goes).
    std::vector<std::pair<double, const EdgeKey*>> split;
    for (const auto& [key, w] : worst)
      if (w > refine.threshold) split.emplace_back(w, &key);
    if (split.empty()) break;
    std::sort(split.begin(), split.end(), [](const auto& x, const auto& y) {
      return x.first != y.first ? x.first > y.first : x.second->bits < y.second->bits;
    });
    std::unordered_map<EdgeKey, char, EdgeKeyHash> chosen;
    std::unordered_map<EdgeKey, int, EdgeKeyHash> sides;  // index edges on each position edge
    for (const Candidate& e : edges) ++sides[e.key];
    std::size_t vertices = m.positions.size();
    for (const auto& [w, key] : split) {
      const std::size_t cost = static_cast<std::size_t>(sides[*key]);
      if (vertices + cost > maxVertices) break;
      vertices += cost;
      chosen.emplace(*key, 0);
    }
    if (chosen.empty()) break;

    // Midpoints, one per index edge on a chosen position edge.
    const std::size_t first = m.positions.size();
    std::unordered_map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t, IndexPairHash> midpoint;
    for (const Candidate& e : edges) {
      if (!chosen.contains(e.key)) continue;
      midpoint.emplace(std::pair{e.a, e.b}, static_cast<std::uint32_t>(m.positions.size()));
      m.positions.push_back(0.5f * (m.positions[e.a] + m.positions[e.b]));
      m.normals.push_back(meanNormal(m.normals[e.a], m.normals[e.b]));
    }
    std::vector<glm::uvec3> triangles;
    triangles.reserve(m.triangles.size() + 3 * midpoint.size());
    for (const glm::uvec3& t : m.triangles) {
      std::array<std::uint32_t, 3> mids{kNone, kNone, kNone};
      for (int k = 0; k < 3; ++k) {
        const auto it = midpoint.find(ordered(t[k], t[(k + 1) % 3]));
        if (it != midpoint.end()) mids[static_cast<std::size_t>(k)] = it->second;
      }
      retriangulate(m, {t.x, t.y, t.z}, mids, triangles);
    }
    m.triangles = std::move(triangles);

    VisibilityBits grown(options.level, m.positions.size());
    std::vector<std::uint32_t> words(grown.pointCount() * grown.wordsPerPoint(), 0u);
    std::copy(out.bits.words().begin(), out.bits.words().end(), words.begin());
    grown.assign(words);
    // Every vertex with bits so far, against the budget (the header).
    const auto cumulative = [&](std::size_t done, std::size_t /*added*/) {
      if (progress) progress(std::min(first + done, maxVertices), maxVertices);
    };
    computeVisibilityBitsFrom(occluders, m, options, first, grown, cumulative);
    out.bits = std::move(grown);
    ++out.rounds;
  }
  if (progress) progress(maxVertices, maxVertices);
  return out;
}

std::size_t refineVertexBudget(std::size_t vertices, const RefineOptions& refine) {
  return std::max({static_cast<std::size_t>(refine.growth * static_cast<double>(vertices)), refine.floor, vertices});
}

RefinedVisibility computeRefinedVisibility(const Mesh& mesh, const VisibilityOptions& options,
                                           const RefineOptions& refine,
                                           const std::function<void(std::size_t done, std::size_t total)>& progress) {
  checkRefineOptions(refine);
  Mesh withNormals = mesh;
  if (withNormals.normals.empty()) withNormals.computeNormals();
  const RayScene scene({Instance{&withNormals}});
  // The mesh's own vertices first, on the same scale as the rounds after.
  const std::size_t budget = refineVertexBudget(withNormals.positions.size(), refine);
  VisibilityBits bits = computeVisibilityBits(scene, withNormals, options, [&](std::size_t done, std::size_t /*total*/) {
    if (progress) progress(std::min(done, budget), budget);
  });
  return refineVisibility(scene, withNormals, std::move(bits), options, refine, progress);
}

}  // namespace haarcast
