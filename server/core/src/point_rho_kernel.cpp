// ρ at the point lights' directions (fused_kernel.h pointRho), a vector of
// lights at a time, compiled for every SIMD target as fused_kernel.cpp is.
//
// Per light direction ω (object frame): R_x(−β)R_y(−α)ω as the pass turns
// it (fused_lookup-inl.h), zero below the slices' cut and inside the lobe
// path's core; else θ', φ' and Catmull-Rom over 4 × 4 taps of the point
// slices (shared::catmullRomWeights; rows clamped, columns wrapped), each
// slice of the blend summed on its own and the two sums blended (the blend
// is linear), and never below zero.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "point_rho_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "fused_kernel.h"
#include "haarcast/core/fused.h"
#include "fused_lookup-inl.h"
#include "haarcast/core/shared_layout.h"

HWY_BEFORE_NAMESPACE();
namespace haarcast::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// shared::catmullRomWeights, one lane per light.
template <class D, class V = hn::Vec<D>>
HWY_INLINE void CatmullRom(D d, V t, V w[4]) {
  const V halfV = hn::Set(d, 0.5f);
  const V t2 = hn::Mul(t, t);
  const V t3 = hn::Mul(t2, t);
  w[0] = hn::Mul(halfV, hn::Sub(hn::Sub(hn::Add(t2, t2), t3), t));
  w[1] = hn::Mul(halfV, hn::Add(hn::Sub(hn::Mul(hn::Set(d, 3.0f), t3), hn::Mul(hn::Set(d, 5.0f), t2)), hn::Set(d, 2.0f)));
  w[2] = hn::Mul(halfV, hn::Add(hn::Sub(hn::Mul(hn::Set(d, 4.0f), t2), hn::Mul(hn::Set(d, 3.0f), t3)), t));
  w[3] = hn::Mul(halfV, hn::Sub(t3, t2));
}

