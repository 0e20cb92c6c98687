// The scene controls: which of the server's scenes is shown, each object's
// material, and the objects a drag can turn. They show the scene the server
// says is in effect (SceneInfo), so a refused choice leaves them truthful;
// a new scene's objects are listed once its first frame is on the canvas
// (its renderer may take a while to build), not over the old scene's frame.
import { expectBuild } from './build_view.js';
import { choices, state } from './page_state.js';
import { send } from './session.js';
import { fillSelect, selectValue } from './settings_panel.js';
import { noteChange, resetView, touched, view } from './view.js';

const $ = (id) => document.getElementById(id);

// The server's scenes (Welcome.scenes).
export function showScenes(names) {
  fillSelect($('scene'), names.map((s) => [s, s]));
}

// The scene in effect: from Welcome, in answer to each accepted
// SceneChoice, and again with the objects' levels when a renderer built
// later has other levels than the client was told. Another scene resets the view to its own camera (the server
// reset its poses to the scene's own); the same scene (a material change)
// keeps the view.
export function onSceneInfo(info, fromWelcome) {
  const previous = state.sceneInfo;
  const newScene = !previous || previous.name !== info.name;
  state.sceneInfo = info;
  choices.scene = info.name;
  if (newScene || (fromWelcome && !touched.camera)) resetView();
  if (newScene && !fromWelcome) {
    // Frames answering older poses still show the previous scene.
    state.scene = { name: info.name, firstPose: view.poseSequence + 1 };
  } else if (fromWelcome) {
    state.scene = { name: info.name, firstPose: 0 };
  }
  if (view.pendingScene === info.name) view.pendingScene = null;
  view.poseDirty = true;
  selectValue($('scene'), info.name);
  if (newScene && !fromWelcome) {
    state.sceneReady = false;
    showPreparing(info.name);
  } else if (!fromWelcome && !state.sceneReady) {
    // The same scene again before its first frame (the server names its
    // objects' levels once its renderer is built): still held back.
  } else {
    state.sceneReady = true;
    showObjects(info);
  }
}

// A frame of the scene in effect is on the canvas: its objects are listed
// if they were held back.
export function sceneShown() {
  if (state.sceneReady || !state.sceneInfo) return;
  state.sceneReady = true;
  showObjects(state.sceneInfo);
}

function removeObjectTargets() {
  for (const r of document.querySelectorAll('#drag-target input')) {
    if (r.value.startsWith('object:')) {
      if (r.checked) document.querySelector('#drag-target input[value="camera"]').checked = true;
      r.closest('label').remove();
    }
  }
}

function showPreparing(name) {
  const note = document.createElement('li');
  note.className = 'note';
  note.textContent = `preparing ${name}: its objects are listed with its first frame`;
  $('objects').replaceChildren(note);
  removeObjectTargets();
}

function showObjects(info) {
  const offered = state.welcome ? state.welcome.materials : [];
  const list = $('objects');
  list.replaceChildren();
  const dragTargets = [...document.querySelectorAll('#drag-target input')];
  const chosen = (dragTargets.find((r) => r.checked) || {}).value;
  for (const r of dragTargets) if (r.value.startsWith('object:')) r.closest('label').remove();
  for (const o of info.objects) {
    const li = document.createElement('li');
    const name = document.createElement('span');
    name.className = 'name';
    name.textContent = o.name || `object ${o.index}`;
    const index = document.createElement('span');
    index.className = 'index';
    index.textContent = ` #${o.index}`;
    name.append(index);
    const select = document.createElement('select');
    select.dataset.object = String(o.index);
    select.setAttribute('aria-label', `material of ${o.name || `object ${o.index}`}`);
    const options = offered.map((m) => [m, m]);
    // A scene file's own material (say, a MERL file) is in effect but not
    // offered: shown by its name, and not choosable again once changed.
    if (!offered.includes(o.material)) {
      options.unshift([o.material, o.material]);
      const own = document.createElement('span');
      own.className = 'own';
      own.textContent = ' · the scene\'s own material';
      name.append(own);
    }
    fillSelect(select, options, o.material);
    select.addEventListener('change', () => chooseMaterial(o.index, select.value));
    li.append(name, select);
    list.append(li);

    const label = document.createElement('label');
    label.className = 'inline';
    const radio = document.createElement('input');
    radio.type = 'radio';
    radio.name = 'drag';
    radio.value = `object:${o.index}`;
    label.append(radio, ` ${o.name || `object ${o.index}`}`);
    $('drag-target').append(label);
  }
  const keep = [...document.querySelectorAll('#drag-target input')].find((r) => r.value === chosen);
  (keep || document.querySelector('#drag-target input[value="camera"]')).checked = true;
}

// The server refused a scene or material choice: the session goes on with
// the scene it had, and the controls show it again.
export function undoSceneChoice() {
  view.pendingScene = null;
  if (state.sceneInfo) onSceneInfo(state.sceneInfo, false);
}

function chooseScene(name) {
  if (state.sceneInfo && name === state.sceneInfo.name) return;
  choices.scene = name;
  view.pendingScene = name;
  // Poses sent before the answer would move the new scene with the old
  // scene's camera: none carry a view until SceneInfo comes.
  touched.camera = false;
  touched.light = false;
  touched.objects.clear();
  expectBuild(`scene ${name}`);
  if (send({ scene: { scene: name } })) noteChange();
}

function chooseMaterial(index, spec) {
  if (!state.sceneInfo) return;
  const o = state.sceneInfo.objects.find((x) => x.index === index);
  expectBuild(`${spec} on ${(o && o.name) || `object ${index}`}`);
  if (send({ scene: { scene: state.sceneInfo.name, objectMaterials: { [index]: spec } } })) noteChange();
}

$('scene').addEventListener('change', () => chooseScene($('scene').value));
