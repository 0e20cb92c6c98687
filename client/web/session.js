// The page's session with the server: one WebSocket, one protobuf message per
// binary WebSocket message. A session that drops is opened again on its own,
// with back-off and a countdown on the page, and its Hello asks again for
// what the user chose; a session the server will not take back (a bad token,
// another protocol version) stops, saying why.
import { backoffMs } from './frame_stats.js';
import { helloEncoding } from './h264_view.js';
import { choices, exposureSettings, page, state, toneSettings } from './page_state.js';
import { helloSize } from './resolution.js';
import { ClientMessage, Encoding, ErrorCode, ServerMessage, methodValue } from './schema.js';
import { endWaiting, showWaiting } from './frame_progress_view.js';
import { setStatus, showBanner } from './status.js';

const $ = (id) => document.getElementById(id);

let ws = null;
// One per socket: late decodes of an old one are dropped.
export let generation = 0;
let lastFatal = null;      // {code, retry} of the fatal Error that closes this socket
let reconnectTimer = null;
let reconnectAt = 0;
let reconnectWhy = '';

// What the page does with the server's messages:
// {welcome(w), frame(f, generation) → Promise, sceneInfo(info), stats(s), refused(code),
//  buildProgress(p), frameProgress(p)}; refused: a non-fatal Error, the change it answers was not made.
let handlers = null;
export function onServerMessages(h) {
  handlers = h;
}

// Fatal errors worth another try: the server timed us out, restarted, or was full.
const RETRYABLE = new Set(['ERROR_CODE_TIMEOUT', 'ERROR_CODE_SHUTTING_DOWN', 'ERROR_CODE_TOO_MANY_SESSIONS']);

export function send(body) {
  if (!ws || ws.readyState !== WebSocket.OPEN) return false;
  ws.send(ClientMessage.encode(ClientMessage.create(body)).finish());
  return true;
}

function socketUrl() {
  const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
  // The token rides in the query: browsers cannot set headers on a WebSocket.
  return `${scheme}//${location.host}/ws${page.token ? `?token=${encodeURIComponent(page.token)}` : ''}`;
}

function hello() {
  state.helloEncoding = helloEncoding(page.encoding, state.h264).encoding;
  const encoding = { jpeg: 'ENCODING_JPEG', png: 'ENCODING_PNG', raw: 'ENCODING_RAW_RGBA8', h264: 'ENCODING_H264' }[
    state.helloEncoding];
  const size = helloSize();
  const h = {
    protocolVersion: 1, authToken: page.token, width: size.width, height: size.height,
    encoding: Encoding.values[encoding], fpsCap: page.fps, jpegQuality: page.quality, clientName: 'browser',
    settings: { method: methodValue(choices.method), level: choices.level, lightCoefficients: choices.k,
                ...exposureSettings(), ...toneSettings() },
  };
  if (choices.scene) {
    h.scene = { scene: choices.scene, objectMaterials: {} };
    // After a reconnect: the materials in effect, where the server offers them.
    const info = state.sceneInfo;
    if (info && info.name === choices.scene && state.welcome) {
      // The probe and mesh in effect too (SceneChoice says the whole choice).
      Object.assign(h.scene, { probe: info.probe || '', mesh: info.mesh || '', up: info.mesh ? info.up || '' : '' });
      for (const o of info.objects) {
        if (state.welcome.materials.includes(o.material)) h.scene.objectMaterials[o.index] = o.material;
      }
    } else if (!state.welcome && choices.scene === page.scene) {
      // The first Hello: the probe, mesh and materials the address names (share_url.js).
      Object.assign(h.scene, { probe: page.probe, mesh: page.mesh, up: page.up });
      for (const m of page.materials) h.scene.objectMaterials[m.index] = m.spec;
    }
  }
  return h;
}

export function connect() {
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
  showWaiting('connecting to the server', state.reconnectAttempt ? `attempt ${state.reconnectAttempt + 1}` : '');
  socket.binaryType = 'arraybuffer';
  socket.onopen = () => {
    opened = true;
    state.connection = 'waiting-welcome';
    setStatus('connected; waiting for Welcome (the server prepares the scene: seconds the first time)…');
    send({ hello: hello() });
    showWaiting('waiting for the server', 'it prepares the scene', 'seconds the first time; progress shows once it starts');
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
    if (m.welcome) handlers.welcome(m.welcome);
    else if (m.frame) handlers.frame(m.frame, gen).catch((err) => showBanner(`frame ${m.frame.sequence}: ${err.message}`));
    else if (m.sceneInfo) handlers.sceneInfo(m.sceneInfo);
    else if (m.stats) handlers.stats(m.stats);
    else if (m.error) onError(m.error);
    else if (m.buildProgress) handlers.buildProgress(m.buildProgress);
    else if (m.frameProgress) handlers.frameProgress(m.frameProgress);
    // Pong needs no answer. Any other message type a newer server adds
    // decodes to none of the above and is ignored too.
    else if (m.pong) { /* nothing to do */ }
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

// A new session in place of this one: what only a Hello says (the encoding)
// changed.
export function restartSession() {
  const old = ws;
  connect();
  if (old) old.close();
}

export function stop(text) {
  state.connection = 'stopped';
  state.reconnectInS = null;
  endWaiting();  // nothing is coming: the status line and the banner say why
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
  showWaiting('not connected', why, `the page reconnects on its own (attempt ${state.reconnectAttempt})`);
  $('reconnect').textContent = 'reconnect now';
  $('reconnect').hidden = false;
  showReconnectCountdown();
}

export function showReconnectCountdown() {
  if (state.connection !== 'reconnect-wait') return;
  const s = Math.max(0, Math.ceil((reconnectAt - performance.now()) / 1000));
  state.reconnectInS = s;
  setStatus(`${reconnectWhy}; reconnecting in ${s} s (attempt ${state.reconnectAttempt})`, true);
}

function onError(e) {
  const code = ErrorCode.valuesById[e.code] || `error code ${e.code}`;
  state.errors.push({ code, message: e.message, fatal: e.fatal });
  if (e.fatal) {
    lastFatal = { code, retry: RETRYABLE.has(code) };
    if (code === 'ERROR_CODE_BAD_RESOLUTION' && !(page.width > 0) && !state.sizeFallback) {
      // The size that fits the view is over this server's limits, which the
      // page learns only from a Welcome: once more at the server's default
      // size, then within the limits its Welcome gives.
      state.sizeFallback = true;
      lastFatal.retry = true;
    }
    const next = lastFatal.retry ? 'The session was closed; the page reconnects.' : `The session was closed. ${advice(code)}`;
    showBanner(`server error ${code}: ${e.message}\n${next}`);
    return;
  }
  showBanner(`server error ${code}: ${e.message}`);
  handlers.refused(code);
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

$('reconnect').addEventListener('click', () => connect());
