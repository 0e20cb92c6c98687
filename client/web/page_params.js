// The page's parameters (?size=…&encoding=…), checked before the page
// connects: a bad one is reported at once, naming the parameter and its valid
// values, instead of a Hello the server would refuse (or one never sent).
// Pure, so that node tests it (tests/e2e/web_client_test.mjs).
//
// Ranges only the server knows (level, size, exposure, scene names) are left
// to it: its Error names them, and the page shows that.

// What the browser can draw: EXR frames are linear floats, not an image type.
// H.264 is drawn through WebCodecs where the browser has it, else the page
// asks for JPEG and says why (h264_view.js).
export const ENCODINGS = ['jpeg', 'png', 'raw', 'h264'];
// The resolution control (stream_size.js): the view's own size, or lines.
export const RESOLUTION_CHOICES = ['auto', '360p', '540p', '720p', '1080p'];

export const PARAMETERS = {
  size: 'WIDTHxHEIGHT, e.g. 256x256 (a fixed size instead of one that fits the view)',
  resolution: RESOLUTION_CHOICES.join(', '),
  encoding: ENCODINGS.join(', '),
  quality: 'a JPEG quality 1..100',
  fps: 'frames per second at most, a number > 0',
  token: 'the server\'s --token',
  method: '',  // filled from the schema's RotationMethod values
  level: 'a map level, e.g. 4 (the server says its range)',
  k: 'light coefficients kept, a whole number > 0',
  exposure: '"auto" or stops, e.g. -1.5',
  scene: 'a scene the server offers, e.g. default',
  // The view itself (share_url.js keeps them in the address as the user
  // steers, so that the address opens the same view elsewhere).
  cam: 'AZIMUTH,ELEVATION,DISTANCE: the camera\'s orbit about the scene\'s target in degrees and scene units, e.g. 30,15,4.2',
  light: 'the light\'s turn about +Y in degrees, e.g. 90',
  obj: 'objects\' turns, INDEX:X:Y:Z in degrees, comma-separated, e.g. 0:10:45:0',
  mat: 'objects\' materials, INDEX:SPEC comma-separated, e.g. 0:phong:64,1:ggx:0.3 (with ?scene=)',
  tone: '',  // filled from the schema's ToneCurve values
  probe: 'a probe the server offers (serve --data), by name',
  mesh: 'a mesh the server offers (serve --data), by name',
  up: 'the mesh\'s up axis, y or z (with ?mesh=)',
};

function wholeNumber(text) {
  return /^\d+$/.test(text) ? Number(text) : NaN;
}

