// The browser's H.264 path (client/web/h264_decoder.js) in Debian's headless
// Chromium, driven by playwright-core as browser_e2e.mjs is. The stream is
// the server encoder's own: 60 frames of an orbit at 256², a keyframe
// requested at frame 30, written by `haarcast_h264_client_tests
// --gtest_filter=H264Client.WritesTheOrbitForTheBrowserCheck`.
//
// When WebCodecs decodes the stream's codec here, checks that
//   1. the codec string comes from the SPS, and each unit's key/delta type
//      from its NAL types agrees with the encoder's keyframe flags;
//   2. every frame is decoded and drawn, none blank, and the last one is
//      within the encoder test's PSNR of its source (the colour conversion,
//      BT.709 limited range, agrees with the encoder's);
//   3. a delta unit before any keyframe is refused (the caller asks for a
//      keyframe), and a decoder joining at the requested keyframe decodes on;
//   4. every VideoFrame is closed (no "garbage collected" warnings).
// Otherwise it reports why, and that the page falls back to JPEG; that is a
// pass: the fallback is the behaviour the client promises there.
//
// usage: node h264_webcodecs.mjs --stream DIR [--chromium /usr/bin/chromium]
import { readFileSync } from 'node:fs';
import http from 'node:http';
import { createRequire } from 'node:module';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const repo = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
const require = createRequire(join(repo, 'client', 'web', 'package.json'));
const { chromium } = require('playwright-core');

const args = process.argv.slice(2);
const opts = { stream: '', chromium: '/usr/bin/chromium' };
for (let i = 0; i < args.length; i += 2) {
  const key = args[i].replace(/^--/, '');
  if (!(key in opts) || i + 1 >= args.length) throw new Error(`unknown or incomplete argument "${args[i]}"`);
  opts[key] = args[i + 1];
}
if (!opts.stream) throw new Error('--stream DIR (orbit.h264, orbit.json, last-source.rgba) is required');

const failures = [];
function check(condition, what) {
  console.log(`${condition ? 'ok  ' : 'FAIL'} ${what}`);
  if (!condition) failures.push(what);
}

// WebCodecs exists only in secure contexts: the page is served from
// 127.0.0.1, which browsers treat as one.
const files = {
  '/h264_decoder.js': [join(repo, 'client', 'web', 'h264_decoder.js'), 'text/javascript'],
  '/orbit.h264': [join(opts.stream, 'orbit.h264'), 'application/octet-stream'],
  '/orbit.json': [join(opts.stream, 'orbit.json'), 'application/json'],
  '/last-source.rgba': [join(opts.stream, 'last-source.rgba'), 'application/octet-stream'],
};
const page = '<!doctype html><meta charset="utf-8"><title>h264</title><canvas id="c"></canvas>';
const server = http.createServer((req, res) => {
  if (req.url === '/') return res.writeHead(200, { 'content-type': 'text/html' }).end(page);
  if (req.url === '/favicon.ico') return res.writeHead(204).end();
  const file = files[req.url];
  if (!file) return res.writeHead(404).end();
  res.writeHead(200, { 'content-type': file[1] }).end(readFileSync(file[0]));
});
await new Promise((r) => server.listen(0, '127.0.0.1', r));
const base = `http://127.0.0.1:${server.address().port}`;

