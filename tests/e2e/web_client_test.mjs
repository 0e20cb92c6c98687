// Unit tests of the browser client's pure parts, in node (no browser): the
// HUD's frame window (client/web/frame_stats.js) with made-up arrival times,
// the page-parameter checks (client/web/page_params.js), the view's orbit
// maths and pinch (client/web/orbit.js), the stream's size and auto's rule
// (client/web/stream_size.js), the words of a build and of an idle stream
// (client/web/build_status.js), and the page's H.264 view
// (client/web/h264_view.js) over a stand-in WebCodecs VideoDecoder.
//
// usage: node web_client_test.mjs
import assert from 'node:assert/strict';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const web = join(resolve(dirname(fileURLToPath(import.meta.url)), '..', '..'), 'client', 'web');
const { FrameWindow, backoffMs, formatNumber, formatStops } = await import(pathToFileURL(join(web, 'frame_stats.js')));
const { parsePageParameters, viewParameters } = await import(pathToFileURL(join(web, 'page_params.js')));
const { H264View, helloEncoding } = await import(pathToFileURL(join(web, 'h264_view.js')));
const { DRAG_DEGREES_PER_PIXEL, dragOrbit, orbitEye, orbitFromCamera, pinchOrbit, v3, zoomOrbit } =
  await import(pathToFileURL(join(web, 'orbit.js')));
const { AutoResolution, FIRST_LIMITS, FPS_FLOOR, autoSteps, fpsFloor, frameSize, sizeWithin } =
  await import(pathToFileURL(join(web, 'stream_size.js')));
const { describeBuild, describeFrame, formatSeconds, idleText } = await import(pathToFileURL(join(web, 'build_status.js')));
const { takesTyping } = await import(pathToFileURL(join(web, 'shortcuts.js')));

const tests = [];
const test = (name, fn) => tests.push({ name, fn });

// Frames every `intervalMs` from t0: the window after each one, sampled
// every 100 ms between frames as the HUD does (every 250 ms).
function stream(w, { t0 = 0, count, intervalMs, sample }) {
  let t = t0;
  for (let i = 0; i < count; i++) {
    w.add(t, { bytes: 1000, latencyMs: 50, serverMs: 40, stages: [{ name: 'fused', ms: 30 }, { name: 'encode', ms: 1 }] });
    if (sample) for (let s = t; s < t + intervalMs; s += 100) sample(w.summary(s), s);
    t += intervalMs;
  }
  return t - intervalMs;  // the last frame's time
}

test('no rate until three frames, then the stream rate', () => {
  const w = new FrameWindow();
  assert.equal(w.summary(0).fps, null);
  w.add(0, { bytes: 500 });
  assert.equal(w.summary(10).fps, null);
  assert.equal(formatNumber(w.summary(10).fps), '—');
  w.add(100, { bytes: 500 });
  assert.equal(w.summary(110).fps, null);
  w.add(200, { bytes: 500 });
  assert.equal(w.summary(210).fps, 10);
  // kbit/s: the bytes after the first frame over the span (1000 B in 200 ms = 40 kbit/s).
  assert.equal(w.summary(210).kbps, 40);
});

test('30 fps: the rate over the last two seconds', () => {
  const w = new FrameWindow();
  stream(w, { count: 200, intervalMs: 1000 / 30 });
  const s = w.summary(200 * 1000 / 30);
  assert.ok(Math.abs(s.fps - 30) < 0.5, `fps ${s.fps}`);
  assert.ok(s.frames >= 55 && s.frames <= 62, `frames in the window: ${s.frames}`);
  assert.equal(s.latencyMs, 50);
  assert.equal(s.serverMs, 40);
  assert.deepEqual(s.stages.map((x) => x.name), ['fused', 'encode']);
  assert.equal(formatNumber(s.fps), '30');
});

test('below 1 fps the number is steady and never 0', () => {
  for (const fps of [0.9, 0.5, 0.2, 0.05]) {
    const w = new FrameWindow();
    const seen = [];
    stream(w, {
      count: 12, intervalMs: 1000 / fps,
      sample: (s) => { if (w.frames.length >= 3) seen.push(s.fps); },
    });
    assert.ok(seen.every((x) => x !== null && x > 0), `${fps} fps: a null or zero rate among ${seen.length} samples`);
    assert.ok(seen.every((x) => Math.abs(x - fps) / fps < 1e-9), `${fps} fps: the rate moved (${Math.min(...seen)}..${Math.max(...seen)})`);
    assert.ok(seen.every((x) => !/^0(\.0*)?$/.test(formatNumber(x))), `${fps} fps printed as ${formatNumber(seen[0])}`);
    assert.ok(!w.summary(w.frames.at(-1).t + 1000 / fps).idle, `${fps} fps: idle one interval after a frame`);
  }
});

test('jittery 0.5 fps stays within 0.4..0.6', () => {
  const w = new FrameWindow();
  let t = 0;
  const seen = [];
  for (let i = 0; i < 30; i++) {
    w.add(t);
    for (let s = t; s < t + 1000; s += 250) if (w.frames.length >= 3) seen.push(w.summary(s).fps);
    t += 2000 + (i % 3 - 1) * 600;  // 1.4, 2.0, 2.6 s
  }
  assert.ok(seen.every((x) => x > 0.4 && x < 0.6), `rates ${Math.min(...seen)}..${Math.max(...seen)}`);
});

