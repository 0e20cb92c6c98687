// Screenshots of the browser client against a running server, at a desktop
// window, a small one and a touch phone, with frames streaming (a slow
// orbit drag just before each shot, so that the HUD has numbers). Each
// page asks for the frame size that fits its view (no ?size=). Uses
// Debian's Chromium through playwright-core (a devDependency: `npm ci` in
// client/web).
//
// usage: node client/web/scripts/screenshots.mjs URL OUT_DIR [--chromium /usr/bin/chromium]
//   e.g. build/bin/haarcast serve --port 8080 &
//        node client/web/scripts/screenshots.mjs 'http://127.0.0.1:8080/' build/screens
// Writes OUT_DIR/page-1280x800.png, page-400x300.png and page-390x844.png
// (the phone's whole page, 3 device pixels per CSS pixel).
import { mkdirSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join } from 'node:path';

const require = createRequire(import.meta.url);
const { chromium } = require('playwright-core');

const [url, out, ...rest] = process.argv.slice(2);
if (!url || !out) {
  console.error('usage: screenshots.mjs URL OUT_DIR [--chromium PATH]');
  process.exit(2);
}
const chromiumPath = rest[0] === '--chromium' && rest[1] ? rest[1] : '/usr/bin/chromium';
mkdirSync(out, { recursive: true });

const shots = [
  { name: 'page-1280x800.png', context: { viewport: { width: 1280, height: 800 } } },
  { name: 'page-400x300.png', context: { viewport: { width: 400, height: 300 } } },
  { name: 'page-390x844.png', fullPage: true,
    context: { viewport: { width: 390, height: 844 }, deviceScaleFactor: 3, isMobile: true, hasTouch: true } },
];

const browser = await chromium.launch({ executablePath: chromiumPath, headless: true,
                                        args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'] });
try {
  for (const shot of shots) {
    const context = await browser.newContext(shot.context);
    const page = await context.newPage();
    await page.goto(url);
    await page.waitForFunction(() => window.haarcast && window.haarcast.framesShown >= 1, null, { timeout: 120000 });
    // Two seconds of a slow orbit: frames stream and the HUD fills in.
    const box = await page.locator('#frame').boundingBox();
    const x = box.x + box.width / 2, y = box.y + box.height / 2;
    await page.mouse.move(x, y);
    await page.mouse.down();
    for (let i = 1; i <= 40; i++) {
      await page.mouse.move(x + i * 2, y + i * 0.3);
      await page.waitForTimeout(50);
    }
    await page.mouse.up();
    await page.waitForTimeout(500);
    await page.screenshot({ path: join(out, shot.name), fullPage: !!shot.fullPage });
    const hud = await page.evaluate(() => document.getElementById('hud').innerText.replace(/\n/g, ' | '));
    console.log(`${join(out, shot.name)}: ${hud}`);
    await context.close();
  }
} finally {
  await browser.close();
}
