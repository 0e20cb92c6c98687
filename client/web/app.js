// The haarcast browser client: one page, one WebSocket, one protobuf message
// per binary WebSocket message. The schema is fetched from the server
// (GET /haarcast.proto), so the wire contract has one definition; the page
// quotes the server's limits (Welcome.limits) and scenes (Welcome.scenes,
// SceneInfo) instead of keeping copies.
//
//   drag          the target chosen under "drag rotates" (the camera by default)
//   shift-drag    the chosen object (the first one when none is chosen)
//   alt-drag      the light (the environment) about +Y
//   wheel         camera distance
//   f / Esc       full window on / off
//
// Page parameters (page_params.js; a bad one is shown and nothing connects):
//   ?size=256x256&encoding=jpeg|png|raw|h264&quality=85&fps=30&token=T
//   &method=fused&level=4&k=256&exposure=auto|STOPS&scene=NAME
/* global protobuf */
import { FrameWindow, backoffMs, formatNumber, formatStops } from './frame_stats.js';
import { h264Support } from './h264_decoder.js';
import { H264View, helloEncoding } from './h264_view.js';
import { parsePageParameters } from './page_params.js';

const $ = (id) => document.getElementById(id);
const canvas = $('frame');
const ctx = canvas.getContext('2d');

// Exposed for the end-to-end test and for curious users (devtools).
const state = {
  welcome: null,
  sceneInfo: null,
  framesReceived: 0,
  framesShown: 0,
  lastShownSequence: 0,
  lastFrame: null,     // {sequence, poseSequence, width, height, encoding, method, bytes, exposureStops, exposureMode}
  posesSent: 0,
  errors: [],          // {code, message, fatal}; page-parameter errors have code "PAGE_PARAMETER"
  closed: null,        // {code, reason} of the last socket close
  hudUpdates: 0,
  connection: 'loading',  // loading | connecting | waiting-welcome | ready | reconnect-wait | stopped
  connections: 0,      // sockets opened (attempts)
  welcomes: 0,
  reconnectAttempt: 0,
  reconnectInS: null,  // seconds to the next attempt while waiting
  scene: { name: '', firstPose: 0 },  // frames answering poses older than firstPose show the previous scene
  h264: null,          // h264Support()'s answer, once H.264 was chosen
  helloEncoding: '',   // what the last Hello asked for (jpeg when H.264 falls back)
  keyframeRequests: 0, // poses sent with PoseUpdate.keyframe
};
window.haarcast = state;
// The eye the next camera pose would carry (for the test: a scene switch
// starts the orbit at the scene's own camera).
state.viewEye = () => (orbit.target ? orbitEye() : null);
state.objectPose = (i) => objectRotation.get(i) || scenePoseOf(i);

// ---- schema -------------------------------------------------------------------

let ClientMessage, ServerMessage, Encoding, RotationMethod, ErrorCode, ExposureMode;
let methodNames = [];  // "haar", …, "fused": the schema's RotationMethod values

const enumName = (e, value, prefix) => (e.valuesById[value] || '').replace(prefix, '').toLowerCase();
const methodName = (value) => enumName(RotationMethod, value, 'ROTATION_METHOD_') || null;
const methodValue = (name) => (name ? RotationMethod.values[`ROTATION_METHOD_${name.toUpperCase()}`] : 0);

// ---- what the user asked for (the next Hello, after a reconnect, says it again) --

let page = null;  // parsePageParameters(location.search)
const choices = { scene: '', method: '', level: 0, k: 0, exposure: { auto: true, stops: 0 } };

// ---- the view: an orbit about the scene camera's target ------------------------

// Set from SceneInfo.camera: the scene's own view is where the orbit starts.
// The pole is the camera's up vector; azimuth is measured in the plane
// normal to it, elevation from that plane.
const orbit = { target: null, up: null, forward: null, right: null, azimuth: 0, elevation: 0, distance: 1,
                startDistance: 1, fov: 45, camera: null };
const touched = { camera: false, light: false, objects: new Set() };
const objectRotation = new Map();  // object index → {x, y} degrees (R = Rz Ry Rx)
let lightY = 0;                    // degrees about world +Y
let poseSequence = 0;
let poseDirty = false;
let pendingScene = null;           // a SceneChoice for another scene, not answered yet

