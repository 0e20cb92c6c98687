// The frame size the page asks for, so that the stream fits its view: the
// view's size in device pixels (CSS pixels × devicePixelRatio) within the
// server's limits (Welcome.limits: max_width, max_height, max_pixels), or a
// fixed number of lines (360p … 1080p) with the view's aspect ratio. And the
// rule of "auto": step the size down while the server cannot render frames
// at the frame-rate floor, and back up when it can. Pure (no DOM, no clock),
// so that node tests it (tests/e2e/web_client_test.mjs).

// The choices of the resolution control (?resolution=).
export const RESOLUTIONS = ['auto', '360p', '540p', '720p', '1080p'];

// The sizes "auto" may step down to, by lines, below the view's own.
export const AUTO_STEPS = [1080, 720, 540, 360, 270, 180];

// Frames per second "auto" holds: below it dragging feels like a slide show.
// Never above 80 % of the session's frame-rate cap (a session capped at 10
// fps is not "too slow" at 10).
export const FPS_FLOOR = 15;
export function fpsFloor(fpsCap) {
  return fpsCap > 0 ? Math.min(FPS_FLOOR, 0.8 * fpsCap) : FPS_FLOOR;
}

// The limits assumed for the first Hello, before any Welcome said the
// server's: the protocol's defaults for the sides, and no more than
// 1280×720 pixels, so that a server with a smaller budget than its default
// is not asked for more than it allows at once (the page asks again after
// Welcome, within the limits it gives).
export const FIRST_LIMITS = { maxWidth: 2048, maxHeight: 2048, maxPixels: 1280 * 720 };

// A protobufjs uint64 (a Long, or a number) as a number.
const num = (v) => (v === null || v === undefined ? 0 : typeof v === 'number' ? v : typeof v.toNumber === 'function' ? v.toNumber() : Number(v));

// The server's limits that bound a frame size, from Welcome.limits; 0 or a
// missing field bounds nothing.
export function sizeLimits(limits) {
  const l = limits || {};
  return { maxWidth: num(l.maxWidth) || Infinity, maxHeight: num(l.maxHeight) || Infinity,
           maxPixels: num(l.maxPixels) || Infinity };
}

// The largest even size (H.264 takes only even ones) with `aspect` (width /
// height) and at most `lines` lines that the limits allow.
export function sizeWithin(aspect, lines, limits) {
  const l = sizeLimits(limits);
  const a = aspect > 0 && Number.isFinite(aspect) ? aspect : 1;
  let h = Math.max(2, lines);
  let w = h * a;
  const s = Math.min(1, l.maxWidth / w, l.maxHeight / h, Math.sqrt(l.maxPixels / (w * h)));
  w *= s;
  h *= s;
  return { width: Math.max(2, 2 * Math.floor(w / 2)), height: Math.max(2, 2 * Math.floor(h / 2)) };
}

// view: {cssWidth, cssHeight, dpr} of the box the frame is shown in.
// choice: 'auto' or '360p' … '1080p'. capLines: auto's current step (lines
// at most; Infinity = the view's own size).
export function frameSize(choice, view, limits, capLines = Infinity) {
  const dpr = view.dpr > 0 ? view.dpr : 1;
  const w = Math.max(1, view.cssWidth * dpr), h = Math.max(1, view.cssHeight * dpr);
  const lines = choice === 'auto' ? Math.min(Math.round(h), capLines) : Number.parseInt(choice, 10);
  return sizeWithin(w / h, lines, limits);
}

// Auto's steps for a view `viewLines` device pixels tall: the view's own
// size (Infinity), then each of AUTO_STEPS below it.
export function autoSteps(viewLines) {
  return [Infinity, ...AUTO_STEPS.filter((lines) => lines < viewLines)];
}

