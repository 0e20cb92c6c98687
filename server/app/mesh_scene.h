// A "mesh scene": one mesh, centred and scaled to unit radius, stood up on
// its up axis, optionally on a ground, under the built-in environment (the
// caller swaps in a probe), with a camera framing it. `render --mesh` draws
// one, and `serve --data` offers one per mesh file, so both build it here.
#pragma once

#include <string>

#include <glm/vec3.hpp>

#include "haarcast/core/mesh.h"
#include "haarcast/render/scene.h"

namespace haarcast::app {

// The material of a mesh scene's mesh when none is chosen (render --mesh
// without --material, serve's mesh scenes).
inline constexpr const char* kMeshMaterial = "phong:64";

// The up axis a mesh most likely has in its file, from its bounding box's
// extent: Z when Z is the longest side and Y the shortest, under half of Z
// (a statue stored Z-up, like Lucy: 930 × 534 × 1597); Y otherwise (most
// OBJ and PLY files; a cow as long in Z as it is tall in Y stays Y-up). A
// guess: clients may say otherwise (SceneChoice.up).
render::UpAxis guessUpAxis(const glm::dvec3& extent);
render::UpAxis guessUpAxis(const Mesh& mesh);  // of its bounds as loaded

// `mesh` as its file has it, turned by `up` (render::makeYUp), fitted to the
// unit sphere, named `name`, with `material` and `pose`; a ground under it
// when asked (render::addGround). The camera looks at the origin from
// (0, 0.3, 3): the unit sphere fills the default field of view.
render::Scene meshScene(Mesh mesh, const std::string& name, render::UpAxis up, render::Material material,
                        const render::Pose& pose, bool ground);

}  // namespace haarcast::app
