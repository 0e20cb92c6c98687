// The scene controls: which of the server's scenes is shown, under which of
// its probes, or which of its meshes instead of the scene's objects (and
// which way up), each object's material, and the objects a drag can turn.
// They show the scene the server says is in effect (SceneInfo), so a
// refused choice leaves them truthful; a new scene's objects are listed
// once its first frame is on the canvas (its renderer may take a while to
// build), not over the old scene's frame.
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

// The server's probes and meshes (Welcome.probes, Welcome.meshes, from
// `serve --data`): a select for each kind it offers, none for a kind it
// does not (a control that cannot be used is not on the page).
function showDataChoices(welcome) {
  const lists = [['probe', welcome.probes || [], "the scene's own light", chooseProbe],
    ['mesh', welcome.meshes || [], "the scene's own objects", chooseMesh]];
  for (const [id, names, own, choose] of lists) {
    const old = $(`${id}-choice`);
    if (old) old.remove();
    if (names.length === 0) continue;
    const label = document.createElement('label');
    label.id = `${id}-choice`;
    label.className = 'wide';
    const select = document.createElement('select');
    select.id = id;
    fillSelect(select, [['', own], ...names.map((n) => [n, n])]);
    select.addEventListener('change', () => choose(select.value));
    label.append(`${id} `, select);
    $('objects').before(label);
  }
}

// The up axis of the mesh shown: "up: y / z", only while a mesh is shown.
function showUpChoice(info) {
  let group = $('up-choice');
  if (!info.mesh) {
    if (group) group.remove();
    return;
  }
  if (!group) {
    group = document.createElement('div');
    group.id = 'up-choice';
    group.setAttribute('role', 'radiogroup');
    group.setAttribute('aria-label', "the mesh's up axis in its file");
    const title = document.createElement('span');
    title.textContent = 'up';
    group.append(title);
    for (const axis of ['y', 'z']) {
      const label = document.createElement('label');
      label.className = 'inline';
      const radio = document.createElement('input');
      radio.type = 'radio';
      radio.name = 'up';
      radio.value = axis;
      radio.addEventListener('change', () => { if (radio.checked) chooseUp(axis); });
      label.append(radio, ` ${axis}`);
      group.append(label);
    }
    const note = document.createElement('span');
    note.id = 'up-note';
    group.append(note);
    $('objects').before(group);
  }
  for (const r of group.querySelectorAll('input')) r.checked = r.value === info.up;
  $('up-note').textContent = upChosen ? '' : 'guessed from its shape';
}

// What is drawn: the scene, or the mesh shown instead of its objects (and
// which way up). Another such answer means other objects and another view.
const objectsOf = (info) => `${info.name}|${info.mesh || ''}|${info.up || ''}`;
// A SceneChoice waiting for its answer (view.pendingScene): the scene and mesh.
const pendingOf = (scene, mesh) => `${scene}|${mesh || ''}`;
let upChosen = false;  // the user flipped the mesh's up axis: not the server's guess

// The scene in effect: from Welcome, in answer to each accepted
// SceneChoice, and again with the objects' levels when a renderer built
// later has other levels than the client was told. Another scene resets the view to its own camera (the server
// reset its poses to the scene's own); the same scene (a material change)
// keeps the view.
export function onSceneInfo(info, fromWelcome) {
  const previous = state.sceneInfo;
  const newScene = !previous || objectsOf(previous) !== objectsOf(info);
  state.sceneInfo = info;
  if (fromWelcome && state.welcome) showDataChoices(state.welcome);
  if (!info.mesh || (previous && previous.mesh !== info.mesh)) upChosen = false;
  showDataChoice(info);
  choices.scene = info.name;
  if (newScene || (fromWelcome && !touched.camera)) resetView();
  if (newScene && !fromWelcome) {
    // Frames answering older poses still show the previous scene.
    state.scene = { name: info.name, firstPose: view.poseSequence + 1 };
  } else if (fromWelcome) {
    state.scene = { name: info.name, firstPose: 0 };
  }
  if (view.pendingScene === pendingOf(info.name, info.mesh)) view.pendingScene = null;
  view.poseDirty = true;
  selectValue($('scene'), info.name);
  if (newScene && !fromWelcome) {
    state.sceneReady = false;
    showPreparing(info.mesh || info.name);
  } else if (!fromWelcome && !state.sceneReady) {
    // The same scene again before its first frame (the server names its
    // objects' levels once its renderer is built): still held back.
  } else {
    state.sceneReady = true;
    showObjects(info);
  }
}

// The probe, mesh and up axis in effect (SceneInfo), so a refused choice
// shows what is drawn; the up control only for a mesh.
function showDataChoice(info) {
  if ($('probe')) selectValue($('probe'), info.probe || '');
  if ($('mesh')) selectValue($('mesh'), info.mesh || '');
  showUpChoice(info);
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

// A SceneChoice says the whole choice (an empty field is the scene's own):
// what is in effect, with `change` on top.
function sceneChoice(change) {
  const info = state.sceneInfo || { name: choices.scene || '' };
  return { scene: info.name, probe: info.probe || '', mesh: info.mesh || '', up: info.mesh ? info.up || '' : '',
    ...change };
}

// Other objects: poses sent before the answer would move them with the old
// objects' camera, so none carry a view until SceneInfo comes.
function awaitObjects(choice) {
  view.pendingScene = pendingOf(choice.scene, choice.mesh);
  touched.camera = false;
  touched.light = false;
  touched.objects.clear();
}

// Another scene: its own objects, under the probe chosen (if any).
function chooseScene(name) {
  if (state.sceneInfo && name === state.sceneInfo.name && !state.sceneInfo.mesh) return;
  choices.scene = name;
  const choice = sceneChoice({ scene: name, mesh: '', up: '' });
  awaitObjects(choice);
  expectBuild(`scene ${name}`);
  if (send({ scene: choice })) noteChange();
}

// Another probe: the same objects under its light ('' the scene's own).
function chooseProbe(probe) {
  expectBuild(probe ? `probe ${probe}` : 'the scene\'s own light');
  if (send({ scene: sceneChoice({ probe }) })) noteChange();
}

// A mesh instead of the scene's objects ('' back to them), up as guessed.
function chooseMesh(mesh) {
  const choice = sceneChoice({ mesh, up: '' });
  awaitObjects(choice);
  expectBuild(mesh ? `mesh ${mesh}` : `scene ${choice.scene}`);
  if (send({ scene: choice })) noteChange();
}

// The mesh the other way up: its file's Y or Z stood along the view's up.
function chooseUp(up) {
  upChosen = true;
  const choice = sceneChoice({ up });
  awaitObjects(choice);
  expectBuild(`${choice.mesh} with ${up} up`);
  if (send({ scene: choice })) noteChange();
}

function chooseMaterial(index, spec) {
  if (!state.sceneInfo) return;
  const o = state.sceneInfo.objects.find((x) => x.index === index);
  expectBuild(`${spec} on ${(o && o.name) || `object ${index}`}`);
  if (send({ scene: sceneChoice({ objectMaterials: { [index]: spec } }) })) noteChange();
}

$('scene').addEventListener('change', () => chooseScene($('scene').value));