const v3 = {
  add: (a, b) => ({ x: a.x + b.x, y: a.y + b.y, z: a.z + b.z }),
  sub: (a, b) => ({ x: a.x - b.x, y: a.y - b.y, z: a.z - b.z }),
  scale: (a, s) => ({ x: a.x * s, y: a.y * s, z: a.z * s }),
  dot: (a, b) => a.x * b.x + a.y * b.y + a.z * b.z,
  cross: (a, b) => ({ x: a.y * b.z - a.z * b.y, y: a.z * b.x - a.x * b.z, z: a.x * b.y - a.y * b.x }),
  norm: (a) => Math.hypot(a.x, a.y, a.z),
  unit: (a) => v3.scale(a, 1 / (v3.norm(a) || 1)),
  of: (v, fallback) => (v ? { x: v.x || 0, y: v.y || 0, z: v.z || 0 } : fallback),
};

function orbitFromCamera(camera) {
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
  Object.assign(orbit, {
    target, up, forward, right, distance, startDistance: distance,
    elevation: Math.asin(Math.max(-1, Math.min(1, v3.dot(d, up) / distance))),
    azimuth: Math.atan2(v3.dot(d, right), v3.dot(d, forward)),
    fov: c.fovYDegrees > 0 ? c.fovYDegrees : 45,
    camera: c,
  });
}

function orbitEye() {
  const c = Math.cos(orbit.elevation);
  const dir = v3.add(v3.add(v3.scale(orbit.right, c * Math.sin(orbit.azimuth)),
                            v3.scale(orbit.forward, c * Math.cos(orbit.azimuth))),
                     v3.scale(orbit.up, Math.sin(orbit.elevation)));
  return v3.add(orbit.target, v3.scale(dir, orbit.distance));
}

// The scene's own pose of an object (SceneInfo), where its turns start from,
// so the first drag does not snap it back to no rotation.
function scenePoseOf(index) {
  const o = state.sceneInfo && state.sceneInfo.objects.find((x) => x.index === index);
  const p = (o && o.pose) || {};
  const r = p.rotateDegrees || {};
  const t = p.translate || {};
  return { x: r.x || 0, y: r.y || 0, z: r.z || 0, translate: { x: t.x || 0, y: t.y || 0, z: t.z || 0 } };
}

function resetView() {
  orbitFromCamera(state.sceneInfo && state.sceneInfo.camera);
  lightY = 0;
  touched.camera = false;
  touched.light = false;
  touched.objects.clear();
  objectRotation.clear();
}

// ---- the socket -----------------------------------------------------------------

let ws = null;
let generation = 0;        // one per socket: late decodes of an old one are dropped
let lastFatal = null;      // {code, retry} of the fatal Error that closes this socket
let reconnectTimer = null;
let reconnectAt = 0;
let reconnectWhy = '';

// Fatal errors worth another try: the server timed us out, restarted, or was full.
const RETRYABLE = new Set(['ERROR_CODE_TIMEOUT', 'ERROR_CODE_SHUTTING_DOWN', 'ERROR_CODE_TOO_MANY_SESSIONS']);

function send(body) {
  if (!ws || ws.readyState !== WebSocket.OPEN) return false;
  ws.send(ClientMessage.encode(ClientMessage.create(body)).finish());
  return true;
}

function socketUrl() {
  const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
  // The token rides in the query: browsers cannot set headers on a WebSocket.
  return `${scheme}//${location.host}/ws${page.token ? `?token=${encodeURIComponent(page.token)}` : ''}`;
}

function exposureSettings() {
  return choices.exposure.auto
    ? { exposureMode: ExposureMode.values.EXPOSURE_MODE_AUTO }
    : { exposureMode: ExposureMode.values.EXPOSURE_MODE_FIXED, exposureStops: choices.exposure.stops };
}

function hello() {
  state.helloEncoding = helloEncoding(page.encoding, state.h264).encoding;
  const encoding = { jpeg: 'ENCODING_JPEG', png: 'ENCODING_PNG', raw: 'ENCODING_RAW_RGBA8', h264: 'ENCODING_H264' }[
    state.helloEncoding];
  const h = {
    protocolVersion: 1, authToken: page.token, width: page.width, height: page.height,
    encoding: Encoding.values[encoding], fpsCap: page.fps, jpegQuality: page.quality, clientName: 'browser',
    settings: { method: methodValue(choices.method), level: choices.level, lightCoefficients: choices.k,
                ...exposureSettings() },
  };
  if (choices.scene) {
    h.scene = { scene: choices.scene, objectMaterials: {} };
    // After a reconnect: the materials in effect, where the server offers them.
    const info = state.sceneInfo;
    if (info && info.name === choices.scene && state.welcome) {
      for (const o of info.objects) {
        if (state.welcome.materials.includes(o.material)) h.scene.objectMaterials[o.index] = o.material;
      }
    }
  }
  return h;
}

