// The frame size the page asks for, so that the stream fits its view: the
// view's size in device pixels (CSS pixels × devicePixelRatio) within the
// server's limits (Welcome.limits: max_width, max_height, max_pixels), or a
// fixed number of lines (360p … 1080p) with the view's aspect ratio. And the
// rule of "auto": while the view moves, a smaller size when the server
// cannot render frames at the frame-rate floor (and back up when it can);
// once it is still, the view's own size. Pure (no DOM, no clock), so that
// node tests it (tests/e2e/web_client_test.mjs).

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
// build never included); the time at another size is taken as t × its
// pixels / these pixels (as if the render were all per pixel: where a frame
// costs something besides, the move's own frames step further). Steps are
// for a view that moves; a still view needs no frame rate:
//   - still (the default, and STILL_MS after the last move, whatever else
//     changed meanwhile: a scene, a material, a setting, a resize): the
//     view's own size, one frame however long the server takes. Frames of a
//     still view step nothing; the last one is kept for the next move.
//   - a move starts (moved()): the step for the move is chosen from the last
//     frame's time and pixels alone, before the move's first pose is sent:
//     the largest step whose estimate holds the floor (the smallest when
//     none does), so a slow server's first drag frame already comes small.
//     Above the step of the last move only with `headroom` and after
//     `holdMs` (as up, below), so that it does not flap between moves.
//   - while it moves, over the frames of the size asked for (the median of
//     the last `frames`): down as soon as `downFrames` of them say the floor
//     is missed, to the largest step that holds it; up one step, when the
//     estimate at the next step up is at least `headroom` × inside the
//     floor's budget and the size has held for `holdMs`.
// The floor (fpsFloor) and the rule are in docs/clients.md.
// How long a view stays unmoved before auto shows it at its own size.
export const STILL_MS = 700;

export class AutoResolution {
  constructor({ frames = 4, downFrames = 2, headroom = 1.5, holdMs = 3000 } = {}) {
    this.frames = frames;
    this.downFrames = downFrames;
    this.headroom = headroom;
    this.holdMs = holdMs;
    this.capLines = Infinity;  // the step of a moving view: lines at most
    this.samples = [];         // server ms of this move's frames of the size in effect
    this.pixels = 0;           // the size in effect (the one asked for)
    this.changedAt = -Infinity;  // when that size was asked for
    this.steppedAt = -Infinity;  // when capLines last changed
    this.moving = false;
    this.last = null;          // {pixels, serverMs} of the last frame with a time, of any size
  }

  // The cap to ask for now: the step while the view moves, none while still.
  wantedCap() {
    return this.moving ? this.capLines : Infinity;
  }

  // The view has been still for STILL_MS. True when that changes the size
  // asked for (the move had a step).
  still() {
    if (!this.moving) return false;
    this.moving = false;
    this.samples = [];
    return Number.isFinite(this.capLines);
  }

  // The view moves (each drag, wheel or pinch event). The first of a move
  // picks its step from the last frame; `steps` and `floor` as for frame().
  // True when the size asked for changes (before the move's pose is sent).
  moved(now, steps, floor) {
    if (this.moving) return false;
    this.moving = true;
    this.samples = [];
    if (this.last) {
      const budget = 1000 / floor;
      const estimate = (s) => this.last.serverMs * s.pixels / this.last.pixels;
      const mayRise = now - this.steppedAt >= this.holdMs;
      const fits = (s) => estimate(s) <= budget &&
        (s.lines <= this.capLines || (mayRise && estimate(s) * this.headroom <= budget));
      const pick = steps.find(fits) || steps[steps.length - 1];
      if (pick && pick.lines !== this.capLines) {
        this.capLines = pick.lines;
        this.steppedAt = now;
      }
    }
    return Number.isFinite(this.capLines);
  }

  // A new size was asked for (a step, a resize, still or moving): samples of
  // the old one no longer say anything.
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
    if (!(serverMs > 0)) return null;
    this.last = { pixels, serverMs };
    if (!this.moving || pixels !== this.pixels) return null;
    this.samples.push(serverMs);
    if (this.samples.length > this.frames) this.samples.shift();
    const n = this.samples.length;
    if (n < Math.min(this.downFrames, this.frames)) return null;
    // The lower median: one slow frame among quick ones steps nothing.
    const t = [...this.samples].sort((a, b) => a - b)[Math.floor((n - 1) / 2)];
    const budget = 1000 / floor;  // ms a frame may take
    const at = steps.findIndex((s) => s.lines === this.capLines);
    const index = at >= 0 ? at : 0;
    const estimate = (s) => t * s.pixels / pixels;
    if (t > budget) {
      let next = steps.length - 1;
      for (let i = index + 1; i < steps.length; i++) {
        if (estimate(steps[i]) <= budget) { next = i; break; }
      }
      if (next <= index) return null;  // the smallest step already
      return this.step(steps[next].lines, now);
    }
    if (n >= this.frames && index > 0 && now - this.changedAt >= this.holdMs &&
        estimate(steps[index - 1]) * this.headroom <= budget) {
      return this.step(steps[index - 1].lines, now);
    }
    return null;
  }

  step(lines, now) {
    this.capLines = lines;
    this.samples = [];
    this.changedAt = now;
    this.steppedAt = now;
    return lines;
  }

  // What auto is doing, for the HUD: `shown` and `asked` are the pixels of
  // the frame on the canvas and of the size asked for.
  label(shown, asked) {
    if (this.moving) return Number.isFinite(this.capLines) ? `auto ≤${this.capLines}p (moving)` : 'auto: full size (moving)';
    return shown > 0 && asked > 0 && shown < asked ? 'auto: sharpening…' : 'auto: full size (still)';
  }
}
