// The pass of `fused` over the M² map directions (fused_kernel.h), written
// once with Google Highway and compiled for every SIMD target Highway knows
// (foreach_target.h); the best one the machine has is picked at run time.
//
// Per direction ω (the unit vector of a pixel centre):
//   Rᵀω = R_y(−γ) R_x(−β) R_y(−α) ω        (core/rotation.h; seed eq. for p)
//   θ' = atan2(|(x, z)|, y),  φ' = atan2(x, z) − γ
//   ρ_c = bilinear lookup of the slice at (θ', φ')   (sphere_map.h bilinearTaps),
//         0 inside the lobe path's core (FusedPass::coreCos)
//   acc_c += (L_c·ΔΩ)(ω) · V(ω) · ρ_c
// γ never needs trigonometry: it only offsets the source column.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "fused_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include "fused_kernel.h"
#include "haarcast/core/shared_layout.h"

HWY_BEFORE_NAMESPACE();
namespace haarcast::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// atan2(y, x) in (−π, π] from Highway's few-ULP atan on [0, 1].
template <class D, class V>
HWY_INLINE V Atan2(D d, V y, V x) {
  const V ay = hn::Abs(y);
  const V ax = hn::Abs(x);
  const V big = hn::Max(ay, ax);
  const V small = hn::Min(ay, ax);
  // 0/0 (a pole) gives 0, as std::atan2(0, 0) does.
  const V ratio = hn::Div(small, hn::Max(big, hn::Set(d, 1e-30f)));
  V a = hn::Atan(d, ratio);
  a = hn::IfThenElse(hn::Gt(ay, ax), hn::Sub(hn::Set(d, 1.57079632679489662f), a), a);
  a = hn::IfThenElse(hn::Lt(x, hn::Zero(d)), hn::Sub(hn::Set(d, shared::kPiF), a), a);
  return hn::CopySign(a, y);
}

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

  const VF cosA = hn::Set(d, p.cosAlpha), sinA = hn::Set(d, p.sinAlpha);
  const VF cosB = hn::Set(d, p.cosBeta), sinB = hn::Set(d, p.sinBeta);
  const VF skipBelow = hn::Set(d, p.skipBelowY);
  const VF axisX = hn::Set(d, p.axisX), axisY = hn::Set(d, p.axisY), axisZ = hn::Set(d, p.axisZ);
  const VF coreCos = hn::Set(d, p.coreCos);
  // Continuous pixel coordinates with centres at integer + ½ (bilinearTaps).
  const VF rowScale = hn::Set(d, static_cast<float>(m) / shared::kPiF);
  const VF colScale = hn::Set(d, static_cast<float>(m) / shared::kTwoPiF);
  const VF half = hn::Set(d, 0.5f);
  const VF colFraction = hn::Set(d, p.columnFraction);
  const VF zero = hn::Zero(d);
  const VF lastRow = hn::Set(d, static_cast<float>(m - 1));
  const VI lastRowI = hn::Set(di, m - 1);
  const VI colMask = hn::Set(di, m - 1);
  const VI colShift = hn::Set(di, p.columnShift);
  const VI one = hn::Set(di, 1);
  const float* HWY_RESTRICT red = p.slice;
  const float* HWY_RESTRICT green = p.slice + 1;
  const float* HWY_RESTRICT blue = p.slice + 2;
  const float* HWY_RESTRICT l0 = p.light;
  const float* HWY_RESTRICT l1 = p.light + n;
  const float* HWY_RESTRICT l2 = p.light + 2 * n;
  const float* HWY_RESTRICT vis = p.visibility;
  // Lane j tests bit j of the 32-bit word shifted to the vector's first
  // direction (lanes ≤ 32: fusedLanes).
  const VI laneBit = hn::Shl(hn::Set(di, 1), hn::Iota(di, 0));
  const VF bitWeight0 = hn::Set(d, p.bitWeight[0]), bitWeight1 = hn::Set(d, p.bitWeight[1]);
  const VF bitWeight2 = hn::Set(d, p.bitWeight[2]);

  VF accR = zero, accG = zero, accB = zero;
  VF sumR = zero, sumG = zero, sumB = zero;
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
    // R_y(−α): x₁ = cos α·x − sin α·z, z₁ = sin α·x + cos α·z.
    const VF x1 = hn::NegMulAdd(sinA, z0, hn::Mul(cosA, x0));
    const VF z1 = hn::MulAdd(sinA, x0, hn::Mul(cosA, z0));
    // R_x(−β): y₂ = cos β·y + sin β·z₁, z₂ = −sin β·y + cos β·z₁.
    const VF y2 = hn::MulAdd(sinB, z1, hn::Mul(cosB, y0));
    if (hn::AllTrue(d, hn::Lt(y2, skipBelow))) continue;  // all of them read zero texels
    const VF z2 = hn::NegMulAdd(sinB, y0, hn::Mul(cosB, z1));
    const VF theta = Atan2(d, hn::Sqrt(hn::MulAdd(x1, x1, hn::Mul(z2, z2))), y2);
    const VF phi = Atan2(d, x1, z2);
    const VF rowPos = hn::Min(hn::Max(hn::MulSub(theta, rowScale, half), zero), lastRow);
    const VF colPos = hn::MulSub(phi, colScale, colFraction);
    const VF rowFloor = hn::Floor(rowPos);
    const VF colFloor = hn::Floor(colPos);
    const VF tRow = hn::Sub(rowPos, rowFloor);
    const VF tCol = hn::Sub(colPos, colFloor);
    const VI r0 = hn::ConvertTo(di, rowFloor);
    const VI r1 = hn::Min(hn::Add(r0, one), lastRowI);
    const VI c0 = hn::And(hn::Sub(hn::ConvertTo(di, colFloor), colShift), colMask);
    const VI c1 = hn::And(hn::Add(c0, one), colMask);
    const VI row0 = hn::ShiftLeftSame(r0, p.level);
    const VI row1 = hn::ShiftLeftSame(r1, p.level);
    const VI i00 = hn::ShiftLeft<2>(hn::Or(row0, c0));
    const VI i01 = hn::ShiftLeft<2>(hn::Or(row0, c1));
    const VI i10 = hn::ShiftLeft<2>(hn::Or(row1, c0));
    const VI i11 = hn::ShiftLeft<2>(hn::Or(row1, c1));
    auto lookup = [&](const float* HWY_RESTRICT channel) {
      const VF a = hn::GatherIndex(d, channel, i00);
      const VF b = hn::GatherIndex(d, channel, i01);
      const VF c = hn::GatherIndex(d, channel, i10);
      const VF e = hn::GatherIndex(d, channel, i11);
      const VF top = hn::MulAdd(tCol, hn::Sub(b, a), a);
      const VF bottom = hn::MulAdd(tCol, hn::Sub(e, c), c);
      return hn::MulAdd(tRow, hn::Sub(bottom, top), top);
    };
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
    // Outside the lobe path's core (ρ·0 there: the core is the path's).
    VF rhoR = lookup(red), rhoG = lookup(green), rhoB = lookup(blue);
    if constexpr (kCore) {
      const auto outside = hn::Le(hn::MulAdd(x1, axisX, hn::MulAdd(y2, axisY, hn::Mul(z2, axisZ))), coreCos);
      rhoR = hn::IfThenElseZero(outside, rhoR);
      rhoG = hn::IfThenElseZero(outside, rhoG);
      rhoB = hn::IfThenElseZero(outside, rhoB);
    }
    accR = hn::MulAdd(hn::Mul(hn::LoadU(d, l0 + i), v), rhoR, accR);
    accG = hn::MulAdd(hn::Mul(hn::LoadU(d, l1 + i), v), rhoG, accG);
    accB = hn::MulAdd(hn::Mul(hn::LoadU(d, l2 + i), v), rhoB, accB);
    sumR = hn::MulAdd(dOmega, rhoR, sumR);
    sumG = hn::MulAdd(dOmega, rhoG, sumG);
    sumB = hn::MulAdd(dOmega, rhoB, sumB);
  }
  out[0] = hn::GetLane(hn::SumOfLanes(d, accR));
  out[1] = hn::GetLane(hn::SumOfLanes(d, accG));
  out[2] = hn::GetLane(hn::SumOfLanes(d, accB));
  out[3] = hn::GetLane(hn::SumOfLanes(d, sumR));
  out[4] = hn::GetLane(hn::SumOfLanes(d, sumG));
  out[5] = hn::GetLane(hn::SumOfLanes(d, sumB));
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