// search: location.search (or a URLSearchParams); methods: the rotation
// method names the schema defines ("fused", "haar", …); tones: its tone
// curve names ("reinhard", …).
// Returns the choices and `errors`, one line per bad parameter.
export function parsePageParameters(search, { methods, tones = ['reinhard', 'aces', 'agx'] }) {
  const params = search instanceof URLSearchParams ? search : new URLSearchParams(search);
  const out = {
    width: 0, height: 0, resolution: 'auto', encoding: 'jpeg', quality: 0, fps: 0, token: '',
    method: '', level: 0, k: 0, exposure: { auto: true, stops: 0 }, scene: '',
    camera: null,    // {azimuth, elevation, distance}: degrees, degrees, scene units
    light: null,     // degrees about +Y
    objects: [],     // [{index, x, y, z}] degrees
    materials: [],   // [{index, spec}]
    tone: '',
    probe: '', mesh: '', up: '',
    errors: [],
  };
  const bad = (name, value, valid) => {
    out.errors.push({ parameter: name, value, message: `?${name}=${value} is not valid: ${valid}` });
  };
  const valid = { ...PARAMETERS, method: `use one of ${methods.join(', ')}`, tone: `use one of ${tones.join(', ')}` };
  for (const name of new Set(params.keys())) {
    if (!(name in valid)) {
      out.errors.push({ parameter: name, value: params.get(name),
                        message: `?${name} is not a parameter of this page (it takes ${Object.keys(valid).join(', ')})` });
    } else if (params.getAll(name).length > 1) {
      out.errors.push({ parameter: name, value: params.getAll(name).join(','), message: `?${name} is given more than once` });
    }
  }
  const get = (name) => params.get(name);

  const size = get('size');
  if (size !== null) {
    const m = /^(\d+)x(\d+)$/.exec(size);
    if (!m || Number(m[1]) < 1 || Number(m[2]) < 1) bad('size', size, 'use WIDTHxHEIGHT, e.g. 256x256');
    else { out.width = Number(m[1]); out.height = Number(m[2]); }
  }
  const resolution = get('resolution');
  if (resolution !== null) {
    if (!RESOLUTION_CHOICES.includes(resolution)) bad('resolution', resolution, `use one of ${valid.resolution}`);
    else if (size !== null) bad('resolution', resolution, 'give ?size= (a fixed size) or ?resolution=, not both');
    else out.resolution = resolution;
  }
  const encoding = get('encoding');
  if (encoding !== null) {
    if (ENCODINGS.includes(encoding)) out.encoding = encoding;
    else if (encoding === 'exr') bad('encoding', encoding, `the browser cannot show EXR frames (linear floats); use one of ${valid.encoding}`);
    else bad('encoding', encoding, `use one of ${valid.encoding}`);
  }
  const quality = get('quality');
  if (quality !== null) {
    const q = wholeNumber(quality);
    if (!(q >= 1 && q <= 100)) bad('quality', quality, 'use a JPEG quality 1..100');
    else out.quality = q;
  }
  const fps = get('fps');
  if (fps !== null) {
    const f = Number(fps);
    if (fps.trim() === '' || !Number.isFinite(f) || f <= 0) bad('fps', fps, 'use a number of frames per second > 0, e.g. 30');
    else out.fps = f;
  }
  if (get('token') !== null) out.token = get('token');
  const method = get('method');
  if (method !== null) {
    if (methods.includes(method)) out.method = method;
    else bad('method', method, valid.method);
  }
  const level = get('level');
  if (level !== null) {
    const n = wholeNumber(level);
    if (!(n >= 1)) bad('level', level, 'use a whole number, e.g. 4 (the server says its range)');
    else out.level = n;
  }
  const k = get('k');
  if (k !== null) {
    const n = wholeNumber(k);
    if (!(n >= 1)) bad('k', k, 'use a whole number of light coefficients > 0, e.g. 256');
    else out.k = n;
  }
  const exposure = get('exposure');
  if (exposure !== null) {
    const stops = Number(exposure);
    if (exposure === 'auto') out.exposure = { auto: true, stops: 0 };
    else if (exposure.trim() !== '' && Number.isFinite(stops)) out.exposure = { auto: false, stops };
    else bad('exposure', exposure, 'use "auto" or a number of stops, e.g. -1.5');
  }
  const scene = get('scene');
  if (scene !== null) {
    if (scene === '') bad('scene', scene, 'name a scene the server offers, e.g. default');
    else out.scene = scene;
  }
  const numbers = (text, count) => {
    const parts = text.split(',');
    const values = parts.map((p) => (p.trim() === '' ? NaN : Number(p)));
    return parts.length === count && values.every(Number.isFinite) ? values : null;
  };
  const cam = get('cam');
  if (cam !== null) {
    const v = numbers(cam, 3);
    if (!v || !(v[2] > 0) || Math.abs(v[1]) >= 90) bad('cam', cam, `${valid.cam}, the elevation within ±90 and the distance > 0`);
    else out.camera = { azimuth: v[0], elevation: v[1], distance: v[2] };
  }
  const light = get('light');
  if (light !== null) {
    const v = numbers(light, 1);
    if (!v) bad('light', light, `use ${valid.light}`);
    else out.light = v[0];
  }
  const obj = get('obj');
  if (obj !== null) {
    const turns = obj.split(',').map((t) => t.split(':'));
    const ok = turns.every((t) => t.length === 4 && /^\d+$/.test(t[0]) && t.slice(1).every((x) => x.trim() !== '' && Number.isFinite(Number(x))));
    if (!ok || new Set(turns.map((t) => t[0])).size !== turns.length) bad('obj', obj, `use ${valid.obj}, each object once`);
    else out.objects = turns.map((t) => ({ index: Number(t[0]), x: Number(t[1]), y: Number(t[2]), z: Number(t[3]) }));
  }
  const mat = get('mat');
  if (mat !== null) {
    const pairs = mat.split(',').map((m) => /^(\d+):(.+)$/.exec(m));
    if (pairs.some((m) => !m) || new Set(pairs.map((m) => m[1])).size !== pairs.length) bad('mat', mat, `use ${valid.mat}, each object once`);
    else if (scene === null) bad('mat', mat, 'give ?scene= too: the materials are the named scene\'s objects\'');
    else out.materials = pairs.map((m) => ({ index: Number(m[1]), spec: m[2] }));
  }
  for (const name of ['probe', 'mesh']) {
    const value = get(name);
    if (value === null) continue;
    if (value === '') bad(name, value, `name ${valid[name]}`);
    else if (scene === null) bad(name, value, `give ?scene= too: the ${name} replaces part of a scene`);
    else out[name] = value;
  }
  const up = get('up');
  if (up !== null) {
    if (up !== 'y' && up !== 'z') bad('up', up, 'use y or z');
    else if (get('mesh') === null) bad('up', up, 'give ?mesh= too: the up axis is a mesh\'s');
    else out.up = up;
  }
  const tone = get('tone');
  if (tone !== null) {
    if (tones.includes(tone)) out.tone = tone;
    else bad('tone', tone, valid.tone);
  }
  return out;
}

// The other way: the parameters that say a view, for the address
// (share_url.js); parsePageParameters reads them back.
// Enough digits that the view comes back to well under a pixel.
const fixed = (x, digits) => String(Number(x.toFixed(digits)));

// The address's parameters for the view now (pure: `materials` [{index,
// spec}], `snapshot` view.js viewSnapshot()).
export function viewParameters({ scene, probe, mesh, up, materials, method, level, k, exposure, tone, snapshot }) {
  const p = {};
  if (scene) p.scene = scene;
  if (probe) p.probe = probe;
  if (mesh) p.mesh = mesh;
  if (mesh && up) p.up = up;
  if (materials && materials.length) p.mat = materials.map((m) => `${m.index}:${m.spec}`).join(',');
  if (method) p.method = method;
  if (level > 0) p.level = String(level);
  if (k > 0) p.k = String(k);
  if (exposure) p.exposure = exposure.auto ? 'auto' : fixed(exposure.stops, 3);
  if (tone) p.tone = tone;
  if (snapshot.camera) {
    const c = snapshot.camera;
    p.cam = [fixed(c.azimuth, 4), fixed(c.elevation, 4), fixed(c.distance, 5)].join(',');
  }
  if (snapshot.light !== null) p.light = fixed(snapshot.light, 4);
  if (snapshot.objects.length) {
    p.obj = snapshot.objects.map((o) => [o.index, fixed(o.x, 4), fixed(o.y, 4), fixed(o.z, 4)].join(':')).join(',');
  }
  return p;
}