test('a pause is idle, not a slow rate; the window restarts after it', () => {
  const w = new FrameWindow();
  const last = stream(w, { count: 60, intervalMs: 40 });
  assert.ok(!w.summary(last + 100).idle);
  const paused = w.summary(last + 10000);
  assert.ok(paused.idle, 'idle 10 s after the last frame');
  assert.ok(Math.abs(paused.fps - 25) < 0.5, `the last stretch's rate is kept (${paused.fps})`);
  // The stream resumes 20 s later: the pause is not averaged in.
  stream(w, { t0: last + 20000, count: 3, intervalMs: 100 });
  const resumed = w.summary(last + 20250);
  assert.equal(resumed.frames, 3);
  assert.ok(Math.abs(resumed.fps - 10) < 1e-9, `fps after the pause ${resumed.fps}`);
  assert.ok(!resumed.idle);
});

test('stage times: the newest frame\'s stages, averaged over the window', () => {
  const w = new FrameWindow();
  w.add(0, { stages: [{ name: 'rotation', ms: 20 }, { name: 'encode', ms: 1 }] });
  w.add(100, { stages: [{ name: 'fused', ms: 4 }, { name: 'encode', ms: 2 }] });
  w.add(200, { stages: [{ name: 'fused', ms: 6 }, { name: 'encode', ms: 3 }] });
  assert.deepEqual(w.summary(200).stages, [{ name: 'fused', ms: 5 }, { name: 'encode', ms: 2 }]);
});

test('number formats', () => {
  assert.equal(formatNumber(null), '—');
  assert.equal(formatNumber(NaN), '—');
  assert.equal(formatNumber(123.4), '123');
  assert.equal(formatNumber(27.26), '27');
  assert.equal(formatNumber(3.33), '3.3');
  assert.equal(formatNumber(0.4), '0.40');
  assert.equal(formatNumber(0.04), '0.040');
  assert.equal(formatStops(1.26), '+1.3');
  assert.equal(formatStops(-0.5), '−0.5');
  assert.equal(formatStops(0.01), '0.0');
  assert.equal(formatStops(NaN), '—');
});

test('reconnect back-off: 1, 2, 4, … 30 s with ±20 % jitter', () => {
  assert.deepEqual([1, 2, 3, 4, 5, 6, 7, 12].map((a) => backoffMs(a, 0.5)),
                   [1000, 2000, 4000, 8000, 16000, 30000, 30000, 30000]);
  assert.equal(backoffMs(1, 0), 800);
  assert.equal(backoffMs(1, 0.999999), 1200);
});

const methods = ['haar', 'spatial', 'matrix', 'table', 'fused', 'splitsum'];

test('page parameters: good ones', () => {
  const p = parsePageParameters('?size=320x200&encoding=raw&quality=90&fps=0.5&token=a%20b&method=haar&level=5&k=64' +
                                '&exposure=-1.5&scene=studio', { methods });
  assert.deepEqual(p.errors, []);
  assert.deepEqual([p.width, p.height, p.encoding, p.quality, p.fps, p.token, p.method, p.level, p.k, p.scene],
                   [320, 200, 'raw', 90, 0.5, 'a b', 'haar', 5, 64, 'studio']);
  assert.deepEqual(p.exposure, { auto: false, stops: -1.5 });
  const defaults = parsePageParameters('', { methods });
  assert.deepEqual(defaults.errors, []);
  // No size: the stream fits the view (resolution auto).
  assert.deepEqual([defaults.width, defaults.height, defaults.resolution, defaults.encoding, defaults.method, defaults.level],
                   [0, 0, 'auto', 'jpeg', '', 0]);
  assert.equal(parsePageParameters('?resolution=720p', { methods }).resolution, '720p');
  assert.deepEqual(defaults.exposure, { auto: true, stops: 0 });
  assert.deepEqual(parsePageParameters('?exposure=auto', { methods }).exposure, { auto: true, stops: 0 });
});

test('page parameters: each bad one is named with its valid values', () => {
  const one = (query) => {
    const p = parsePageParameters(query, { methods });
    assert.equal(p.errors.length, 1, `${query}: ${JSON.stringify(p.errors)}`);
    return p.errors[0];
  };
  let e = one('?method=fast');
  assert.equal(e.parameter, 'method');
  assert.match(e.message, /\?method=fast/);
  assert.match(e.message, /haar, spatial, matrix, table, fused/);
  e = one('?encoding=exr');
  assert.match(e.message, /\?encoding=exr.*cannot show EXR.*jpeg, png, raw, h264/);
  assert.match(one('?encoding=gif').message, /jpeg, png, raw, h264/);
  assert.match(one('?encoding=H264').message, /\?encoding=H264/);  // names are lower case, as the page lists them
  assert.match(one('?size=big').message, /\?size=big.*WIDTHxHEIGHT/);
  assert.match(one('?size=0x10').message, /\?size=0x10/);
  assert.match(one('?level=4.5').message, /\?level=4\.5/);
  assert.match(one('?level=-1').message, /\?level=-1/);
  assert.match(one('?k=0').message, /\?k=0/);
  assert.match(one('?fps=fast').message, /\?fps=fast/);
  assert.match(one('?quality=101').message, /1\.\.100/);
  assert.match(one('?exposure=bright').message, /"auto" or a number of stops/);
  assert.match(one('?scene=').message, /\?scene=/);
  assert.match(one('?methd=haar').message, /\?methd is not a parameter.*method/);
  assert.match(one('?level=3&level=4').message, /more than once/);
  assert.match(one('?resolution=4k').message, /\?resolution=4k.*auto, 360p, 540p, 720p, 1080p/);
  assert.match(one('?resolution=720p&size=64x64').message, /\?size=.*or \?resolution=, not both/);
  assert.equal(parsePageParameters('?method=fast&encoding=exr', { methods }).errors.length, 2);
});

