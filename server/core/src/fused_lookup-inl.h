// The slice lookup of `fused`'s passes, per SIMD target (Highway's -inl.h
// convention: included once per target by fused_kernel.cpp and
// fused_cells_kernel.cpp, each a foreach_target.h translation unit).
//
// Per direction ω (unit vectors, one per lane):
//   Rᵀω = R_y(−γ) R_x(−β) R_y(−α) ω        (core/rotation.h; seed eq. for p)
//   θ' = atan2(|(x, z)|, y),  φ' = atan2(x, z) − γ
//   ρ_c = bilinear lookup of the slice at (θ', φ')   (sphere_map.h bilinearTaps)
// γ never needs trigonometry: it only offsets the source column.
#if defined(HAARCAST_FUSED_LOOKUP_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAARCAST_FUSED_LOOKUP_INL_H_
#undef HAARCAST_FUSED_LOOKUP_INL_H_
#else
#define HAARCAST_FUSED_LOOKUP_INL_H_
#endif

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

// R_x(−β) R_y(−α) ω: what the lookup, the cut and the lobe path's core test read.
template <class V>
struct Turned {
  V x1, y2, z2;
};

// A pass's constants for the lookup, set once per pixel.
inline constexpr std::size_t kMaxLanes = 16;  // float lanes of the widest target the kernels are built for
// Each lane's taps as 4-float loads (a target with 4-float vectors) rather
// than gathers.
inline constexpr bool kTexelLoads = HWY_TARGET != HWY_SCALAR;

template <class D>
struct SliceLookup {
  using VF = hn::Vec<D>;
  using DI = hn::RebindToSigned<D>;
  using VI = hn::Vec<DI>;
  D d;
  DI di;
  int level;
  VF cosA, sinA, cosB, sinB;
  // Continuous pixel coordinates with centres at integer + ½ (bilinearTaps).
  VF rowScale, colScale, half, colFraction, zero, lastRow;
  VI lastRowI, colMask, colShift, one;
  const float* HWY_RESTRICT red;
  const float* HWY_RESTRICT green;
  const float* HWY_RESTRICT blue;

  SliceLookup(D tag, const FusedPass& p)
      : d(tag),
        di(),
        level(p.level),
        cosA(hn::Set(tag, p.cosAlpha)),
        sinA(hn::Set(tag, p.sinAlpha)),
        cosB(hn::Set(tag, p.cosBeta)),
        sinB(hn::Set(tag, p.sinBeta)),
        rowScale(hn::Set(tag, static_cast<float>(1 << p.level) / shared::kPiF)),
        colScale(hn::Set(tag, static_cast<float>(1 << p.level) / shared::kTwoPiF)),
        half(hn::Set(tag, 0.5f)),
        colFraction(hn::Set(tag, p.columnFraction)),
        zero(hn::Zero(tag)),
        lastRow(hn::Set(tag, static_cast<float>((1 << p.level) - 1))),
        lastRowI(hn::Set(di, (1 << p.level) - 1)),
        colMask(hn::Set(di, (1 << p.level) - 1)),
        colShift(hn::Set(di, p.columnShift)),
        one(hn::Set(di, 1)),
        red(p.slice),
        green(p.slice + 1),
        blue(p.slice + 2) {}

  // R_y(−α): x₁ = cos α·x − sin α·z, z₁ = sin α·x + cos α·z;
  // R_x(−β): y₂ = cos β·y + sin β·z₁, z₂ = −sin β·y + cos β·z₁.
  HWY_INLINE Turned<VF> Turn(VF x0, VF y0, VF z0) const {
    const VF x1 = hn::NegMulAdd(sinA, z0, hn::Mul(cosA, x0));
    const VF z1 = hn::MulAdd(sinA, x0, hn::Mul(cosA, z0));
    const VF y2 = hn::MulAdd(sinB, z1, hn::Mul(cosB, y0));
    const VF z2 = hn::NegMulAdd(sinB, y0, hn::Mul(cosB, z1));
    return {x1, y2, z2};
  }