// Runs in the page: decodes the stream three ways and measures each picture.
async function decodeInPage() {
  const mod = await import('/h264_decoder.js');
  const index = await (await fetch('/orbit.json')).json();
  const stream = new Uint8Array(await (await fetch('/orbit.h264')).arrayBuffer());
  const source = new Uint8Array(await (await fetch('/last-source.rgba')).arrayBuffer());
  const { width: w, height: h } = index;
  const unit = (i) => stream.subarray(index.units[i].offset, index.units[i].offset + index.units[i].size);
  const codec = mod.codecFromSps(unit(0));
  const probe = await mod.h264Support();
  const support = await mod.h264Support(codec);
  // The fallback path, whatever this browser supports: a codec no decoder
  // knows is reported with the encoding to ask for instead.
  const bogus = await mod.h264Support('avc1.FF0099');
  const result = { codec, probe, support, bogus, userAgent: navigator.userAgent };
  if (!support.supported) return result;

  result.keyFlagsAgree = index.units.every((u, i) => mod.isKeyframe(unit(i)) === u.key);
  const canvas = document.getElementById('c');
  canvas.width = w;
  canvas.height = h;
  const ctx = canvas.getContext('2d', { willReadFrequently: true });
  const lumaStddev = (d) => {
    let mean = 0, m2 = 0;
    for (let i = 0, n = 1; i < d.length; i += 4, n++) {
      const l = 0.2126 * d[i] + 0.7152 * d[i + 1] + 0.0722 * d[i + 2];
      const delta = l - mean;
      mean += delta / n;
      m2 += delta * (l - mean);
    }
    return Math.sqrt(m2 / (d.length / 4));
  };
  const psnr = (a, b) => {
    let sum = 0, n = 0;
    for (let i = 0; i < a.length; i++) {
      if (i % 4 === 3) continue;
      sum += (a[i] - b[i]) ** 2;
      n++;
    }
    return sum === 0 ? 99 : 10 * Math.log10((255 * 255) / (sum / n));
  };
  const run = async (from) => {
    const out = { stddevs: [], errors: [], last: null, accepted: 0 };
    const decoder = new mod.H264Decoder({
      draw: (frame) => {
        ctx.drawImage(frame, 0, 0);
        const pixels = ctx.getImageData(0, 0, w, h).data;
        out.stddevs.push(lumaStddev(pixels));
        out.last = pixels;
      },
      onError: (message) => out.errors.push(message),
    });
    for (let i = from; i < index.units.length; i++) {
      if (decoder.decode(unit(i), w, h, i * 33333)) out.accepted++;
    }
    await decoder.flush();
    out.decoded = decoder.decoded;
    out.skipped = decoder.skipped;
    out.lastPsnr = out.last ? psnr(out.last, source) : 0;
    delete out.last;
    decoder.close();
    return out;
  };
  result.full = await run(0);
  result.late = await run(30);   // joins at the requested keyframe
  result.between = await run(31); // joins between keyframes: nothing until the interval's next
  result.minPsnrDb = index.min_psnr_db;
  result.frames = index.units.length;
  return result;
}

let browser = null;
try {
  browser = await chromium.launch({
    executablePath: opts.chromium,
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
  });
  const p = await browser.newPage();
  const consoleLines = [];
  p.on('console', (m) => consoleLines.push(m.text()));
  p.on('pageerror', (e) => consoleLines.push(`page error: ${e.message}`));
  await p.goto(`${base}/`);
  const r = await p.evaluate(decodeInPage);
  console.log(`${r.userAgent}\nstream codec ${r.codec}; probe ${JSON.stringify(r.probe)}; stream ${JSON.stringify(r.support)}`);
  check(/^avc1\.[0-9A-F]{6}$/.test(r.codec || ''), `the codec string comes from the SPS (${r.codec})`);
  check(!r.bogus.supported && r.bogus.fallback === 'jpeg',
    `an unknown codec is reported with the JPEG fallback (${JSON.stringify(r.bogus)})`);
  if (!r.support.supported) {
    check(r.support.fallback === 'jpeg' && r.support.reason.length > 0,
      `WebCodecs H.264 is not available here (${r.support.reason}): the client is told to ask for JPEG`);
  } else {
    check(r.keyFlagsAgree, 'key/delta from the NAL types agrees with the encoder\'s keyframe flags');
    check(r.full.decoded === r.frames && r.full.errors.length === 0,
      `every frame decoded and drawn (${r.full.decoded}/${r.frames}; ${r.full.errors.length} errors, the first: ${r.full.errors[0] || 'none'})`);
    const blank = r.full.stddevs.filter((s) => s < 1).length;
    check(blank === 0, `no frame is blank (luma stddev min ${Math.min(...r.full.stddevs).toFixed(1)})`);
    check(r.full.lastPsnr >= r.minPsnrDb,
      `the last picture is within ${r.minPsnrDb} dB PSNR of its source (${r.full.lastPsnr.toFixed(1)} dB)`);
    check(r.late.decoded === r.frames - 30 && r.late.skipped === 0,
      `a decoder joining at the requested keyframe decodes on (${r.late.decoded}/${r.frames - 30})`);
    check(r.between.skipped === r.frames - 31 && r.between.decoded === 0,
      `a decoder joining between keyframes refuses the delta units (${r.between.skipped} refused)`);
  }
  // Chromium warns on the console when a VideoFrame is garbage collected
  // without close(); page errors land there too. Both fail the check.
  check(consoleLines.length === 0, `every VideoFrame closed, no page errors (${consoleLines.join(' | ') || 'console clean'})`);
} catch (err) {
  failures.push(err.message);
  console.log(`FAIL ${err.stack || err.message}`);
} finally {
  if (browser) await browser.close();
  server.close();
}
console.log(failures.length ? `${failures.length} check(s) failed` : 'all checks passed');
process.exit(failures.length ? 1 : 0);