test('page parameters: a view written to the address reads back the same, and a bad one is named', () => {
  const view = { scene: 'default', probe: 'uffizi', mesh: 'lucy', up: 'z', materials: [{ index: 0, spec: 'phong:64' }, { index: 1, spec: 'merl:alum-bronze-sgd' }],
                 method: 'fused', level: 5, k: 128, exposure: { auto: false, stops: -1.25 }, tone: 'aces',
                 snapshot: { camera: { azimuth: -35.123456, elevation: 22.5, distance: 4.874681 }, light: 25,
                             objects: [{ index: 0, x: 15, y: -20, z: 0 }, { index: 2, x: 0, y: 90.5, z: 0 }] } };
  const p = parsePageParameters(new URLSearchParams(viewParameters(view)), { methods: ['fused', 'haar'] });
  assert.deepEqual(p.errors, []);
  assert.equal(p.scene, 'default');
  assert.deepEqual([p.probe, p.mesh, p.up], ['uffizi', 'lucy', 'z']);
  assert.deepEqual(p.materials, view.materials);
  assert.equal(p.method, 'fused');
  assert.equal(p.level, 5);
  assert.equal(p.k, 128);
  assert.deepEqual(p.exposure, { auto: false, stops: -1.25 });
  assert.equal(p.tone, 'aces');
  assert.deepEqual(p.camera, { azimuth: -35.1235, elevation: 22.5, distance: 4.87468 }, 'to 1e-4 degree, 1e-5 unit');
  assert.equal(p.light, 25);
  assert.deepEqual(p.objects, view.snapshot.objects);
  // Nothing steered: no camera, light or objects in the address.
  const still = viewParameters({ ...view, snapshot: { camera: null, light: null, objects: [] } });
  assert.ok(!('cam' in still) && !('light' in still) && !('obj' in still));
  const bad = parsePageParameters('?cam=1,95,3&obj=0:1:2:3,0:4:5:6&mat=0:lambert&tone=filmic&probe=x&up=x', { methods: ['fused'] });
  assert.deepEqual(bad.errors.map((e) => e.parameter), ['cam', 'obj', 'mat', 'probe', 'up', 'tone']);
});

test('page parameters: ?encoding=h264', () => {
  const p = parsePageParameters('?encoding=h264&size=320x240', { methods });
  assert.deepEqual(p.errors, []);
  assert.equal(p.encoding, 'h264');
});

test('H.264 falls back to JPEG, with the reason, where WebCodecs cannot decode it', () => {
  const reason = 'this browser has no WebCodecs VideoDecoder';
  const off = helloEncoding('h264', { supported: false, reason, fallback: 'jpeg' });
  assert.equal(off.encoding, 'jpeg');
  assert.ok(off.note.includes(reason) && off.note.includes('JPEG'), off.note);
  assert.deepEqual(helloEncoding('h264', { supported: true, codec: 'avc1.42E01E' }), { encoding: 'h264', note: '' });
  assert.deepEqual(helloEncoding('png', { supported: false, reason, fallback: 'jpeg' }), { encoding: 'png', note: '' });
});

// ---- the view's orbit (orbit.js) ----------------------------------------------------

const near = (a, b, what, eps = 1e-9) =>
  assert.ok(v3.norm(v3.sub(a, b)) < eps, `${what}: ${JSON.stringify(a)} is not ${JSON.stringify(b)}`);

// Scene cameras as SceneInfo carries them: protobuf leaves zero fields out.
const cameras = {
  'none (the default camera)': undefined,
  'along +Z': { eye: { z: 4 }, target: {}, up: { y: 1 }, fovYDegrees: 40 },
  'off axis, above': { eye: { x: 1, y: 2, z: 3 }, target: { x: 0.5, y: -1 }, up: { y: 1 } },
  'below the target': { eye: { x: -2, y: -3, z: 0.5 }, target: { x: 0.1, y: 0.2, z: 0.3 }, up: { y: 2 } },
  'Z up': { eye: { x: 3, y: -4, z: 2 }, target: {}, up: { z: 1 } },
  'tilted up': { eye: { x: 0, y: 1, z: 6 }, target: { y: 1 }, up: { x: 1, y: 1 } },
  'no up vector': { eye: { x: 2, y: 2, z: 2 }, target: {}, up: {} },
};

test('orbit: a scene camera made an orbit gives back its own eye', () => {
  for (const [name, camera] of Object.entries(cameras)) {
    const o = orbitFromCamera(camera);
    const eye = v3.of(camera && camera.eye, { x: 0, y: 0, z: 5 });
    near(orbitEye(o), eye, name);
    near(o.target, v3.of(camera && camera.target, { x: 0, y: 0, z: 0 }), `${name}: target`);
    assert.ok(Math.abs(o.distance - v3.norm(v3.sub(eye, o.target))) < 1e-9, `${name}: distance ${o.distance}`);
    assert.equal(o.startDistance, o.distance, name);
    // The frame the angles are measured in is orthonormal, with the camera's up as its pole.
    for (const [a, b] of [['up', 'forward'], ['up', 'right'], ['forward', 'right']]) {
      assert.ok(Math.abs(v3.dot(o[a], o[b])) < 1e-12, `${name}: ${a}·${b}`);
    }
    for (const k of ['up', 'forward', 'right']) assert.ok(Math.abs(v3.norm(o[k]) - 1) < 1e-12, `${name}: |${k}|`);
  }
  assert.equal(orbitFromCamera(cameras['along +Z']).fov, 40);
  assert.equal(orbitFromCamera(cameras['off axis, above']).fov, 45);  // fovYDegrees 0: the default
});

