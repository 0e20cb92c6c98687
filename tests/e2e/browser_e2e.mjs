// End-to-end test of the browser client: starts `haarcast serve --port 0`
// with a second scene (a box, written to a temporary folder), opens the page
// in Debian's Chromium (headless, driven by playwright-core; no browser is
// ever downloaded), and checks that
//   1. a bad page parameter (?method=fast, ?encoding=exr) is shown on the
//      page within 2 s, naming the parameter and its valid values, and
//      nothing connects;
//   2. a server Error (?level=99) is shown with its code and message, and a
//      fatal one that reconnecting cannot fix is not retried;
//   3. a frame arrives on the canvas and a screenshot of it is not blank;
//   4. a drag (camera orbit) brings a new frame that differs from the first;
//      shift-drag (object) and alt-drag (light) are sent and answered;
//   5. the HUD shows fps, latency, kbit/s, frame time, stage times and the
//      method, keeps updating, and never shows "0 fps" once a frame arrived,
//      also at 0.8 fps;
//   6. the method control reaches the server (frames come back with it);
//   7. the scene picker lists the served scenes; switching changes the frame
//      and starts the orbit at the new scene's camera; objects are named,
//      each with the material in effect; a material change is answered;
//   8. exposure "auto" gives a frame with < 2 % of its pixels at 255, a
//      fixed +3 stops gives more, and each frame's exposure is shown; the
//      tone select offers the schema's curves, starts at reinhard, and a
//      choice reaches the server (frames come back with it, and differ);
//   9. at 1200×800 every control is visible without scrolling; at 400×800
//      nothing is wider than the window; the canvas keeps the frame's aspect
//      ratio (also for a 128×96 frame) and goes full window and back;
//  10. a dropped connection (a proxy between page and server cuts it) shows
//      the countdown to the next attempt and reconnects;
//  11. no page errors and no request outside the server; SIGTERM → exit 0;
//  12. a renderer build (the server's cache starts empty): switching to a
//      scene not built yet dims the frame and shows the stage and a progress
//      bar, the new scene's objects are not listed until its first frame,
//      and that frame's time in the HUD does not count the build;
//  13. no server path on the page: the box scene names a MERL file by its
//      absolute path, and the panel shows it as merl:STEM;
//  14. the panel fits its column at every width from 320 px up (no name,
//      select or control cut off or past the window);
//  15. the stream fits the window: without ?size= the frames are the view's
//      size in device pixels, asked again after a resize (once, debounced),
//      and a fixed 360p gives 360 lines with the view's aspect;
//  16. the HUD says "idle — last frame N s ago" when no frame comes, folds
//      to one line (the button, h; folded by default under 600 px), and
//      folded it covers little of a 400×300 view;
//  17. a pinch on a touch screen moves the camera closer.
//
// usage: node browser_e2e.mjs --haarcast BUILD/bin/haarcast [--chromium /usr/bin/chromium]
//        [--out DIR] [--page-query 'size=96x96&encoding=jpeg'] [-- extra `serve` args]
import { mkdirSync, mkdtempSync, readFileSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import net from 'node:net';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { inflateSync } from 'node:zlib';

import { checks, launchChromium, parseArgs, playwright, startServer as serve } from './browser_harness.mjs';

const { chromium } = playwright();
const opts = parseArgs(process.argv.slice(2), { 'page-query': 'size=96x96&encoding=jpeg' });
const { check, failures } = checks();
const section = (what) => console.log(`--- ${what}`);

// ---- a tiny PNG decoder (8-bit RGB/RGBA, not interlaced: what Chromium writes) ----

function decodePng(buf) {
  if (buf.readUInt32BE(0) !== 0x89504e47) throw new Error('screenshot is not a PNG');
  let pos = 8, width = 0, height = 0, channels = 0;
  const idat = [];
  while (pos < buf.length) {
    const len = buf.readUInt32BE(pos);
    const type = buf.toString('latin1', pos + 4, pos + 8);
    const data = buf.subarray(pos + 8, pos + 8 + len);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      const depth = data[8], color = data[9], interlace = data[12];
      if (depth !== 8 || (color !== 2 && color !== 6) || interlace !== 0) {
        throw new Error(`unsupported PNG: depth ${depth}, color type ${color}, interlace ${interlace}`);
      }
      channels = color === 6 ? 4 : 3;
    } else if (type === 'IDAT') {
      idat.push(data);
    }
    pos += 12 + len;
  }
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const out = Buffer.alloc(height * stride);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; x++) {
      const a = x >= channels ? out[y * stride + x - channels] : 0;
      const b = y > 0 ? out[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? out[(y - 1) * stride + x - channels] : 0;
      let v = line[x];
      if (filter === 1) v += a;
      else if (filter === 2) v += b;
      else if (filter === 3) v += (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      out[y * stride + x] = v & 255;
    }
  }
  return { width, height, channels, pixels: out };
}

function luma(img) {
  const n = img.width * img.height;
  const l = new Float64Array(n);
  for (let i = 0; i < n; i++) {
    const p = i * img.channels;
    l[i] = 0.2126 * img.pixels[p] + 0.7152 * img.pixels[p + 1] + 0.0722 * img.pixels[p + 2];
  }
  return l;
}

function stddev(l) {
  const mean = l.reduce((a, b) => a + b, 0) / l.length;
  return Math.sqrt(l.reduce((a, b) => a + (b - mean) ** 2, 0) / l.length);
}

function meanAbsDiff(a, b) {
  if (a.length !== b.length) return Infinity;
  let s = 0;
  for (let i = 0; i < a.length; i++) s += Math.abs(a[i] - b[i]);
  return s / a.length;
}

// Pixels of the canvas, exactly as drawn (raw frames are put unchanged).
async function canvasPixels(page) {
  return page.evaluate(() => {
    const c = document.getElementById('frame');
    return Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data);
  });
}

// The share of pixels with a channel at 255: clipped highlights.
function clippedShare(rgba) {
  let clipped = 0;
  for (let i = 0; i < rgba.length; i += 4) {
    if (rgba[i] === 255 || rgba[i + 1] === 255 || rgba[i + 2] === 255) clipped++;
  }
  return clipped / (rgba.length / 4);
}

// ---- the server, and a proxy that can cut its connections ------------------------------

const startServer = (serveArgs) => serve(opts.haarcast, serveArgs);

// A TCP proxy to the server: `drop(ms)` resets every connection through it
// (the page sees its WebSocket die without a close frame, as when a network
// goes away) and refuses new ones for `ms`.
async function startProxy(target) {
  const live = new Set();
  let refuseUntil = 0;
  const kill = (s) => (s.resetAndDestroy ? s.resetAndDestroy() : s.destroy());
  const server = net.createServer((client) => {
    if (Date.now() < refuseUntil) { kill(client); return; }
    const upstream = net.connect(Number(target.port), target.hostname);
    const pair = [client, upstream];
    live.add(pair);
    client.pipe(upstream);
    upstream.pipe(client);
    const end = () => { live.delete(pair); client.destroy(); upstream.destroy(); };
    for (const s of pair) { s.on('error', end); s.on('close', end); }
  });
  await new Promise((r) => server.listen(0, '127.0.0.1', r));
  return {
    base: `http://127.0.0.1:${server.address().port}/`,
    drop(ms) {
      refuseUntil = Date.now() + ms;
      for (const pair of live) pair.forEach(kill);
      live.clear();
    },
    close: () => new Promise((r) => { for (const pair of live) pair.forEach(kill); server.close(r); }),
  };
}

// ---- the test ---------------------------------------------------------------------

