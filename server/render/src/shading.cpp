#include "haarcast/render/shading.h"

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
  const double sx = (2.0 * px / width_ - 1.0) * basis_.tanHalf * aspect_;
  const double sy = (1.0 - 2.0 * py / height_) * basis_.tanHalf;
  return glm::normalize(basis_.forward + sx * basis_.right + sy * basis_.up);
}

glm::dmat3 shadingFrame(const glm::dvec3& n, const glm::dvec3& wo, double& thetaOut) {
  const double c = std::clamp(glm::dot(n, wo), -1.0, 1.0);
  thetaOut = std::acos(std::max(c, 0.0));
  glm::dvec3 z = wo - c * n;
  if (glm::dot(z, z) < 1e-16) {  // view along the normal: any tangent will do
    z = std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1, 0, 0)) : glm::cross(n, glm::dvec3(0, 1, 0));
  }
  z = glm::normalize(z);
  const glm::dvec3 x = glm::cross(n, z);  // right-handed: x = y × z
  return glm::dmat3(x, n, z);
}

}  // namespace haarcast::render
