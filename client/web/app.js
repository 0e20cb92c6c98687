// The haarcast browser client: one page, one WebSocket, one protobuf message
// per binary WebSocket message. The schema is fetched from the server
// (GET /haarcast.proto), so the wire contract has one definition.
//
//   drag          orbit the camera about the target
//   shift-drag    rotate object 0
//   alt-drag      rotate the light (the environment) about +Y
//
// Page parameters: ?size=256x256&encoding=jpeg|png|raw&token=T&fps=30
//                  &method=fused&level=5&k=64 (the initial settings)
/* global protobuf */

const params = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);
const canvas = $('frame');
const ctx = canvas.getContext('2d');

// Exposed for the end-to-end test and for curious users (devtools).
const state = {
  welcome: null,
  framesReceived: 0,
  framesShown: 0,
  lastShownSequence: 0,
  lastFrame: null,     // {sequence, poseSequence, width, height, encoding, method, bytes}
  posesSent: 0,
  errors: [],
  closed: null,        // {code, reason} once the socket closed
  hudUpdates: 0,
};
window.haarcast = state;

// ---- pose state -------------------------------------------------------------

// The built-in default scene's camera: eye (0, 0.6, 3.4) looking at the
// origin. The first pose carries no camera, so the server shows its own view
// until the first drag.
const camera = { azimuth: 0, elevation: Math.atan2(0.6, 3.4), distance: Math.hypot(0.6, 3.4), fov: 35 };
const object0 = { x: 0, y: 0 };  // degrees, R = Rz Ry Rx
let lightY = 0;                  // degrees about world +Y
const touched = { camera: false, object: false, light: false };
let poseSequence = 0;
let poseDirty = true;

function eye() {
  // The shared convention: azimuth from +Z toward +X, +Y up.
  const c = Math.cos(camera.elevation);
  return {
    x: camera.distance * c * Math.sin(camera.azimuth),
    y: camera.distance * Math.sin(camera.elevation),
    z: camera.distance * c * Math.cos(camera.azimuth),
  };
}

// ---- protocol ---------------------------------------------------------------

let ClientMessage, ServerMessage, Encoding, RotationMethod, ErrorCode;
let ws = null;

function encodingFromParam(name) {
  const e = { jpeg: 'ENCODING_JPEG', png: 'ENCODING_PNG', raw: 'ENCODING_RAW_RGBA8' }[name || 'jpeg'];
  if (!e) throw new Error(`?encoding must be jpeg, png or raw (got "${name}")`);
  return Encoding.values[e];
}

function sizeFromParam(text) {
  const m = /^(\d+)x(\d+)$/.exec(text || '256x256');
  if (!m) throw new Error(`?size must be WIDTHxHEIGHT (got "${text}")`);
  return { width: Number(m[1]), height: Number(m[2]) };
}

// Initial settings from the page's parameters; 0 / unspecified = the server's.
function settingsFromParams() {
  const method = params.get('method');
  const value = method ? RotationMethod.values[`ROTATION_METHOD_${method.toUpperCase()}`] : 0;
  if (value === undefined) throw new Error(`?method must be fused, haar, spatial, matrix or table (got "${method}")`);
  return { method: value, level: Number(params.get('level') || 0), lightCoefficients: Number(params.get('k') || 0) };
}

function methodName(value) {
  const name = RotationMethod.valuesById[value] || '';
  return name.replace('ROTATION_METHOD_', '').toLowerCase() || '–';
}

function send(body) {
  if (!ws || ws.readyState !== WebSocket.OPEN) return;
  const message = ClientMessage.create(body);
  ws.send(ClientMessage.encode(message).finish());
}

function sendPose() {
  const pose = { sequence: ++poseSequence, clientTimeMs: performance.now() };
  if (touched.camera) {
    pose.camera = { eye: eye(), target: { x: 0, y: 0, z: 0 }, up: { x: 0, y: 1, z: 0 }, fovYDegrees: camera.fov };
  }
  if (touched.object) pose.objects = [{ object: 0, rotateDegrees: { x: object0.x, y: object0.y, z: 0 } }];
  if (touched.light) pose.lightRotateDegrees = { x: 0, y: lightY, z: 0 };
  send({ pose });
  state.posesSent++;
}