function connect() {
  clearTimeout(reconnectTimer);
  reconnectTimer = null;
  state.reconnectInS = null;
  lastFatal = null;
  const socket = new WebSocket(socketUrl());
  ws = socket;
  const gen = ++generation;
  let opened = false;
  state.connections++;
  state.connection = 'connecting';
  setStatus(`connecting to ${socketUrl().replace(/\?token=.*/, '?token=…')}` +
            (state.reconnectAttempt ? ` (attempt ${state.reconnectAttempt + 1})` : '') + '…');
  $('reconnect').hidden = true;
  socket.binaryType = 'arraybuffer';
  socket.onopen = () => {
    opened = true;
    state.connection = 'waiting-welcome';
    setStatus('connected; waiting for Welcome (the server prepares the scene: seconds the first time)…');
    send({ hello: hello() });
  };
  socket.onmessage = (event) => {
    if (gen !== generation) return;
    let m;
    try {
      m = ServerMessage.decode(new Uint8Array(event.data));
    } catch (err) {
      showBanner(`a message from the server did not decode: ${err.message}`);
      return;
    }
    if (m.welcome) onWelcome(m.welcome);
    else if (m.frame) onFrame(m.frame, gen).catch((err) => showBanner(`frame ${m.frame.sequence}: ${err.message}`));
    else if (m.sceneInfo) onSceneInfo(m.sceneInfo, false);
    else if (m.stats) serverStats = m.stats;
    else if (m.error) onError(m.error);
  };
  socket.onclose = (event) => {
    if (gen !== generation) return;
    ws = null;
    state.closed = { code: event.code, reason: event.reason };
    const why = `disconnected (close code ${event.code}${event.reason ? `: ${event.reason}` : ''})`;
    if (lastFatal && !lastFatal.retry) {
      stop(`not connected: the server closed the session (${lastFatal.code})`);
      return;
    }
    if (!opened) {
      // The upgrade failed. If the server answers plain HTTP, it refused the
      // WebSocket itself: a wrong or missing token (HTTP 401) will not fix
      // itself, so the page does not retry on its own.
      fetch('/healthz', { cache: 'no-store' }).then((r) => {
        if (gen !== generation) return;
        if (r.ok) {
          stop('not connected: the server is up but refused the WebSocket upgrade');
          showBanner('The server answers HTTP but refused the WebSocket upgrade at /ws, most likely with ' +
                     (page.token ? 'HTTP 401: the page\'s ?token= is not the server\'s.'
                                 : 'HTTP 401: the server runs with --token; add ?token=… to the address.') +
                     ' (A server that is shutting down answers 503; reconnect later.)');
        } else {
          scheduleReconnect(`cannot reach the server's WebSocket (/healthz: HTTP ${r.status})`);
        }
      }, () => { if (gen === generation) scheduleReconnect('cannot reach the server'); });
      return;
    }
    scheduleReconnect(why);
  };
}

function stop(text) {
  state.connection = 'stopped';
  state.reconnectInS = null;
  setStatus(text, true);
  $('reconnect').textContent = 'reconnect';
  $('reconnect').hidden = false;
}

function scheduleReconnect(why) {
  state.reconnectAttempt++;
  const delay = backoffMs(state.reconnectAttempt, Math.random());
  reconnectAt = performance.now() + delay;
  reconnectWhy = why;
  state.connection = 'reconnect-wait';
  reconnectTimer = setTimeout(connect, delay);
  $('reconnect').textContent = 'reconnect now';
  $('reconnect').hidden = false;
  showReconnectCountdown();
}

function showReconnectCountdown() {
  if (state.connection !== 'reconnect-wait') return;
  const s = Math.max(0, Math.ceil((reconnectAt - performance.now()) / 1000));
  state.reconnectInS = s;
  setStatus(`${reconnectWhy}; reconnecting in ${s} s (attempt ${state.reconnectAttempt})`, true);
}

// ---- messages from the server -----------------------------------------------------

let serverStats = null;
let effective = null;  // the RenderSettings in effect: Welcome's, then each frame's

function fillSelect(select, items, value) {
  select.replaceChildren(...items.map(([v, text]) => new Option(text, String(v))));
  if (value !== undefined && value !== null) selectValue(select, value);
}

