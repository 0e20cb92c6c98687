// Words for what the server is doing while the page waits: a renderer build
// (BuildProgress) shown over the dimmed view, and the HUD's line when no
// frame has come for a while. Pure, so that node tests it
// (tests/e2e/web_client_test.mjs).

// "0.4 s", "12 s", "3 min 05 s", "2 h 07 min".
export function formatSeconds(s) {
  if (!Number.isFinite(s) || s < 0) return '—';
  if (s < 9.95) return `${s.toFixed(1)} s`;
  if (s < 59.5) return `${Math.round(s)} s`;
  if (s < 3600) {
    const m = Math.floor(Math.round(s) / 60), r = Math.round(s) % 60;
    return `${m} min ${String(r).padStart(2, '0')} s`;
  }
  const h = Math.floor(s / 3600), m = Math.floor((s % 3600) / 60);
  return `${h} h ${String(m).padStart(2, '0')} min`;
}

// The server's stage words ("slices bunny", "visibility bunny", "rotators
// bunny": docs/service.md) as a reader would say them.
const STEPS = {
  slices: 'BRDF slice table',
  visibility: 'visibility',
  rotators: 'rotation tables',
};

function stageText(stage) {
  const s = String(stage || '').trim();
  const space = s.indexOf(' ');
  const step = space < 0 ? s : s.slice(0, space);
  const object = space < 0 ? '' : s.slice(space + 1);
  if (!(step in STEPS)) return s || 'the renderer';
  return object ? `${STEPS[step]} of ${object}` : STEPS[step];
}

// progress: a BuildProgress (protobufjs object: stage, stageIndex, done,
// total, fraction, elapsedSeconds, estimatedStageSecondsLeft; uint64s may
// be Longs). what: what the page asked for that needs the build ("level 6",
// "scene gallery"), or ''.
// Returns {title, stage, fraction (null: unknown), percent, detail}.
export function describeBuild(progress, what = '') {
  const p = progress || {};
  const total = Number(p.total || 0);
  const fraction = total > 0 && Number.isFinite(p.fraction) ? Math.min(1, Math.max(0, p.fraction)) : null;
  const details = [`step ${(p.stageIndex || 0) + 1}`];
  if (total > 0) details.push(`${Number(p.done || 0)} of ${total}`);
  if (p.estimatedStageSecondsLeft > 0) details.push(`about ${formatSeconds(p.estimatedStageSecondsLeft)} left in this step`);
  if (p.elapsedSeconds > 0) details.push(`${formatSeconds(p.elapsedSeconds)} so far`);
  return {
    title: `preparing ${what || 'the renderer'}`,
    stage: stageText(p.stage),
    fraction,
    // Never "100 %" before the end.
    percent: fraction === null ? null : Math.min(99, Math.floor(100 * fraction)),
    detail: details.join(' · '),
  };
}

// The HUD's first line while no frame comes: the stream is up to date (the
// server sends a frame only when something changes), and how long ago the
// last one came.
export function idleText(sinceLastMs) {
  return `idle — last frame ${formatSeconds(Math.max(0, sinceLastMs) / 1000)} ago, up to date`;
}
