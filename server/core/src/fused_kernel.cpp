// The pass of `fused` over the M² map directions (fused_kernel.h), written
// once with Google Highway and compiled for every SIMD target Highway knows
// (foreach_target.h); the best one the machine has is picked at run time.
//
// Per direction ω (the unit vector of a pixel centre): ρ_c at Rᵀω
// (fused_lookup-inl.h), 0 inside the lobe path's core (FusedPass::coreCos),
// and acc_c += (L_c·ΔΩ)(ω) · V(ω) · ρ_c.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "fused_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "fused_kernel.h"
#include "fused_lookup-inl.h"
#include "haarcast/core/shared_layout.h"

HWY_BEFORE_NAMESPACE();
namespace haarcast::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// kBits: V from the three vertices' bits (FusedPass::bits); kCore: a lobe
// path's core to leave out (coreCos ≤ 1). Each a copy of the loop without
// the other's work.
template <bool kBits, bool kCore>
void FusedSampleWith(const FusedPass& p, float* HWY_RESTRICT out) {
  const hn::ScalableTag<float> d;
  const hn::RebindToSigned<decltype(d)> di;
  using VF = hn::Vec<decltype(d)>;
  using VI = hn::Vec<decltype(di)>;
  const int m = 1 << p.level;
  const std::size_t n = static_cast<std::size_t>(m) * static_cast<std::size_t>(m);
  const std::size_t lanes = hn::Lanes(d);

  const SliceLookup<decltype(d)> look(d, p);
  const VF skipBelow = hn::Set(d, p.skipBelowY);
  const VF axisX = hn::Set(d, p.axisX), axisY = hn::Set(d, p.axisY), axisZ = hn::Set(d, p.axisZ);
  const VF coreCos = hn::Set(d, p.coreCos);
  const VF zero = hn::Zero(d);
  const float* HWY_RESTRICT l0 = p.light;
  const float* HWY_RESTRICT l1 = p.light + n;
  const float* HWY_RESTRICT l2 = p.light + 2 * n;
  const float* HWY_RESTRICT vis = p.visibility;
  // Lane j tests bit j of the 32-bit word shifted to the vector's first
  // direction (lanes ≤ 32: fusedLanes).
  const VI laneBit = hn::Shl(hn::Set(di, 1), hn::Iota(di, 0));
  const VF bitWeight0 = hn::Set(d, p.bitWeight[0]), bitWeight1 = hn::Set(d, p.bitWeight[1]);
  const VF bitWeight2 = hn::Set(d, p.bitWeight[2]);

  PassSums<decltype(d)> sums(d);
  const float* HWY_RESTRICT omega = p.directions.solidAngle;
  // n ≥ 16 ≥ lanes on every target for level ≥ 2, and both are powers of
  // two. The rows' range, rounded out to whole vectors where a row is
  // narrower than one (levels 2 and 3): the directions of the other rows
  // read zero texels, so the sums are those of the whole map.
  const std::size_t begin = (static_cast<std::size_t>(p.firstRow) * static_cast<std::size_t>(m)) / lanes * lanes;
  const std::size_t end = std::min(n, (static_cast<std::size_t>(p.endRow) * static_cast<std::size_t>(m) + lanes - 1) / lanes * lanes);
  for (std::size_t i = begin; i < end; i += lanes) {
    const VF x0 = hn::LoadU(d, p.directions.x + i);
    const VF y0 = hn::LoadU(d, p.directions.y + i);
    const VF z0 = hn::LoadU(d, p.directions.z + i);
    const Turned<VF> t = look.Turn(x0, y0, z0);
    if (hn::AllTrue(d, hn::Lt(t.y2, skipBelow))) continue;  // all of them read zero texels
    // W_c = (L_c·ΔΩ)·V, formed only for the directions that are not skipped.
    VF v;
    if constexpr (kBits) {
      // V = ((0 + b₀·bit₀) + b₁·bit₁) + b₂·bit₂, blendVisibility's sums.
      const std::size_t word = i / 32, shift = i % 32;
      auto seen = [&](const std::uint32_t* bits) {
        return hn::RebindMask(d, hn::TestBit(hn::Set(di, static_cast<int32_t>(bits[word] >> shift)), laneBit));
      };
      v = hn::Add(zero, hn::IfThenElseZero(seen(p.bits[0]), bitWeight0));
      v = hn::Add(v, hn::IfThenElseZero(seen(p.bits[1]), bitWeight1));
      v = hn::Add(v, hn::IfThenElseZero(seen(p.bits[2]), bitWeight2));
    } else {
      v = hn::LoadU(d, vis + i);
    }
    const VF dOmega = hn::LoadU(d, omega + i);
    VF rowPos, colPos, rhoR, rhoG, rhoB;
    look.Position(t, rowPos, colPos);
    look.Rho(rowPos, colPos, rhoR, rhoG, rhoB);
    // Outside the lobe path's core (ρ·0 there: the core is the path's).
    if constexpr (kCore) {
      LeaveOutCore(hn::Le(hn::MulAdd(t.x1, axisX, hn::MulAdd(t.y2, axisY, hn::Mul(t.z2, axisZ))), coreCos), rhoR, rhoG, rhoB);
    }
    sums.Add(hn::LoadU(d, l0 + i), hn::LoadU(d, l1 + i), hn::LoadU(d, l2 + i), v, dOmega, rhoR, rhoG, rhoB);
  }
  sums.Store(d, out);
}

void FusedSample(const FusedPass& p, float* HWY_RESTRICT out) {
  // A cosine is at most 1: coreCos above it leaves out nothing.
  const bool core = p.coreCos <= 1.0f;
  if (p.visibility) {
    core ? FusedSampleWith<false, true>(p, out) : FusedSampleWith<false, false>(p, out);
  } else {
    core ? FusedSampleWith<true, true>(p, out) : FusedSampleWith<true, false>(p, out);
  }
}

const char* FusedTarget() { return hwy::TargetName(HWY_TARGET); }

std::size_t FusedLanes() { return hn::Lanes(hn::ScalableTag<float>()); }

}  // namespace HWY_NAMESPACE
}  // namespace haarcast::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace haarcast::detail {
HWY_EXPORT(FusedSample);
HWY_EXPORT(FusedTarget);
HWY_EXPORT(FusedLanes);

void fusedSample(const FusedPass& pass, float out[6]) { HWY_DYNAMIC_DISPATCH(FusedSample)(pass, out); }
const char* fusedTarget() { return HWY_DYNAMIC_DISPATCH(FusedTarget)(); }
std::size_t fusedLanes() { return HWY_DYNAMIC_DISPATCH(FusedLanes)(); }
}  // namespace haarcast::detail
#endif