  // The continuous texel position (row, column before γ's whole columns).
  HWY_INLINE void Position(const Turned<VF>& t, VF& rowPos, VF& colPos) const {
    const VF theta = Atan2(d, hn::Sqrt(hn::MulAdd(t.x1, t.x1, hn::Mul(t.z2, t.z2))), t.y2);
    const VF phi = Atan2(d, t.x1, t.z2);
    rowPos = hn::Min(hn::Max(hn::MulSub(theta, rowScale, half), zero), lastRow);
    colPos = hn::MulSub(phi, colScale, colFraction);
  }

  // ρ_c bilinear at the position (θ clamped, φ wrapped): the two rows'
  // taps blended by the row fraction, then the two columns.
  HWY_INLINE void Rho(VF rowPos, VF colPos, VF& rhoR, VF& rhoG, VF& rhoB) const {
    const VF rowFloor = hn::Floor(rowPos);
    const VF colFloor = hn::Floor(colPos);
    const VF tRow = hn::Sub(rowPos, rowFloor);
    const VF tCol = hn::Sub(colPos, colFloor);
    const VI r0 = hn::ConvertTo(di, rowFloor);
    const VI r1 = hn::Min(hn::Add(r0, one), lastRowI);
    const VI c0 = hn::And(hn::Sub(hn::ConvertTo(di, colFloor), colShift), colMask);
    const VI c1 = hn::And(hn::Add(c0, one), colMask);
    const VI row0 = hn::ShiftLeftSame(r0, level);
    const VI row1 = hn::ShiftLeftSame(r1, level);
    const VI i00 = hn::ShiftLeft<2>(hn::Or(row0, c0));
    const VI i01 = hn::ShiftLeft<2>(hn::Or(row0, c1));
    const VI i10 = hn::ShiftLeft<2>(hn::Or(row1, c0));
    const VI i11 = hn::ShiftLeft<2>(hn::Or(row1, c1));
    if constexpr (kTexelLoads) {
      // A texel's R, G, B and its zero are one 4-float vector: each lane's
      // four taps are four loads, blended there, and the lanes' results read
      // back by channel (fewer, cheaper loads than 12 gathers of every lane).
      HWY_ALIGN int32_t o00[kMaxLanes], o01[kMaxLanes], o10[kMaxLanes], o11[kMaxLanes];
      HWY_ALIGN float tr[kMaxLanes], tc[kMaxLanes], texel[4 * kMaxLanes];
      hn::Store(i00, di, o00);
      hn::Store(i01, di, o01);
      hn::Store(i10, di, o10);
      hn::Store(i11, di, o11);
      hn::Store(tRow, d, tr);
      hn::Store(tCol, d, tc);
      const hn::CappedTag<float, 4> d4;
      const std::size_t lanes = hn::Lanes(d);
      for (std::size_t j = 0; j < lanes; ++j) {
#if HWY_MAX_BYTES >= 32
        if (o01[j] == o00[j] + 4) {
          // The two columns side by side (all but the wrap): a row's two taps
          // are one 8-float load, the rows blended first, then the halves.
          const hn::FixedTag<float, 8> d8;
          const hn::Half<decltype(d8)> dh;
          const auto upper = hn::LoadU(d8, red + o00[j]);
          const auto lower = hn::LoadU(d8, red + o10[j]);
          const auto rows = hn::MulAdd(hn::Set(d8, tr[j]), hn::Sub(lower, upper), upper);
          const auto left = hn::LowerHalf(dh, rows);
          const auto right = hn::UpperHalf(dh, rows);
          hn::Store(hn::MulAdd(hn::Set(dh, tc[j]), hn::Sub(right, left), left), dh, texel + 4 * j);
          continue;
        }
#endif
        const auto a = hn::LoadU(d4, red + o00[j]);
        const auto b = hn::LoadU(d4, red + o01[j]);
        const auto c = hn::LoadU(d4, red + o10[j]);
        const auto e = hn::LoadU(d4, red + o11[j]);
        // The rows blended first, as above.
        const auto row = hn::Set(d4, tr[j]);
        const auto left = hn::MulAdd(row, hn::Sub(c, a), a);
        const auto right = hn::MulAdd(row, hn::Sub(e, b), b);
        hn::Store(hn::MulAdd(hn::Set(d4, tc[j]), hn::Sub(right, left), left), d4, texel + 4 * j);
      }
      VF zeroChannel;
      hn::LoadInterleaved4(d, texel, rhoR, rhoG, rhoB, zeroChannel);
    } else {
      auto lookup = [&](const float* HWY_RESTRICT channel) {
        const VF a = hn::GatherIndex(d, channel, i00);
        const VF b = hn::GatherIndex(d, channel, i01);
        const VF c = hn::GatherIndex(d, channel, i10);
        const VF e = hn::GatherIndex(d, channel, i11);
        // The rows blended first, as the texel loads blend them.
        const VF left = hn::MulAdd(tRow, hn::Sub(c, a), a);
        const VF right = hn::MulAdd(tRow, hn::Sub(e, b), b);
        return hn::MulAdd(tCol, hn::Sub(right, left), left);
      };
      rhoR = lookup(red);
      rhoG = lookup(green);
      rhoB = lookup(blue);
    }
  }
};

