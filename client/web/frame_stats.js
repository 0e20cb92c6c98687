// The HUD's numbers: rates and means over a window of recent frames that
// suits the frame rate. Pure (no DOM, no clock of its own), so that node
// tests it with made-up arrival times (tests/e2e/frame_stats_test.mjs).
//
// The window holds the frames of the last `seconds`, but never fewer than
// `minFrames` (so at 0.3 fps it spans the last few frames, not one second
// that holds zero or one of them), and it never reaches back across an idle
// gap: the server sends frames only when something changed, so a pause is
// not a slow frame rate. A gap is an interval longer than `gapFactor` times
// the median of the recent intervals (at least `minGapMs`).
//
// A rate needs three frames (two intervals; the first two frames of a
// session, the scene's own view and the answer to the first pose, say
// little): until then it is null (the HUD shows "—"). A rate is never 0:
// with frames in the window there is a positive span.

export class FrameWindow {
  constructor({ seconds = 2, minFrames = 5, gapFactor = 4, minGapMs = 2000, keep = 240 } = {}) {
    this.seconds = seconds;
    this.minFrames = minFrames;
    this.gapFactor = gapFactor;
    this.minGapMs = minGapMs;
    this.keep = keep;
    this.frames = [];  // {t, bytes, latencyMs, serverMs, stages: [{name, ms}]}, oldest first
  }

  clear() {
    this.frames.length = 0;
  }

  // t: arrival time in ms (performance.now()); the rest may be NaN / [].
  add(t, { bytes = 0, latencyMs = NaN, serverMs = NaN, stages = [] } = {}) {
    this.frames.push({ t, bytes, latencyMs, serverMs, stages });
    if (this.frames.length > this.keep) this.frames.splice(0, this.frames.length - this.keep);
  }

  // The longest interval that still counts as streaming, from the median of
  // the last few intervals (a median, so one long pause does not stretch it).
  gapLimitMs() {
    const f = this.frames;
    const intervals = [];
    for (let i = f.length - 1; i > 0 && intervals.length < 2 * this.minFrames; i--) intervals.push(f[i].t - f[i - 1].t);
    if (!intervals.length) return this.minGapMs;
    intervals.sort((a, b) => a - b);
    const median = intervals[Math.floor(intervals.length / 2)];
    return Math.max(this.minGapMs, this.gapFactor * median);
  }

  // The frames the numbers are taken over, oldest first.
  window() {
    const f = this.frames;
    if (!f.length) return [];
    const gap = this.gapLimitMs();
    const newest = f[f.length - 1].t;
    let first = f.length - 1;
    while (first > 0) {
      const previous = f[first - 1];
      if (f[first].t - previous.t > gap) break;  // an idle pause: the window starts after it
      if (newest - previous.t > this.seconds * 1000 && f.length - first >= this.minFrames) break;
      first--;
    }
    return f.slice(first);
  }

  // Everything the HUD shows. `idle`: no frame for longer than a gap, so the
  // stream is paused (the numbers are those of the last stretch of frames);
  // `sinceLastMs`: how long ago the newest frame came (null: none yet).
  summary(now) {
    const w = this.window();
    const mean = (values) => {
      const v = values.filter(Number.isFinite);
      return v.length ? v.reduce((a, b) => a + b, 0) / v.length : null;
    };
    const span = w.length >= 3 ? w[w.length - 1].t - w[0].t : 0;
    // Frames after the first arrived within the span: n-1 intervals.
    const fps = span > 0 ? (w.length - 1) * 1000 / span : null;
    const kbps = span > 0 ? w.slice(1).reduce((a, x) => a + x.bytes, 0) * 8 / span : null;
    // The newest frame's stages (another method has others), each averaged
    // over the frames in the window that have it.
    const stageTotals = new Map((w.length ? w[w.length - 1].stages : []).map((s) => [s.name, { sum: 0, n: 0 }]));
    for (const x of w) {
      for (const s of x.stages) {
        const e = stageTotals.get(s.name);
        if (e) { e.sum += s.ms; e.n += 1; }
      }
    }
    const stages = [...stageTotals].map(([name, e]) => ({ name, ms: e.sum / e.n }));
    const last = this.frames.length ? this.frames[this.frames.length - 1].t : null;
    return {
      frames: w.length,
      fps,
      kbps,
      latencyMs: mean(w.map((x) => x.latencyMs)),
      serverMs: mean(w.map((x) => x.serverMs)),
      stages,
      idle: last !== null && now - last > this.gapLimitMs(),
      sinceLastMs: last === null ? null : now - last,
    };
  }
}

// "—" for no data; otherwise digits that suit the size (never "0" for a
// positive rate: 0.04 fps is printed as "0.040").
export function formatNumber(x) {
  if (x === null || x === undefined || !Number.isFinite(x)) return '—';
  const a = Math.abs(x);
  if (a >= 9.95) return x.toFixed(0);
  if (a >= 0.995) return x.toFixed(1);
  if (a === 0) return '0';
  return x.toPrecision(2);
}

// Exposure in stops with its sign: "+1.3", "−0.5", "0.0".
export function formatStops(x) {
  if (!Number.isFinite(x)) return '—';
  const r = Math.round(x * 10) / 10;
  if (r === 0) return '0.0';
  return `${r > 0 ? '+' : '−'}${Math.abs(r).toFixed(1)}`;
}

// Reconnect delays: 1, 2, 4, 8, 16, 30, 30, … seconds, each with ±20 %
// jitter (`random` in [0, 1)) so that many pages dropped together do not
// come back in step.
export function backoffMs(attempt, random = 0.5) {
  const base = Math.min(30, 2 ** Math.max(0, attempt - 1)) * 1000;
  return Math.round(base * (0.8 + 0.4 * random));
}