function selectValue(select, value) {
  const v = String(value);
  if (![...select.options].some((o) => o.value === v)) select.add(new Option(v, v));
  select.value = v;
}

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
  setFrameSize(w.width, w.height);
  startH264View(w.encoding === Encoding.values.ENCODING_H264);
  effective = w.settings || {};
  const limits = w.limits || {};

  fillSelect($('method'), methodNames.map((m) => [m, m]), methodName(effective.method) || undefined);
  // Levels: the server's range, not a copy in the page.
  const levels = [];
  if (limits.maxLevel) {
    for (let n = limits.minLevel || 1; n <= limits.maxLevel; n++) levels.push([n, `${n} (${2 ** n}×${2 ** n})`]);
  }
  fillSelect($('level'), levels, effective.level || undefined);
  const ks = [16, 64, 256, 1024, 4096].filter((k) => !limits.maxLightCoefficients || k <= limits.maxLightCoefficients);
  fillSelect($('coefficients'), ks.map((k) => [k, String(k)]), effective.lightCoefficients || undefined);

  // Exposure: the slider spans ±8 stops, or less when the server allows less.
  const range = Math.min(8, limits.maxExposureStops || 8);
  const slider = $('exposure');
  slider.min = String(-range);
  slider.max = String(range);
  const fixed = effective.exposureMode === ExposureMode.values.EXPOSURE_MODE_FIXED;
  $('exposure-auto').checked = !fixed;
  if (fixed) slider.value = String(effective.exposureStops || 0);
  choices.exposure = { auto: !fixed, stops: Number(slider.value) };

  fillSelect($('scene'), w.scenes.map((s) => [s, s]));
  for (const id of ['scene', 'method', 'level', 'coefficients', 'exposure-auto', 'exposure', 'reset-view']) {
    $(id).disabled = false;
  }
  settingsBeforeChange = null;
  settingsAfterChange = currentSettings();
  pendingScene = null;
  onSceneInfo(w.sceneInfo || { name: w.scenes[0] || '', objects: [] }, true);
  setStatus(`connected: ${w.device || 'renderer'}, ${w.width}×${w.height}, session ${w.sessionId}`);
  poseDirty = true;  // the first pose: the view kept across a reconnect, or none
}

// The scene in effect: from Welcome, and in answer to each accepted
// SceneChoice. Another scene resets the view to its own camera (the server
// reset its poses to the scene's own); the same scene (a material change)
// keeps the view.
function onSceneInfo(info, fromWelcome) {
  const previous = state.sceneInfo;
  const newScene = !previous || previous.name !== info.name;
  state.sceneInfo = info;
  choices.scene = info.name;
  if (newScene || (fromWelcome && !touched.camera)) resetView();
  if (newScene && !fromWelcome) {
    // Frames answering older poses still show the previous scene.
    state.scene = { name: info.name, firstPose: poseSequence + 1 };
  } else if (fromWelcome) {
    state.scene = { name: info.name, firstPose: 0 };
  }
  if (pendingScene === info.name) pendingScene = null;
  poseDirty = true;
  selectValue($('scene'), info.name);
  showObjects(info);
}

function showObjects(info) {
  const offered = state.welcome ? state.welcome.materials : [];
  const list = $('objects');
  list.replaceChildren();
  const dragTargets = [...document.querySelectorAll('#drag-target input')];
  const chosen = (dragTargets.find((r) => r.checked) || {}).value;
  for (const r of dragTargets) if (r.value.startsWith('object:')) r.closest('label').remove();
  for (const o of info.objects) {
    const li = document.createElement('li');
    const name = document.createElement('span');
    name.className = 'name';
    name.textContent = o.name || `object ${o.index}`;
    const index = document.createElement('span');
    index.className = 'index';
    index.textContent = ` #${o.index}`;
    name.append(index);
    const select = document.createElement('select');
    select.dataset.object = String(o.index);
    select.setAttribute('aria-label', `material of ${o.name || `object ${o.index}`}`);
    const options = offered.map((m) => [m, m]);
    // A scene file's own material (say, a MERL file) is in effect but not
    // offered: shown, and not choosable again once changed.
    if (!offered.includes(o.material)) options.unshift([o.material, `${o.material} (the scene's own)`]);
    fillSelect(select, options, o.material);
    select.addEventListener('change', () => chooseMaterial(o.index, select.value));
    li.append(name, select);
    list.append(li);

    const label = document.createElement('label');
    label.className = 'inline';
    const radio = document.createElement('input');
    radio.type = 'radio';
    radio.name = 'drag';
    radio.value = `object:${o.index}`;
    label.append(radio, ` ${o.name || `object ${o.index}`}`);
    $('drag-target').append(label);
  }
  const keep = [...document.querySelectorAll('#drag-target input')].find((r) => r.value === chosen);
  (keep || document.querySelector('#drag-target input[value="camera"]')).checked = true;
}

