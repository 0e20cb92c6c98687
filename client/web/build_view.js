// A renderer build on the page: while the server builds the renderer a
// change needs (BuildProgress: a new scene, level, method or material, or
// the session's first), the old frame is dimmed and what is built, how far
// and the time left are shown over it, until the first frame of the change
// (or Welcome, or an Error). The words come from build_status.js.
import { describeBuild } from './build_status.js';
import { state } from './page_state.js';

const $ = (id) => document.getElementById(id);

const build = { what: '', shown: false };

// What the next build would be for, said when the page asks for a change
// ("level 6", "scene gallery").
export function expectBuild(what) {
  build.what = what;
}

export function showBuildProgress(progress) {
  const d = describeBuild(progress, build.what);
  build.shown = true;
  $('build-title').textContent = d.title;
  $('build-stage').textContent = d.stageLine;
  const bar = $('build-bar');
  if (d.fraction === null) bar.removeAttribute('value');  // indeterminate: the total is not known
  else bar.value = d.fraction;
  $('build-detail').textContent = d.detail;
  $('build').hidden = false;
  $('view').classList.add('building');
  state.build = { what: build.what, stage: d.stage, percent: d.percent, fraction: d.fraction, detail: d.detail };
  state.buildProgressMessages++;
}

export function buildShown() {
  return build.shown;
}

// The build is over (its first frame is shown, Welcome came, or it failed).
// Returns whether one was on the page.
export function endBuild() {
  const was = build.shown;
  build.shown = false;
  build.what = '';
  $('build').hidden = true;
  $('view').classList.remove('building');
  if (was) state.buildsEnded++;
  state.build = null;
  return was;
}
