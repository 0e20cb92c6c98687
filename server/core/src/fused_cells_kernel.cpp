// The adaptive pass of `fused` (shared_cells.h, fused_kernel.h
// fusedSampleCells), compiled for every SIMD target as fused_kernel.cpp is.
//
//   1. The cells whose directions can reach the slice's non-zero cap (the
//      others add zero), compacted with their V_C from the three vertices'
//      cell masks (fused_cells.h), or −1 where mixed.
//   2. Vectors of them: ρ at each cell's turned centre gives the sampled
//      energy Ω_C·ρ and the slice's detail there; a cell that is not mixed,
//      not detailed and clear of the lobe path's core is coarse, and a lit
//      coarse cell adds V_C·P_c·ρ_c at its light's centroid. The rest are
//      listed.
//   3. The listed cells, 16 directions each, as the full pass takes them.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "fused_cells_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "fused_kernel.h"
#include "fused_lookup-inl.h"
#include "haarcast/core/fused_cells.h"
#include "haarcast/core/shared_cells.h"

HWY_BEFORE_NAMESPACE();
namespace haarcast::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

template <bool kCore>
void CellSampleWith(const FusedCellPass& c, CellScratch& scratch, float* HWY_RESTRICT out, CellCounts& counts) {
  // At most 16 lanes: a cell's directions are whole vectors.
  const hn::CappedTag<float, shared::kCellDirections> d;
  const hn::RebindToSigned<decltype(d)> di;
  using VF = hn::Vec<decltype(d)>;
  using VI = hn::Vec<decltype(di)>;
  const FusedPass& p = c.pass;
  const std::uint32_t m = 1u << p.level, across = m / shared::kCellSide;
  const std::size_t n = static_cast<std::size_t>(m) * m, cells = static_cast<std::size_t>(across) * across;
  const std::size_t lanes = hn::Lanes(d);
  const SliceLookup<decltype(d)> look(d, p);
  const VF zero = hn::Zero(d);
  const VF half = hn::Set(d, 0.5f);
  const VF skipBelow = hn::Set(d, p.skipBelowY);
  const VF axisX = hn::Set(d, p.axisX), axisY = hn::Set(d, p.axisY), axisZ = hn::Set(d, p.axisZ);
  const VF coreCos = hn::Set(d, p.coreCos), coreCellCos = hn::Set(d, c.coreCellCos);
  const VF tolerance = hn::Set(d, c.tolerance);
  const VI lastRowI = hn::Set(di, static_cast<int32_t>(m - 1));
  const VI colMask = hn::Set(di, static_cast<int32_t>(m - 1));
  const VI colShift = hn::Set(di, p.columnShift);
  const CellDirections& dirs = *c.cells;
  const CellLight& light = *c.light;

  const std::uint32_t r0 = static_cast<std::uint32_t>(p.firstRow) / shared::kCellSide;
  const std::uint32_t r1 = std::min(across, (static_cast<std::uint32_t>(p.endRow) + shared::kCellSide - 1) / shared::kCellSide);
  scratch.fine.resize(cells + lanes);
  scratch.mixed.resize(cells + lanes);
  const std::size_t q0 = static_cast<std::size_t>(r0) * across, q1 = static_cast<std::size_t>(r1) * across;

  PassSums<decltype(d)> sums(d);
  VF& accR = sums.accR;  // the coarse cells add to the same sums
  VF& accG = sums.accG;
  VF& accB = sums.accB;
  VF& sumR = sums.sumR;
  VF& sumG = sums.sumG;
  VF& sumB = sums.sumB;
  auto coreTest = [&](const Turned<VF>& t) { return hn::MulAdd(t.x1, axisX, hn::MulAdd(t.y2, axisY, hn::Mul(t.z2, axisZ))); };

  // Step 1. The cells that can reach the cut, compacted with what step 2
  // reads of them (a cell below reachCut adds exactly zero: ρ is zero at
  // its centre, at its light's centroids and at each of its directions).
  // The cell arrays are padded by 16 past the last cell, so the last
  // vector's loads stay inside them; its lanes past q1 are masked off.
  enum Plane : std::size_t { kX, kY, kZ, kOmega, kV, kPowerR, kPowerG, kPowerB, kCentroidX, kCentroidY, kCentroidZ, kPlanes };
  const std::size_t stride = cells + lanes;
  scratch.reaching.resize(stride);
  scratch.reachingData.resize(kPlanes * stride);
  std::uint32_t* HWY_RESTRICT reaching = scratch.reaching.data();
  float* HWY_RESTRICT plane[kPlanes];
  for (std::size_t k = 0; k < kPlanes; ++k) plane[k] = scratch.reachingData.data() + k * stride;
  const VF reachCut = hn::Set(d, c.reachCut);
  const VI laneBit = hn::Shl(hn::Set(di, 1), hn::Iota(di, 0));
  const VF bitWeight[3] = {hn::Set(d, p.bitWeight[0]), hn::Set(d, p.bitWeight[1]), hn::Set(d, p.bitWeight[2])};
  // V_C of cells q … q + lanes − 1: Σ_v b_v·whole_v, or −1 where a vertex
  // of non-zero weight sees part of a cell (shared::cellVisibility, its
  // sums in its order).
  auto cellVisibility = [&](std::size_t q) {
    auto window = [&](const std::uint32_t* set) {
      const std::uint64_t pair = set[q / 32] | (static_cast<std::uint64_t>(set[q / 32 + 1]) << 32);
      return hn::RebindMask(d, hn::TestBit(hn::Set(di, static_cast<int32_t>(static_cast<std::uint32_t>(pair >> (q % 32)))), laneBit));
    };
    VF v = zero;
    auto mixed = hn::Lt(v, zero);  // none
    for (std::size_t k = 0; k < 3; ++k) {
      const auto whole = window(c.cellMasks[k]);
      v = hn::Add(v, hn::IfThenElseZero(whole, bitWeight[k]));
      if (p.bitWeight[k] != 0.0f) mixed = hn::Or(mixed, hn::AndNot(whole, window(c.cellMasks[k] + c.cellMaskWords)));
    }
    return hn::IfThenElse(mixed, hn::Set(d, -1.0f), v);
  };
  std::size_t reached = 0;
  for (std::size_t q = q0; q < q1; q += lanes) {
    const auto valid = hn::RebindMask(d, hn::Lt(hn::Iota(di, static_cast<int32_t>(q)), hn::Set(di, static_cast<int32_t>(q1))));
    const Turned<VF> t = look.Turn(hn::LoadU(d, dirs.centreX.data() + q), hn::LoadU(d, dirs.centreY.data() + q),
                                   hn::LoadU(d, dirs.centreZ.data() + q));
    const auto keep = hn::And(valid, hn::Ge(t.y2, reachCut));
    if (hn::AllFalse(d, keep)) continue;
    // Compressed in registers and stored whole (the arrays have a vector's
    // room past the last cell): cheaper than a compressing store on some cores.
    auto put = [&](VF v, Plane k) { hn::StoreU(hn::Compress(v, keep), d, plane[k] + reached); };
    put(t.x1, kX);
    put(t.y2, kY);
    put(t.z2, kZ);
    put(hn::LoadU(d, dirs.cellSolidAngle.data() + q), kOmega);
    put(cellVisibility(q), kV);
    put(hn::LoadU(d, light.power.data() + q), kPowerR);
    put(hn::LoadU(d, light.power.data() + light.stride + q), kPowerG);
    put(hn::LoadU(d, light.power.data() + 2 * light.stride + q), kPowerB);
    put(hn::LoadU(d, light.centroidX.data() + q), kCentroidX);
    put(hn::LoadU(d, light.centroidY.data() + q), kCentroidY);
    put(hn::LoadU(d, light.centroidZ.data() + q), kCentroidZ);
    hn::StoreU(hn::Compress(hn::Iota(di, static_cast<int32_t>(q)), hn::RebindMask(di, keep)), di,
               reinterpret_cast<int32_t*>(reaching) + reached);
    reached += hn::CountTrue(d, keep);
  }
  // The last vector's lanes past `reached`: a direction the lookup reads
  // inside the slice (their sums are masked off below).
  for (std::size_t j = reached; j < (reached + lanes - 1) / lanes * lanes; ++j) {
    for (std::size_t k = 0; k < kPlanes; ++k) plane[k][j] = 0.0f;
    plane[kY][j] = plane[kCentroidY][j] = 1.0f;
    reaching[j] = 0;
  }

  // Step 2. Vectors of reaching cells.
  std::size_t fineCount = 0, mixedCount = 0;
  for (std::size_t j = 0; j < reached; j += lanes) {
    const auto valid = hn::RebindMask(d, hn::Lt(hn::Iota(di, static_cast<int32_t>(j)), hn::Set(di, static_cast<int32_t>(reached))));
    const Turned<VF> t{hn::LoadU(d, plane[kX] + j), hn::LoadU(d, plane[kY] + j), hn::LoadU(d, plane[kZ] + j)};
    VF rowPos, colPos, rhoR, rhoG, rhoB;
    look.Position(t, rowPos, colPos);
    look.Rho(rowPos, colPos, rhoR, rhoG, rhoB);
    // The detail texel holding the turned centre (shared::detailTexel).
    const VI detailRow = hn::ShiftRight<2>(hn::Min(hn::ConvertTo(di, hn::Add(rowPos, half)), lastRowI));
    const VI detailCol = hn::ShiftRight<2>(hn::And(hn::Sub(hn::ConvertTo(di, hn::Floor(hn::Add(colPos, half))), colShift), colMask));
    const VI detailIndex = hn::Or(hn::ShiftLeftSame(detailRow, p.level - 2), detailCol);  // row·(M/4) + column
    const VF detail = hn::Max(hn::GatherIndex(d, c.detail[0], detailIndex), hn::GatherIndex(d, c.detail[1], detailIndex));
    const VF v = hn::LoadU(d, plane[kV] + j);
    auto fine = hn::Gt(detail, tolerance);
    if constexpr (kCore) fine = hn::Or(fine, hn::Gt(coreTest(t), coreCellCos));
    fine = hn::And(fine, valid);
    const auto coarse = hn::AndNot(fine, valid);
    const VF omega = hn::LoadU(d, plane[kOmega] + j);
    sumR = hn::MulAdd(hn::IfThenElseZero(coarse, omega), rhoR, sumR);
    sumG = hn::MulAdd(hn::IfThenElseZero(coarse, omega), rhoG, sumG);
    sumB = hn::MulAdd(hn::IfThenElseZero(coarse, omega), rhoB, sumB);
    counts.coarse += hn::CountTrue(d, coarse);
    const auto lit = hn::And(coarse, hn::Gt(v, zero));
    if (!hn::AllFalse(d, lit)) {
      const Turned<VF> tc = look.Turn(hn::LoadU(d, plane[kCentroidX] + j), hn::LoadU(d, plane[kCentroidY] + j),
                                      hn::LoadU(d, plane[kCentroidZ] + j));
      VF cRow, cCol, cR, cG, cB;
      look.Position(tc, cRow, cCol);
      look.Rho(cRow, cCol, cR, cG, cB);
      const VF w = hn::IfThenElseZero(lit, v);
      accR = hn::MulAdd(hn::Mul(hn::LoadU(d, plane[kPowerR] + j), w), cR, accR);
      accG = hn::MulAdd(hn::Mul(hn::LoadU(d, plane[kPowerG] + j), w), cG, accG);
      accB = hn::MulAdd(hn::Mul(hn::LoadU(d, plane[kPowerB] + j), w), cB, accB);
    }
    const auto mixed = hn::And(coarse, hn::Lt(v, zero));
    const VI index = hn::LoadU(di, reinterpret_cast<const int32_t*>(reaching) + j);
    if (!hn::AllFalse(d, mixed)) {
      hn::StoreU(hn::Compress(index, hn::RebindMask(di, mixed)), di, reinterpret_cast<int32_t*>(scratch.mixed.data()) + mixedCount);
      mixedCount += hn::CountTrue(d, mixed);
    }
    if (!hn::AllFalse(d, fine)) {
      hn::StoreU(hn::Compress(index, hn::RebindMask(di, fine)), di, reinterpret_cast<int32_t*>(scratch.fine.data()) + fineCount);
      fineCount += hn::CountTrue(d, fine);
    }
  }
  counts.fine += fineCount;
  counts.mixed += mixedCount;

  const VF bitWeight0 = hn::Set(d, p.bitWeight[0]), bitWeight1 = hn::Set(d, p.bitWeight[1]);
  const VF bitWeight2 = hn::Set(d, p.bitWeight[2]);
  // V = ((0 + b₀·bit₀) + b₁·bit₁) + b₂·bit₂ over directions k … k + lanes − 1
  // of a cell, from its vertices' 16 bits (blendVisibility's sums).
  auto cellV = [&](const std::uint32_t bits[3], std::size_t k) {
    auto seen = [&](std::uint32_t word) {
      return hn::RebindMask(d, hn::TestBit(hn::Set(di, static_cast<int32_t>(word >> k)), laneBit));
    };
    VF v = hn::Add(zero, hn::IfThenElseZero(seen(bits[0]), bitWeight0));
    v = hn::Add(v, hn::IfThenElseZero(seen(bits[1]), bitWeight1));
    return hn::Add(v, hn::IfThenElseZero(seen(bits[2]), bitWeight2));
  };
  auto bitsOf = [&](std::uint32_t q, std::uint32_t bits[3]) {
    const std::uint32_t shift = shared::cellShift(m, q);
    for (std::size_t v = 0; v < 3; ++v) {
      const std::uint32_t* b = p.bits[v];
      bits[v] = shared::cellBits(b[shared::cellWordIndex(m, q, 0)], b[shared::cellWordIndex(m, q, 1)],
                                 b[shared::cellWordIndex(m, q, 2)], b[shared::cellWordIndex(m, q, 3)], shift);
    }
  };

  // Step 2b: each mixed cell's V·L summed, and its centroid (the
  // uniform cells' P_c and ω̄, with V inside the sums).
  scratch.mixedPower.resize(3 * (cells + lanes));
  for (auto* a : {&scratch.mixedX, &scratch.mixedY, &scratch.mixedZ}) a->resize(cells + lanes);
  const std::size_t mixedStride = cells + lanes;
  for (std::size_t j = 0; j < mixedCount; ++j) {
    const std::uint32_t q = scratch.mixed[j];
    std::uint32_t bits[3];
    bitsOf(q, bits);
    const std::size_t base = static_cast<std::size_t>(q) * shared::kCellDirections;
    VF pR = zero, pG = zero, pB = zero, cx = zero, cy = zero, cz = zero;
    for (std::size_t k = 0; k < shared::kCellDirections; k += lanes) {
      const std::size_t i = base + k;
      const VF v = cellV(bits, k);
      const VF lR = hn::Mul(hn::LoadU(d, light.planes.data() + i), v);
      const VF lG = hn::Mul(hn::LoadU(d, light.planes.data() + n + i), v);
      const VF lB = hn::Mul(hn::LoadU(d, light.planes.data() + 2 * n + i), v);
      pR = hn::Add(pR, lR);
      pG = hn::Add(pG, lG);
      pB = hn::Add(pB, lB);
      const VF w = hn::Add(hn::Add(lR, lG), lB);
      cx = hn::MulAdd(w, hn::LoadU(d, dirs.x.data() + i), cx);
      cy = hn::MulAdd(w, hn::LoadU(d, dirs.y.data() + i), cy);
      cz = hn::MulAdd(w, hn::LoadU(d, dirs.z.data() + i), cz);
    }
    scratch.mixedPower[j] = hn::GetLane(hn::SumOfLanes(d, pR));
    scratch.mixedPower[mixedStride + j] = hn::GetLane(hn::SumOfLanes(d, pG));
    scratch.mixedPower[2 * mixedStride + j] = hn::GetLane(hn::SumOfLanes(d, pB));
    // Not normalised: the lookup reads only the direction (atan2 of ratios).
    scratch.mixedX[j] = hn::GetLane(hn::SumOfLanes(d, cx));
    scratch.mixedY[j] = hn::GetLane(hn::SumOfLanes(d, cy));
    scratch.mixedZ[j] = hn::GetLane(hn::SumOfLanes(d, cz));
  }
  // Step 2c: ρ at their centroids, a vector of mixed cells at a time (lanes
  // past the last read zero power).
  for (std::size_t j = mixedCount; j < (mixedCount + lanes - 1) / lanes * lanes; ++j) {
    for (std::size_t ch = 0; ch < 3; ++ch) scratch.mixedPower[ch * mixedStride + j] = 0.0f;
    scratch.mixedX[j] = scratch.mixedZ[j] = 0.0f;
    scratch.mixedY[j] = 1.0f;
  }
  for (std::size_t j = 0; j < mixedCount; j += lanes) {
    const Turned<VF> tc = look.Turn(hn::LoadU(d, scratch.mixedX.data() + j), hn::LoadU(d, scratch.mixedY.data() + j),
                                    hn::LoadU(d, scratch.mixedZ.data() + j));
    VF cRow, cCol, cR, cG, cB;
    look.Position(tc, cRow, cCol);
    look.Rho(cRow, cCol, cR, cG, cB);
    accR = hn::MulAdd(hn::LoadU(d, scratch.mixedPower.data() + j), cR, accR);
    accG = hn::MulAdd(hn::LoadU(d, scratch.mixedPower.data() + mixedStride + j), cG, accG);
    accB = hn::MulAdd(hn::LoadU(d, scratch.mixedPower.data() + 2 * mixedStride + j), cB, accB);
  }

  // Step 3: the detailed cells, direction by direction.
  for (std::size_t f = 0; f < fineCount; ++f) {
    const std::uint32_t q = scratch.fine[f];
    std::uint32_t bits[3];
    bitsOf(q, bits);
    const std::size_t base = static_cast<std::size_t>(q) * shared::kCellDirections;
    for (std::size_t k = 0; k < shared::kCellDirections; k += lanes) {
      const std::size_t i = base + k;
      const Turned<VF> t = look.Turn(hn::LoadU(d, dirs.x.data() + i), hn::LoadU(d, dirs.y.data() + i), hn::LoadU(d, dirs.z.data() + i));
      if (hn::AllTrue(d, hn::Lt(t.y2, skipBelow))) continue;  // all of them read zero texels
      const VF v = cellV(bits, k);
      VF rowPos, colPos, rhoR, rhoG, rhoB;
      look.Position(t, rowPos, colPos);
      look.Rho(rowPos, colPos, rhoR, rhoG, rhoB);
      if constexpr (kCore) LeaveOutCore(hn::Le(coreTest(t), coreCos), rhoR, rhoG, rhoB);
      sums.Add(hn::LoadU(d, light.planes.data() + i), hn::LoadU(d, light.planes.data() + n + i),
               hn::LoadU(d, light.planes.data() + 2 * n + i), v, hn::LoadU(d, dirs.solidAngle.data() + i), rhoR, rhoG, rhoB);
    }
  }
  sums.Store(d, out);
}

void FusedSampleCells(const FusedCellPass& c, CellScratch& scratch, float* HWY_RESTRICT out, CellCounts& counts) {
  c.pass.coreCos <= 1.0f ? CellSampleWith<true>(c, scratch, out, counts) : CellSampleWith<false>(c, scratch, out, counts);
}

}  // namespace HWY_NAMESPACE
}  // namespace haarcast::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace haarcast::detail {
HWY_EXPORT(FusedSampleCells);

void fusedSampleCells(const FusedCellPass& pass, CellScratch& scratch, float out[6], CellCounts& counts) {
  HWY_DYNAMIC_DISPATCH(FusedSampleCells)(pass, scratch, out, counts);
}
}  // namespace haarcast::detail
#endif
