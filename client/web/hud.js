// The HUD over the view: how the session is doing (frame rate, latency,
// bandwidth, the server's frame time and its stages), so that a slow frame
// can be told from a slow network. Its numbers come from frame_stats.js.
import { FrameWindow, formatNumber, formatStops } from './frame_stats.js';
import { state } from './page_state.js';
import { showReconnectCountdown } from './session.js';

const $ = (id) => document.getElementById(id);

export const frameWindow = new FrameWindow();

let serverStats = null;
export function setServerStats(stats) {
  serverStats = stats;
}

export function updateHud() {
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
