// Screenshots of the browser client against a running server, at a desktop
// and a phone-sized viewport, with frames streaming (a slow orbit drag just
// before each shot, so that the HUD has numbers). Uses Debian's Chromium
// through playwright-core (a devDependency: `npm ci` in client/web).
//
// usage: node client/web/scripts/screenshots.mjs URL OUT_DIR [--chromium /usr/bin/chromium]
//   e.g. build/bin/haarcast serve --port 8080 &
//        node client/web/scripts/screenshots.mjs 'http://127.0.0.1:8080/' build/screens
// Writes OUT_DIR/page-1200x800.png and OUT_DIR/page-400x800.png.
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
  { name: 'page-1200x800.png', viewport: { width: 1200, height: 800 }, query: 'size=480x360' },
  { name: 'page-400x800.png', viewport: { width: 400, height: 800 }, query: 'size=256x256' },
];

const browser = await chromium.launch({ executablePath: chromiumPath, headless: true,
                                        args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'] });
try {
  for (const shot of shots) {
    const page = await browser.newPage({ viewport: shot.viewport });
    const base = url.includes('?') ? `${url}&` : `${url}?`;
    await page.goto(`${base}${shot.query}`);
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
    await page.waitForTimeout(300);
    await page.screenshot({ path: join(out, shot.name) });
    const hud = await page.evaluate(() => document.getElementById('hud').innerText.replace(/\n/g, ' | '));
    console.log(`${join(out, shot.name)}: ${hud}`);
    await page.close();
  }
} finally {
  await browser.close();
}