test('orbit: a drag of 0 and a wheel turn of 0 leave the view as it was', () => {
  for (const [name, camera] of Object.entries(cameras)) {
    const start = orbitFromCamera(camera);
    // The scene's own view, and one already dragged and zoomed away from it.
    for (const o of [start, { ...start, ...dragOrbit(start, 40, -30), distance: zoomOrbit(start, 300) }]) {
      const eye = orbitEye(o);
      const after = { ...o, ...dragOrbit(o, 0, 0), distance: zoomOrbit(o, 0) };
      assert.equal(after.azimuth, o.azimuth, name);
      assert.equal(after.elevation, o.elevation, name);
      assert.equal(after.distance, o.distance, name);
      near(orbitEye(after), eye, name);
    }
  }
});

test('orbit: a sideways drag circles the target; a full turn comes back', () => {
  for (const [name, camera] of Object.entries(cameras)) {
    const o = orbitFromCamera(camera);
    const height = v3.dot(v3.sub(orbitEye(o), o.target), o.up);
    for (const dx of [1, -37, 250]) {
      const eye = orbitEye({ ...o, ...dragOrbit(o, dx, 0) });
      const d = v3.sub(eye, o.target);
      assert.ok(Math.abs(v3.norm(d) - o.distance) < 1e-9, `${name}, dx ${dx}: off the sphere`);
      assert.ok(Math.abs(v3.dot(d, o.up) - height) < 1e-9, `${name}, dx ${dx}: the height changed`);
    }
    const turn = 360 / DRAG_DEGREES_PER_PIXEL;
    near(orbitEye({ ...o, ...dragOrbit(o, turn, 0) }), orbitEye(o), `${name}: a full turn`, 1e-9);
  }
  // Half a degree per pixel, and the camera moves against the drag: from +Z,
  // a drag of a quarter turn to the right puts the eye at −X.
  const o = orbitFromCamera(undefined);
  near(orbitEye({ ...o, ...dragOrbit(o, 90 / DRAG_DEGREES_PER_PIXEL, 0) }), { x: -5, y: 0, z: 0 }, 'quarter turn');
  assert.ok(orbitEye({ ...o, ...dragOrbit(o, 0, 20) }).y > 0, 'a downward drag raises the eye');
});

test('orbit: an upward or downward drag stops short of the pole', () => {
  for (const [name, camera] of Object.entries(cameras)) {
    const o = orbitFromCamera(camera);
    for (const dy of [1e4, -1e4]) {
      const pose = dragOrbit(o, 0, dy);
      assert.ok(Math.abs(Math.abs(pose.elevation) - 89 * Math.PI / 180) < 1e-12, `${name}, dy ${dy}: ${pose.elevation}`);
      assert.equal(Math.sign(pose.elevation), Math.sign(dy), name);
      // The view direction is never along up, or the camera's frame would be undefined.
      const d = v3.unit(v3.sub(orbitEye({ ...o, ...pose }), o.target));
      assert.ok(v3.norm(v3.cross(d, o.up)) > 0.01, `${name}, dy ${dy}: along the pole`);
    }
  }
});

test('orbit: the wheel keeps the distance within a fifth and ten times the scene\'s own', () => {
  const o = orbitFromCamera(cameras['off axis, above']);
  const d = o.startDistance;
  assert.ok(zoomOrbit(o, 100) > d && zoomOrbit(o, -100) < d, 'wheel down moves away, up comes closer');
  assert.ok(Math.abs(zoomOrbit({ ...o, distance: zoomOrbit(o, 250) }, -250) - d) < 1e-12, 'there and back');
  assert.equal(zoomOrbit(o, 1e5), 10 * d);
  assert.equal(zoomOrbit(o, -1e5), 0.2 * d);
  // The limits are the scene's distance, not the current one.
  assert.equal(zoomOrbit({ ...o, distance: 10 * d }, 1e5), 10 * d);
  const far = { ...o, distance: zoomOrbit(o, 500) };
  assert.ok(Math.abs(v3.norm(v3.sub(orbitEye(far), o.target)) - far.distance) < 1e-9, 'the eye is that far');
});

test('pinch: fingers spreading bring the eye closer by their ratio, within the wheel\'s range', () => {
  const o = orbitFromCamera(cameras['off axis, above']);
  const d = o.startDistance;
  assert.ok(Math.abs(pinchOrbit(o, 100, 200) - d / 2) < 1e-12, 'twice as far apart: half the distance');
  assert.ok(Math.abs(pinchOrbit(o, 200, 100) - 2 * d) < 1e-12, 'pinched together: twice the distance');
  assert.equal(pinchOrbit(o, 100, 100), d);
  assert.equal(pinchOrbit(o, 1, 1000), 0.2 * d);
  assert.equal(pinchOrbit(o, 1000, 1), 10 * d);
  assert.equal(pinchOrbit(o, 0, 100), d, 'no distance yet: no change');
});

// ---- the stream's size (stream_size.js) ------------------------------------------------

const LIMITS = { maxWidth: 2048, maxHeight: 2048, maxPixels: 4194304 };