// Frames are decoded asynchronously and may finish out of order; only a
// frame newer than the one on the canvas is drawn.
async function onFrame(f, gen) {
  state.framesReceived++;
  const received = performance.now();
  const bytes = f.data.byteLength;
  frameWindow.add(received, {
    bytes,
    latencyMs: f.clientTimeMs > 0 ? received - f.clientTimeMs : NaN,
    // The first frame (pose 0) waited for the renderer to be prepared: not a frame time.
    serverMs: f.serverMs > 0 && f.poseSequence > 0 ? f.serverMs : NaN,
    stages: f.timings.map((t) => ({ name: t.name, ms: t.ms })),
  });
  if (f.poseSequence < state.scene.firstPose) return;  // the previous scene, rendered before the switch
  if (f.settings) effective = f.settings;
  const method = f.settings && f.settings.method ? methodName(f.settings.method) : null;
  const exposureMode = f.settings && f.settings.exposureMode === ExposureMode.values.EXPOSURE_MODE_FIXED ? 'fixed' : 'auto';
  const fresh = () => gen === generation && f.sequence > state.lastShownSequence;
  const shown = () => {
    state.lastShownSequence = f.sequence;
    state.framesShown++;
    state.lastFrame = { sequence: f.sequence, poseSequence: f.poseSequence, width: f.width, height: f.height,
                        encoding: f.encoding, method, bytes, exposureStops: f.exposureStops, exposureMode };
    showFrameExposure(f.exposureStops, exposureMode);
  };
  if (f.encoding === Encoding.values.ENCODING_RAW_RGBA8) {
    if (bytes !== f.width * f.height * 4) throw new Error(`raw frame of ${bytes} bytes for ${f.width}×${f.height}`);
    // A copy: ImageData needs its own buffer, f.data views the message.
    const image = new ImageData(new Uint8ClampedArray(f.data), f.width, f.height);
    if (!fresh()) return;
    setFrameSize(f.width, f.height);
    ctx.putImageData(image, 0, 0);
    shown();
  } else if (f.encoding === Encoding.values.ENCODING_JPEG || f.encoding === Encoding.values.ENCODING_PNG) {
    const type = f.encoding === Encoding.values.ENCODING_JPEG ? 'image/jpeg' : 'image/png';
    const bitmap = await createImageBitmap(new Blob([f.data], { type }));
    if (fresh()) {
      setFrameSize(f.width, f.height);
      ctx.drawImage(bitmap, 0, 0);
      shown();
    }
    bitmap.close();
  } else if (f.encoding === Encoding.values.ENCODING_H264 && h264View) {
    // Decoded in order by the session's decoder; drawn when its picture comes out.
    h264View.frame(f, () => { if (gen === generation) shown(); });
  } else {
    showBanner(`cannot show ${Encoding.valuesById[f.encoding]} frames here; use ?encoding=jpeg, png, raw or h264`);
  }
}

// ---- H.264 (h264_view.js) -----------------------------------------------------------

let h264View = null;  // one per session: the decoder keeps the stream's reference pictures

function startH264View(on) {
  if (h264View) h264View.close();
  h264View = on ? new H264View({
    draw: (frame, done) => {
      setFrameSize(frame.displayWidth, frame.displayHeight);
      ctx.drawImage(frame, 0, 0);
      done();
    },
    // A pose with no view fields, only `keyframe` (and the time the frame
    // echoes for the HUD latency): the same view, as a keyframe.
    requestKeyframe: () => {
      const sequence = ++poseSequence;
      if (!send({ pose: { sequence, clientTimeMs: performance.now(), keyframe: true } })) return 0;
      state.keyframeRequests++;
      return sequence;
    },
  }) : null;
  state.h264View = h264View;
}

// The encoding chosen on the page (or ?encoding=): H.264 is asked for only
// where WebCodecs decodes it; otherwise the reason is shown and the Hello
// asks for JPEG.
async function chooseEncoding(name) {
  page.encoding = name;
  $('encoding').value = name;
  if (name === 'h264' && !state.h264) state.h264 = await h264Support();
  const { note } = helloEncoding(name, state.h264);
  $('encoding-note').textContent = note;
  $('encoding-note').hidden = !note;
}

function onError(e) {
  const code = ErrorCode.valuesById[e.code] || `error code ${e.code}`;
  state.errors.push({ code, message: e.message, fatal: e.fatal });
  if (e.fatal) {
    lastFatal = { code, retry: RETRYABLE.has(code) };
    const next = lastFatal.retry ? 'The session was closed; the page reconnects.' : `The session was closed. ${advice(code)}`;
    showBanner(`server error ${code}: ${e.message}\n${next}`);
    return;
  }
  showBanner(`server error ${code}: ${e.message}`);
  // The change was refused and the session goes on as before: the controls
  // show what is in effect again.
  if (code === 'ERROR_CODE_UNKNOWN_SCENE' || code === 'ERROR_CODE_UNKNOWN_MATERIAL') {
    pendingScene = null;
    if (state.sceneInfo) onSceneInfo(state.sceneInfo, false);
  } else if (code === 'ERROR_CODE_BAD_SETTINGS') {
    showSettings(settingsBeforeChange || effective);
    settingsAfterChange = settingsBeforeChange;
  }
}