void PointRho(const PointRhoPass& p, const float* HWY_RESTRICT x, const float* HWY_RESTRICT y, const float* HWY_RESTRICT z,
              std::size_t n, float* HWY_RESTRICT rho) {
  const hn::ScalableTag<float> d;
  const hn::RebindToSigned<decltype(d)> di;
  using VF = hn::Vec<decltype(d)>;
  using VI = hn::Vec<decltype(di)>;
  const std::size_t lanes = hn::Lanes(d);
  const FusedPass& turn = *p.pass;
  const int m = 1 << p.level;
  const VF cosA = hn::Set(d, turn.cosAlpha), sinA = hn::Set(d, turn.sinAlpha);
  const VF cosB = hn::Set(d, turn.cosBeta), sinB = hn::Set(d, turn.sinBeta);
  const VF skipBelow = hn::Set(d, turn.skipBelowY);
  const VF axisX = hn::Set(d, turn.axisX), axisY = hn::Set(d, turn.axisY), axisZ = hn::Set(d, turn.axisZ);
  const VF coreCos = hn::Set(d, turn.coreCos);
  const VF rowScale = hn::Set(d, static_cast<float>(m) / shared::kPiF);
  const VF colScale = hn::Set(d, static_cast<float>(m) / (2.0f * shared::kPiF));
  const VF half = hn::Set(d, 0.5f), zero = hn::Zero(d), lastRow = hn::Set(d, static_cast<float>(m - 1));
  const VF colFraction = hn::Set(d, p.columnFraction);
  const VI colMask = hn::Set(di, m - 1), colShift = hn::Set(di, p.columnShift);
  const bool blend = p.weight != 0.0f && p.second != p.first;
  HWY_ALIGN int32_t row0[kPointLightLanes], col0[kPointLightLanes];
  HWY_ALIGN float rowWeight[4][kPointLightLanes], colWeight[4][kPointLightLanes], reads[kPointLightLanes];
  static_assert(HWY_MAX_BYTES / sizeof(float) <= kPointLightLanes - shared::kMaxPointLights, "a vector past the last light");
  HWY_DASSERT(n <= shared::kMaxPointLights);
  for (std::size_t i = 0; i < n; i += lanes) {
    const std::size_t count = std::min(lanes, n - i);
    // Whole vectors: the arrays hold kPointLightLanes (fused.h).
    const VF x0 = hn::LoadU(d, x + i), y0 = hn::LoadU(d, y + i), z0 = hn::LoadU(d, z + i);
    const VF x1 = hn::NegMulAdd(sinA, z0, hn::Mul(cosA, x0));  // R_y(−α)
    const VF z1 = hn::MulAdd(sinA, x0, hn::Mul(cosA, z0));
    const VF y2 = hn::MulAdd(sinB, z1, hn::Mul(cosB, y0));  // R_x(−β)
    const VF z2 = hn::NegMulAdd(sinB, y0, hn::Mul(cosB, z1));
    const auto inCore = hn::Gt(hn::MulAdd(x1, axisX, hn::MulAdd(y2, axisY, hn::Mul(z2, axisZ))), coreCos);
    const auto read = hn::AndNot(inCore, hn::And(hn::FirstN(d, count), hn::Ge(y2, skipBelow)));
    const VF theta = Atan2(d, hn::Sqrt(hn::MulAdd(x1, x1, hn::Mul(z2, z2))), y2);
    const VF phi = Atan2(d, x1, z2);
    const VF rowPos = hn::Min(hn::Max(hn::MulSub(theta, rowScale, half), zero), lastRow);
    const VF colPos = hn::MulSub(phi, colScale, colFraction);
    const VF rowFloor = hn::Floor(rowPos), colFloor = hn::Floor(colPos);
    VF wr[4], wc[4];
    CatmullRom(d, hn::Sub(rowPos, rowFloor), wr);
    CatmullRom(d, hn::Sub(colPos, colFloor), wc);
    // Each light's first tap (row r0 − 1, column c0 − 1), its weights, and
    // whether it reads at all, for the taps below.
    hn::StoreU(hn::ConvertTo(di, rowFloor), di, row0 + i);
    hn::StoreU(hn::And(hn::Sub(hn::ConvertTo(di, colFloor), colShift), colMask), di, col0 + i);
    for (int k = 0; k < 4; ++k) {
      hn::StoreU(wr[k], d, rowWeight[k] + i);
      hn::StoreU(wc[k], d, colWeight[k] + i);
    }
    hn::StoreU(hn::IfThenElseZero(read, hn::Set(d, 1.0f)), d, reads + i);
  }
  // The taps, light by light: a texel's R, G, B (and its zero) are one
  // 4-float vector (fewer lanes only on the scalar target), so each tap is a
  // load and a multiply-add per slice.
  const hn::CappedTag<float, shared::kTexelFloats> d4;
  const std::size_t lanes4 = hn::Lanes(d4);
  for (std::size_t j = 0; j < n; ++j) {
    HWY_ALIGN float rgb[2][shared::kTexelFloats] = {};
    if (reads[j] != 0.0f) {
      for (int s = 0; s < (blend ? 2 : 1); ++s) {
        const float* HWY_RESTRICT slice = s == 0 ? p.first : p.second;
        for (std::size_t k = 0; k < shared::kTexelFloats; k += lanes4) {
          auto sum = hn::Zero(d4);
          for (int a = 0; a < 4; ++a) {
            const int row = std::min(std::max(row0[j] - 1 + a, 0), m - 1);
            const float* HWY_RESTRICT texels = slice + (static_cast<std::size_t>(row) << p.level) * shared::kTexelFloats + k;
            auto across = hn::Zero(d4);
            for (int b = 0; b < 4; ++b) {
              const std::size_t col = static_cast<std::size_t>((col0[j] - 1 + b) & (m - 1));
              across = hn::MulAdd(hn::Set(d4, colWeight[b][j]), hn::LoadU(d4, texels + col * shared::kTexelFloats), across);
            }
            sum = hn::MulAdd(hn::Set(d4, rowWeight[a][j]), across, sum);
          }
          hn::Store(sum, d4, rgb[s] + k);
        }
      }
    }
    for (int c = 0; c < 3; ++c) {
      const float v = blend ? rgb[0][c] + p.weight * (rgb[1][c] - rgb[0][c]) : rgb[0][c];
      // The cubic overshoots below zero beside a steep lobe; ρ never is.
      rho[static_cast<std::size_t>(c) * kPointLightLanes + j] = std::max(v, 0.0f);
    }
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace haarcast::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace haarcast::detail {
HWY_EXPORT(PointRho);

void pointRho(const PointRhoPass& pass, const float* x, const float* y, const float* z, std::size_t n, float* rho) {
  HWY_DYNAMIC_DISPATCH(PointRho)(pass, x, y, z, n, rho);
}
}  // namespace haarcast::detail
#endif
