// The frame size the page asks for: one that fits the view (the resolution
// control's "auto", the default), a fixed number of lines (360p … 1080p), or
// the address's ?size=. The size is asked for in the Hello and again, as
// RenderSettings.width/height, after the view is resized (debounced), when
// a move starts or auto steps the size down or up while it goes on, and once
// the view is still again (stream_size.js has the sizes and the rule,
// docs/clients.md says them).
import { MOVE_EVENT, choices, page, state } from './page_state.js';
import { send } from './session.js';
import { AutoResolution, FIRST_LIMITS, STILL_MS, autoSteps, fpsFloor, frameSize } from './stream_size.js';
import { noteChange } from './view.js';

const $ = (id) => document.getElementById(id);
const stage = $('stage');

// A resize is asked for once the view has kept its size this long.
export const RESIZE_DEBOUNCE_MS = 300;

export const auto = new AutoResolution();

// The box the frame is shown in: #stage less its padding, in CSS pixels,
// and the device pixels per CSS pixel.
function viewBox() {
  const cs = getComputedStyle(stage);
  return {
    cssWidth: Math.max(1, stage.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight)),
    cssHeight: Math.max(1, stage.clientHeight - parseFloat(cs.paddingTop) - parseFloat(cs.paddingBottom)),
    dpr: window.devicePixelRatio || 1,
  };
}

// The server's limits once a Welcome said them; before, the protocol's
// defaults with a modest pixel count (stream_size.js FIRST_LIMITS).
const limits = () => (state.welcome && state.welcome.limits) || FIRST_LIMITS;

const fixedByAddress = () => page.width > 0 && page.height > 0;

// The size to ask for now.
export function wantedSize() {
  if (fixedByAddress()) return { width: page.width, height: page.height };
  const cap = choices.resolution === 'auto' ? auto.wantedCap() : Infinity;
  return frameSize(choices.resolution, viewBox(), limits(), cap);
}

function asked(size) {
  state.requestedSize = size;
  auto.asked(size.width * size.height, performance.now());
}

// The Hello's size. After a BAD_RESOLUTION the server gave for a size that
// fits the view (its limits are below the page's first guess), 0×0: the
// server's own default size, and the page asks again within the limits its
// Welcome gives.
export function helloSize() {
  if (state.sizeFallback && !fixedByAddress()) {
    state.requestedSize = null;
    return { width: 0, height: 0 };
  }
  const size = wantedSize();
  asked(size);
  return size;
}

// The size a Welcome granted (the Hello's, or the server's default).
export function granted(width, height) {
  asked({ width, height });
}

// Ask for the size that fits now, when it is not the one asked for.
export function refit() {
  if (state.connection !== 'ready') return;
  const size = wantedSize();
  const r = state.requestedSize;
  if (r && r.width === size.width && r.height === size.height) return;
  if (send({ settings: { width: size.width, height: size.height } })) {
    asked(size);
    state.resizes++;
    noteChange();  // a pose follows: the frame at the new size answers it
  }
}

let debounce = null;
function viewChanged() {
  clearTimeout(debounce);
  debounce = setTimeout(refit, RESIZE_DEBOUNCE_MS);
}
new ResizeObserver(viewChanged).observe(stage);
window.addEventListener('resize', viewChanged);  // devicePixelRatio changes with the browser's zoom

// Auto's steps for the view as it is now: [{lines, pixels}] from its own size down.
function stepsNow() {
  const view = viewBox();
  return autoSteps(view.cssHeight * view.dpr).map((lines) => {
    const s = frameSize('auto', view, limits(), lines);
    return { lines, pixels: s.width * s.height };
  });
}

const autoActive = () => choices.resolution === 'auto' && !fixedByAddress() && state.welcome !== null;

// Moving and still (stream_size.js AutoResolution): the first move picks
// its step from the last frame and asks for it before its pose leaves (the
// pose goes at the next display frame); each move restarts the timer, and
// STILL_MS after the last one the view's own size is asked for, whatever
// else changed meanwhile (the steps are for moves only).
let stillTimer = null;
window.addEventListener(MOVE_EVENT, () => {
  clearTimeout(stillTimer);
  if (autoActive() && auto.moved(performance.now(), stepsNow(), fpsFloor(state.welcome.fpsCap))) {
    state.autoSteps++;
    refit();
  }
  stillTimer = setTimeout(() => {
    if (auto.still() && autoActive()) refit();
  }, STILL_MS);
});

// Each frame's size and server time, for auto's rule.
export function frameTiming(width, height, serverMs) {
  if (!autoActive()) return;
  if (auto.frame(performance.now(), { pixels: width * height, serverMs }, stepsNow(), fpsFloor(state.welcome.fpsCap)) !== null) {
    state.autoSteps++;
    refit();
  }
}

const pixelsOf = (size) => (size ? size.width * size.height : 0);

// Auto asked for a still view's own size and the canvas still shows a smaller frame.
export function autoSharpening() {
  return autoActive() && !auto.moving && pixelsOf(state.lastFrame) < pixelsOf(state.requestedSize);
}

// What the HUD says of the size: "?size=", "720p", or what auto is doing
// ("auto ≤180p (moving)", "auto: sharpening…", "auto: full size (still)").
export function resolutionLabel() {
  if (fixedByAddress()) return '?size=';
  return choices.resolution === 'auto' ? auto.label(pixelsOf(state.lastFrame), pixelsOf(state.requestedSize))
    : choices.resolution;
}

// The control, from the address: ?size= shows as its own choice.
export function showResolutionChoice() {
  const select = $('resolution');
  if (fixedByAddress()) {
    const fixed = new Option(`${page.width}×${page.height} (?size=)`, 'fixed');
    select.add(fixed, 0);
    select.value = 'fixed';
  } else {
    select.value = choices.resolution;
  }
  $('app').classList.toggle('fit', !fixedByAddress());
}

$('resolution').addEventListener('change', () => {
  const value = $('resolution').value;
  if (value === 'fixed') return;
  // The address's ?size= no longer holds; ?resolution= keeps the choice.
  page.width = page.height = 0;
  const fixed = [...$('resolution').options].find((o) => o.value === 'fixed');
  if (fixed) fixed.remove();
  choices.resolution = value;
  auto.capLines = Infinity;
  const params = new URLSearchParams(location.search);
  params.delete('size');
  if (value === 'auto') params.delete('resolution');
  else params.set('resolution', value);
  history.replaceState(null, '', params.toString() ? `?${params}` : location.pathname);
  $('app').classList.add('fit');
  refit();
});