// The automatic rule. Each frame reports its pixel count and the server's
// time for it (Frame.server_ms: the request it answers → frame queued, a
// build never included). Over the last `frames` frames of the size in
// effect, the median time t gives the frame rate the server can hold at
// this size, 1000 / t; the time at another size is taken as t × its pixels /
// these pixels (the render is per pixel).
//   - down: when 1000 / t is under the floor, to the largest step whose
//     estimate makes the floor (the smallest step when none does);
//   - up: one step, when the estimate at the next step up is at least
//     `headroom` × the floor and the size has held for `holdMs`.
//   - still: the steps hold a frame rate while the view moves, and a view
//     that has stopped needs none, so once it has been still for STILL_MS
//     (the page's timer: still()) the view's own size is asked for, one
//     frame however long the server takes; the next move (moved()) goes
//     back to the step in effect before its pose is sent.
// The floor (fpsFloor) and the rule are in docs/clients.md.
// How long a view stays unmoved before auto shows it at its own size.
export const STILL_MS = 700;

export class AutoResolution {
  constructor({ frames = 4, headroom = 1.5, holdMs = 3000 } = {}) {
    this.frames = frames;
    this.headroom = headroom;
    this.holdMs = holdMs;
    this.capLines = Infinity;  // the current step: lines at most
    this.samples = [];         // server ms of frames of the size in effect
    this.pixels = 0;           // the size in effect (the one asked for)
    this.changedAt = -Infinity;
    this.sharp = false;        // a still view, shown at its own size
  }

  // The cap to ask for now: the step in effect, or none while still.
  wantedCap() {
    return this.sharp ? Infinity : this.capLines;
  }

  // The view has been still for STILL_MS. True when that changes the size
  // asked for (auto had stepped down).
  still() {
    if (this.sharp || !Number.isFinite(this.capLines)) return false;
    this.sharp = true;
    return true;
  }

  // The view moves. True when the size asked for goes back to the step.
  moved() {
    if (!this.sharp) return false;
    this.sharp = false;
    return true;
  }

  // A new size was asked for (a step, a resize): samples of the old one no
  // longer say anything.
  asked(pixels, now) {
    if (pixels !== this.pixels) {
      this.pixels = pixels;
      this.samples = [];
      this.changedAt = now;
    }
  }

  // One frame: `pixels` (width × height), `serverMs` (NaN: no time, e.g. the
  // first frame). `steps`: [{lines, pixels}] from the view's own size down
  // (autoSteps with the pixels frameSize gives each). Returns the new cap in
  // lines when the rule changes it, else null.
  frame(now, { pixels, serverMs }, steps, floor) {
    if (pixels !== this.pixels || !(serverMs > 0)) return null;
    this.samples.push(serverMs);
    if (this.samples.length > this.frames) this.samples.shift();
    if (this.samples.length < this.frames) return null;
    const sorted = [...this.samples].sort((a, b) => a - b);
    const t = sorted[Math.floor(sorted.length / 2)];
    const budget = 1000 / floor;  // ms a frame may take
    const at = steps.findIndex((s) => s.lines === this.capLines);
    const index = at >= 0 ? at : 0;
    const estimate = (s) => t * s.pixels / pixels;
    if (t > budget) {
      let next = steps.length - 1;
      for (let i = index + 1; i < steps.length; i++) {
        if (estimate(steps[i]) <= budget) { next = i; break; }
      }
      if (next === index) return null;  // the smallest step already
      return this.step(steps[next].lines, now);
    }
    if (index > 0 && now - this.changedAt >= this.holdMs && estimate(steps[index - 1]) * this.headroom <= budget) {
      return this.step(steps[index - 1].lines, now);
    }
    return null;
  }

  step(lines, now) {
    this.capLines = lines;
    this.samples = [];
    this.changedAt = now;
    return lines;
  }

  // "auto 540p" for the HUD: the step in effect ("auto" at the view's own size).
  label() {
    if (this.sharp) return `auto (still: full size; ≤${this.capLines}p moving)`;
    return Number.isFinite(this.capLines) ? `auto ≤${this.capLines}p` : 'auto';
  }
}