function advice(code) {
  switch (code) {
    case 'ERROR_CODE_UNAUTHORIZED': return 'Give the server\'s token as ?token=… in the address.';
    case 'ERROR_CODE_UNSUPPORTED_VERSION': return 'This page and the server speak different protocol versions: reload the page.';
    case 'ERROR_CODE_BAD_SETTINGS':
    case 'ERROR_CODE_BAD_RESOLUTION':
    case 'ERROR_CODE_UNKNOWN_SCENE':
    case 'ERROR_CODE_UNKNOWN_MATERIAL': return 'Change the page\'s parameters in the address and reload.';
    default: return 'Reload the page to try again.';
  }
}

// ---- controls -------------------------------------------------------------------

let settingsBeforeChange = null;
let exposureDirty = false;

function showSettings(s) {
  if (!s) return;
  if (s.method) selectValue($('method'), methodName(s.method));
  if (s.level) selectValue($('level'), s.level);
  if (s.lightCoefficients) selectValue($('coefficients'), s.lightCoefficients);
  if (s.exposureMode) {
    const fixed = s.exposureMode === ExposureMode.values.EXPOSURE_MODE_FIXED;
    $('exposure-auto').checked = !fixed;
    if (fixed) $('exposure').value = String(s.exposureStops || 0);
    choices.exposure = { auto: !fixed, stops: Number($('exposure').value) };
  }
  choices.method = $('method').value;
  choices.level = Number($('level').value);
  choices.k = Number($('coefficients').value);
}

function currentSettings() {
  return { method: methodValue($('method').value), level: Number($('level').value),
           lightCoefficients: Number($('coefficients').value), ...exposureSettings() };
}

// The controls' settings before the last change and after it: a change the
// server refuses (BAD_SETTINGS) puts the controls back as they were.
let settingsAfterChange = null;

function sendSettings(fields) {
  if (send({ settings: fields })) {
    settingsBeforeChange = settingsAfterChange;
    settingsAfterChange = currentSettings();
  }
}

function onSettingsControl() {
  choices.method = $('method').value;
  choices.level = Number($('level').value);
  choices.k = Number($('coefficients').value);
  const { method, level, lightCoefficients } = currentSettings();
  sendSettings({ method, level, lightCoefficients });
  poseDirty = true;
}

function chooseScene(name) {
  if (state.sceneInfo && name === state.sceneInfo.name) return;
  choices.scene = name;
  pendingScene = name;
  // Poses sent before the answer would move the new scene with the old
  // scene's camera: none carry a view until SceneInfo comes.
  touched.camera = false;
  touched.light = false;
  touched.objects.clear();
  send({ scene: { scene: name } });
}

function chooseMaterial(index, spec) {
  if (!state.sceneInfo) return;
  send({ scene: { scene: state.sceneInfo.name, objectMaterials: { [index]: spec } } });
}

function showFrameExposure(stops, mode) {
  $('exposure-value').textContent = `${formatStops(stops)} stops (${mode})`;
  // In auto mode the slider follows the frames, so that leaving auto starts
  // from the exposure on the screen.
  if ($('exposure-auto').checked && !exposureDragging && Number.isFinite(stops)) $('exposure').value = String(stops);
}

let exposureDragging = false;
$('exposure').addEventListener('pointerdown', () => { exposureDragging = true; });
// The release may land outside the slider: any pointerup ends the drag.
window.addEventListener('pointerup', () => { exposureDragging = false; });
$('exposure').addEventListener('change', () => { exposureDragging = false; });
$('exposure').addEventListener('input', () => {
  $('exposure-auto').checked = false;
  choices.exposure = { auto: false, stops: Number($('exposure').value) };
  $('exposure-value').textContent = `${formatStops(choices.exposure.stops)} stops (fixed)`;
  exposureDirty = true;  // sent by tick(): at most one per display frame
});
$('exposure-auto').addEventListener('change', () => {
  choices.exposure = { auto: $('exposure-auto').checked, stops: Number($('exposure').value) };
  exposureDirty = true;
});
for (const id of ['method', 'level', 'coefficients']) $(id).addEventListener('change', onSettingsControl);
$('scene').addEventListener('change', () => chooseScene($('scene').value));
$('reset-view').addEventListener('click', () => {
  if (!state.sceneInfo) return;
  resetView();
  touched.camera = true;  // say it: the server's camera may be a dragged one
  touched.light = true;
  poseDirty = true;
});
$('reconnect').addEventListener('click', () => connect());
// The encoding is a Hello field: another one takes a new session. The address
// keeps the choice, so a reload asks for it again.
$('encoding').addEventListener('change', async () => {
  await chooseEncoding($('encoding').value);
  const params = new URLSearchParams(location.search);
  params.set('encoding', page.encoding);
  history.replaceState(null, '', `?${params}`);
  const old = ws;
  connect();
  if (old) old.close();
});
$('banner-close').addEventListener('click', () => { $('banner').hidden = true; });

