// The rendering, exposure and tone curve controls. They offer what the server allows
// (Welcome.limits, the schema's methods), not a copy kept in the page, and
// they show the settings in effect: a change the server refuses puts them
// back as they were, and in auto exposure the slider follows the frames.
import { h264Support } from './h264_decoder.js';
import { helloEncoding } from './h264_view.js';
import { formatStops } from './frame_stats.js';
import { choices, exposureSettings, page, state, toneSettings } from './page_state.js';
import { ExposureMode, LevelMode, methodName, methodNames, methodValue, toneName, toneNames } from './schema.js';
import { restartSession, send } from './session.js';
import { expectBuild } from './build_view.js';
import { noteChange } from './view.js';

const $ = (id) => document.getElementById(id);

export function fillSelect(select, items, value) {
  select.replaceChildren(...items.map(([v, text]) => new Option(text, String(v))));
  if (value !== undefined && value !== null) selectValue(select, value);
}

export function selectValue(select, value) {
  const v = String(value);
  if (![...select.options].some((o) => o.value === v)) select.add(new Option(v, v));
  select.value = v;
}

let effective = null;  // the RenderSettings in effect: Welcome's, then each frame's
let autoCap = 0;       // the server's cap of automatic levels (Welcome's level under auto), 0 = unknown
export function setEffective(settings) {
  effective = settings;
}

// The controls' settings before the last change and after it: a change the
// server refuses (BAD_SETTINGS) puts the controls back as they were.
let settingsBeforeChange = null;
let settingsAfterChange = null;
let exposureDirty = false;

// A new session: its limits and the settings it starts with.
export function showWelcomeSettings(w) {
  effective = w.settings || {};
  const limits = w.limits || {};
  autoCap = effective.levelMode === LevelMode.values.LEVEL_MODE_AUTO ? effective.level || 0 : 0;

  fillSelect($('method'), methodNames.map((m) => [m, m]), methodName(effective.method) || undefined);
  // Levels: "auto" (each object at the level its material needs, the cap
  // the server's), then the server's range, not a copy in the page.
  const levels = [['auto', 'auto (by material)']];
  if (limits.maxLevel) {
    for (let n = limits.minLevel || 1; n <= limits.maxLevel; n++) levels.push([n, `${n} (${2 ** n}×${2 ** n})`]);
  }
  fillSelect($('level'), levels, levelChoice(effective));
  const ks = [16, 64, 256, 1024, 4096].filter((k) => !limits.maxLightCoefficients || k <= limits.maxLightCoefficients);
  fillSelect($('coefficients'), ks.map((k) => [k, String(k)]), effective.lightCoefficients || undefined);

  // Exposure: the slider spans ±8 stops, or less when the server allows less.
  const range = Math.min(8, limits.maxExposureStops || 8);
  const slider = $('exposure');
  slider.min = String(-range);
  slider.max = String(range);
  const fixed = effective.exposureMode === ExposureMode.values.EXPOSURE_MODE_FIXED;
  $('exposure-auto').checked = !fixed;
  if (fixed) slider.value = String(effective.exposureStops || 0);
  choices.exposure = { auto: !fixed, stops: Number(slider.value) };
  // Tone curves: the schema's, the one in effect selected.
  fillSelect($('tone'), toneNames.map((t) => [t, t]), toneName(effective.toneCurve) || toneNames[0]);
  choices.tone = $('tone').value;

  settingsBeforeChange = null;
  settingsAfterChange = currentSettings();
}

function showSettings(s) {
  if (!s) return;
  if (s.method) selectValue($('method'), methodName(s.method));
  if (s.level) selectValue($('level'), levelChoice(s));
  if (s.lightCoefficients) selectValue($('coefficients'), s.lightCoefficients);
  if (s.exposureMode) {
    const fixed = s.exposureMode === ExposureMode.values.EXPOSURE_MODE_FIXED;
    $('exposure-auto').checked = !fixed;
    if (fixed) $('exposure').value = String(s.exposureStops || 0);
    choices.exposure = { auto: !fixed, stops: Number($('exposure').value) };
  }
  if (s.toneCurve) selectValue($('tone'), toneName(s.toneCurve));
  choices.tone = $('tone').value;
  choices.method = $('method').value;
  choices.level = levelNumber();
  choices.k = Number($('coefficients').value);
}

