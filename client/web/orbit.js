// The view is an orbit about the scene camera's target: the scene's own view
// is where the orbit starts, and drags and the wheel move the eye over a
// sphere about that target. The maths is kept pure (no DOM, no page state) so
// that node checks it (tests/e2e/web_client_test.mjs): a camera turned into
// an orbit and back must give the same eye, or the first pose would jump.
//
// The pole is the camera's up vector; azimuth is measured in the plane normal
// to it, elevation from that plane.

// Half a degree per CSS pixel: a drag across the canvas is a half turn or so.
export const DRAG_DEGREES_PER_PIXEL = 0.5;

export const v3 = {
  add: (a, b) => ({ x: a.x + b.x, y: a.y + b.y, z: a.z + b.z }),
  sub: (a, b) => ({ x: a.x - b.x, y: a.y - b.y, z: a.z - b.z }),
  scale: (a, s) => ({ x: a.x * s, y: a.y * s, z: a.z * s }),
  dot: (a, b) => a.x * b.x + a.y * b.y + a.z * b.z,
  cross: (a, b) => ({ x: a.y * b.z - a.z * b.y, y: a.z * b.x - a.x * b.z, z: a.x * b.y - a.y * b.x }),
  norm: (a) => Math.hypot(a.x, a.y, a.z),
  unit: (a) => v3.scale(a, 1 / (v3.norm(a) || 1)),
  of: (v, fallback) => (v ? { x: v.x || 0, y: v.y || 0, z: v.z || 0 } : fallback),
};

// The orbit that starts at `camera` (SceneInfo.camera; missing fields take
// the defaults of a camera at +5 Z looking at the origin).
export function orbitFromCamera(camera) {
  const c = camera || {};
  const eye = v3.of(c.eye, { x: 0, y: 0, z: 5 });
  const target = v3.of(c.target, { x: 0, y: 0, z: 0 });
  let up = v3.of(c.up, { x: 0, y: 1, z: 0 });
  if (v3.norm(up) < 1e-9) up = { x: 0, y: 1, z: 0 };
  up = v3.unit(up);
  // A reference direction in the plane normal to up: +Z there, else +X.
  let forward = v3.sub({ x: 0, y: 0, z: 1 }, v3.scale(up, up.z));
  if (v3.norm(forward) < 1e-6) forward = v3.sub({ x: 1, y: 0, z: 0 }, v3.scale(up, up.x));
  forward = v3.unit(forward);
  const right = v3.cross(up, forward);  // up = +Y, forward = +Z → right = +X
  const d = v3.sub(eye, target);
  const distance = v3.norm(d) || 1;
  return {
    target, up, forward, right, distance, startDistance: distance,
    elevation: Math.asin(Math.max(-1, Math.min(1, v3.dot(d, up) / distance))),
    azimuth: Math.atan2(v3.dot(d, right), v3.dot(d, forward)),
    fov: c.fovYDegrees > 0 ? c.fovYDegrees : 45,
    camera: c,
  };
}

export function orbitEye(orbit) {
  const c = Math.cos(orbit.elevation);
  const dir = v3.add(v3.add(v3.scale(orbit.right, c * Math.sin(orbit.azimuth)),
                            v3.scale(orbit.forward, c * Math.cos(orbit.azimuth))),
                     v3.scale(orbit.up, Math.sin(orbit.elevation)));
  return v3.add(orbit.target, v3.scale(dir, orbit.distance));
}

// Where a drag of (dx, dy) CSS pixels takes the orbit's angles.
export function dragOrbit(orbit, dx, dy) {
  const limit = 89 * Math.PI / 180;  // never along the pole: the up vector would be parallel
  return {
    azimuth: orbit.azimuth - dx * DRAG_DEGREES_PER_PIXEL * Math.PI / 180,
    elevation: Math.max(-limit, Math.min(limit, orbit.elevation + dy * DRAG_DEGREES_PER_PIXEL * Math.PI / 180)),
  };
}

// The distance after a wheel turn of `deltaY`: from a fifth of the scene's
// own distance to ten times it.
export function zoomOrbit(orbit, deltaY) {
  const d = orbit.startDistance;
  return Math.max(0.2 * d, Math.min(10 * d, orbit.distance * Math.exp(deltaY * 0.001)));
}

// The distance after a pinch whose fingers moved from `fromPx` apart to
// `toPx` apart: spreading them brings the eye closer by the same ratio, as
// a map does; within the wheel's range.
export function pinchOrbit(orbit, fromPx, toPx) {
  if (!(fromPx > 0) || !(toPx > 0)) return orbit.distance;
  const d = orbit.startDistance;
  return Math.max(0.2 * d, Math.min(10 * d, orbit.distance * fromPx / toPx));
}