// ---- status, errors, HUD ------------------------------------------------------------

function setStatus(text, isError = false) {
  $('status').textContent = text;
  $('status').classList.toggle('error', isError);
}

function showBanner(text) {
  $('banner-text').textContent = text;
  $('banner').hidden = false;
}

const frameWindow = new FrameWindow();

function updateHud() {
  const s = frameWindow.summary(performance.now());
  $('hud-fps').textContent = formatNumber(s.fps);
  $('hud-latency').textContent = formatNumber(s.latencyMs);
  $('hud-kbps').textContent = formatNumber(s.kbps);
  $('hud-frame-ms').textContent = formatNumber(s.serverMs);
  $('hud-method').textContent = (state.lastFrame && state.lastFrame.method) || '—';
  $('hud-exposure').textContent = state.lastFrame
    ? `${formatStops(state.lastFrame.exposureStops)} stops ${state.lastFrame.exposureMode}` : '—';
  $('hud-stages').textContent = s.stages.length
    ? s.stages.map((x) => `${x.name} ${formatNumber(x.ms)}`).join(' · ') + ' ms' : '—';
  $('hud').classList.toggle('idle', s.idle);
  $('hud').title = [
    `over the last ${s.frames} frame(s)${s.idle ? '; no frames lately (the server sends one when something changes)' : ''}`,
    'frame: the server\'s time from pose to frame queued; stages: the renderer\'s and the encoder\'s',
    serverStats ? `server: ${serverStats.fps.toFixed(1)} fps, ${serverStats.sessions} session(s)` : '',
  ].filter(Boolean).join('\n');
  state.hudUpdates++;
  showReconnectCountdown();
}

// ---- layout: the canvas keeps the frame's aspect ratio ---------------------------

const stage = $('stage');

function setFrameSize(width, height) {
  if (canvas.width === width && canvas.height === height) return;
  canvas.width = width;
  canvas.height = height;
  document.documentElement.style.setProperty('--frame-aspect', String(height / width));
  fitCanvas();
}

// The largest box with the frame's aspect ratio inside #stage.
function fitCanvas() {
  const cs = getComputedStyle(stage);
  const w = stage.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight);
  const h = stage.clientHeight - parseFloat(cs.paddingTop) - parseFloat(cs.paddingBottom);
  if (!(w > 0 && h > 0)) return;
  const aspect = canvas.height / canvas.width;
  const width = Math.min(w, h / aspect);
  canvas.style.width = `${Math.floor(width)}px`;
  canvas.style.height = `${Math.floor(width * aspect)}px`;
}
new ResizeObserver(fitCanvas).observe(stage);

let fullWindow = false;
function setFullWindow(on) {
  fullWindow = on;
  $('app').classList.toggle('fullwindow', on);
  $('fullwindow').setAttribute('aria-pressed', String(on));
  // The Fullscreen API where the browser allows it; the CSS mode alone otherwise.
  if (on && document.documentElement.requestFullscreen && !document.fullscreenElement) {
    document.documentElement.requestFullscreen().catch(() => {});
  } else if (!on && document.fullscreenElement) {
    document.exitFullscreen().catch(() => {});
  }
}
$('fullwindow').addEventListener('click', () => setFullWindow(!fullWindow));
document.addEventListener('fullscreenchange', () => { if (!document.fullscreenElement && fullWindow) setFullWindow(false); });
document.addEventListener('keydown', (e) => {
  if (e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement) return;
  if (e.key === 'f' && !e.ctrlKey && !e.metaKey && !e.altKey) setFullWindow(!fullWindow);
  else if (e.key === 'Escape' && fullWindow) setFullWindow(false);
});

// ---- input ------------------------------------------------------------------------

let drag = null;

function dragTarget(e) {
  const chosen = (document.querySelector('#drag-target input:checked') || {}).value || 'camera';
  if (e.altKey) return 'light';
  if (e.shiftKey) return chosen.startsWith('object:') ? chosen : 'object:0';
  return chosen;
}

