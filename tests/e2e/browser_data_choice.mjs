// Probes and meshes chosen in the page (`haarcast serve --data DIR`,
// client/web/scene_panel.js), in Debian's headless Chromium (playwright-core,
// as browser_view_size.mjs). The test writes its own --data folder: a tiny
// warm lat-long probe (PFM) and a tiny tall box stored Z-up (OBJ). It checks
// that
//   - the scene fieldset offers the probe and the mesh (Welcome.probes,
//     Welcome.meshes), and no up control while no mesh is shown;
//   - choosing the probe, then the mesh (its up guessed: z), then flipping
//     its up to y, each is answered with a SceneInfo saying so and a frame
//     of the new choice that differs from the frame before it;
//   - the mesh scene lists its objects (the mesh and the ground);
//   - the panel fits a 400 px wide window with the new controls shown.
// With --out DIR it writes screenshots of the page with the mesh chosen, at
// 1000×800 and 400×800.
//
// usage: node browser_data_choice.mjs --haarcast BUILD/bin/haarcast [--chromium /usr/bin/chromium] [--out DIR]
//        [-- extra `serve` args]
import { mkdirSync, mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

import { checks, finish, launchChromium, parseArgs, playwright, startServer } from './browser_harness.mjs';

const { chromium } = playwright();
const opts = parseArgs(process.argv.slice(2));
const { check, failures } = checks();

// A lat-long probe, 32×16, as a little-endian colour PFM (rows bottom to
// top): a warm sky over a dark blue floor, unlike the built-in sky.
function warmProbePfm() {
  const w = 32, h = 16;
  const header = Buffer.from(`PF\n${w} ${h}\n-1.0\n`, 'ascii');
  const pixels = Buffer.alloc(w * h * 3 * 4);
  for (let row = 0; row < h; row++) {  // row 0 of the file: the bottom (θ = π)
    const up = row >= h / 2;
    for (let col = 0; col < w; col++) {
      const rgb = up ? [3.0, 1.4, 0.3] : [0.05, 0.08, 0.3];
      rgb.forEach((v, c) => pixels.writeFloatLE(v, 4 * (3 * (row * w + col) + c)));
    }
  }
  return Buffer.concat([header, pixels]);
}

// A box 0.4 × 0.3 × 1.2 stored Z-up (its long side along Z, Y the shortest):
// the server guesses z, and y lays it down.
function pillarObj() {
  const [x, y, z] = [0.4, 0.3, 1.2];
  let obj = '';
  for (let i = 0; i < 8; i++) obj += `v ${i & 1 ? x : 0} ${i & 2 ? y : 0} ${i & 4 ? z : 0}\n`;
  return obj + 'f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\nf 3 7 4\nf 4 7 8\nf 1 5 3\nf 3 5 7\nf 2 4 6\nf 4 8 6\n';
}

const dir = mkdtempSync(join(tmpdir(), 'haarcast-data-choice-'));
mkdirSync(join(dir, 'data', 'probes'), { recursive: true });
mkdirSync(join(dir, 'data', 'meshes'), { recursive: true });
writeFileSync(join(dir, 'data', 'probes', 'warm.pfm'), warmProbePfm());
writeFileSync(join(dir, 'data', 'meshes', 'pillar.obj'), pillarObj());
const started = startServer(opts.haarcast, ['--backend', 'cpu', '--level', '4',
                                     '--data', join(dir, 'data'), '--cache-dir', join(dir, 'cache'), '--quiet',
                                     ...opts.serveArgs]);
const base = await started.url;

let browser = null;
try {
  browser = await launchChromium(chromium, opts.chromium);
  const problems = [];
  const page = await browser.newPage({ viewport: { width: 1000, height: 800 } });
  page.on('pageerror', (e) => problems.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') problems.push(m.text()); });
  // A fixed exposure: another probe shows as another brightness, and a
  // still page gets no frames while auto exposure settles.
  // A small fixed size: each choice costs its build and a quick frame.
  await page.goto(`${base}?level=4&exposure=-1&size=160x120`);

  // The canvas once frames have stopped coming for 1 s (at most 60 s), as
  // bytes; `seq` the last frame's sequence.
  const settled = async () => {
    await page.waitForFunction(() => window.haarcast && window.haarcast.lastFrame, null, { timeout: 60000 });
    let seq = -1;
    for (let waited = 0; waited < 60000; waited += 1000) {
      const now = await page.evaluate(() => window.haarcast.lastFrame.sequence);
      if (now === seq) break;
      seq = now;
      await page.waitForTimeout(1000);
    }
    const pixels = await page.evaluate(() => {
      const c = document.getElementById('frame');
      return { w: c.width, h: c.height, data: Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data) };
    });
    return { seq, ...pixels };
  };
  // Mean absolute difference per channel (0..255); Infinity for other sizes.
  const difference = (a, b) => {
    if (a.w !== b.w || a.h !== b.h) return Infinity;
    let s = 0;
    for (let i = 0; i < a.data.length; i++) s += Math.abs(a.data[i] - b.data[i]);
    return s / a.data.length;
  };
  // After a choice: the SceneInfo answering it, then a newer frame, settled.
  const answered = async (what, want, before) => {
    await page.waitForFunction((w) => {
      const i = window.haarcast.sceneInfo;
      return i && (i.probe || '') === w.probe && (i.mesh || '') === w.mesh && (i.up || '') === w.up;
    }, want, { timeout: 60000 });
    await page.waitForFunction((s) => window.haarcast.lastFrame.sequence > s, before.seq, { timeout: 60000 });
    const after = await settled();
    const d = difference(before, after);
    check(d > 2, `${what}: a new frame (sequence ${after.seq} after ${before.seq}) differs from the one before ` +
                 `(mean difference ${d.toFixed(2)} of 255; want > 2)`);
    return after;
  };
  const shown = (id) => page.evaluate((i) => {
    const e = document.getElementById(i);
    return !!e && !e.closest('[hidden]') && e.getBoundingClientRect().width > 0;
  }, id);
  const optionsOf = (id) => page.evaluate((i) => [...document.getElementById(i).options].map((o) => o.value), id);

  const first = await settled();
  check(await shown('probe') && JSON.stringify(await optionsOf('probe')) === JSON.stringify(['', 'warm']),
        `the probe select is shown with the scene's own light and "warm" (${await optionsOf('probe')})`);
  check(await shown('mesh') && JSON.stringify(await optionsOf('mesh')) === JSON.stringify(['', 'pillar']),
        `the mesh select is shown with the scene's own objects and "pillar" (${await optionsOf('mesh')})`);
  check(!(await shown('up-choice')), 'no up control while no mesh is shown');

  await page.selectOption('#probe', 'warm');
  const warm = await answered('the probe "warm"', { probe: 'warm', mesh: '', up: '' }, first);

  await page.selectOption('#mesh', 'pillar');
  const pillar = await answered('the mesh "pillar"', { probe: 'warm', mesh: 'pillar', up: 'z' }, warm);
  const objects = await page.evaluate(() => [...document.querySelectorAll('#objects .name')].map((e) => e.firstChild.textContent));
  check(JSON.stringify(objects) === JSON.stringify(['pillar', 'ground']), `the objects listed are the mesh and the ground (${objects})`);
  const upState = await page.evaluate(() => ({
    checked: (document.querySelector('#up-choice input:checked') || {}).value,
    note: document.getElementById('up-note').textContent }));
  check(await shown('up-choice') && upState.checked === 'z' && /guessed/.test(upState.note),
        `the up control is shown with the guess, z, checked (${JSON.stringify(upState)})`);
  if (opts.out) await page.screenshot({ path: join(opts.out, 'data-choice-1000x800.png') });

  await page.check('#up-choice input[value="y"]');
  const flipped = await answered('the mesh flipped to y up', { probe: 'warm', mesh: 'pillar', up: 'y' }, pillar);
  check(flipped.seq > pillar.seq, 'the flip was drawn');
  // The address says the choice (share_url.js), and a page opened at it
  // draws the same canvas.
  await page.waitForTimeout(700);
  const address = await page.evaluate(() => location.href);
  const q = new URL(address).searchParams;
  check(q.get('probe') === 'warm' && q.get('mesh') === 'pillar' && q.get('up') === 'y',
        `the address names the probe, mesh and up (${decodeURIComponent(new URL(address).search)})`);
  const second = await browser.newPage({ viewport: { width: 1000, height: 800 } });
  await second.goto(address);
  await second.waitForFunction(() => window.haarcast && window.haarcast.lastFrame && window.haarcast.sceneInfo &&
                               window.haarcast.sceneInfo.mesh === 'pillar', null, { timeout: 60000 });
  await second.waitForTimeout(1500);
  const again = await second.evaluate(() => {
    const c = document.getElementById('frame');
    return { w: c.width, h: c.height, data: Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data) };
  });
  const same = difference(flipped, again);
  check(same < 0.5, `a page opened at the address draws the same (mean difference ${same.toFixed(3)})`);
  await second.close();

  // The new controls in a 400 px window: nothing in the panel is cut or outside it.
  await page.setViewportSize({ width: 400, height: 800 });
  await page.waitForTimeout(300);
  const cut = await page.evaluate(() => {
    const out = [];
    const panel = document.getElementById('panel').getBoundingClientRect();
    for (const e of document.querySelectorAll('#scene-controls select, #scene-controls label, #scene-controls input')) {
      if (e.closest('[hidden]')) continue;
      const r = e.getBoundingClientRect();
      if (r.width === 0) continue;
      if (r.left < panel.left - 0.5 || r.right > panel.right + 0.5) out.push(`${e.id || e.textContent.trim()} is outside the panel`);
      if (e.scrollWidth > e.clientWidth + 1 && e.tagName !== 'SELECT' && e.tagName !== 'INPUT') out.push(`${e.id} is cut`);
    }
    if (document.documentElement.scrollWidth > window.innerWidth) out.push(`the page is ${document.documentElement.scrollWidth} px wide`);
    return out;
  });
  check(cut.length === 0, `400×800: the scene fieldset fits the panel (${cut.join('; ')})`);
  if (opts.out) await page.screenshot({ path: join(opts.out, 'data-choice-400x800.png'), fullPage: true });
  check(problems.length === 0, `no page errors (${problems.join('; ')})`);
} catch (e) {
  check(false, `the test stopped: ${e.stack || e}`);  // finish() exits: the error must count
} finally {
  await finish({ browser, started, check, failures, dir, what: 'data-choice' });
}