function sendSettings() {
  const method = RotationMethod.values[`ROTATION_METHOD_${$('method').value.toUpperCase()}`];
  send({ settings: { method, level: Number($('level').value), lightCoefficients: Number($('coefficients').value) } });
  poseDirty = true;  // a fresh frame with the new settings
}

function sendMaterial() {
  const object = Number($('object').value);
  send({ scene: { scene: '', objectMaterials: { [object]: $('material').value } } });
  poseDirty = true;
}

function setStatus(text, isError = false) {
  $('status').textContent = text;
  $('status').classList.toggle('error', isError);
}

function selectValue(select, value) {
  const v = String(value);
  if (![...select.options].some((o) => o.value === v)) select.add(new Option(v, v));
  select.value = v;
}

function onWelcome(w) {
  state.welcome = w;
  canvas.width = w.width;
  canvas.height = w.height;
  const s = w.settings || {};
  if (s.method) $('method').value = methodName(s.method);
  if (s.level) selectValue($('level'), s.level);
  if (s.lightCoefficients) selectValue($('coefficients'), s.lightCoefficients);
  const objects = $('object');
  objects.replaceChildren();
  for (let i = 0; i < Math.max(1, w.objectCount); i++) objects.add(new Option(String(i), String(i)));
  const materials = $('material');
  materials.replaceChildren();
  for (const m of w.materials) materials.add(new Option(m, m));
  setStatus(`connected: ${w.device || 'renderer'}, ${w.width}×${w.height}, session ${w.sessionId}`);
  poseDirty = true;
}

// Frames are decoded asynchronously and may finish out of order; only a
// frame newer than the one on the canvas is drawn.
async function onFrame(f) {
  state.framesReceived++;
  const received = performance.now();
  const bytes = f.data.byteLength;
  history.push({ t: received, bytes, latency: f.clientTimeMs > 0 ? received - f.clientTimeMs : NaN });
  // The method the server says it rendered with (null if it did not say).
  const method = f.settings && f.settings.method ? methodName(f.settings.method) : null;
  const shown = () => {
    if (f.sequence <= state.lastShownSequence) return;
    state.lastShownSequence = f.sequence;
    state.framesShown++;
    state.lastFrame = { sequence: f.sequence, poseSequence: f.poseSequence, width: f.width, height: f.height,
                        encoding: f.encoding, method, bytes };
    hudMethod = method || $('method').value;
  };
  if (canvas.width !== f.width || canvas.height !== f.height) {
    canvas.width = f.width;
    canvas.height = f.height;
  }
  if (f.encoding === Encoding.values.ENCODING_RAW_RGBA8) {
    if (bytes !== f.width * f.height * 4) throw new Error(`raw frame of ${bytes} bytes for ${f.width}×${f.height}`);
    // A copy: ImageData needs its own buffer, f.data views the message.
    const image = new ImageData(new Uint8ClampedArray(f.data), f.width, f.height);
    if (f.sequence > state.lastShownSequence) ctx.putImageData(image, 0, 0);
    shown();
  } else if (f.encoding === Encoding.values.ENCODING_JPEG || f.encoding === Encoding.values.ENCODING_PNG) {
    const type = f.encoding === Encoding.values.ENCODING_JPEG ? 'image/jpeg' : 'image/png';
    const bitmap = await createImageBitmap(new Blob([f.data], { type }));
    if (f.sequence > state.lastShownSequence) ctx.drawImage(bitmap, 0, 0);
    bitmap.close();
    shown();
  } else {
    setStatus(`cannot show ${Encoding.valuesById[f.encoding]} frames in the browser; use jpeg, png or raw`, true);
  }
}

function onError(e) {
  const code = ErrorCode.valuesById[e.code] || e.code;
  state.errors.push({ code, message: e.message, fatal: e.fatal });
  setStatus(`server error ${code}: ${e.message}${e.fatal ? ' (session closed)' : ''}`, true);
}

let serverStats = null;