test('size: auto asks for the view in device pixels, even, within the limits', () => {
  assert.deepEqual(frameSize('auto', { cssWidth: 964, cssHeight: 784, dpr: 1 }, LIMITS), { width: 964, height: 784 });
  assert.deepEqual(frameSize('auto', { cssWidth: 377, cssHeight: 301, dpr: 2 }, LIMITS), { width: 754, height: 602 });
  // Even sides (H.264 takes only those): an odd view gives up its last pixel.
  assert.deepEqual(frameSize('auto', { cssWidth: 377, cssHeight: 301, dpr: 1 }, LIMITS), { width: 376, height: 300 });
  // A phone at 3 device pixels per CSS pixel.
  const phone = frameSize('auto', { cssWidth: 378, cssHeight: 382, dpr: 3 }, LIMITS);
  assert.deepEqual(phone, { width: 1134, height: 1146 });
  // Over the pixel budget: the largest size with the view's aspect under it.
  const big = frameSize('auto', { cssWidth: 1900, cssHeight: 1000, dpr: 2 }, LIMITS);
  assert.ok(big.width * big.height <= LIMITS.maxPixels && big.width <= 2048, JSON.stringify(big));
  assert.ok(Math.abs(big.width / big.height - 1.9) < 0.01, JSON.stringify(big));
  assert.ok(big.width % 2 === 0 && big.height % 2 === 0);
  // The budget the first Hello assumes, before Welcome says the server's.
  const first = frameSize('auto', { cssWidth: 1900, cssHeight: 1000, dpr: 2 }, FIRST_LIMITS);
  assert.ok(first.width * first.height <= 1280 * 720, JSON.stringify(first));
  // Protobuf's uint64 arrives as a Long: its number is used.
  const long = { maxWidth: 4096, maxHeight: 4096, maxPixels: { toNumber: () => 10000 } };
  const small = sizeWithin(1, 1000, long);
  assert.ok(small.width * small.height <= 10000 && small.width === small.height, JSON.stringify(small));
});

test('size: a fixed resolution is that many lines with the view\'s aspect; auto\'s steps lie below the view', () => {
  const view = { cssWidth: 1280, cssHeight: 720, dpr: 1 };
  assert.deepEqual(frameSize('360p', view, LIMITS), { width: 640, height: 360 });
  assert.deepEqual(frameSize('1080p', view, LIMITS), { width: 1920, height: 1080 });
  assert.deepEqual(frameSize('auto', view, LIMITS, 540), { width: 960, height: 540 });
  assert.deepEqual(frameSize('auto', { cssWidth: 400, cssHeight: 186, dpr: 1 }, LIMITS, 540), { width: 400, height: 186 },
                   'a step above the view changes nothing');
  assert.deepEqual(autoSteps(784), [Infinity, 720, 540, 360, 270, 180]);
  assert.deepEqual(autoSteps(2160), [Infinity, 1080, 720, 540, 360, 270, 180]);
  assert.deepEqual(autoSteps(150), [Infinity]);
  assert.equal(fpsFloor(30), FPS_FLOOR);
  assert.equal(fpsFloor(10), 8);
});

// Auto's steps for `view`, as the page computes them (resolution.js stepsNow).
const VIEW = { cssWidth: 1280, cssHeight: 720, dpr: 1 };  // 1280×720: 0.92 Mpx
const stepsOf = (view) => autoSteps(view.cssHeight * view.dpr).map((lines) => {
  const s = frameSize('auto', view, LIMITS, lines);
  return { lines, pixels: s.width * s.height };
});
// A made-up server: `msPerMegapixel` per million pixels, and 5 ms besides.
const msAt = (msPerMegapixel, pixels) => 5 + msPerMegapixel * pixels / 1e6;

// Auto's rule against that server while the view moves (a drag from
// `start`), frames every `interval` ms; the size asked for after each.
function runAuto(auto, { msPerMegapixel, frames, start = 0, interval = 100, view = VIEW }) {
  const steps = stepsOf(view);
  let t = start;
  const sizes = [];
  auto.moved(t, steps, FPS_FLOOR);
  let size = frameSize('auto', view, LIMITS, auto.wantedCap());
  auto.asked(size.width * size.height, t);
  for (let i = 0; i < frames; i++, t += interval) {
    const pixels = size.width * size.height;
    const changed = auto.frame(t, { pixels, serverMs: msAt(msPerMegapixel, pixels) }, steps, FPS_FLOOR);
    if (changed !== null) {
      size = frameSize('auto', view, LIMITS, auto.wantedCap());
      auto.asked(size.width * size.height, t);
    }
    sizes.push(size.height);
  }
  return { sizes, t };
}

test('auto: while the view moves, a server too slow for the floor steps down to the largest size that holds it', () => {
  const auto = new AutoResolution();
  // No frame before the move to estimate from. 1280×720 at 200 ms/Mpx:
  // 189 ms, 5 fps. 360p (0.23 Mpx): 51 ms, 19.6 fps, the largest that
  // holds 15 fps (540p: 108 ms).
  const { sizes } = runAuto(auto, { msPerMegapixel: 200, frames: 20 });
  assert.equal(sizes[0], 720);
  assert.equal(sizes.at(-1), 360, sizes.join(' '));
  assert.equal(auto.label(), 'auto ≤360p (moving)');
  assert.ok(sizes.indexOf(360) <= 1, `it steps after two frames: ${sizes.join(' ')}`);
  // It stays there: 360p holds the floor and 540p would not.
  assert.equal(new Set(sizes.slice(sizes.indexOf(360))).size, 1);
});

test('auto: a fast server keeps the view\'s own size; one that gets faster is stepped back up, one step at a time', () => {
  const fast = new AutoResolution();
  const kept = runAuto(fast, { msPerMegapixel: 20, frames: 30 }).sizes;
  assert.ok(kept.every((h) => h === 720), kept.join(' '));
  assert.equal(fast.label(), 'auto: full size (moving)');

  const auto = new AutoResolution();
  const slow = runAuto(auto, { msPerMegapixel: 500, frames: 20 });
  assert.equal(slow.sizes.at(-1), 180, slow.sizes.join(' '));
  const downAt = auto.changedAt;
  // The server frees up (another session ended) during a long drag: 270p,
  // then 360p, … back to the view's size.
  const start = slow.t + 100;
  const up = runAuto(auto, { msPerMegapixel: 20, frames: 200, start }).sizes;
  const steps = up.filter((h, i) => i === 0 || h !== up[i - 1]);
  assert.deepEqual(steps, [180, 270, 360, 540, 720], up.join(' '));
  // Each step only after the size has held for holdMs (3 s).
  let last = downAt;
  for (const h of steps.slice(1)) {
    const at = start + 100 * up.indexOf(h);
    assert.ok(at - last >= auto.holdMs, `${h}p ${at - last} ms after the step before`);
    last = at;
  }
});

