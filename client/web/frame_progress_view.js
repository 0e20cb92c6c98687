// What the page says while it waits for a frame: from the first second to
// the first frame (the page loading, the connection, the server's answer,
// the first frame's progress), and over the old frame, dimmed, while a
// frame takes longer than half a second (the server's FrameProgress). A
// renderer build has its own overlay (build_view.js), which goes first.
// The words come from build_status.js.
import { buildShown } from './build_view.js';
import { describeFrame, formatSeconds } from './build_status.js';
import { state } from './page_state.js';

const $ = (id) => document.getElementById(id);

// A waiting step of the page's own (no server progress yet) counts its
// seconds on the page, so that the overlay is never still.
const waiting = { since: 0, detail: '', timer: null };

function show(title, stage, fraction, detail) {
  $('progress-title').textContent = title;
  $('progress-stage').textContent = stage;
  const bar = $('progress-bar');
  if (fraction === null) bar.removeAttribute('value');  // indeterminate
  else bar.value = fraction;
  $('progress-detail').textContent = detail;
  const hidden = buildShown();
  $('progress').hidden = hidden;
  // Dimmed only over a frame: before the first, the canvas is empty anyway.
  $('view').classList.toggle('rendering', !hidden && state.framesShown > 0);
  state.progress = { title, stage, fraction, detail, shown: !hidden };
  state.progressUpdates++;
}

function tickWaiting() {
  const seconds = (performance.now() - waiting.since) / 1000;
  const detail = [waiting.detail, `${formatSeconds(seconds)} so far`].filter(Boolean).join(' · ');
  show(state.progress ? state.progress.title : '', state.progress ? state.progress.stage : '', null, detail);
}

// A step of the page's own before its first frame: "connecting to the
// server", "waiting for the server", "rendering the first frame". Ignored
// once a frame has been shown (a reconnect has its own banner).
export function showWaiting(title, stage = '', detail = '') {
  if (state.framesShown > 0) return;
  clearInterval(waiting.timer);
  waiting.since = performance.now();
  waiting.detail = detail;
  show(title, stage, null, detail);
  waiting.timer = setInterval(tickWaiting, 250);
}

export function showFrameProgress(progress) {
  clearInterval(waiting.timer);
  waiting.timer = null;
  const d = describeFrame(progress);
  show(d.title, `${d.stage}: ${d.percent} %`, d.fraction, d.detail);
  state.frameProgress = { stage: progress.stage, fraction: d.fraction, elapsedSeconds: progress.elapsedSeconds };
  state.frameProgressMessages++;
}

// A frame is on the canvas: nothing to wait for.
export function endWaiting() {
  clearInterval(waiting.timer);
  waiting.timer = null;
  $('progress').hidden = true;
  $('view').classList.remove('rendering');
  if (state.progress) state.progress.shown = false;
}