// The select's value for settings: "auto" under LEVEL_MODE_AUTO, else the level.
function levelChoice(s) {
  if (s.levelMode === LevelMode.values.LEVEL_MODE_AUTO) return 'auto';
  return s.level || undefined;
}

// The chosen fixed level, 0 under auto (the page's `level` parameter is a number).
function levelNumber() {
  return $('level').value === 'auto' ? 0 : Number($('level').value);
}

// RenderSettings for the level select: a level is fixed; auto takes the
// server's cap (or, when the session began fixed, the level in effect).
function levelSettings() {
  if ($('level').value === 'auto') return { level: autoCap, levelMode: LevelMode.values.LEVEL_MODE_AUTO };
  return { level: Number($('level').value), levelMode: LevelMode.values.LEVEL_MODE_FIXED };
}

// The server refused the last change (BAD_SETTINGS): the session goes on as
// before, and the controls show what is in effect again.
export function undoSettingsChange() {
  showSettings(settingsBeforeChange || effective);
  settingsAfterChange = settingsBeforeChange;
}

function currentSettings() {
  return { method: methodValue($('method').value), ...levelSettings(),
           lightCoefficients: Number($('coefficients').value), ...exposureSettings(), ...toneSettings() };
}

function sendSettings(fields) {
  if (send({ settings: fields })) {
    settingsBeforeChange = settingsAfterChange;
    settingsAfterChange = currentSettings();
    noteChange();
  }
}

function onSettingsControl() {
  choices.method = $('method').value;
  choices.level = levelNumber();
  choices.k = Number($('coefficients').value);
  const { method, level, levelMode, lightCoefficients } = currentSettings();
  // What a build, if one comes, is for: the method and the level.
  expectBuild(choices.level ? `${choices.method} at level ${choices.level} (${2 ** choices.level}×${2 ** choices.level} maps)`
                            : `${choices.method} at levels by material`);
  sendSettings({ method, level, levelMode, lightCoefficients });
}

// The exposure change due, if one is: called once per display frame, as the
// slider moves faster than that and the server keeps only the latest.
export function flushExposure() {
  if (exposureDirty) {
    exposureDirty = false;
    sendSettings(exposureSettings());
  }
}

export function showFrameExposure(stops, mode) {
  $('exposure-value').textContent = `${formatStops(stops)} stops (${mode})`;
  // In auto mode the slider follows the frames, so that leaving auto starts
  // from the exposure on the screen.
  if ($('exposure-auto').checked && !exposureDragging && Number.isFinite(stops)) $('exposure').value = String(stops);
}

let exposureDragging = false;
$('exposure').addEventListener('pointerdown', () => { exposureDragging = true; });
// The release may land outside the slider: any pointerup ends the drag.
window.addEventListener('pointerup', () => { exposureDragging = false; });
$('exposure').addEventListener('change', () => { exposureDragging = false; });
$('exposure').addEventListener('input', () => {
  $('exposure-auto').checked = false;
  choices.exposure = { auto: false, stops: Number($('exposure').value) };
  $('exposure-value').textContent = `${formatStops(choices.exposure.stops)} stops (fixed)`;
  exposureDirty = true;  // sent by flushExposure(): at most one per display frame
});
$('exposure-auto').addEventListener('change', () => {
  choices.exposure = { auto: $('exposure-auto').checked, stops: Number($('exposure').value) };
  exposureDirty = true;
});
for (const id of ['method', 'level', 'coefficients']) $(id).addEventListener('change', onSettingsControl);
$('tone').addEventListener('change', () => {
  choices.tone = $('tone').value;
  sendSettings(toneSettings());
});

// The encoding chosen on the page (or ?encoding=): H.264 is asked for only
// where WebCodecs decodes it; otherwise the reason is shown and the Hello
// asks for JPEG.
export async function chooseEncoding(name) {
  page.encoding = name;
  $('encoding').value = name;
  if (name === 'h264' && !state.h264) state.h264 = await h264Support();
  const { note } = helloEncoding(name, state.h264);
  $('encoding-note').textContent = note;
  $('encoding-note').hidden = !note;
}

// The encoding is a Hello field: another one takes a new session. The address
// keeps the choice, so a reload asks for it again.
$('encoding').addEventListener('change', async () => {
  await chooseEncoding($('encoding').value);
  const params = new URLSearchParams(location.search);
  params.set('encoding', page.encoding);
  history.replaceState(null, '', `?${params}`);
  restartSession();
});
