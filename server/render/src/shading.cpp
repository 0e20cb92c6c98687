#include "haarcast/render/shading.h"

#include "haarcast/core/shared_frame.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

namespace haarcast::render {

double verticalTanHalf(const Camera& camera, int width, int height) {
  const double tanHalf = std::tan(glm::radians(camera.fovYDegrees) * 0.5);
  return width < height ? tanHalf * static_cast<double>(height) / width : tanHalf;
}

CameraBasis cameraBasis(const Camera& camera, int width, int height) {
  CameraBasis b;
  b.forward = glm::normalize(camera.target - camera.eye);
  b.right = glm::normalize(glm::cross(b.forward, camera.up));
  b.up = glm::cross(b.right, b.forward);
  b.tanHalf = verticalTanHalf(camera, width, height);
  return b;
}

glm::dmat4 viewProjection(const Camera& camera, const CameraBasis& basis, int width, int height, double nearPlane) {
  const glm::dvec3 &f = basis.forward, &r = basis.right, &u = basis.up;
  const double aspect = static_cast<double>(width) / height;
  const glm::dvec3& e = camera.eye;
  glm::dmat4 m(0.0);  // m[column][row]
  const double sx = 1.0 / (basis.tanHalf * aspect), sy = -1.0 / basis.tanHalf;
  for (int c = 0; c < 3; ++c) {
    m[c][0] = sx * r[c];
    m[c][1] = sy * u[c];
    m[c][2] = 0.0;
    m[c][3] = f[c];
  }
  m[3][0] = -sx * glm::dot(r, e);
  m[3][1] = -sy * glm::dot(u, e);
  m[3][2] = nearPlane;
  m[3][3] = -glm::dot(f, e);
  return m;
}

CameraRays::CameraRays(const Camera& camera, int width, int height)
    : eye_(camera.eye),
      basis_(cameraBasis(camera, width, height)),
      aspect_(static_cast<double>(width) / height),
      width_(width),
      height_(height) {}

glm::dvec3 CameraRays::direction(int x, int y) const { return directionAt(x + 0.5, y + 0.5); }

glm::dvec3 CameraRays::directionAt(double px, double py) const {
  return shared::cameraDirectionAt(basis_.forward, basis_.right, basis_.up, basis_.tanHalf, aspect_,
                                   static_cast<double>(width_), static_cast<double>(height_), px, py);
}

glm::dvec3 CameraRays::subsampleDirection(int x, int y, unsigned k) const {
  return directionAt(shared::subsampleCoordinate<double>(static_cast<shared::uint>(x), k, 1u),
                     shared::subsampleCoordinate<double>(static_cast<shared::uint>(y), k, 2u));
}

glm::dmat3 shadingFrame(const glm::dvec3& n, const glm::dvec3& wo, double& thetaOut) {
  return shared::shadingFrame(n, wo, thetaOut);
}

}  // namespace haarcast::render