test('auto: a move starts at the step one frame\'s time says holds the floor, before its first pose', () => {
  const steps = stepsOf(VIEW);
  const full = steps[0].pixels;
  const auto = new AutoResolution();
  // A still view: slow frames at its own size step nothing (a scene switch,
  // a setting: no move, no step).
  auto.asked(full, 0);
  for (let i = 0; i < 10; i++) assert.equal(auto.frame(500 * i, { pixels: full, serverMs: msAt(200, full) }, steps, FPS_FLOOR), null);
  assert.equal(auto.wantedCap(), Infinity);
  assert.equal(auto.capLines, Infinity);
  // The move: the last frame (189 ms at 0.92 Mpx) says 360p holds 15 fps.
  assert.equal(auto.moved(5000, steps, FPS_FLOOR), true, 'the step is asked for at the move\'s first event');
  assert.equal(auto.wantedCap(), 360);
  assert.equal(auto.moved(5016, steps, FPS_FLOOR), false, 'later events of the move ask nothing');
  // A fresh page's one frame, 1.9 s: no step holds the floor, the smallest.
  const fresh = new AutoResolution();
  fresh.frame(0, { pixels: full, serverMs: 1870 }, steps, FPS_FLOOR);
  assert.equal(fresh.moved(10, steps, FPS_FLOOR), true);
  assert.equal(fresh.wantedCap(), 180);
  // A fast server: the move keeps the view's own size.
  const fast = new AutoResolution();
  fast.frame(0, { pixels: full, serverMs: 30 }, steps, FPS_FLOOR);
  assert.equal(fast.moved(10, steps, FPS_FLOOR), false);
  assert.equal(fast.wantedCap(), Infinity);
  // A frame with no time (the first) is nothing to estimate from: the move
  // starts at the view's size, and its frames step it.
  const blind = new AutoResolution();
  blind.frame(0, { pixels: full, serverMs: NaN }, steps, FPS_FLOOR);
  assert.equal(blind.moved(10, steps, FPS_FLOOR), false);
  // Between moves, up only as the rule allows: after 180p, a full-size
  // frame of 400 ms says 270p (56 ms) holds the floor, but not with 1.5×
  // to spare: the next move stays at 180p. At 250 ms, 270p (35 ms) has the
  // room, and is taken once 180p has held for 3 s.
  assert.equal(fresh.still(), true);
  fresh.frame(1000, { pixels: full, serverMs: 400 }, steps, FPS_FLOOR);
  fresh.moved(5000, steps, FPS_FLOOR);
  assert.equal(fresh.wantedCap(), 180);
  fresh.still();
  fresh.frame(6000, { pixels: full, serverMs: 250 }, steps, FPS_FLOOR);
  fresh.moved(6500, steps, FPS_FLOOR);
  assert.equal(fresh.wantedCap(), 270);
  fresh.still();
  fresh.frame(7000, { pixels: full, serverMs: 150 }, steps, FPS_FLOOR);
  fresh.moved(7500, steps, FPS_FLOOR);
  assert.equal(fresh.wantedCap(), 270, '360p has the room, but 270p was taken 1 s ago');
});

test('auto: still after any change, the view\'s own size; the next move back at its step', () => {
  const steps = stepsOf(VIEW);
  const full = steps[0].pixels;
  const small = steps.at(-1).pixels;
  const auto = new AutoResolution();
  auto.frame(0, { pixels: full, serverMs: 1500 }, steps, FPS_FLOOR);
  assert.equal(auto.label(full, full), 'auto: full size (still)');
  assert.equal(auto.moved(100, steps, FPS_FLOOR), true);
  assert.equal(auto.wantedCap(), 180);
  auto.asked(small, 100);
  assert.equal(auto.label(full, small), 'auto ≤180p (moving)');
  // Right after the drag, a scene switch, a material and a setting are
  // answered at the step (slow ones: the smallest step stays); a resize
  // asks for the step of the new view.
  for (const ms of [300, 250, 280]) assert.equal(auto.frame(900, { pixels: small, serverMs: ms }, steps, FPS_FLOOR), null);
  auto.asked(small - 2 * 180, 1000);
  // STILL_MS after the last move: the view's own size, whatever changed.
  assert.equal(auto.still(), true);
  assert.equal(auto.wantedCap(), Infinity);
  assert.equal(auto.still(), false, 'still twice asks once');
  assert.equal(auto.label(small, full), 'auto: sharpening…', 'the full-size frame not shown yet');
  assert.equal(auto.label(full, full), 'auto: full size (still)');
  // Frames of the still view, however slow, keep its size.
  auto.asked(full, 2000);
  for (let i = 0; i < 8; i++) assert.equal(auto.frame(2000 + 100 * i, { pixels: full, serverMs: 2000 }, steps, FPS_FLOOR), null);
  assert.equal(auto.wantedCap(), Infinity);
  assert.equal(auto.samples.length, 0, 'not counted for the next move\'s rule');
  // The next move goes back to a step before its pose (from the last frame).
  assert.equal(auto.moved(5000, steps, FPS_FLOOR), true);
  assert.equal(auto.wantedCap(), 180);
  // A view never stepped down has nothing to sharpen.
  const fast = new AutoResolution();
  fast.frame(0, { pixels: full, serverMs: 20 }, steps, FPS_FLOOR);
  fast.moved(10, steps, FPS_FLOOR);
  assert.equal(fast.still(), false);
  assert.equal(fast.wantedCap(), Infinity);
});

