// A renderer that draws nothing: a frame of the asked size. For the tests
// and fuzz targets that drive a RenderSession without the render service.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "haarcast/render/renderer.h"

namespace haarcast::net {

class StubRenderer : public render::Renderer {
 public:
  StubRenderer() = default;
  explicit StubRenderer(std::vector<int> levels) : levels_(std::move(levels)) {}
  std::string backend() const override { return "cpu"; }
  std::string deviceName() const override { return "stub"; }
  const render::RenderOptions& options() const override { return options_; }
  std::size_t objectCount() const override { return 2; }
  std::vector<int> objectLevels() const override { return levels_; }
  render::Frame render(const render::FrameRequest& request) override {
    render::Frame f;
    f.width = request.width;
    f.height = request.height;
    return f;
  }

 private:
  render::RenderOptions options_;
  std::vector<int> levels_;  // the objects' levels it reports (none: not known)
};

}  // namespace haarcast::net
