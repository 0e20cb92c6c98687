// The haarcast browser client: one page, one WebSocket, one protobuf message
// per binary WebSocket message. The schema is fetched from the server
// (GET /haarcast.proto), so the wire contract has one definition; the page
// quotes the server's limits (Welcome.limits) and scenes (Welcome.scenes,
// SceneInfo) instead of keeping copies. This module is the page's entry: it
// ties the page's parts together (what each server message does to them) and
// starts them.
//
//   drag          the target chosen under "drag rotates" (the camera by default)
//   shift-drag    the chosen object (the first one when none is chosen)
//   alt-drag      the light (the environment) about +Y
//   wheel, pinch  camera distance
//   f / Esc       full window on / off
//   h             the HUD's details folded / shown
//
// Page parameters (page_params.js; a bad one is shown and nothing connects):
//   ?resolution=auto|360p|540p|720p|1080p (or ?size=WxH, fixed)
//   &encoding=jpeg|png|raw|h264&quality=85&fps=30&token=T
//   &method=fused&level=4&k=256&exposure=auto|STOPS&scene=NAME
//   &mat=SPEC,SPEC…&tone=reinhard|aces|agx&cam=AZ,EL,DIST&light=DEG&obj=I:X:Y:Z,…
//   (the page keeps these up to date as the view changes: share_url.js)
import './save_frame.js';  // the save button and s: the frame as a PNG
import './view_input.js';  // drags, pinches, the wheel and the reset button steer the view
import { endBuild, expectBuild, showBuildProgress } from './build_view.js';
import { endWaiting, showFrameProgress, showWaiting } from './frame_progress_view.js';
import { onFrame, startH264View } from './frames.js';
import { frameWindow, setServerStats, updateHud } from './hud.js';
import { setFrameSize } from './layout.js';
import { orbitEye } from './orbit.js';
import { parsePageParameters } from './page_params.js';
import { choices, page, setPage, state } from './page_state.js';
import { onSceneInfo, showScenes, undoSceneChoice } from './scene_panel.js';
import { Encoding, loadSchema, methodNames, toneNames } from './schema.js';
import { connect, onServerMessages, send, stop } from './session.js';
import { chooseEncoding, flushExposure, showWelcomeSettings, undoSettingsChange } from './settings_panel.js';
import { granted, refit, showResolutionChoice } from './resolution.js';
import { applyAddressView, startAddress } from './share_url.js';
import { setStatus, showBanner } from './status.js';
import { flushPose, objectRotation, orbit, scenePoseOf, view } from './view.js';

const $ = (id) => document.getElementById(id);

// The eye the next camera pose would carry (for the test: a scene switch
// starts the orbit at the scene's own camera).
state.viewEye = () => (orbit.target ? orbitEye(orbit) : null);
state.objectPose = (i) => objectRotation.get(i) || scenePoseOf(i);
state.viewDistance = () => orbit.distance;

// ---- messages from the server -----------------------------------------------------

function onWelcome(w) {
  state.welcome = w;
  state.welcomes++;
  state.connection = 'ready';
  state.reconnectAttempt = 0;
  state.reconnectInS = null;
  state.lastShownSequence = 0;
  frameWindow.clear();
  $('reconnect').hidden = true;
  $('banner').hidden = true;  // what it said was about the previous session
  endBuild();
  setFrameSize(w.width, w.height);
  startH264View(w.encoding === Encoding.values.ENCODING_H264);
  showWelcomeSettings(w);
  showScenes(w.scenes);
  for (const id of ['scene', 'method', 'level', 'coefficients', 'exposure-auto', 'exposure', 'tone', 'reset-view']) {
    $(id).disabled = false;
  }
  view.pendingScene = null;
  onSceneInfo(w.sceneInfo || { name: w.scenes[0] || '', objects: [] }, true);
  applyAddressView();  // the view the address named, once
  // The frame size is the HUD's to say: it follows the view.
  // Where its shadow rays are traced: on the GPU itself or by the server's CPU.
  const rays = w.rays === 'device' ? ', rays on the device' : w.rays === 'host' ? ', rays on the host' : '';
  setStatus(`connected: ${w.device || 'renderer'}${rays}, session ${w.sessionId}`);
  view.poseDirty = true;  // the first pose: the view kept across a reconnect, or none
  // The Hello's size was a guess made before the server's limits were known
  // (or the view changed meanwhile): ask for the one that fits now.
  granted(w.width, w.height);
  refit();
  showWaiting('rendering the first frame', `${w.width}×${w.height}`, 'the server says how far once it takes over half a second');
}

// A change the server refused; the session goes on as before.
function onRefused(code) {
  // A build that failed (RENDER_FAILED) or a change refused: nothing is built.
  endBuild();
  if (code === 'ERROR_CODE_UNKNOWN_SCENE' || code === 'ERROR_CODE_UNKNOWN_MATERIAL') undoSceneChoice();
  else if (code === 'ERROR_CODE_BAD_SETTINGS') undoSettingsChange();
}

onServerMessages({
  welcome: onWelcome,
  frame: onFrame,
  sceneInfo: (info) => onSceneInfo(info, false),
  stats: setServerStats,
  refused: onRefused,
  buildProgress: (p) => {
    showBuildProgress(p);
    endWaiting();  // the build's overlay says more
  },
  frameProgress: showFrameProgress,
});

// At most one pose and one exposure change per display frame: pointer and
// slider events come faster than that, and the server keeps only the latest.
function tick() {
  if (state.connection === 'ready') {
    flushExposure();
    flushPose();
  }
  requestAnimationFrame(tick);
}

// ---- start ------------------------------------------------------------------------

async function main() {
  await loadSchema();

  // The page's parameters first: a bad one is reported and nothing connects.
  setPage(parsePageParameters(location.search, { methods: methodNames, tones: toneNames }));
  if (page.errors.length) {
    for (const e of page.errors) state.errors.push({ code: 'PAGE_PARAMETER', message: e.message, fatal: true });
    showBanner(`${page.errors.map((e) => e.message).join('\n')}\nFix the address and reload.`);
    stop('not connected: a page parameter is not valid');
    $('reconnect').hidden = true;
    return;
  }
  Object.assign(choices, { scene: page.scene, method: page.method, level: page.level, k: page.k,
                           exposure: page.exposure, resolution: page.resolution, tone: page.tone });
  showResolutionChoice();
  // The first build: the scene the Hello asks for.
  expectBuild(`scene ${page.scene || 'default'}`);
  if (!page.exposure.auto) {
    $('exposure-auto').checked = false;
    $('exposure').value = String(page.exposure.stops);
  }
  await chooseEncoding(page.encoding);
  connect();
  setInterval(updateHud, 250);
  startAddress();
  // The server closes sessions that send nothing for a while; a page left
  // alone (no drags) pings to stay connected.
  let nonce = 0;
  setInterval(() => send({ ping: { nonce: ++nonce } }), 15000);
  requestAnimationFrame(tick);
}

main().catch((err) => {
  state.errors.push({ code: 'PAGE', message: err.message, fatal: true });
  showBanner(err.message);
  stop(`not started: ${err.message}`);
});