test('auto: frames of another size, and frames with no time, are not counted', () => {
  const auto = new AutoResolution();
  const steps = [{ lines: Infinity, pixels: 1000 }, { lines: 180, pixels: 250 }];
  auto.moved(0, steps, 15);
  auto.asked(1000, 0);
  for (let i = 0; i < 10; i++) {
    assert.equal(auto.frame(i, { pixels: 4000, serverMs: 500 }, steps, 15), null);  // an old size's
    assert.equal(auto.frame(i, { pixels: 1000, serverMs: NaN }, steps, 15), null);  // the first frame
  }
  assert.equal(auto.samples.length, 0);
  // A (lower) median, so one slow frame among quick ones does not step.
  for (const ms of [20, 20, 900, 20, 900, 20]) assert.equal(auto.frame(20, { pixels: 1000, serverMs: ms }, steps, 15), null);
  const once = new AutoResolution();
  once.moved(0, steps, 15);
  once.asked(1000, 0);
  assert.equal(once.frame(10, { pixels: 1000, serverMs: 900 }, steps, 15), null, 'one slow frame alone does not step');
  assert.equal(once.frame(20, { pixels: 1000, serverMs: 900 }, steps, 15), 180, 'two do');
});

// ---- what the page says of a build and of an idle stream (build_status.js) -------------

test('build: the stage in words, its share, the time left, never 100 % before the end', () => {
  const d = describeBuild({ stage: 'visibility bunny', stageIndex: 1, done: 14379, total: 35947, fraction: 0.4,
                            elapsedSeconds: 12.3, estimatedStageSecondsLeft: 80 }, 'level 6');
  assert.equal(d.title, 'preparing level 6');
  assert.equal(d.stage, 'visibility of bunny');
  assert.equal(d.fraction, 0.4);
  assert.equal(d.percent, 40);
  assert.equal(d.detail, 'step 2 · 14379 of 35947 · about 1 min 20 s left in this step · 12 s so far');
  assert.equal(describeBuild({ stage: 'slices ball', total: 10, done: 10, fraction: 1 }).percent, 99);
  assert.equal(describeBuild({ stage: 'slices ball' }).stage, 'BRDF slice table of ball');
  assert.equal(describeBuild({ stage: 'rotators torus' }).stage, 'rotation tables of torus');
  // Unknown total: no share (an indeterminate bar); an unknown step is said as the server said it.
  const u = describeBuild({ stage: 'lights sky', total: 0, fraction: 0 });
  assert.equal(u.fraction, null);
  assert.equal(u.percent, null);
  assert.equal(u.stage, 'lights sky');
  assert.equal(u.title, 'preparing the renderer');
  // A Long (uint64) total and done.
  assert.equal(describeBuild({ stage: 'x', done: { toString: () => '5' }, total: { toString: () => '20' }, fraction: 0.25 }).percent, 25);
});

test('build with a plan: the build\'s share in the title, the step counted in the plan, the build\'s time left', () => {
  const d = describeBuild({ stage: 'visibility bunny', stageIndex: 1, done: 14379, total: 35947, fraction: 0.4,
                            elapsedSeconds: 12.3, estimatedStageSecondsLeft: 80, buildFraction: 0.55,
                            stages: ['slices bunny', 'visibility bunny', 'slices ground', 'visibility ground'],
                            estimatedBuildSecondsLeft: 95 }, 'level 6');
  assert.equal(d.fraction, 0.55, 'the bar is the whole build\'s');
  assert.equal(d.percent, 55);
  assert.equal(d.title, 'preparing level 6: 55 %');
  assert.equal(d.stageLine, 'visibility of bunny · this step 40 %');
  assert.equal(d.detail, 'step 2 of 4 · about 1 min 35 s left · 12 s so far');
  // Without a plan, the stage's own share on the stage line, as before.
  assert.equal(describeBuild({ stage: 'slices ball', total: 10, done: 5, fraction: 0.5 }).stageLine, 'BRDF slice table of ball: 50 %');
  // A stage outside the plan (warm-up): no step number in the plan.
  assert.equal(describeBuild({ stage: 'warm-up', total: 1, done: 0, fraction: 0, buildFraction: 0.99,
                               stages: ['slices a', 'visibility a'] }).detail, 'step 1');
});

test('frame progress: the frame\'s share, the stage in words, the time so far and left', () => {
  const d = describeFrame({ stage: 'fused', stageFraction: 0.5, fraction: 0.456, elapsedSeconds: 2.04,
                            estimatedSecondsLeft: 3.1, width: 964, height: 784 });
  assert.equal(d.title, 'rendering the frame 964×784');
  assert.equal(d.stage, 'shading');
  assert.equal(d.percent, 45);
  assert.equal(d.fraction, 0.456);
  assert.equal(d.detail, '2.0 s so far · about 3.1 s left');
  const q = describeFrame({ stage: 'queued', fraction: 0, elapsedSeconds: 0.6 });
  assert.equal(q.stage, 'waiting for a render thread');
  assert.equal(q.detail, '0.6 s so far');
  assert.equal(describeFrame({ stage: 'tonemap', fraction: 1 }).percent, 99, 'never 100 % before the frame');
  assert.equal(describeFrame({ stage: 'something-new', fraction: 0.2 }).stage, 'something-new');
});

test('idle: the HUD says the stream is up to date and how old the last frame is', () => {
  assert.equal(idleText(3400), 'idle — last frame 3.4 s ago, up to date');
  assert.equal(idleText(75000), 'idle — last frame 1 min 15 s ago, up to date');
  assert.equal(formatSeconds(0.04), '0.0 s');
  assert.equal(formatSeconds(12.4), '12 s');
  assert.equal(formatSeconds(3 * 3600 + 7 * 60), '3 h 07 min');
  // The frame window says how long ago the newest frame came.
  const w = new FrameWindow();
  assert.equal(w.summary(0).sinceLastMs, null);
  for (let t = 0; t <= 1000; t += 100) w.add(t, { bytes: 100 });
  const s = w.summary(6000);
  assert.equal(s.idle, true);
  assert.equal(s.sinceLastMs, 5000);
  assert.equal(w.summary(1050).idle, false);
});