canvas.addEventListener('pointerdown', (e) => {
  drag = { x: e.clientX, y: e.clientY };
  canvas.setPointerCapture(e.pointerId);
  canvas.classList.add('dragging');
  e.preventDefault();
});

canvas.addEventListener('pointermove', (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x;
  const dy = e.clientY - drag.y;
  drag = { x: e.clientX, y: e.clientY };
  if (!state.sceneInfo || pendingScene !== null) return;  // no view to move yet
  // Half a degree per CSS pixel: a drag across the canvas is a half turn or so.
  const target = dragTarget(e);
  if (target === 'light') {
    lightY += dx * 0.5;
    touched.light = true;
  } else if (target.startsWith('object:')) {
    const index = Number(target.slice(7));
    if (!state.sceneInfo.objects.some((o) => o.index === index)) return;
    const r = objectRotation.get(index) || scenePoseOf(index);
    r.y += dx * 0.5;
    r.x += dy * 0.5;
    objectRotation.set(index, r);
    touched.objects.add(index);
  } else {
    orbit.azimuth -= dx * 0.5 * Math.PI / 180;
    const limit = 89 * Math.PI / 180;  // never along the pole: the up vector would be parallel
    orbit.elevation = Math.max(-limit, Math.min(limit, orbit.elevation + dy * 0.5 * Math.PI / 180));
    touched.camera = true;
  }
  poseDirty = true;
});

const endDrag = (e) => {
  if (!drag) return;
  drag = null;
  canvas.classList.remove('dragging');
  if (canvas.hasPointerCapture(e.pointerId)) canvas.releasePointerCapture(e.pointerId);
};
canvas.addEventListener('pointerup', endDrag);
canvas.addEventListener('pointercancel', endDrag);
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  if (!state.sceneInfo || pendingScene !== null) return;
  const d = orbit.startDistance;
  orbit.distance = Math.max(0.2 * d, Math.min(10 * d, orbit.distance * Math.exp(e.deltaY * 0.001)));
  touched.camera = true;
  poseDirty = true;
}, { passive: false });

function sendPose() {
  const pose = { sequence: ++poseSequence, clientTimeMs: performance.now() };
  if (touched.camera) {
    pose.camera = { eye: orbitEye(), target: orbit.target, up: orbit.up, fovYDegrees: orbit.fov };
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

// At most one pose and one exposure change per display frame: pointer and
// slider events come faster than that, and the server keeps only the latest.
function tick() {
  if (state.connection === 'ready') {
    if (exposureDirty) {
      exposureDirty = false;
      sendSettings(exposureSettings());
    }
    if (poseDirty) {
      poseDirty = false;
      sendPose();
    }
  }
  requestAnimationFrame(tick);
}

// ---- start ------------------------------------------------------------------------

async function main() {
  if (typeof protobuf === 'undefined') {
    throw new Error('protobufjs did not load (vendor/protobuf.min.js): run `npm ci` in client/web');
  }
  const root = await protobuf.load('/haarcast.proto');
  ClientMessage = root.lookupType('haarcast.v1.ClientMessage');
  ServerMessage = root.lookupType('haarcast.v1.ServerMessage');
  Encoding = root.lookupEnum('haarcast.v1.Encoding');
  RotationMethod = root.lookupEnum('haarcast.v1.RotationMethod');
  ErrorCode = root.lookupEnum('haarcast.v1.ErrorCode');
  ExposureMode = root.lookupEnum('haarcast.v1.ExposureMode');
  methodNames = Object.keys(RotationMethod.values)
    .filter((n) => n !== 'ROTATION_METHOD_UNSPECIFIED')
    .map((n) => n.replace('ROTATION_METHOD_', '').toLowerCase());

  // The page's parameters first: a bad one is reported and nothing connects.
  page = parsePageParameters(location.search, { methods: methodNames });
  if (page.errors.length) {
    for (const e of page.errors) state.errors.push({ code: 'PAGE_PARAMETER', message: e.message, fatal: true });
    showBanner(`${page.errors.map((e) => e.message).join('\n')}\nFix the address and reload.`);
    stop('not connected: a page parameter is not valid');
    $('reconnect').hidden = true;
    return;
  }
  Object.assign(choices, { scene: page.scene, method: page.method, level: page.level, k: page.k,
                           exposure: page.exposure });
  if (!page.exposure.auto) {
    $('exposure-auto').checked = false;
    $('exposure').value = String(page.exposure.stops);
  }
  await chooseEncoding(page.encoding);
  connect();
  setInterval(updateHud, 250);
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