function connect() {
  const size = sizeFromParam(params.get('size'));
  const token = params.get('token') || '';
  const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
  // The token rides in the query: browsers cannot set headers on a WebSocket.
  const url = `${scheme}//${location.host}/ws${token ? `?token=${encodeURIComponent(token)}` : ''}`;
  ws = new WebSocket(url);
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => {
    setStatus('connected, waiting for Welcome…');
    send({ hello: { protocolVersion: 1, authToken: token, width: size.width, height: size.height,
                    encoding: encodingFromParam(params.get('encoding')), fpsCap: Number(params.get('fps') || 0),
                    clientName: 'browser', settings: settingsFromParams() } });
  };
  ws.onmessage = (event) => {
    let m;
    try {
      m = ServerMessage.decode(new Uint8Array(event.data));
    } catch (err) {
      setStatus(`bad message from the server: ${err.message}`, true);
      return;
    }
    if (m.welcome) onWelcome(m.welcome);
    else if (m.frame) onFrame(m.frame).catch((err) => setStatus(`frame ${m.frame.sequence}: ${err.message}`, true));
    else if (m.stats) serverStats = m.stats;
    else if (m.error) onError(m.error);
  };
  ws.onclose = (event) => {
    state.closed = { code: event.code, reason: event.reason };
    if (!state.errors.some((e) => e.fatal)) {
      setStatus(`disconnected (code ${event.code}${event.reason ? `: ${event.reason}` : ''}); reload to reconnect`, true);
    }
  };
}

// ---- HUD ----------------------------------------------------------------------

// The last second of frames: fps, kbit/s and mean latency over it.
const history = [];
let hudMethod = '–';

function updateHud() {
  const now = performance.now();
  while (history.length && history[0].t < now - 1000) history.shift();
  const latencies = history.map((h) => h.latency).filter((l) => Number.isFinite(l));
  const mean = latencies.length ? latencies.reduce((a, b) => a + b, 0) / latencies.length : NaN;
  $('hud-fps').textContent = history.length.toFixed(0);
  $('hud-latency').textContent = Number.isFinite(mean) ? mean.toFixed(0) : '–';
  $('hud-kbps').textContent = (history.reduce((a, h) => a + h.bytes, 0) * 8 / 1000).toFixed(0);
  $('hud-method').textContent = hudMethod;
  if (serverStats) $('hud').title = `server: ${serverStats.fps.toFixed(1)} fps, ${serverStats.sessions} sessions`;
  state.hudUpdates++;
}

// ---- input --------------------------------------------------------------------

let drag = null;

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
  // Half a degree per CSS pixel: a drag across the canvas is a half turn or so.
  if (e.altKey) {
    lightY += dx * 0.5;
    touched.light = true;
  } else if (e.shiftKey) {
    object0.y += dx * 0.5;
    object0.x += dy * 0.5;
    touched.object = true;
  } else {
    camera.azimuth -= dx * 0.5 * Math.PI / 180;
    const limit = 89 * Math.PI / 180;  // never straight up: the up vector would be parallel
    camera.elevation = Math.max(-limit, Math.min(limit, camera.elevation + dy * 0.5 * Math.PI / 180));
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
  camera.distance = Math.max(0.5, Math.min(20, camera.distance * Math.exp(e.deltaY * 0.001)));
  touched.camera = true;
  poseDirty = true;
  e.preventDefault();
}, { passive: false });

for (const id of ['method', 'level', 'coefficients']) $(id).addEventListener('change', sendSettings);
$('material').addEventListener('change', sendMaterial);

// At most one pose per display frame: pointer events come faster than that,
// and the server keeps only the latest anyway.
function tick() {
  if (poseDirty && state.welcome && ws.readyState === WebSocket.OPEN) {
    poseDirty = false;
    sendPose();
  }
  requestAnimationFrame(tick);
}

// ---- start --------------------------------------------------------------------

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
  connect();
  setInterval(updateHud, 250);
  // The server closes sessions that send nothing for a while; a page left
  // alone (no drags) pings to stay connected.
  let nonce = 0;
  setInterval(() => send({ ping: { nonce: ++nonce } }), 15000);
  requestAnimationFrame(tick);
}

main().catch((err) => setStatus(err.message, true));
