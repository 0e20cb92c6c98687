#include "mesh_scene.h"

#include <memory>
#include <utility>

namespace haarcast::app {

render::UpAxis guessUpAxis(const glm::dvec3& e) {
  const bool zLongest = e.z >= e.x && e.z >= e.y;
  const bool yShortest = e.y <= e.x;
  return zLongest && yShortest && e.y < 0.5 * e.z ? render::UpAxis::Z : render::UpAxis::Y;
}

render::UpAxis guessUpAxis(const Mesh& mesh) {
  const Bounds b = mesh.bounds();
  return guessUpAxis(b.hi - b.lo);
}

render::Scene meshScene(Mesh mesh, const std::string& name, render::UpAxis up, render::Material material,
                        const render::Pose& pose, bool ground) {
  render::Scene scene = render::defaultScene();  // its environment and camera; not its objects
  scene.objects.clear();
  render::makeYUp(mesh, up);
  render::fitToUnitSphere(mesh);
  scene.objects.push_back({name, std::make_shared<Mesh>(std::move(mesh)), std::move(material), pose});
  scene.camera.eye = {0.0, 0.3, 3.0};
  if (ground) render::addGround(scene);
  return scene;
}

}  // namespace haarcast::app
