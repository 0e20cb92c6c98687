// The canvas on the page: it keeps the frame's aspect ratio at any window
// size, so a frame is never stretched, and it can take the whole window
// (f / Esc, or the button on the view) for a closer look.
import { onShortcut } from './shortcuts.js';

const $ = (id) => document.getElementById(id);

export const canvas = $('frame');
export const ctx = canvas.getContext('2d');
const stage = $('stage');

export function setFrameSize(width, height) {
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
onShortcut('f', () => setFullWindow(!fullWindow));
onShortcut('Escape', () => { if (fullWindow) setFullWindow(false); });
