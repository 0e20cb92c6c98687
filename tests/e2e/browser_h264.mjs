// The browser client with ?encoding=h264 against `haarcast serve`, in
// Debian's headless Chromium (playwright-core, as browser_e2e.mjs).
//
// Where WebCodecs decodes H.264 here (h264Support()), the page asks for H.264:
//   - when the server answers Welcome with ENCODING_H264: frames are drawn
//     through the WebCodecs decoder, the canvas is not blank, a drag brings a
//     new picture, no keyframe had to be asked for after the first frames;
//   - when the server refuses ENCODING_H264 with an Error: exit 77 (skip),
//     quoting it: the server side of H.264 is a separate piece.
// Where it does not, the page shows the reason and its Hello asks for JPEG:
// the JPEG frames arrive and are drawn (the fallback is the check). That is
// also checked on a page whose VideoDecoder is removed before it loads, so
// the fallback is tested whatever this Chromium and this server can do; a
// failure there fails the test even when the H.264 part is skipped.
//
// usage: node browser_h264.mjs --haarcast BUILD/bin/haarcast [--chromium /usr/bin/chromium] [--out DIR]
//        [-- extra `serve` args]   (--out is accepted for run_browser_e2e.sh; nothing is written)
import { checks, launchChromium, parseArgs, playwright, repo, startServer } from './browser_harness.mjs';

const { chromium } = playwright();
const opts = parseArgs(process.argv.slice(2));
const { check, failures } = checks();

const started = startServer(opts.haarcast, ['--backend', process.env.HAARCAST_SMOKE_BACKEND || 'cpu',
                                     ...opts.serveArgs]);
const server = started.child;
const base = await started.url;

let exitCode = 0;
let browser = null;
try {
  browser = await launchChromium(chromium, opts.chromium);
  const page = await browser.newPage({ viewport: { width: 900, height: 900 } });
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') problems.push(m.text()); });
  await page.goto(`${base}?encoding=h264&size=256x256`);
  // The first frame, a server Error, or the page's own failure: whichever comes first.
  await page.waitForFunction(() => {
    const h = window.haarcast;
    return h && (h.framesShown > 0 || h.errors.length > 0);
  }, null, { timeout: 120000 });
  const s = () => page.evaluate(() => {
    const h = window.haarcast;
    return { support: h.h264, hello: h.helloEncoding, welcome: h.welcome && h.welcome.encoding,
             framesShown: h.framesShown, lastFrame: h.lastFrame, errors: h.errors, keyframes: h.keyframeRequests,
             note: document.getElementById('encoding-note').hidden ? '' : document.getElementById('encoding-note').textContent,
             stddev: (() => {
               const c = document.getElementById('frame');
               const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
               let sum = 0, sq = 0;
               for (let i = 0; i < d.length; i += 4) {
                 const l = 0.2126 * d[i] + 0.7152 * d[i + 1] + 0.0722 * d[i + 2];
                 sum += l;
                 sq += l * l;
               }
               const n = d.length / 4;
               return Math.sqrt(Math.max(0, sq / n - (sum / n) ** 2));
             })() };
  });
  const first = await s();
  console.log(`WebCodecs: ${JSON.stringify(first.support)}; the Hello asked for ${first.hello}`);
  const refused = first.errors.find((e) => /encoding|h\.?264/i.test(e.message));
  if (first.support.supported && first.framesShown === 0 && refused) {
    console.log(`SKIP: this server refuses H.264 frames: ${refused.code}: ${refused.message}`);
    exitCode = 77;
  } else if (first.support.supported) {
    check(first.hello === 'h264' && first.note === '', `the page asks for H.264 (${first.hello}) and shows no fallback note`);
    check(first.framesShown > 0 && first.lastFrame.encoding === 5,
          `an H.264 frame is drawn (frame ${first.lastFrame && first.lastFrame.sequence}, encoding ${first.lastFrame && first.lastFrame.encoding})`);
    check(first.stddev > 2, `the canvas is not blank (luma stddev ${first.stddev.toFixed(1)} > 2)`);
    const box = await page.locator('#frame').boundingBox();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width / 2 + 120, box.y + box.height / 2 + 20, { steps: 6 });
    await page.mouse.up();
    await page.waitForFunction((n) => window.haarcast.framesShown > n, first.framesShown, { timeout: 60000 });
    const after = await s();
    check(after.framesShown > first.framesShown && after.stddev > 2,
          `a drag brings new H.264 pictures (${after.framesShown} shown), not blank (${after.stddev.toFixed(1)})`);
    check(after.keyframes === 0, `the stream decoded without asking for a keyframe (${after.keyframes} asked)`);
  } else {
    check(first.hello === 'jpeg', `without WebCodecs H.264 the Hello asks for JPEG (${first.hello})`);
    check(first.note.includes(first.support.reason) && /JPEG/.test(first.note),
          `the page says why: ${JSON.stringify(first.note)}`);
    check(first.framesShown > 0 && first.lastFrame.encoding === 1 && first.stddev > 2,
          `JPEG frames are drawn instead (${first.framesShown}, luma stddev ${first.stddev.toFixed(1)})`);
  }
  if (exitCode !== 77) check(problems.length === 0, `no page errors (${problems.join('; ')})`);

  // A browser without WebCodecs (the page's VideoDecoder removed before its
  // scripts run): the fallback, whatever this Chromium and server can do.
  const bare = await browser.newPage({ viewport: { width: 900, height: 900 } });
  await bare.addInitScript(() => { delete window.VideoDecoder; });
  await bare.goto(`${base}?encoding=h264&size=128x128`);
  await bare.waitForFunction(() => window.haarcast && (window.haarcast.framesShown > 0 || window.haarcast.errors.length > 0),
                             null, { timeout: 120000 });
  const fb = await bare.evaluate(() => ({
    hello: window.haarcast.helloEncoding, shown: window.haarcast.framesShown, errors: window.haarcast.errors,
    encoding: window.haarcast.lastFrame && window.haarcast.lastFrame.encoding,
    note: document.getElementById('encoding-note').hidden ? '' : document.getElementById('encoding-note').textContent,
  }));
  check(fb.hello === 'jpeg' && /no WebCodecs VideoDecoder.*JPEG/.test(fb.note),
        `without WebCodecs: the Hello asks for ${fb.hello}, the page says ${JSON.stringify(fb.note)}`);
  check(fb.shown > 0 && fb.encoding === 1, `without WebCodecs: JPEG frames are drawn (${fb.shown}; ${JSON.stringify(fb.errors)})`);
} finally {
  if (browser) await browser.close();
  server.kill('SIGTERM');
}
if (exitCode === 77 && failures.length === 0) process.exit(77);
console.log(failures.length ? `${failures.length} failure(s)` : 'all browser H.264 checks passed');
process.exit(failures.length ? 1 : 0);