// A MERL file (int32 dims 90, 90, 180, then three channels of doubles),
// one value everywhere: a measured material the box scene names by its
// absolute path, which must never reach the page.
function constantMerl(value) {
  const cells = 90 * 90 * 180;
  const bytes = Buffer.alloc(12 + 3 * cells * 8);
  bytes.writeInt32LE(90, 0);
  bytes.writeInt32LE(90, 4);
  bytes.writeInt32LE(180, 8);
  for (let i = 0; i < 3 * cells; i++) bytes.writeDoubleLE(value, 12 + 8 * i);
  return bytes;
}

// The second scene: a box with its own camera (docs/scenes.md), and a ball
// in a MERL material named by its absolute path. --materials-dir offers
// another name for the same file (merl:e2e-chrome). The cache starts empty,
// so that a scene's first use is a build the page shows.
const sceneDir = mkdtempSync(join(tmpdir(), 'haarcast-e2e-'));
const boxScene = join(sceneDir, 'e2e-box.json');
const boxCamera = [1.6, 1.2, 2.6];
mkdirSync(join(sceneDir, 'brdfs'));
const gilt = join(sceneDir, 'brdfs', 'e2e-gilt.binary');
writeFileSync(gilt, constantMerl(0.02));
const offered = join(sceneDir, 'offered');
mkdirSync(offered);
symlinkSync(gilt, join(offered, 'e2e-chrome.binary'));
writeFileSync(boxScene, JSON.stringify({
  camera: { eye: boxCamera, target: [0, 0, 0], up: [0, 1, 0], fov_y: 40 },
  objects: [{ name: 'box', mesh: { builtin: 'box' }, material: 'lambert', rotate: [0, 30, 0], scale: 0.8 },
            { name: 'gilded ball with a name longer than the panel is wide', mesh: { builtin: 'sphere' },
              material: gilt, translate: [1.1, 0, 0], scale: 0.3 }],
}));

const server = startServer(['--scene', boxScene, '--materials-dir', offered, '--cache-dir', join(sceneDir, 'cache'),
                            ...opts.serveArgs]);
