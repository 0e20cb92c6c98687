#include "haarcast/render/render_options.h"

#include <stdexcept>
#include <string>

namespace haarcast::render {

void checkRenderOptions(const RenderOptions& o) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("render options: " + what); };
  if (o.width < 1 || o.height < 1 || o.width > kMaxFrameSide || o.height > kMaxFrameSide) {
    bad("resolution " + std::to_string(o.width) + "×" + std::to_string(o.height) + " is outside 1.." +
        std::to_string(kMaxFrameSide));
  }
  if (o.level < kMinRenderLevel || o.level > kMaxRenderLevel) {
    bad("level " + std::to_string(o.level) + " is outside " + std::to_string(kMinRenderLevel) + ".." +
        std::to_string(kMaxRenderLevel));
  }
  if (o.lightCoefficients == 0) bad("light coefficients must be at least 1");
  if (o.thetaSamples < 1 || o.thetaSamples > 256) bad("theta samples must be in 1..256");
  checkRefineOptions(o.refine);
  if (!(o.sumTolerance >= 0.0f && o.sumTolerance <= 1.0f)) bad("sum tolerance " + std::to_string(o.sumTolerance) + " is outside 0..1");
  if (!(o.smoothSumTolerance >= 0.0f && o.smoothSumTolerance <= 1.0f))
    bad("smooth-sum tolerance " + std::to_string(o.smoothSumTolerance) + " is outside 0..1");
  if (o.pointLights.maxLights > shared::kMaxPointLights) {
    bad("point lights " + std::to_string(o.pointLights.maxLights) + " is over " + std::to_string(shared::kMaxPointLights));
  }
}

}  // namespace haarcast::render