// The pass's two sums per lane: Σ W_c·ρ_c, W_c = (L_c·ΔΩ)·V, and Σ ΔΩ·ρ_c
// (the lobe's energy as the directions sample it); out[0..5] as
// fusedSample's.
template <class D>
struct PassSums {
  using VF = hn::Vec<D>;
  VF accR, accG, accB, sumR, sumG, sumB;
  explicit PassSums(D d)
      : accR(hn::Zero(d)), accG(hn::Zero(d)), accB(hn::Zero(d)), sumR(hn::Zero(d)), sumG(hn::Zero(d)), sumB(hn::Zero(d)) {}
  HWY_INLINE void Add(VF lR, VF lG, VF lB, VF v, VF dOmega, VF rhoR, VF rhoG, VF rhoB) {
    accR = hn::MulAdd(hn::Mul(lR, v), rhoR, accR);
    accG = hn::MulAdd(hn::Mul(lG, v), rhoG, accG);
    accB = hn::MulAdd(hn::Mul(lB, v), rhoB, accB);
    sumR = hn::MulAdd(dOmega, rhoR, sumR);
    sumG = hn::MulAdd(dOmega, rhoG, sumG);
    sumB = hn::MulAdd(dOmega, rhoB, sumB);
  }
  HWY_INLINE void Store(D d, float* HWY_RESTRICT out) const {
    out[0] = hn::GetLane(hn::SumOfLanes(d, accR));
    out[1] = hn::GetLane(hn::SumOfLanes(d, accG));
    out[2] = hn::GetLane(hn::SumOfLanes(d, accB));
    out[3] = hn::GetLane(hn::SumOfLanes(d, sumR));
    out[4] = hn::GetLane(hn::SumOfLanes(d, sumG));
    out[5] = hn::GetLane(hn::SumOfLanes(d, sumB));
  }
};

// ρ·0 inside the lobe path's core (cos to the axis above coreCos): the
// core is the path's.
template <class V, class M>
HWY_INLINE void LeaveOutCore(M outside, V& rhoR, V& rhoG, V& rhoB) {
  rhoR = hn::IfThenElseZero(outside, rhoR);
  rhoG = hn::IfThenElseZero(outside, rhoG);
  rhoB = hn::IfThenElseZero(outside, rhoB);
}

}  // namespace HWY_NAMESPACE
}  // namespace haarcast::detail
HWY_AFTER_NAMESPACE();

#endif  // include guard per target
