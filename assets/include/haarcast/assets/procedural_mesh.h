// The built-in meshes: what the default scene shows without any file, and
// the shapes the visibility tests reason about analytically.
//
// Every mesh is in its object frame (+Y up, DESIGN.md "Directions"), wound
// counter-clockwise seen from outside, so cross(b − a, c − a) points out of a
// closed mesh (and up, out of the plane), and carries exact unit normals of the
// analytic surface. Bad sizes throw std::invalid_argument naming the value.
#pragma once

#include "haarcast/core/mesh.h"

namespace haarcast::assets {

// Unit sphere at the origin, a UV sphere: `segments` columns of azimuth
// (φ, DESIGN.md convention) by segments/2 rows of elevation, with one vertex at
// each pole, so it is closed and watertight. segments ∈ [4, 4096]. A UV sphere
// rather than an icosphere because its vertices sit on the lat-long grid the
// maps use, and its size is any even number, not 20·4^k.
// Vertices: segments·(segments/2 − 1) + 2; triangles: 2·segments·(segments/2 − 1).
Mesh makeSphere(int segments);

// Torus about the +Y axis, centred at the origin: the tube of radius
// minorRadius around the circle of radius majorRadius in the XZ plane.
// 0 < minorRadius < majorRadius; segments ∈ [3, 4096] each. Area 4π²Rr, volume
// 2π²Rr². A shape that shadows itself, for visibility tests.
Mesh makeTorus(double majorRadius = 1.0, double minorRadius = 0.35, int majorSegments = 64,
               int minorSegments = 32);

// Axis-aligned box [−h, h] centred at the origin, h = halfExtents (each > 0).
// Each face has its own four vertices with the face's normal, so the
// shading is flat (24 vertices, 12 triangles).
Mesh makeBox(double halfExtentX = 1.0, double halfExtentY = 1.0, double halfExtentZ = 1.0);

// A shape that shadows itself deeply, for shadow tests: a square slab
// [−1, 1] × [−0.1, 0] × [−1, 1] with n × n square pillars standing on it
// (pillar (i, j) centred in cell (i, j) of the n × n grid over the slab's
// top, 0.6 of the cell wide, of height 1.2·(0.4 + 0.6·((3i + 5j) mod n)/(n − 1))),
// so that the slots between them are 2–6 times deeper than wide. Every box
// is closed, its faces flat-shaded like makeBox's, each face a
// faceSubdivisions² grid of quads (per-vertex visibility needs vertices
// inside a shadow). A pillar's bottom lies on the slab's top: the boxes
// touch and do not overlap, so area and volume are the boxes' sums.
// pillars ∈ [2, 64], faceSubdivisions ∈ [1, 256].
Mesh makePillars(int pillars = 4, int faceSubdivisions = 6);

// Square [−halfSize, halfSize]² in the XZ plane at y = 0, facing +Y, as a
// subdivisions × subdivisions grid of quads (per-vertex visibility needs
// vertices inside a shadow, not only at the corners). halfSize > 0,
// subdivisions ∈ [1, 4096].
Mesh makePlane(double halfSize, int subdivisions = 1);

}  // namespace haarcast::assets
