// End-to-end test of the browser client: starts `haarcast serve --port 0`,
// opens the page in Debian's Chromium (headless, driven by playwright-core;
// no browser is ever downloaded), and checks that
//   1. a frame arrives on the canvas and a screenshot of it is not blank;
//   2. a drag (camera orbit) brings a new frame that differs from the first;
//   3. shift-drag (object) and alt-drag (light) are sent as poses and answered;
//   4. the HUD shows fps, latency, kbit/s and the method, and keeps updating;
//   5. the method control reaches the server (frames come back with it);
//   6. the server exits 0 on SIGTERM.
//
// usage: node browser_e2e.mjs --haarcast BUILD/bin/haarcast [--chromium /usr/bin/chromium]
//        [--out DIR] [--page-query 'size=64x64&encoding=jpeg'] [-- extra `serve` args]
import { spawn } from 'node:child_process';
import { mkdirSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { inflateSync } from 'node:zlib';

const repo = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
// playwright-core is a devDependency of the browser client (client/web).
const require = createRequire(join(repo, 'client', 'web', 'package.json'));
const { chromium } = require('playwright-core');

// ---- arguments ------------------------------------------------------------------

const args = process.argv.slice(2);
const opts = { haarcast: '', chromium: '/usr/bin/chromium', out: '', 'page-query': 'size=96x96&encoding=jpeg', serveArgs: [] };
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--') { opts.serveArgs = args.slice(i + 1); break; }
  const key = args[i].replace(/^--/, '');
  if (!(key in opts) || i + 1 >= args.length) throw new Error(`unknown or incomplete argument "${args[i]}"`);
  opts[key] = args[++i];
}
if (!opts.haarcast) throw new Error('--haarcast PATH (the haarcast binary) is required');

const failures = [];
function check(condition, what) {
  console.log(`${condition ? 'ok  ' : 'FAIL'} ${what}`);
  if (!condition) failures.push(what);
}

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

// ---- the server -------------------------------------------------------------------

function startServer() {
  const child = spawn(opts.haarcast, ['serve', '--port', '0', ...opts.serveArgs], {
    stdio: ['ignore', 'pipe', 'pipe'],
  });
  let log = '';
  const url = new Promise((resolveUrl, reject) => {
    const timer = setTimeout(() => reject(new Error(`the server printed no "listening on" line in 60 s:\n${log}`)), 60000);
    const onData = (chunk) => {
      log += chunk;
      const m = /listening on (http:\/\/[^\s]+)/.exec(log);
      if (m) { clearTimeout(timer); resolveUrl(m[1]); }
    };
    child.stdout.on('data', onData);
    child.stderr.on('data', (chunk) => { log += chunk; });
    child.on('exit', (code, signal) => {
      clearTimeout(timer);
      reject(new Error(`the server exited early (code ${code}, signal ${signal}):\n${log}`));
    });
  });
  const exited = new Promise((resolveExit) => child.on('exit', (code, signal) => resolveExit({ code, signal })));
  return { child, url, exited, log: () => log };
}

// ---- the test ---------------------------------------------------------------------