let browser = null;
let proxy = null;
try {
  const base = await server.url;
  console.log(`server at ${base}`);
  browser = await launchChromium(chromium, opts.chromium);

  // A page whose console errors, page errors and requests outside `origin`
  // are collected. `networkErrors`: a page whose connection is cut on
  // purpose logs failed WebSocket and fetch attempts; those are expected.
  const openPage = async (query, { origin = base, viewport = { width: 900, height: 900 }, networkErrors = false } = {}) => {
    const page = await browser.newPage({ viewport });
    const problems = [];
    const expected = /WebSocket connection to .* failed|net::ERR_(CONNECTION|EMPTY_RESPONSE|SOCKET)|Failed to load resource/;
    page.on('console', (m) => {
      if (m.type() === 'error' && !(networkErrors && expected.test(m.text()))) problems.push(m.text());
    });
    page.on('pageerror', (e) => problems.push(e.message));
    page.on('request', (r) => {
      if (!r.url().startsWith(origin)) problems.push(`request outside the server: ${r.url()}`);
    });
    const started = Date.now();
    await page.goto(`${origin}?${query}`);
    return { page, problems, started };
  };
  const pick = (page) => page.evaluate(() => {
    const h = window.haarcast;
    return {
      framesShown: h.framesShown, lastFrame: h.lastFrame, posesSent: h.posesSent, errors: h.errors,
      connection: h.connection, connections: h.connections, welcomes: h.welcomes, scene: h.scene,
      sceneInfo: h.sceneInfo && { name: h.sceneInfo.name, objects: h.sceneInfo.objects.map((o) => ({ ...o })) },
      viewEye: h.viewEye(),
    };
  });
  const text = (page, selector) => page.evaluate((s) => {
    const e = document.querySelector(s);
    return e && !e.closest('[hidden]') ? e.textContent : null;
  }, selector);
  // Nothing in the panel is cut or past its column: names wrap, each select
  // is wide enough for its chosen option's text, no control sticks out.
  const panelProblems = (page) => page.evaluate(() => {
    const problems = [];
    const panel = document.getElementById('panel').getBoundingClientRect();
    const measure = document.createElement('canvas').getContext('2d');
    for (const e of document.querySelectorAll('#panel select, #panel input, #panel button, #panel label, #objects .name')) {
      if (e.closest('[hidden]')) continue;
      const r = e.getBoundingClientRect();
      if (r.width === 0) continue;
      const id = e.id || e.getAttribute('aria-label') || e.textContent.trim().slice(0, 24);
      if (r.left < panel.left - 0.5 || r.right > panel.right + 0.5) problems.push(`${id} is outside the panel (${r.left.toFixed(0)}..${r.right.toFixed(0)} of ${panel.left.toFixed(0)}..${panel.right.toFixed(0)})`);
      if (e.scrollWidth > e.clientWidth + 1 && e.tagName !== 'SELECT' && e.tagName !== 'INPUT') problems.push(`${id} is cut (${e.scrollWidth} > ${e.clientWidth})`);
      if (e.tagName === 'SELECT' && e.selectedIndex >= 0) {
        const cs = getComputedStyle(e);
        measure.font = `${cs.fontSize} ${cs.fontFamily}`;
        const need = measure.measureText(e.options[e.selectedIndex].text).width + parseFloat(cs.paddingLeft) + 18;
        if (need > e.clientWidth + 0.5) problems.push(`select ${id} cuts "${e.options[e.selectedIndex].text}" (${need.toFixed(0)} > ${e.clientWidth})`);
      }
    }
    if (document.documentElement.scrollWidth > window.innerWidth) problems.push(`the page is ${document.documentElement.scrollWidth} px wide`);
    return problems;
  });
  const panelFits = async (what) => {
    const problems = await panelProblems(page);
    check(problems.length === 0, `${what}: the panel fits its column (${problems.slice(0, 4).join('; ')})`);
  };
  const waitFrames = (page, n, timeout = 120000) =>
    page.waitForFunction((k) => window.haarcast && window.haarcast.framesShown >= k, n, { timeout });

  // 1. Bad page parameters: named on the page at once, nothing connects.
  section('page parameters');
  for (const [query, words] of [['method=fast', ['?method=fast', 'fused', 'haar']],
                                 ['encoding=exr', ['?encoding=exr', 'jpeg, png, raw']]]) {
    const { page, problems, started } = await openPage(query);
    await page.waitForFunction(() => !document.getElementById('banner').hidden, null,
                               { timeout: Math.max(1, 2000 - (Date.now() - started)) }).catch(() => {});
    const elapsed = Date.now() - started;
    const banner = (await text(page, '#banner-text')) || '';
    check(words.every((w) => banner.includes(w)) && elapsed <= 2000,
          `?${query}: the page says ${JSON.stringify(banner)} after ${elapsed} ms (want ${words.join(', ')} within 2 s)`);
    const s = await pick(page);
    check(s.connections === 0, `?${query}: no connection is opened (${s.connections})`);
    check(problems.length === 0, `?${query}: no page errors (${problems.join('; ')})`);
    await page.close();
  }

  // 2. A server Error: shown with its code, and not retried (a bad setting stays bad).
  section('server errors');
  {
    const { page, started } = await openPage('level=99&size=64x64');
    await page.waitForFunction(() => !document.getElementById('banner').hidden, null, { timeout: 10000 }).catch(() => {});
    const banner = (await text(page, '#banner-text')) || '';
    check(/ERROR_CODE_BAD_SETTINGS/.test(banner) && /level 99 is outside \d+\.\.\d+/.test(banner),
          `?level=99: the page shows the server's Error ${JSON.stringify(banner)} (${Date.now() - started} ms)`);
    await page.waitForTimeout(2500);
    const s = await pick(page);
    check(s.connection === 'stopped' && s.connections === 1,
          `a fatal BAD_SETTINGS is not retried (state ${s.connection}, ${s.connections} connection(s) in 2.5 s)`);
    await page.close();
  }

  // 3.–6. The main page.
  section('frames, drags, HUD');
  const { page, problems: consoleErrors } = await openPage(opts['page-query']);
  const state = () => pick(page);
  // The first frame may wait for the server to prepare the scene (slice
  // tables, visibility): generous, but bounded.
  await waitFrames(page, 1);
  // From now on, every text the fps field takes is recorded.
  await page.evaluate(() => {
    const fps = document.getElementById('hud-fps');
    window.fpsTexts = [fps.textContent];
    new MutationObserver(() => window.fpsTexts.push(fps.textContent))
      .observe(fps, { childList: true, characterData: true, subtree: true });
  });
  const first = await state();
  check(first.framesShown >= 1, `a frame is on the canvas (frame ${first.lastFrame.sequence}, ${first.lastFrame.bytes} bytes)`);

  const canvas = page.locator('#frame');
  // The HUD and the full-window button float over the canvas: hidden in
  // screenshots, or their text alone would make a blank frame look varied.
  const shotOptions = { style: '#hud, #fullwindow { visibility: hidden !important; }' };
  const shot = async () => decodePng(await canvas.screenshot(shotOptions));
  const shot1 = await shot();
  const l1 = luma(shot1);
  const sd1 = stddev(l1);
  check(sd1 > 2, `the screenshot is not blank (luma stddev ${sd1.toFixed(1)} > 2)`);
  if (opts.out) {
    mkdirSync(opts.out, { recursive: true });
    writeFileSync(join(opts.out, 'first.png'), await canvas.screenshot(shotOptions));
  }

  // Drag to orbit: the frame must change.
  let box = await canvas.boundingBox();
  const drag = async (modifier, dx = 120, dy = 20) => {
    box = await canvas.boundingBox();
    const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
    if (modifier) await page.keyboard.down(modifier);
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    await page.mouse.move(cx + dx, cy + dy, { steps: 6 });
    await page.mouse.up();
    if (modifier) await page.keyboard.up(modifier);
  };
  const dragAndWait = async (what, modifier) => {
    const before = await state();
    await drag(modifier);
    const sentTo = (await state()).posesSent;
    check(sentTo > before.posesSent, `${what}: poses sent (${before.posesSent} → ${sentTo})`);
    // Wait for the frame that answers the last pose of the drag.
    await page.waitForFunction((n) => window.haarcast.lastFrame && window.haarcast.lastFrame.poseSequence >= n,
                               sentTo, { timeout: 60000 });
    // One animation frame for the draw to land.
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => r())));
  };
  await dragAndWait('drag (orbit)');
  const shot2 = await shot();
  const diffOrbit = meanAbsDiff(l1, luma(shot2));
  check(diffOrbit > 1, `the frame changed after the orbit drag (mean |Δluma| ${diffOrbit.toFixed(2)} > 1)`);
  if (opts.out) writeFileSync(join(opts.out, 'orbit.png'), await canvas.screenshot(shotOptions));

  await dragAndWait('alt-drag (light)', 'Alt');
  const shot3 = await shot();
  const diffLight = meanAbsDiff(luma(shot2), luma(shot3));
  check(diffLight > 0.5, `the frame changed after the light drag (mean |Δluma| ${diffLight.toFixed(2)} > 0.5)`);
  await dragAndWait('shift-drag (object)', 'Shift');
  // The moved object's shadow on the ground is in the frame that answers the drag.
  if (opts.out) writeFileSync(join(opts.out, 'object.png'), await canvas.screenshot(shotOptions));
  // An object's turns start from the scene's own pose (SceneInfo): the
  // default scene's torus is turned (60, 20, 0) and translated to x = 0.8.
  const torus = await page.evaluate(() => window.haarcast.objectPose(1));
  check(torus.x === 60 && torus.y === 20 && Math.abs(torus.translate.x - 0.8) < 1e-9,
        `object 1 starts from its scene pose (got ${JSON.stringify(torus)})`);

  // The HUD: numbers, and they keep updating.
  const hud = async () => page.evaluate(() => {
    const t = (id) => document.getElementById(id).textContent;
    return { fps: t('hud-fps'), latency: t('hud-latency'), kbps: t('hud-kbps'), frameMs: t('hud-frame-ms'),
             stages: t('hud-stages'), method: t('hud-method'), exposure: t('hud-exposure'),
             updates: window.haarcast.hudUpdates };
  });
  // Keep frames flowing until the HUD's window holds three (on the CPU
  // backend a frame can take most of a second).
  let h1 = await hud();
  for (const deadline = Date.now() + 30000; Date.now() < deadline;) {
    await drag(null, 10, 0);
    await page.waitForTimeout(200);
    h1 = await hud();
    if (Number(h1.fps) > 0 && Number(h1.latency) > 0 && Number(h1.kbps) > 0 && Number(h1.frameMs) > 0) break;
  }
  console.log(`HUD: ${h1.fps} fps, ${h1.latency} ms, ${h1.kbps} kbit/s, frame ${h1.frameMs} ms, ${h1.method}, ` +
              `${h1.exposure}; ${h1.stages}`);
  check(Number(h1.fps) > 0, `HUD fps is a positive number ("${h1.fps}")`);
  check(Number(h1.latency) > 0, `HUD latency is a positive number of ms ("${h1.latency}")`);
  check(Number(h1.kbps) > 0, `HUD kbit/s is a positive number ("${h1.kbps}")`);
  check(Number(h1.frameMs) > 0, `HUD frame time is a positive number of ms ("${h1.frameMs}")`);
  check(/encode \d/.test(h1.stages) && /(fused|triple-product) \d/.test(h1.stages),
        `HUD shows the server's stage times ("${h1.stages}")`);
  check(['fused', 'haar', 'spatial', 'matrix', 'table', 'splitsum'].includes(h1.method), `HUD method names a method ("${h1.method}")`);
  check(/stops (auto|fixed)$/.test(h1.exposure), `HUD shows the frame's exposure ("${h1.exposure}")`);
  await page.waitForTimeout(600);
  const h2 = await hud();
  check(h2.updates > h1.updates, `the HUD keeps updating (${h1.updates} → ${h2.updates} redraws)`);

  // A control reaches the server: switch the method, drag, and the next
  // frame must come back rendered with it.
  const target = h1.method === 'fused' ? 'haar' : 'fused';
  await page.selectOption('#method', target);
  await dragAndWait(`drag after choosing ${target}`);
  await page.waitForFunction((m) => window.haarcast.lastFrame.method === m, target, { timeout: 60000 })
    .catch(() => {});
  const after = await state();
  check(after.lastFrame.method === target, `frames come back with method ${target} (got ${after.lastFrame.method})`);
  await page.waitForTimeout(400);
  const h3 = await hud();
  check(h3.method === target, `the HUD shows method ${target} ("${h3.method}")`);
  await page.selectOption('#method', h1.method);

  // The level choices are "auto" and the server's range (Welcome.limits),
  // not a copy; the one selected is the Welcome's, still after the method
  // change above (a change of method must not turn automatic levels fixed).
  const levels = await page.evaluate(() => ({
    options: [...document.querySelectorAll('#level option')].map((o) => o.value),
    selected: document.querySelector('#level').value,
    limits: { min: window.haarcast.welcome.limits.minLevel, max: window.haarcast.welcome.limits.maxLevel },
    welcome: { level: window.haarcast.welcome.settings.level, auto: window.haarcast.welcome.settings.levelMode === 2 },
  }));
  const wantLevels = ['auto', ...Array.from({ length: levels.limits.max - levels.limits.min + 1 },
                                            (_, i) => String(levels.limits.min + i))];
  check(JSON.stringify(levels.options) === JSON.stringify(wantLevels),
        `level choices ${levels.options.join(',')} are auto and Welcome.limits ${levels.limits.min}..${levels.limits.max}`);
  const wantSelected = levels.welcome.auto ? 'auto' : String(levels.welcome.level);
  check(levels.selected === wantSelected, `the level select shows the Welcome's ${wantSelected} (${levels.selected})`);

  // 7. Scenes and objects.
  section('scenes and materials');
  const objects = () => page.evaluate(() => [...document.querySelectorAll('#objects li')].map((li) => ({
    name: li.querySelector('.name').firstChild.textContent, material: li.querySelector('select').value,
    offered: li.querySelectorAll('select option').length,
  })));
  const scenes = await page.evaluate(() => [...document.querySelectorAll('#scene option')].map((o) => o.value));
  check(JSON.stringify(scenes) === JSON.stringify(['default', 'e2e-box']),
        `the scene picker lists the served scenes (${scenes.join(', ')})`);
  let objs = await objects();
  check(JSON.stringify(objs.map((o) => [o.name, o.material])) === JSON.stringify([['sphere', 'phong:64'], ['torus', 'ggx:0.3'], ['ground', 'lambert']]),
        `the default scene's objects are named, each with its material (${JSON.stringify(objs.map((o) => [o.name, o.material]))})`);
  check(objs.every((o) => o.offered > 1), `each object's material select lists the offered materials (${objs.map((o) => o.offered)})`);

  // Waits for the SceneInfo answer and a frame of the new scene (one that
  // answers a pose sent after the answer).
  const switchScene = async (name) => {
    await page.selectOption('#scene', name);
    const answered = await page.waitForFunction((n) => {
      const h = window.haarcast;
      return h.sceneInfo.name === n && h.scene.name === n && h.lastFrame.poseSequence >= h.scene.firstPose;
    }, name, { timeout: 30000 }).then(() => true, () => false);
    const s = await state();
    check(answered, `choosing ${name} is answered with its SceneInfo and a frame of it (scene "${s.sceneInfo.name}")`);
    if (!answered) throw new Error(`no switch to ${name}`);
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => r())));
  };
  const beforeSwitch = await shot();
  // 12. The box scene was never built: record what the page shows meanwhile
  // (every change of the build overlay and the objects list) and each frame.
  await page.evaluate(() => {
    window.buildLog = [];
    window.frameLog = [];
    const snap = () => {
      const b = document.getElementById('build');
      window.buildLog.push({
        t: performance.now(), shown: !b.hidden, dimmed: document.getElementById('view').classList.contains('building'),
        stage: document.getElementById('build-stage').textContent, title: document.getElementById('build-title').textContent,
        bar: document.getElementById('build-bar').hasAttribute('value') ? document.getElementById('build-bar').value : null,
        detail: document.getElementById('build-detail').textContent, objects: document.getElementById('objects').textContent,
      });
    };
    new MutationObserver(snap).observe(document.getElementById('build'), { attributes: true, subtree: true, childList: true, characterData: true });
    new MutationObserver(snap).observe(document.getElementById('objects'), { childList: true, subtree: true });
    const h = window.haarcast;
    let last = h.lastFrame;
    Object.defineProperty(h, 'lastFrame', { configurable: true, get: () => last,
      set: (v) => { last = v; window.frameLog.push({ t: performance.now(), ...v }); } });
  });
  await switchScene('e2e-box');
  const afterSwitch = await shot();
  {
    const { buildLog, frameLog, ended } = await page.evaluate(() => ({ buildLog: window.buildLog, frameLog: window.frameLog,
                                                                       ended: window.haarcast.buildsEnded }));
    const during = buildLog.filter((r) => r.shown);
    console.log(`build: ${during.length} overlay states, e.g. ${JSON.stringify(during.at(-1))}`);
    check(during.length > 0 && during.every((r) => r.dimmed) &&
          during.some((r) => /preparing scene e2e-box/.test(r.title) && /(BRDF slice table|visibility) of /.test(r.stage)),
          'a build: the frame is dimmed and the stage of the scene being prepared is shown');
    check(during.some((r) => r.bar >= 0 && r.bar <= 1 && /\d+ %/.test(r.title)), 'a build: a progress bar and the build\'s percentage');
    // The bar is the whole build's (BuildProgress.build_fraction against the
    // server's plan): it never goes back, and the steps count in the plan.
    const bars = during.map((r) => r.bar).filter((b) => b !== null);
    const back = bars.findIndex((b, i) => i > 0 && b < bars[i - 1]);
    check(bars.length > 1 && back < 0, `a build's bar never goes back (${bars.map((b) => b.toFixed(2)).join(' → ')})`);
    check(during.some((r) => /step \d+ of \d+/.test(r.detail)),
          `a build's steps are counted in its plan (${JSON.stringify(during.at(-1) && during.at(-1).detail)})`);
    // Listed objects read "box #0", "gilded ball … #1".
    check(during.every((r) => !/#\d|gilded/.test(r.objects)) && during.some((r) => /preparing e2e-box/.test(r.objects)),
          `while it builds the new scene's objects are not listed (${JSON.stringify(during.map((r) => r.objects).slice(-1))})`);
    const startedAt = during.length ? during[0].t : Infinity;
    const endedAt = buildLog.filter((r) => !r.shown).map((r) => r.t).find((t) => t > startedAt);
    const buildMs = endedAt - startedAt;
    // No frame comes while the server builds, so the first frame after the
    // build began is the one that ends it (its record may land a moment
    // before the overlay's hide is observed).
    const first = endedAt === undefined ? null : frameLog.find((f) => f.t > startedAt);
    check(ended >= 1 && first && Number.isNaN(first.latencyMs) && first.serverMs < buildMs,
          `the frame that ends the build counts no build: its frame time ${first && first.serverMs.toFixed(1)} ms ` +
          `(the build showed for ${buildMs.toFixed(0)} ms), no latency (${first && first.latencyMs})`);
  }
  // 13. No server path on the page: the scene's own MERL file by its name.
  {
    const panel = await page.evaluate(() => {
      const p = document.getElementById('panel');
      return [p.innerText, ...[...p.querySelectorAll('option')].map((o) => `${o.value} ${o.textContent}`),
              ...[...p.querySelectorAll('[title],[aria-label]')].map((e) => `${e.title} ${e.getAttribute('aria-label')}`)].join('\n');
    });
    check(!panel.includes(sceneDir) && !/\.binary|\/tmp\//.test(panel),
          `no server path in the panel (${JSON.stringify(panel.split('\n').filter((l) => /\//.test(l)).slice(0, 3))})`);
  }
  const diffScene = meanAbsDiff(luma(beforeSwitch), luma(afterSwitch));
  check(diffScene > 3, `switching to e2e-box changes the frame (mean |Δluma| ${diffScene.toFixed(2)} > 3)`);
  if (opts.out) writeFileSync(join(opts.out, 'scene-e2e-box.png'), await canvas.screenshot(shotOptions));
  let s = await state();
  const eyeError = Math.hypot(s.viewEye.x - boxCamera[0], s.viewEye.y - boxCamera[1], s.viewEye.z - boxCamera[2]);
  check(eyeError < 1e-6, `the orbit starts at the new scene's camera (eye ${JSON.stringify(s.viewEye)}, want ${boxCamera})`);
  objs = await objects();
  check(JSON.stringify(objs.map((o) => [o.name, o.material])) ===
        JSON.stringify([['box', 'lambert'], ['gilded ball with a name longer than the panel is wide', 'merl:e2e-gilt']]),
        `e2e-box's objects are listed, the MERL file by its name (${JSON.stringify(objs.map((o) => [o.name, o.material]))})`);
  const offeredMerl = await page.evaluate(() => [...document.querySelectorAll('#objects select option')].map((o) => o.value));
  check(offeredMerl.includes('merl:e2e-chrome'), `--materials-dir's file is offered as merl:e2e-chrome (${[...new Set(offeredMerl)]})`);
  await panelFits('e2e-box at 900 px');
  await switchScene('default');
  objs = await objects();
  check(objs.length === 3 && objs[0].material === 'phong:64', `back on default, sphere is phong:64 again (${objs[0] && objs[0].material})`);

  // A material change: answered with a SceneInfo that the select shows.
  await page.locator('#objects select').first().selectOption('lambert');
  await page.waitForFunction(() => window.haarcast.sceneInfo.objects[0].material === 'lambert', null, { timeout: 30000 })
    .catch(() => {});
  s = await state();
  objs = await objects();
  check(s.sceneInfo.objects[0].material === 'lambert' && objs[0].material === 'lambert' && s.sceneInfo.name === 'default',
        `a material change is answered (SceneInfo: ${s.sceneInfo.objects[0].material}; select: ${objs[0].material})`);

  // A refused change: a non-fatal Error is shown in words, the select goes
  // back to the material in effect, and the session goes on. (The page only
  // offers what Welcome offers, so the test adds a bogus choice.)
  await page.evaluate(() => {
    const select = document.querySelector('#objects select');
    select.add(new Option('merl:no-such-brdf', 'merl:no-such-brdf'));
  });
  await page.locator('#objects select').first().selectOption('merl:no-such-brdf');
  await page.waitForFunction(() => window.haarcast.errors.length > 0, null, { timeout: 10000 }).catch(() => {});
  await page.waitForTimeout(100);
  s = await state();
  const refused = (await text(page, '#banner-text')) || '';
  objs = await objects();
  check(/ERROR_CODE_UNKNOWN_MATERIAL: material "merl:no-such-brdf" is not offered/.test(refused) &&
        s.errors.length === 1 && !s.errors[0].fatal,
        `a refused material is shown (${JSON.stringify(refused)})`);
  check(objs[0].material === 'lambert' && s.connection === 'ready',
        `the select shows the material in effect again (${objs[0].material}) and the session goes on (${s.connection})`);
  await page.click('#banner-close');
  const expectedErrors = 1;

  // 9. Layout.
  section('layout');
  const layout = () => page.evaluate(() => {
    const r = (e) => e.getBoundingClientRect();
    const c = r(document.getElementById('frame'));
    const f = document.getElementById('frame');
    const controls = [...document.querySelectorAll('#controls select, #controls input, #controls button, #fullwindow')]
      .map((e) => ({ id: e.id || e.name || e.value || e.tagName, box: r(e) }));
    return { canvas: { w: c.width, h: c.height, x: c.x, y: c.y }, frame: { w: f.width, h: f.height },
             scrollW: document.documentElement.scrollWidth, scrollH: document.documentElement.scrollHeight,
             controls };
  });
  const aspectOk = (l) => Math.abs(l.canvas.w / l.canvas.h - l.frame.w / l.frame.h) < 0.02 * (l.frame.w / l.frame.h);
  await page.setViewportSize({ width: 1200, height: 800 });
  await page.waitForTimeout(200);
  let l = await layout();
  const hiddenAt1200 = l.controls.filter((c) => c.box.bottom > 800 || c.box.right > 1200 || c.box.width === 0);
  check(hiddenAt1200.length === 0 && l.scrollH <= 800,
        `1200×800: every control is in view without scrolling (page ${l.scrollW}×${l.scrollH}` +
        `${hiddenAt1200.length ? `; out of view: ${hiddenAt1200.map((c) => c.id).join(', ')}` : ''})`);
  check(aspectOk(l) && l.canvas.h >= 700, `1200×800: the canvas is ${l.canvas.w.toFixed(0)}×${l.canvas.h.toFixed(0)} for a ${l.frame.w}×${l.frame.h} frame`);
  if (opts.out) await page.screenshot({ path: join(opts.out, 'layout-1200x800.png') });

  await page.setViewportSize({ width: 400, height: 800 });
  await page.waitForTimeout(200);
  l = await layout();
  const wide = l.controls.filter((c) => c.box.right > 400 || c.box.left < 0);
  check(l.scrollW <= 400 && wide.length === 0,
        `400×800: nothing is wider than the window (page width ${l.scrollW}${wide.length ? `; too wide: ${wide.map((c) => c.id)}` : ''})`);
  check(aspectOk(l) && l.canvas.w >= 360 && l.canvas.y + l.canvas.h <= 800,
        `400×800: the canvas is ${l.canvas.w.toFixed(0)}×${l.canvas.h.toFixed(0)}, in view at the top`);
  if (opts.out) await page.screenshot({ path: join(opts.out, 'layout-400x800.png'), fullPage: true });

  // 14. Every width from 320 px up (the box scene, with its long names).
  await switchScene('e2e-box');
  for (const width of [320, 360, 400, 480, 600, 720, 721, 800, 1024, 1280, 1600]) {
    await page.setViewportSize({ width, height: 800 });
    await page.waitForTimeout(150);
    await panelFits(`${width}×800`);
    if (opts.out && width === 320) await page.screenshot({ path: join(opts.out, 'panel-320x800.png'), fullPage: true });
  }
  await switchScene('default');

  await page.setViewportSize({ width: 1200, height: 800 });
  await page.click('#fullwindow');
  await page.waitForTimeout(300);
  l = await layout();
  const fullClass = await page.evaluate(() => document.getElementById('app').classList.contains('fullwindow'));
  check(fullClass && aspectOk(l) && l.canvas.h >= 795, `full window: the canvas is ${l.canvas.w.toFixed(0)}×${l.canvas.h.toFixed(0)}`);
  await page.keyboard.press('Escape');
  await page.waitForTimeout(300);
  const leftFull = await page.evaluate(() => !document.getElementById('app').classList.contains('fullwindow') &&
                                             !document.fullscreenElement);
  check(leftFull, 'Escape leaves the full window');

  // Save the frame: the button, then s with focus left on a radio button
  // (a click leaves it there; the shortcuts must still work). Both give a
  // PNG of the stream's own size whose pixels are the canvas's.
  const savedFrame = async (trigger, what) => {
    const [download] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), trigger()]);
    const name = download.suggestedFilename();
    const png = decodePng(readFileSync(await download.path()));
    const shown = await page.evaluate(() => ({ w: document.getElementById('frame').width,
                                               h: document.getElementById('frame').height,
                                               last: [window.haarcast.lastFrame.width, window.haarcast.lastFrame.height] }));
    const canvas = await canvasPixels(page);
    let diff = 0;
    for (let i = 0, j = 0; i < canvas.length; i += 4, j += png.channels) {
      for (let c = 0; c < 3; c++) diff = Math.max(diff, Math.abs(canvas[i + c] - png.pixels[j + c]));
    }
    check(/^haarcast-default-\d+x\d+-\d{8}-\d{6}\.png$/.test(name) && png.width === shown.w && png.height === shown.h &&
          shown.w === shown.last[0] && shown.h === shown.last[1] && diff === 0,
          `${what}: ${name}, ${png.width}×${png.height} (the stream's ${shown.last.join('×')}), ` +
          `the canvas's pixels to ${diff} levels`);
  };
  await savedFrame(() => page.click('#save-frame'), 'the save button');
  await page.check('input[name="drag"][value="light"]');
  await page.check('input[name="drag"][value="camera"]');
  const focusType = await page.evaluate(() => document.activeElement && document.activeElement.type);
  await savedFrame(() => page.keyboard.press('s'), `s with focus on a ${focusType}`);
  await page.keyboard.press('f');
  await page.waitForTimeout(300);
  const fullFromRadio = await page.evaluate(() => document.getElementById('app').classList.contains('fullwindow'));
  await page.keyboard.press('Escape');
  await page.waitForTimeout(300);
  check(focusType === 'radio' && fullFromRadio, `f with focus on a ${focusType} takes the full window`);

  s = await state();
  check(s.errors.length === expectedErrors, `no other server errors (${JSON.stringify(s.errors)})`);
  const fpsTexts = await page.evaluate(() => window.fpsTexts);
  const zeros = fpsTexts.filter((t) => Number(t) === 0);
  check(zeros.length === 0, `the HUD never showed 0 fps after the first frame (${fpsTexts.length} values: ` +
                            `${[...new Set(fpsTexts)].slice(0, 12).join(' ')}${zeros.length ? `; zeros: ${zeros.length}` : ''})`);
  check(consoleErrors.length === 0, `no page errors or outside requests (${consoleErrors.join('; ')})`);
  await page.close();

  // 8. Exposure, on raw frames (exact pixels) of a 128×96 view of the
  // default scene. The clipped share is over the whole frame, sky included:
  // simpler than an object mask, and stricter (the sky counts as well).
  section('exposure');
  {
    const { page: p, problems } = await openPage('encoding=raw&size=128x96', { viewport: { width: 1200, height: 800 } });
    await waitFrames(p, 1);
    // Auto exposure eases over frames: a few poses, then the last frame.
    for (let i = 0; i < 3; i++) {
      await p.mouse.move(300, 300);
      await p.mouse.down();
      await p.mouse.move(302, 300);
      await p.mouse.up();
      await p.waitForTimeout(150);
    }
    let f = (await pick(p)).lastFrame;
    const autoShare = clippedShare(await canvasPixels(p));
    check(f.exposureMode === 'auto' && autoShare < 0.02,
          `exposure auto (${f.exposureStops.toFixed(2)} stops): ${(100 * autoShare).toFixed(2)} % of pixels at 255 (< 2 %)`);
    const shown = await text(p, '#exposure-value');
    check(/stops \(auto\)$/.test(shown), `the exposure control shows the frame's exposure ("${shown}")`);
    const la = await p.evaluate(() => {
      const c = document.getElementById('frame').getBoundingClientRect();
      return c.width / c.height;
    });
    check(Math.abs(la - 128 / 96) < 0.02, `a 128×96 frame keeps its aspect ratio on the page (${la.toFixed(3)})`);

    // A fixed exposure three stops up: the slider sends it, frames say so,
    // and the same measure now finds clipping (it can tell).
    await p.evaluate(() => {
      const slider = document.getElementById('exposure');
      slider.value = '3';
      slider.dispatchEvent(new Event('input', { bubbles: true }));
    });
    await p.waitForFunction(() => window.haarcast.lastFrame.exposureMode === 'fixed' &&
                                  Math.abs(window.haarcast.lastFrame.exposureStops - 3) < 1e-6, null, { timeout: 30000 })
      .catch(() => {});
    f = (await pick(p)).lastFrame;
    const fixedShare = clippedShare(await canvasPixels(p));
    check(f.exposureMode === 'fixed' && f.exposureStops === 3 && fixedShare > 0.02,
          `exposure fixed at ${f.exposureStops} stops: ${(100 * fixedShare).toFixed(2)} % of pixels at 255 (> 2 %)`);
    await p.waitForTimeout(300);
    const hudExposure = await text(p, '#hud-exposure');
    check(hudExposure === '+3.0 stops fixed', `the HUD shows the fixed exposure ("${hudExposure}")`);
    await p.check('#exposure-auto');
    await p.waitForFunction(() => window.haarcast.lastFrame.exposureMode === 'auto', null, { timeout: 30000 }).catch(() => {});
    f = (await pick(p)).lastFrame;
    check(f.exposureMode === 'auto', `checking "auto" again brings auto-exposed frames (${f.exposureMode})`);

    // The tone curve: the schema's three, Reinhard in effect at first; AgX
    // chosen in the select is sent, answered by frames made with it.
    const tones = await p.evaluate(() => [...document.getElementById('tone').options].map((o) => o.value));
    check(tones.join(',') === 'reinhard,aces,agx', `the tone select offers ${tones.join(', ')}`);
    const toneBefore = await p.evaluate(() => document.getElementById('tone').value);
    check(toneBefore === 'reinhard' && f.tone === 'reinhard',
          `the tone select shows the curve in effect (${toneBefore}; frames: ${f.tone})`);
    const reinhardPixels = await canvasPixels(p);
    await p.selectOption('#tone', 'agx');
    await p.waitForFunction(() => window.haarcast.lastFrame.tone === 'agx', null, { timeout: 30000 }).catch(() => {});
    f = (await pick(p)).lastFrame;
    const agxPixels = await canvasPixels(p);
    let changed = 0;
    for (let i = 0; i < Math.min(agxPixels.length, reinhardPixels.length); i++) changed += agxPixels[i] !== reinhardPixels[i];
    check(f.tone === 'agx' && changed > 0, `choosing agx brings frames made with it (${f.tone}; ${changed} bytes differ)`);
    check(problems.length === 0, `exposure page: no page errors (${problems.join('; ')})`);
    await p.close();
  }

  // 5. Below 1 fps (the server paces this session to 0.8 fps): the HUD
  // settles on a number and never shows 0.
  section('HUD below 1 fps');
  {
    const { page: p, problems } = await openPage('size=48x48&fps=0.8');
    await waitFrames(p, 1);
    const seen = [];
    for (const end = Date.now() + 6000; Date.now() < end;) {
      await p.mouse.move(300, 300);
      await p.mouse.down();
      await p.mouse.move(303, 300);
      await p.mouse.up();
      await p.waitForTimeout(100);
      seen.push(await p.evaluate(() => document.getElementById('hud-fps').textContent));
    }
    const last = Number(seen.at(-1));
    check(!seen.some((t) => Number(t) === 0) && last > 0.4 && last < 1.0,
          `at 0.8 fps the HUD shows ${[...new Set(seen)].join(' ')} (never 0; settles on ${seen.at(-1)})`);
    check(problems.length === 0, `slow page: no page errors (${problems.join('; ')})`);
    await p.close();
  }

  // 15. The stream fits the window (no ?size=): the view's size in device
  // pixels, asked again once after a resize; a fixed 360p. And 16. the HUD
  // on a small view: folded by default, idle when nothing changes.
  section('stream size and HUD');
  {
    const { page: p, problems } = await openPage('level=4', { viewport: { width: 400, height: 300 } });
    await waitFrames(p, 1);
    // The view's content box × devicePixelRatio, even, as the page should ask.
    const fits = () => p.evaluate(() => {
      const stage = document.getElementById('stage');
      const cs = getComputedStyle(stage);
      const dpr = window.devicePixelRatio;
      const w = (stage.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight)) * dpr;
      const h = (stage.clientHeight - parseFloat(cs.paddingTop) - parseFloat(cs.paddingBottom)) * dpr;
      const f = window.haarcast.lastFrame;
      return { want: [2 * Math.floor(w / 2), 2 * Math.floor(h / 2)], frame: [f.width, f.height],
               resizes: window.haarcast.resizes };
    });
    const waitSize = (want) => p.waitForFunction((w) => window.haarcast.lastFrame.width === w[0] &&
                                                       window.haarcast.lastFrame.height === w[1], want, { timeout: 30000 })
      .catch(() => {});
    let f = await fits();
    await waitSize(f.want);
    f = await fits();
    check(JSON.stringify(f.frame) === JSON.stringify(f.want), `400×300: the frames are the view's size (${f.frame} for a ${f.want} view)`);
    // Five resizes in quick succession (each well inside the 300 ms
    // debounce, though a loaded machine may stretch one): one or two sizes
    // asked for, the last the last view's.
    const resizesBefore = f.resizes;
    for (const [w, h] of [[500, 360], [560, 400], [600, 420], [620, 450], [640, 480]]) {
      await p.setViewportSize({ width: w, height: h });
      await p.waitForTimeout(20);
    }
    await p.waitForTimeout(600);
    f = await fits();
    await waitSize(f.want);
    f = await fits();
    check(JSON.stringify(f.frame) === JSON.stringify(f.want) && f.resizes >= resizesBefore + 1 && f.resizes <= resizesBefore + 2,
          `after resizing to 640×480 the frames are the new view's size (${f.frame} for ${f.want}; ` +
          `${f.resizes - resizesBefore} size(s) asked for five resizes)`);
    const foldedNow = () => p.evaluate(() => window.haarcast.hudFolded);
    check(!(await foldedNow()), 'at 640×480 the HUD unfolds: its default follows the window until the user chooses');
    await p.selectOption('#resolution', '360p');
    await p.waitForFunction(() => window.haarcast.lastFrame.height === 360, null, { timeout: 30000 }).catch(() => {});
    f = await fits();
    const address = await p.evaluate(() => location.search);
    check(f.frame[1] === 360 && Math.abs(f.frame[0] / 360 - f.want[0] / f.want[1]) < 0.02 && /resolution=360p/.test(address),
          `360p: ${f.frame[0]}×${f.frame[1]} frames with the view's aspect (${(f.want[0] / f.want[1]).toFixed(3)}), address ${address}`);
    await p.selectOption('#resolution', 'auto');
    await p.setViewportSize({ width: 400, height: 300 });
    await p.waitForTimeout(600);
    f = await fits();
    await waitSize(f.want);

    // The HUD at 400×300: folded to its first line, which covers little of the view.
    const hudBox = () => p.evaluate(() => {
      const a = document.getElementById('hud').getBoundingClientRect();
      const c = document.getElementById('frame').getBoundingClientRect();
      return { share: (a.width * a.height) / (c.width * c.height), folded: window.haarcast.hudFolded,
               more: getComputedStyle(document.getElementById('hud-more')).display };
    });
    let hb = await hudBox();
    check(hb.folded && hb.more === 'none' && hb.share < 0.15,
          `400×300: the HUD starts folded and covers ${(100 * hb.share).toFixed(1)} % of the view (< 15 %)`);
    await p.click('#hud-toggle');
    hb = await hudBox();
    check(!hb.folded && hb.more !== 'none', `the HUD's button shows its details (${(100 * hb.share).toFixed(1)} % of the view)`);
    await p.keyboard.press('h');
    hb = await hudBox();
    check(hb.folded, 'h folds it again');
    await p.setViewportSize({ width: 700, height: 500 });
    await p.waitForTimeout(100);
    check(await foldedNow(), 'once the user has folded it, a wider window leaves the HUD folded');
    await p.setViewportSize({ width: 400, height: 300 });
    // Nothing changes for a while: idle, with the last frame's age.
    await p.waitForTimeout(3500);
    const idle = await text(p, '#hud-idle');
    check(/^idle — last frame \d+(\.\d)? s ago, up to date$/.test(idle || ''), `a still view: the HUD says "${idle}"`);
    if (opts.out) await p.screenshot({ path: join(opts.out, 'idle-400x300.png') });
    check(problems.length === 0, `stream size page: no page errors (${problems.join('; ')})`);
    await p.close();
  }

  // 17. Pinch on a touch screen: two fingers spreading bring the camera closer.
  section('pinch');
  {
    const context = await browser.newContext({ viewport: { width: 390, height: 844 }, hasTouch: true, isMobile: true });
    const p = await context.newPage();
    const problems = [];
    p.on('pageerror', (e) => problems.push(e.message));
    await p.goto(`${base}?size=64x64`);
    await waitFrames(p, 1);
    const before = await p.evaluate(() => ({ d: window.haarcast.viewDistance(), poses: window.haarcast.posesSent }));
    const c = await p.locator('#frame').boundingBox();
    const cx = c.x + c.width / 2, cy = c.y + c.height / 2;
    const cdp = await context.newCDPSession(p);
    const touch = (type, spread) => cdp.send('Input.dispatchTouchEvent', {
      type, touchPoints: spread === null ? [] : [{ x: cx - spread, y: cy, id: 1 }, { x: cx + spread, y: cy, id: 2 }],
    });
    await touch('touchStart', 20);
    for (let k = 1; k <= 8; k++) {
      await touch('touchMove', 20 + 5 * k);
      await p.waitForTimeout(20);
    }
    await touch('touchEnd', null);
    await p.waitForTimeout(300);
    const after = await p.evaluate(() => ({ d: window.haarcast.viewDistance(), poses: window.haarcast.posesSent,
                                            pinches: window.haarcast.pinches }));
    // Fingers 40 → 120 px apart: the distance ×1/3.
    check(after.pinches > 0 && Math.abs(after.d / before.d - 1 / 3) < 0.03 && after.poses > before.poses,
          `a pinch from 40 to 120 px apart takes the camera from ${before.d.toFixed(2)} to ${after.d.toFixed(2)} ` +
          `(${after.pinches} pinch moves, ${after.poses - before.poses} poses)`);
    await p.waitForFunction((n) => window.haarcast.lastFrame.poseSequence >= n, after.poses, { timeout: 30000 }).catch(() => {});
    check((await p.evaluate(() => window.haarcast.lastFrame.poseSequence)) >= after.poses, 'the pinch is answered with a frame');
    check(problems.length === 0, `pinch page: no page errors (${problems.join('; ')})`);
    await context.close();
  }

  // 18. From the first second to the first frame the page says what is going
  // on, and a frame that takes long shows how far it is over the old one,
  // dimmed (FrameProgress). A 1600×1200 frame takes seconds on the CPU
  // backend of a small machine.
  section('waiting and frame progress');
  {
    const p = await browser.newPage({ viewport: { width: 900, height: 700 } });
    const problems = [];
    p.on('pageerror', (e) => problems.push(e.message));
    // Every state of the waiting overlay, from the document's start.
    await p.addInitScript(() => {
      window.progressLog = [];
      document.addEventListener('DOMContentLoaded', () => {
        const el = document.getElementById('progress');
        const snap = () => {
          const h = window.haarcast;
          window.progressLog.push({
            t: performance.now(), shown: !el.hidden && getComputedStyle(el).display !== 'none',
            title: document.getElementById('progress-title').textContent,
            stage: document.getElementById('progress-stage').textContent,
            dimmed: document.getElementById('view').classList.contains('rendering'),
            frames: h ? h.framesShown : 0, messages: h ? h.frameProgressMessages : 0,
          });
        };
        snap();
        new MutationObserver(snap).observe(el, { attributes: true, subtree: true, childList: true, characterData: true });
        new MutationObserver(snap).observe(document.getElementById('view'), { attributes: true });
      });
    });
    await p.goto(`${base}?size=1600x1200&encoding=jpeg`);
    await waitFrames(p, 1);
    const log = await p.evaluate(() => window.progressLog);
    const early = log.find((r) => r.shown && r.title.length > 0);
    check(early && early.t <= 1000, `the page says what it waits for within 1 s of load ("${early && early.title}" at ` +
          `${early && early.t.toFixed(0)} ms)`);
    const beforeFrame = log.filter((r) => r.frames === 0);
    check(beforeFrame.every((r) => r.shown), `until the first frame the waiting overlay stays up (${beforeFrame.length} states)`);
    const firstProgress = beforeFrame.filter((r) => r.messages > 0);
    check(firstProgress.some((r) => /\d+ %/.test(r.stage)),
          `the first frame's progress is shown (${JSON.stringify(firstProgress.at(-1) && firstProgress.at(-1).stage)})`);
    const percents = firstProgress.map((r) => Number((/(\d+) %/.exec(r.stage) || [])[1])).filter(Number.isFinite);
    check(percents.every((v, i) => i === 0 || v >= percents[i - 1]), `a frame's progress never goes back (${percents.join(' → ')})`);
    check(!log.at(-1).shown, 'the first frame ends the waiting');
    if (opts.out) await p.screenshot({ path: join(opts.out, 'waiting-first-frame.png') });
    // A drag: its frame takes seconds, and shows its progress over the old frame, dimmed.
    const marker = log.length;
    const c = await p.locator('#frame').boundingBox();
    await p.mouse.move(c.x + c.width / 2, c.y + c.height / 2);
    await p.mouse.down();
    await p.mouse.move(c.x + c.width / 2 + 60, c.y + c.height / 2, { steps: 4 });
    await p.mouse.up();
    await p.waitForFunction(() => window.haarcast.framesShown >= 2, null, { timeout: 120000 });
    await p.waitForFunction((n) => window.haarcast.lastFrame.poseSequence >= n, await p.evaluate(() => window.haarcast.posesSent),
                            { timeout: 120000 });
    const after = (await p.evaluate(() => window.progressLog)).slice(marker);
    const over = after.filter((r) => r.shown && r.frames >= 1);
    check(over.length > 0 && over.every((r) => r.dimmed) && over.some((r) => /\d+ %/.test(r.stage)),
          `a long frame shows its progress over the old one, dimmed (${JSON.stringify(over.at(-1))})`);
    check(!after.at(-1).shown && !after.at(-1).dimmed, 'its frame ends it');
    check(problems.length === 0, `waiting page: no page errors (${problems.join('; ')})`);
    await p.close();
  }

  // 19. The address says the whole view: a page opened at it shows the same
  // picture (share_url.js). PNG frames and a fixed exposure: the two
  // canvases can be compared pixel for pixel.
  section('shareable address');
  {
    const a = await browser.newPage({ viewport: { width: 900, height: 700 } });
    const problems = [];
    a.on('pageerror', (e) => problems.push(e.message));
    await a.goto(`${base}?size=160x120&encoding=png&exposure=-1`);
    await waitFrames(a, 1);
    const c = await a.locator('#frame').boundingBox();
    const dragOn = async (p, box, modifier, dx, dy) => {
      if (modifier) await p.keyboard.down(modifier);
      await p.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
      await p.mouse.down();
      await p.mouse.move(box.x + box.width / 2 + dx, box.y + box.height / 2 + dy, { steps: 4 });
      await p.mouse.up();
      if (modifier) await p.keyboard.up(modifier);
    };
    await dragOn(a, c, null, 70, 25);
    await dragOn(a, c, 'Alt', 50, 0);
    await dragOn(a, c, 'Shift', -40, 30);
    await a.locator('#objects select').nth(1).selectOption('phong:16');
    await a.waitForFunction(() => window.haarcast.sceneInfo.objects[1].material === 'phong:16', null, { timeout: 60000 });
    await a.selectOption('#tone', 'aces');
    // Settled: the frame answers the last pose, and no frame comes for a while.
    const settle = async (p) => {
      await p.waitForFunction(() => window.haarcast.lastFrame.poseSequence >= window.haarcast.posesSent, null, { timeout: 60000 });
      let n = -1;
      while (n !== (await p.evaluate(() => window.haarcast.framesShown))) {
        n = await p.evaluate(() => window.haarcast.framesShown);
        await p.waitForTimeout(1000);
      }
    };
    await settle(a);
    const shared = await a.evaluate(() => location.href);
    const params = new URL(shared).searchParams;
    check(['scene', 'mat', 'tone', 'cam', 'light', 'obj', 'exposure', 'size', 'encoding'].every((k) => params.has(k)) &&
          /1:phong:16/.test(params.get('mat')) && params.get('tone') === 'aces',
          `the address says the view (${decodeURIComponent(new URL(shared).search)})`);
    const pixelsA = await canvasPixels(a);
    const b = await browser.newPage({ viewport: { width: 900, height: 700 } });
    b.on('pageerror', (e) => problems.push(e.message));
    await b.goto(shared);
    await waitFrames(b, 1);
    await settle(b);
    const pixelsB = await canvasPixels(b);
    const diff = meanAbsDiff(pixelsA, pixelsB);
    const sb = await b.evaluate(() => ({ material: window.haarcast.sceneInfo.objects[1].material, pose: window.haarcast.lastFrame.poseSequence }));
    check(sb.material === 'phong:16' && sb.pose >= 1 && diff < 0.5,
          `a second page opened at the address shows the same picture (mean |Δ| ${diff.toFixed(3)} per channel over ` +
          `${pixelsA.length / 4} pixels; its material ${sb.material}, its frame answers pose ${sb.pose})`);
    // And the comparison can fail: the scene's own view differs.
    const c2 = await browser.newPage({ viewport: { width: 900, height: 700 } });
    await c2.goto(`${base}?size=160x120&encoding=png&exposure=-1`);
    await waitFrames(c2, 1);
    const own = meanAbsDiff(pixelsA, await canvasPixels(c2));
    check(own > 2, `the scene's own view is another picture (mean |Δ| ${own.toFixed(2)})`);
    check(problems.length === 0, `address pages: no page errors (${problems.join('; ')})`);
    if (opts.out) await b.screenshot({ path: join(opts.out, 'shared-address.png') });
    await Promise.all([a.close(), b.close(), c2.close()]);
  }

  // 10. A dropped connection: the page counts down and reconnects.
  section('reconnect');
  {
    proxy = await startProxy(new URL(base));
    const { page: p, problems } = await openPage('size=64x64', { origin: proxy.base, networkErrors: true });
    await waitFrames(p, 1);
    const before = await pick(p);
    proxy.drop(2500);
    await p.waitForFunction(() => window.haarcast.connection === 'reconnect-wait', null, { timeout: 5000 }).catch(() => {});
    const status = await text(p, '#status');
    check(/disconnected .*reconnecting in \d+ s \(attempt \d+\)/.test(status), `a dropped socket shows the countdown ("${status}")`);
    await p.waitForFunction((w) => window.haarcast.welcomes > w && window.haarcast.framesShown > 0 &&
                                   window.haarcast.lastShownSequence >= 1, before.welcomes, { timeout: 30000 }).catch(() => {});
    const after = await pick(p);
    const status2 = await text(p, '#status');
    check(after.welcomes === before.welcomes + 1 && after.connection === 'ready' && after.connections >= 2,
          `the page reconnected (${after.connections} connections, ${after.welcomes} Welcomes, "${status2}")`);
    const framesBefore = after.framesShown;
    await p.mouse.move(300, 300);
    await p.mouse.down();
    await p.mouse.move(340, 300, { steps: 3 });
    await p.mouse.up();
    await p.waitForFunction((n) => window.haarcast.framesShown > n, framesBefore, { timeout: 30000 }).catch(() => {});
    check((await pick(p)).framesShown > framesBefore, 'after the reconnect a drag brings a frame');
    check(problems.length === 0, `reconnect page: no page errors (${problems.join('; ')})`);
    await p.close();
  }
} catch (err) {
  failures.push(err.message);
  console.log(`FAIL ${err.stack || err.message}`);
} finally {
  if (browser) await browser.close();
  if (proxy) await proxy.close();
  server.child.kill('SIGTERM');
  const timeout = new Promise((r) => setTimeout(() => r(null), 15000));
  const exit = await Promise.race([server.exited, timeout]);
  if (exit === null) {
    server.child.kill('SIGKILL');
    check(false, 'the server exits within 15 s of SIGTERM');
  } else {
    check(exit.code === 0, `the server exits 0 on SIGTERM (code ${exit.code}, signal ${exit.signal})`);
  }
  rmSync(sceneDir, { recursive: true, force: true });
  if (failures.length) console.log(`--- server log ---\n${server.log().slice(-4000)}`);
}

console.log(failures.length ? `${failures.length} check(s) failed` : 'all checks passed');
process.exit(failures.length ? 1 : 0);
