// A renderer that draws nothing: a frame of the asked size. For the tests
// and fuzz targets that drive a RenderSession without the render service.
#pragma once

#include <cstddef>
#include <string>

#include "haarcast/render/renderer.h"

namespace haarcast::net {

class StubRenderer : public render::Renderer {
 public:
  std::string backend() const override { return "cpu"; }
  std::string deviceName() const override { return "stub"; }
  const render::RenderOptions& options() const override { return options_; }
  std::size_t objectCount() const override { return 2; }
  render::Frame render(const render::FrameRequest& request) override {
    render::Frame f;
    f.width = request.width;
    f.height = request.height;
    return f;
  }

 private:
  render::RenderOptions options_;
};

}  // namespace haarcast::net