const server = startServer();
let browser = null;
try {
  const base = await server.url;
  console.log(`server at ${base}`);
  browser = await chromium.launch({
    executablePath: opts.chromium,
    headless: true,
    // Root in a container has no user namespace for the sandbox.
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
  });
  const page = await browser.newPage({ viewport: { width: 900, height: 900 } });
  const consoleErrors = [];
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(e.message));
  page.on('request', (r) => {
    if (!r.url().startsWith(base)) consoleErrors.push(`request outside the server: ${r.url()}`);
  });

  await page.goto(`${base}?${opts['page-query']}`);
  const state = () => page.evaluate(() => ({ ...window.haarcast, welcome: !!window.haarcast.welcome }));
  // The first frame may wait for the server to prepare the scene (slice
  // tables, visibility): generous, but bounded.
  await page.waitForFunction(() => window.haarcast && window.haarcast.framesShown >= 1, null, { timeout: 120000 });
  const first = await state();
  check(first.framesShown >= 1, `a frame is on the canvas (frame ${first.lastFrame.sequence}, ${first.lastFrame.bytes} bytes)`);

  const canvas = page.locator('#frame');
  // The HUD floats over the canvas: hidden in screenshots, or its text alone
  // would make a blank frame look varied.
  const shotOptions = { style: '#hud { visibility: hidden !important; }' };
  const shot1 = decodePng(await canvas.screenshot(shotOptions));
  const l1 = luma(shot1);
  const sd1 = stddev(l1);
  check(sd1 > 2, `the screenshot is not blank (luma stddev ${sd1.toFixed(1)} > 2)`);
  if (opts.out) {
    mkdirSync(opts.out, { recursive: true });
    writeFileSync(join(opts.out, 'first.png'), await canvas.screenshot(shotOptions));
  }

  // 2. Drag to orbit: the frame must change.
  const box = await canvas.boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  const dragAndWait = async (what, modifier) => {
    const before = await state();
    if (modifier) await page.keyboard.down(modifier);
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    await page.mouse.move(cx + 120, cy + 20, { steps: 6 });
    await page.mouse.up();
    if (modifier) await page.keyboard.up(modifier);
    const sentTo = (await state()).posesSent;
    check(sentTo > before.posesSent, `${what}: poses sent (${before.posesSent} → ${sentTo})`);
    // Wait for the frame that answers the last pose of the drag.
    await page.waitForFunction((n) => window.haarcast.lastFrame && window.haarcast.lastFrame.poseSequence >= n,
                               sentTo, { timeout: 60000 });
    // One animation frame for the draw to land.
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => r())));
  };
  await dragAndWait('drag (orbit)');
  const shot2 = decodePng(await canvas.screenshot(shotOptions));
  const diffOrbit = meanAbsDiff(l1, luma(shot2));
  check(diffOrbit > 1, `the frame changed after the orbit drag (mean |Δluma| ${diffOrbit.toFixed(2)} > 1)`);
  if (opts.out) writeFileSync(join(opts.out, 'orbit.png'), await canvas.screenshot(shotOptions));

  await dragAndWait('alt-drag (light)', 'Alt');
  const shot3 = decodePng(await canvas.screenshot(shotOptions));
  const diffLight = meanAbsDiff(luma(shot2), luma(shot3));
  check(diffLight > 0.5, `the frame changed after the light drag (mean |Δluma| ${diffLight.toFixed(2)} > 0.5)`);
  await dragAndWait('shift-drag (object)', 'Shift');

  // 4. The HUD: numbers, and they keep updating.
  const hud = async () => page.evaluate(() => ({
    fps: document.getElementById('hud-fps').textContent,
    latency: document.getElementById('hud-latency').textContent,
    kbps: document.getElementById('hud-kbps').textContent,
    method: document.getElementById('hud-method').textContent,
    updates: window.haarcast.hudUpdates,
  }));
  // Keep frames flowing until the HUD's one-second window holds one (on the
  // CPU backend a frame can take most of a second).
  let h1 = await hud();
  for (const deadline = Date.now() + 30000; Date.now() < deadline;) {
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    await page.mouse.move(cx + 10, cy, { steps: 2 });
    await page.mouse.up();
    await page.waitForTimeout(200);
    h1 = await hud();
    if (Number(h1.fps) > 0 && Number(h1.latency) > 0 && Number(h1.kbps) > 0) break;
  }
  console.log(`HUD: ${h1.fps} fps, ${h1.latency} ms, ${h1.kbps} kbit/s, ${h1.method}`);
  check(Number(h1.fps) > 0, `HUD fps is a positive number ("${h1.fps}")`);
  check(Number(h1.latency) > 0, `HUD latency is a positive number of ms ("${h1.latency}")`);
  check(Number(h1.kbps) > 0, `HUD kbit/s is a positive number ("${h1.kbps}")`);
  check(['fused', 'haar', 'spatial', 'matrix', 'table'].includes(h1.method), `HUD method names a method ("${h1.method}")`);
  await page.waitForTimeout(600);
  const h2 = await hud();
  check(h2.updates > h1.updates, `the HUD keeps updating (${h1.updates} → ${h2.updates} redraws)`);

  // The controls were filled from Welcome.
  const materials = await page.locator('#material option').count();
  check(materials > 0, `the material control lists the server's materials (${materials})`);

  // 5. A control reaches the server: switch the method, drag, and the next
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

  check(after.errors.length === 0, `no server errors (${JSON.stringify(after.errors)})`);
  check(consoleErrors.length === 0, `no page errors or outside requests (${consoleErrors.join('; ')})`);
} catch (err) {
  failures.push(err.message);
  console.log(`FAIL ${err.stack || err.message}`);
} finally {
  if (browser) await browser.close();
  server.child.kill('SIGTERM');
  const timeout = new Promise((r) => setTimeout(() => r(null), 15000));
  const exit = await Promise.race([server.exited, timeout]);
  if (exit === null) {
    server.child.kill('SIGKILL');
    check(false, 'the server exits within 15 s of SIGTERM');
  } else {
    check(exit.code === 0, `the server exits 0 on SIGTERM (code ${exit.code}, signal ${exit.signal})`);
  }
  if (failures.length) console.log(`--- server log ---\n${server.log().slice(-4000)}`);
}

console.log(failures.length ? `${failures.length} check(s) failed` : 'all checks passed');
process.exit(failures.length ? 1 : 0);
