// The address says the whole view, so that it opens the same picture
// elsewhere: the scene, its objects' materials, the rendering choices
// (method, level, k, exposure, tone curve) and what the user steered (the
// camera's orbit, the light's turn, each turned object's). The address is
// rewritten (history.replaceState, no reload) a moment after a change; a
// page opened at it asks for the same in its Hello and sends the steered
// view as its first pose (applyAddressView). page_params.js parses and
// checks the parameters; the resolution control writes its own.
import { viewParameters } from './page_params.js';
import { choices, page, state } from './page_state.js';
import { applyView, viewSnapshot } from './view.js';

// The keys this module owns in the address.
const OWNED = ['scene', 'probe', 'mesh', 'up', 'mat', 'method', 'level', 'k', 'exposure', 'tone', 'cam', 'light', 'obj'];

function currentParameters() {
  const info = state.sceneInfo;
  return viewParameters({
    scene: info ? info.name : choices.scene,
    probe: info ? info.probe : '', mesh: info ? info.mesh : '', up: info ? info.up : '',
    // Only what the server offers: an object's material that is not offered
    // is its scene's own (the page offers nothing else), which a Hello need
    // not ask for (and could not: only offered specs are taken).
    materials: info ? [...info.objects].sort((a, b) => a.index - b.index)
      .filter((o) => state.welcome.materials.includes(o.material)).map((o) => ({ index: o.index, spec: o.material })) : [],
    method: choices.method, level: choices.level, k: choices.k, exposure: choices.exposure, tone: choices.tone,
    snapshot: viewSnapshot(),
  });
}

// The address brought up to date with the view, if it changed.
export function writeAddress() {
  if (!state.welcome) return;  // nothing is known of the server's scene yet
  const params = new URLSearchParams(location.search);
  const want = currentParameters();
  for (const key of OWNED) {
    if (key in want) params.set(key, want[key]);
    else params.delete(key);
  }
  const search = params.toString() ? `?${params}` : '';
  if (search !== location.search) {
    history.replaceState(null, '', search || location.pathname);
    state.addressWrites++;
  }
}

let applied = false;
// The first Welcome of the page: the view the address named, over the
// scene's own (once: a reconnect keeps the view the user has since).
export function applyAddressView() {
  if (applied) return;
  applied = true;
  if (page.scene && state.sceneInfo && state.sceneInfo.name !== page.scene) return;  // another scene came
  applyView({ camera: page.camera, light: page.light, objects: page.objects });
}

// A change lands in the address within this long.
export const ADDRESS_MS = 500;
export function startAddress() {
  setInterval(writeAddress, ADDRESS_MS);
}
