// What the Haar renderer and the Monte Carlo reference must agree on exactly:
// the camera's rays and each pixel's local shading frame.
#pragma once

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "haarcast/render/scene.h"

namespace haarcast::render {

// tan(½ vertical field of view) of a width × height frame: the camera's
// field of view spans the frame's shorter side, so what a camera frames in a
// square view stays in view at every aspect ratio (a portrait frame widens
// its vertical field instead of cropping the sides).
double verticalTanHalf(const Camera& camera, int width, int height);

// A pinhole camera's orthonormal basis in the world frame and tan(½ vertical
// field of view) for a width × height frame: one definition for CameraRays,
// the Vulkan passes' rays (gpu makeFrameParams) and the G-buffer's projection.
struct CameraBasis {
  glm::dvec3 forward, right, up;
  double tanHalf;
};
CameraBasis cameraBasis(const Camera& camera, int width, int height);

// Clip coordinates of a world point for CameraRays' pinhole, as a rasteriser
// takes them: x right, y down (row 0 at the top, as the image has it), and
// reversed, infinite-far Z (depth = near / distance, greatest wins), whose
// float precision does not depend on the scene's depth range.
glm::dmat4 viewProjection(const Camera& camera, const CameraBasis& basis, int width, int height, double nearPlane);

// A pinhole camera's rays through pixel centres (row 0 at the top).
class CameraRays {
 public:
  CameraRays(const Camera& camera, int width, int height);
  glm::dvec3 direction(int x, int y) const;  // unit, world frame
  // Through the point (px, py) of the image plane in pixels: pixel (x, y)'s
  // centre is (x + ½, y + ½).
  glm::dvec3 directionAt(double px, double py) const;
  // Through sub-sample k of pixel (x, y) (shared::kSubsamples, the
  // antialiasing's samples).
  glm::dvec3 subsampleDirection(int x, int y, unsigned k) const;
  const glm::dvec3& origin() const { return eye_; }

 private:
  glm::dvec3 eye_;
  CameraBasis basis_;
  double aspect_;
  int width_, height_;
};

// The local frame of a shaded point as a rotation local → object: +Y = the
// shading normal n, the view direction wo in the (Y, Z) half-plane at φ = 0
// (DESIGN.md "BRDF slices"). thetaOut gets θₒ (clamped to [0, π/2]).
glm::dmat3 shadingFrame(const glm::dvec3& n, const glm::dvec3& wo, double& thetaOut);

}  // namespace haarcast::render
