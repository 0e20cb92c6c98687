// The HUD over the view: how the session is doing (frame rate, latency,
// bandwidth, the server's frame time and its stages, the frame size), so
// that a slow frame can be told from a slow network; and, when no frame
// has come for a while, that the stream is idle and up to date (the server
// sends a frame only when something changes) with the last frame's age.
// Its details fold away (the button, or h) to one line; folded is the
// default on a window under 600 px wide, where the view is small. Its
// numbers come from frame_stats.js.
import { formatSeconds, idleText } from './build_status.js';
import { FrameWindow, formatNumber, formatStops } from './frame_stats.js';
import { state } from './page_state.js';
import { autoSharpening, resolutionLabel } from './resolution.js';
import { onShortcut } from './shortcuts.js';
import { showReconnectCountdown } from './session.js';

const $ = (id) => document.getElementById(id);

export const frameWindow = new FrameWindow();

// Narrower than this, the HUD starts folded.
export const HUD_FOLDED_BELOW_PX = 600;

let serverStats = null;
export function setServerStats(stats) {
  serverStats = stats;
}

export function setHudFolded(folded) {
  $('hud').classList.toggle('collapsed', folded);
  $('hud-toggle').setAttribute('aria-expanded', String(!folded));
  $('hud-toggle').textContent = folded ? '▸' : '▾';
  $('hud-toggle').title = folded ? 'more details (h)' : 'fewer details (h)';
  state.hudFolded = folded;
}
setHudFolded(window.innerWidth < HUD_FOLDED_BELOW_PX);
// The width's default follows the window (a phone turned, a window
// narrowed) until the user folds or unfolds it: then theirs holds.
let userChose = false;
const toggle = () => {
  userChose = true;
  setHudFolded(!state.hudFolded);
};
window.addEventListener('resize', () => {
  if (!userChose) setHudFolded(window.innerWidth < HUD_FOLDED_BELOW_PX);
});
$('hud-toggle').addEventListener('click', toggle);
onShortcut('h', toggle);

export function updateHud() {
  const s = frameWindow.summary(performance.now());
  // Idle: the last stretch's rates would be stale; say how old the frame is.
  const idle = s.idle && s.sinceLastMs !== null;
  $('hud-rates').hidden = idle;
  $('hud-idle').hidden = !idle;
  // Not "up to date" while auto waits for a still view's full-size frame.
  if (idle) {
    $('hud-idle').textContent = autoSharpening()
      ? `auto: sharpening… — last frame ${formatSeconds(Math.max(0, s.sinceLastMs) / 1000)} ago` : idleText(s.sinceLastMs);
  }
  $('hud-fps').textContent = formatNumber(s.fps);
  $('hud-latency').textContent = formatNumber(s.latencyMs);
  $('hud-kbps').textContent = formatNumber(s.kbps);
  $('hud-frame-ms').textContent = formatNumber(s.serverMs);
  const f = state.lastFrame;
  $('hud-size').textContent = f ? `${f.width}×${f.height} ${resolutionLabel()}` : '—';
  $('hud-method').textContent = (f && f.method) || '—';
  $('hud-exposure').textContent = f ? `${formatStops(f.exposureStops)} stops ${f.exposureMode}` : '—';
  // fused: the level each object is drawn at (SceneInfo.Object.level) and
  // what a pixel cost there, one plan per object: map directions summed (by
  // cells, fewer where the picture allows) and the share of pixels whose
  // sum came from their neighbours.
  const levels = ((state.sceneInfo && state.sceneInfo.objects) || []).map((o) => o.level).filter((l) => l > 0);
  const levelText = levels.length ? `level${levels.length > 1 ? 's' : ''} ${levels.join('/')} · ` : '';
  const smooth = f && f.smoothShare > 0 ? ` · ${Math.round(100 * f.smoothShare)} % from neighbours` : '';
  $('hud-directions').textContent = f && f.directions > 0 ? `${levelText}${formatNumber(f.directions)} directions/px${smooth}` : '';
  $('hud-stages').textContent = s.stages.length
    ? s.stages.map((x) => `${x.name} ${formatNumber(x.ms)}`).join(' · ') + ' ms' : '—';
  $('hud').classList.toggle('idle', s.idle);
  $('hud').title = [
    `over the last ${s.frames} frame(s)${s.idle ? '; no frames lately (the server sends one when something changes)' : ''}`,
    'frame: the server\'s time from the request (a pose, a change) to the frame queued, never a renderer build; ' +
      'stages: the renderer\'s and the encoder\'s',
    'size: auto is the view\'s own size once it has been still for a moment, a smaller one while it moves ' +
      'on a server too slow for a smooth drag',
    serverStats ? `server: ${serverStats.fps.toFixed(1)} fps, ${serverStats.sessions} session(s)` : '',
  ].filter(Boolean).join('\n');
  state.hudUpdates++;
  showReconnectCountdown();
}