// A stand-in for WebCodecs: every chunk decodes at once into a "frame" that
// carries its timestamp; `fail()` makes the decoder report an error as a real
// one does for a damaged stream.
class FakeVideoDecoder {
  static all = [];
  constructor({ output, error }) {
    Object.assign(this, { output, error, state: 'unconfigured', chunks: [] });
    FakeVideoDecoder.all.push(this);
  }
  configure(config) { this.config = config; this.state = 'configured'; }
  decode(chunk) {
    this.chunks.push(chunk);
    this.output({ timestamp: chunk.timestamp, displayWidth: this.config.codedWidth, closed: false,
                  close() { this.closed = true; } });
  }
  fail(message) { this.state = 'closed'; this.error(new Error(message)); }
  close() { this.state = 'closed'; }
}
class FakeChunk { constructor(init) { Object.assign(this, init); } }

// Annex-B access units: a keyframe (SPS High 4.0, PPS, IDR slice) and a delta frame (non-IDR slice).
const KEY = new Uint8Array([0, 0, 0, 1, 0x67, 0x64, 0x00, 0x28, 0xac, 0, 0, 0, 1, 0x68, 0xee, 0x3c, 0x80,
                            0, 0, 0, 1, 0x65, 0x88, 0x84]);
const DELTA = new Uint8Array([0, 0, 0, 1, 0x41, 0x9a, 0x02]);

test('H.264 view: a delta frame before any keyframe asks for one keyframe, then frames are drawn', () => {
  globalThis.VideoDecoder = FakeVideoDecoder;
  globalThis.EncodedVideoChunk = FakeChunk;
  try {
    let pose = 10;
    const asked = [];
    const drawn = [];
    const view = new H264View({
      draw: (frame, done) => { drawn.push(frame.timestamp); done(); },
      requestKeyframe: () => { asked.push(++pose); return pose; },
    });
    const shown = [];
    const frame = (sequence, poseSequence, data) =>
      view.frame({ sequence, poseSequence, width: 64, height: 48, data }, () => shown.push(sequence));

    // Joining mid-stream: delta frames answering poses 9 and 10 cannot be
    // decoded; one request (pose 11), not one per frame.
    assert.equal(frame(1, 9, DELTA), false);
    assert.equal(frame(2, 10, DELTA), false);
    assert.deepEqual(asked, [11]);
    // The request was lost (a frame answering pose 11 is still a delta): ask again.
    assert.equal(frame(3, 11, DELTA), false);
    assert.deepEqual(asked, [11, 12]);
    // The keyframe configures the decoder from its SPS; frames from it on are drawn.
    assert.equal(frame(4, 12, KEY), true);
    assert.equal(frame(5, 13, DELTA), true);  // answers pose 13, a drag after the keyframe
    const decoder = FakeVideoDecoder.all.at(-1);
    assert.equal(decoder.config.codec, 'avc1.640028');
    assert.deepEqual(decoder.chunks.map((c) => c.type), ['key', 'delta']);
    assert.deepEqual(drawn, [4, 5]);
    assert.deepEqual(shown, [4, 5]);
    assert.equal(view.undecoded, 3);
    assert.equal(view.requests, 2);

    // The page sent poses 13 and 14 (drags); the decoder fails on the frame
    // answering 13 (a damaged frame): the view asks for a keyframe again (15).
    pose = 14;
    decoder.fail('decoding error');
    assert.deepEqual(asked, [11, 12, 15]);
    assert.match(view.errors[0], /decoding error/);
    assert.equal(frame(6, 14, DELTA), false);  // answers a pose sent before the asking one: no new request
    assert.deepEqual(asked, [11, 12, 15]);
    assert.equal(frame(7, 15, KEY), true);
    assert.deepEqual(shown, [4, 5, 7]);
    view.close();
  } finally {
    delete globalThis.VideoDecoder;
    delete globalThis.EncodedVideoChunk;
  }
});

test('shortcuts: keys go to the page except where they type', () => {
  const input = (type) => ({ tagName: 'INPUT', type });
  for (const type of ['checkbox', 'radio', 'range', 'button', 'color']) assert.equal(takesTyping(input(type)), false, type);
  for (const type of ['text', 'number', 'search', 'email', 'password', 'TEXT']) assert.equal(takesTyping(input(type)), true, type);
  assert.equal(takesTyping({ tagName: 'INPUT' }), true, 'an input without a type is a text field');
  assert.equal(takesTyping({ tagName: 'select' }), true, "a select's letters pick its options");
  assert.equal(takesTyping({ tagName: 'TEXTAREA' }), true);
  assert.equal(takesTyping({ tagName: 'DIV', isContentEditable: true }), true);
  assert.equal(takesTyping({ tagName: 'CANVAS', isContentEditable: false }), false);
  assert.equal(takesTyping({ tagName: 'BUTTON' }), false);
  assert.equal(takesTyping(null), false);
  assert.equal(takesTyping({}), false, 'the document: no tag');
});

let failed = 0;
for (const t of tests) {
  try {
    t.fn();
    console.log(`ok   ${t.name}`);
  } catch (err) {
    failed++;
    console.log(`FAIL ${t.name}\n     ${err.message.split('\n').join('\n     ')}`);
  }
}
console.log(failed ? `${failed} of ${tests.length} failed` : `all ${tests.length} passed`);
process.exit(failed ? 1 : 0);
