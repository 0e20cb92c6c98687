// The view the user steers — the camera's orbit, each object's turn and the
// light's — and the poses that tell the server about it. A pose carries only
// what the user touched, so the server keeps the scene's own pose for the rest.
import { DRAG_DEGREES_PER_PIXEL, dragOrbit, orbitEye, orbitFromCamera, pinchOrbit, zoomOrbit } from './orbit.js';
import { MOVE_EVENT, state } from './page_state.js';
import { send } from './session.js';

// Set from SceneInfo.camera (orbitFromCamera): the scene's own view is where
// the orbit starts.
export const orbit = { target: null, up: null, forward: null, right: null, azimuth: 0, elevation: 0, distance: 1,
                       startDistance: 1, fov: 45, camera: null };
export const touched = { camera: false, light: false, objects: new Set() };
export const objectRotation = new Map();  // object index → {x, y} degrees (R = Rz Ry Rx)
let lightY = 0;                           // degrees about world +Y

export const view = {
  poseSequence: 0,
  poseDirty: false,    // a pose is due at the next display frame
  pendingScene: null,  // a SceneChoice for another scene, not answered yet
  // The first pose sent after the last change (settings, scene, size):
  // frames answering older poses were made before it or answer the change
  // itself, not a pose, so they carry no pose-to-frame latency.
  changeFromPose: 0,
};

// The user moved the view: an event on window (page_state.js MOVE_EVENT)
// for what follows moves (resolution.js: a still view is shown sharp, a
// moving one at auto's step). An event, not a listener list here, because
// resolution.js is evaluated inside this module's import cycle (view →
// session → resolution → view) and would read the list before it exists.
function moved() {
  window.dispatchEvent(new Event(MOVE_EVENT));
}

// A change was sent: a pose follows it at once, so that the frame made with
// the change answers a pose of its own.
export function noteChange() {
  view.changeFromPose = view.poseSequence + 1;
  view.poseDirty = true;
}

// The scene's own pose of an object (SceneInfo), where its turns start from,
// so the first drag does not snap it back to no rotation.
export function scenePoseOf(index) {
  const o = state.sceneInfo && state.sceneInfo.objects.find((x) => x.index === index);
  const p = (o && o.pose) || {};
  const r = p.rotateDegrees || {};
  const t = p.translate || {};
  return { x: r.x || 0, y: r.y || 0, z: r.z || 0, translate: { x: t.x || 0, y: t.y || 0, z: t.z || 0 } };
}

export function resetView() {
  Object.assign(orbit, orbitFromCamera(state.sceneInfo && state.sceneInfo.camera));
  lightY = 0;
  touched.camera = false;
  touched.light = false;
  touched.objects.clear();
  objectRotation.clear();
}

// What the user has steered, for the address (share_url.js): the camera's
// orbit in degrees, the light's turn, each turned object's; null or empty
// for what was not touched (the scene's own then).
export function viewSnapshot() {
  const deg = (r) => r * 180 / Math.PI;
  return {
    camera: touched.camera ? { azimuth: deg(orbit.azimuth), elevation: deg(orbit.elevation), distance: orbit.distance } : null,
    light: touched.light ? lightY : null,
    objects: [...touched.objects].sort((a, b) => a - b).map((i) => {
      const r = objectRotation.get(i);
      return { index: i, x: r.x, y: r.y, z: r.z };
    }),
  };
}

// A view from the address (page_params.js: camera, light, objects) over the
// scene's own, sent as the next pose. Objects the scene does not have are
// left out.
export function applyView(v) {
  const rad = (d) => d * Math.PI / 180;
  if (v.camera) {
    orbit.azimuth = rad(v.camera.azimuth);
    orbit.elevation = rad(v.camera.elevation);
    orbit.distance = v.camera.distance;
    touched.camera = true;
  }
  if (v.light !== null && v.light !== undefined) {
    lightY = v.light;
    touched.light = true;
  }
  for (const o of v.objects || []) {
    if (!state.sceneInfo || !state.sceneInfo.objects.some((x) => x.index === o.index)) continue;
    objectRotation.set(o.index, { ...scenePoseOf(o.index), x: o.x, y: o.y, z: o.z });
    touched.objects.add(o.index);
  }
  view.poseDirty = true;
}

// Until a scene is shown, or while another one is on its way, there is no
// view to move.
const steerable = () => state.sceneInfo && view.pendingScene === null;

// A drag of (dx, dy) CSS pixels turning `target`: 'camera', 'light' or 'object:INDEX'.
export function steer(target, dx, dy) {
  if (!steerable()) return;
  if (target === 'light') {
    lightY += dx * DRAG_DEGREES_PER_PIXEL;
    touched.light = true;
  } else if (target.startsWith('object:')) {
    const index = Number(target.slice(7));
    if (!state.sceneInfo.objects.some((o) => o.index === index)) return;
    const r = objectRotation.get(index) || scenePoseOf(index);
    r.y += dx * DRAG_DEGREES_PER_PIXEL;
    r.x += dy * DRAG_DEGREES_PER_PIXEL;
    objectRotation.set(index, r);
    touched.objects.add(index);
  } else {
    Object.assign(orbit, dragOrbit(orbit, dx, dy));
    touched.camera = true;
  }
  view.poseDirty = true;
  moved();
}

export function zoom(deltaY) {
  if (!steerable()) return;
  orbit.distance = zoomOrbit(orbit, deltaY);
  touched.camera = true;
  view.poseDirty = true;
  moved();
}

// Fingers that moved from `fromPx` apart to `toPx` apart (a pinch).
export function pinch(fromPx, toPx) {
  if (!steerable()) return;
  orbit.distance = pinchOrbit(orbit, fromPx, toPx);
  touched.camera = true;
  view.poseDirty = true;
  moved();
}

function sendPose() {
  const pose = { sequence: ++view.poseSequence, clientTimeMs: performance.now() };
  if (touched.camera) {
    pose.camera = { eye: orbitEye(orbit), target: orbit.target, up: orbit.up, fovYDegrees: orbit.fov };
  }
  if (touched.objects.size) {
    pose.objects = [...touched.objects].map((i) => {
      const r = objectRotation.get(i);
      return { object: i, rotateDegrees: { x: r.x, y: r.y, z: r.z }, translate: r.translate };
    });
  }
  if (touched.light) pose.lightRotateDegrees = { x: 0, y: lightY, z: 0 };
  if (send({ pose })) state.posesSent++;
}

// The pose due, if one is: called once per display frame.
export function flushPose() {
  if (view.poseDirty) {
    view.poseDirty = false;
    sendPose();
  }
}

// A pose with no view fields, only `keyframe` (and the time the frame
// echoes for the HUD latency): the same view, as a keyframe. Returns its
// sequence, or 0 when it was not sent.
export function requestKeyframe() {
  const sequence = ++view.poseSequence;
  if (!send({ pose: { sequence, clientTimeMs: performance.now(), keyframe: true } })) return 0;
  state.keyframeRequests++;
  return sequence;
}
