#include "haarcast/render/frame_stage.h"

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "haarcast/render/renderer.h"

namespace haarcast::render {
namespace {

// HAARCAST_TEST_STALL_STAGE, read once; nullptr when unset or empty.
const char* stallStage() {
  static const char* const stage = [] {
    const char* s = std::getenv("HAARCAST_TEST_STALL_STAGE");
    return s && *s ? s : nullptr;
  }();
  return stage;
}

[[noreturn]] void stallForever() {
  for (;;) std::this_thread::sleep_for(std::chrono::hours(1));
}

}  // namespace

void enterFrameStage(const FrameRequest& request, const char* stage, std::size_t tiles) {
  if (!request.stage) return;
  request.stage->enter(stage, tiles);
  if (const char* stall = stallStage(); stall && std::strcmp(stall, stage) == 0) stallForever();
}

void tickFrameStage(const FrameRequest& request) {
  if (request.stage) request.stage->tick();
}

}  // namespace haarcast::render
