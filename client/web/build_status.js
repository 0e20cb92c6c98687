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
// total, fraction, elapsedSeconds, estimatedStageSecondsLeft, buildFraction,
// stages, estimatedBuildSecondsLeft; uint64s may be Longs). what: what the
// page asked for that needs the build ("level 6", "scene gallery"), or ''.
// With the server's plan (`stages`), the bar and the percentage are the
// whole build's, which never go back, the step is counted in the plan
// ("step 2 of 4") and the time left is the build's; without one, the
// stage's own.
// Returns {title, stage, fraction (null: unknown), percent, detail,
// stageLine}: stageLine is what the overlay's bold line says (with a plan
// the stage and its own share, "visibility of bunny · this step 40 %", the
// build's percentage going to the title; without, the stage's percentage).
export function describeBuild(progress, what = '') {
  const p = progress || {};
  const total = Number(p.total || 0);
  const planned = Array.isArray(p.stages) && p.stages.length > 0;
  const clamp = (f) => Math.min(1, Math.max(0, f));
  let fraction = null;
  if (planned && Number.isFinite(p.buildFraction)) fraction = clamp(p.buildFraction);
  else if (total > 0 && Number.isFinite(p.fraction)) fraction = clamp(p.fraction);
  const step = planned ? p.stages.indexOf(p.stage) : -1;
  const details = [step >= 0 ? `step ${step + 1} of ${p.stages.length}` : `step ${(p.stageIndex || 0) + 1}`];
  if (total > 0 && !planned) details.push(`${Number(p.done || 0)} of ${total}`);
  if (planned && p.estimatedBuildSecondsLeft > 0) details.push(`about ${formatSeconds(p.estimatedBuildSecondsLeft)} left`);
  else if (!planned && p.estimatedStageSecondsLeft > 0) details.push(`about ${formatSeconds(p.estimatedStageSecondsLeft)} left in this step`);
  if (p.elapsedSeconds > 0) details.push(`${formatSeconds(p.elapsedSeconds)} so far`);
  // Never "100 %" before the end.
  const percent = fraction === null ? null : Math.min(99, Math.floor(100 * fraction));
  const stage = stageText(p.stage);
  const title = `preparing ${what || 'the renderer'}`;
  if (planned) {
    const own = total > 0 && Number.isFinite(p.fraction) ? ` · this step ${Math.min(99, Math.floor(100 * clamp(p.fraction)))} %` : '';
    return { title: percent === null ? title : `${title}: ${percent} %`, stage, fraction, percent,
             detail: details.join(' · '), stageLine: `${stage}${own}` };
  }
  return { title, stage, fraction, percent, detail: details.join(' · '),
           stageLine: percent === null ? stage : `${stage}: ${percent} %` };
}

// The HUD's first line while no frame comes: the stream is up to date (the
// server sends a frame only when something changes), and how long ago the
// last one came.
export function idleText(sinceLastMs) {
  return `idle — last frame ${formatSeconds(Math.max(0, sinceLastMs) / 1000)} ago, up to date`;
}

// The renderer's stage names (FrameProgress.stage, the HUD's stage times)
// as a reader would say them.
const FRAME_STAGES = {
  queued: 'waiting for a render thread',
  light: 'turning the light',
  gbuffer: 'primary rays',
  'rotation-input': 'shading frames',
  'shadow-rays': 'shadow rays',
  fused: 'shading',
  rotation: 'rotating the BRDF slices',
  'triple-product': 'triple product',
  splitsum: 'shading (split sum)',
  tonemap: 'tone mapping',
};

// progress: a FrameProgress (stage, stageFraction, fraction, elapsedSeconds,
// estimatedSecondsLeft, width, height). Returns {title, stage, fraction,
// percent, detail}, as describeBuild.
export function describeFrame(progress) {
  const p = progress || {};
  const fraction = Number.isFinite(p.fraction) ? Math.min(1, Math.max(0, p.fraction)) : 0;
  const size = p.width > 0 && p.height > 0 ? ` ${p.width}×${p.height}` : '';
  const details = [`${formatSeconds(Number(p.elapsedSeconds) || 0)} so far`];
  if (p.estimatedSecondsLeft > 0) details.push(`about ${formatSeconds(p.estimatedSecondsLeft)} left`);
  return {
    title: `rendering the frame${size}`,
    stage: FRAME_STAGES[p.stage] || String(p.stage || 'rendering'),
    fraction,
    percent: Math.min(99, Math.floor(100 * fraction)),
    detail: details.join(' · '),
  };
}
