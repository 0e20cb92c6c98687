// What the browser tests of this folder share (browser_e2e.mjs and its
// siblings, run by run_browser_e2e.sh): their arguments, a `haarcast serve`
// child whose printed URL they wait for, and the ok/FAIL lines they print.
import { spawn } from 'node:child_process';
import { mkdirSync, rmSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

export const repo = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');

// playwright-core, vendored in the browser client's node_modules (npm ci).
export function playwright() {
  return createRequire(join(repo, 'client', 'web', 'package.json'))('playwright-core');
}

// --haarcast PATH [--chromium PATH] [--out DIR] [-- extra `serve` args],
// and a test's own options with their defaults (`more`); --out is made
// when given.
export function parseArgs(args, more = {}) {
  const opts = { haarcast: '', chromium: '/usr/bin/chromium', out: '', ...more, serveArgs: [] };
  for (let i = 0; i < args.length; i++) {
    if (args[i] === '--') { opts.serveArgs = args.slice(i + 1); break; }
    const key = args[i].replace(/^--/, '');
    if (!(key in opts) || key === 'serveArgs' || i + 1 >= args.length) throw new Error(`unknown or incomplete argument "${args[i]}"`);
    opts[key] = args[++i];
  }
  if (!opts.haarcast) throw new Error('--haarcast PATH (the haarcast binary) is required');
  if (opts.out) mkdirSync(opts.out, { recursive: true });
  return opts;
}

// `check(condition, what)` prints one ok/FAIL line; `failures` lists the FAILs.
export function checks() {
  const failures = [];
  const check = (condition, what) => {
    console.log(`${condition ? 'ok  ' : 'FAIL'} ${what}`);
    if (!condition) failures.push(what);
  };
  return { check, failures };
}

// `haarcast serve --port 0 ARGS`: `url` resolves to the URL it prints (or
// rejects, with its log, when it prints none in 60 s or exits first),
// `exited` to its {code, signal}, `log()` is what it wrote so far.
export function startServer(haarcast, serveArgs) {
  const child = spawn(haarcast, ['serve', '--port', '0', ...serveArgs], { stdio: ['ignore', 'pipe', 'pipe'] });
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

// SIGTERM, then SIGKILL after 15 s: a clean stop is exit 0 within them.
export async function stopServer(started, check) {
  started.child.kill('SIGTERM');
  const exit = await Promise.race([started.exited, new Promise((r) => setTimeout(() => r(null), 15000))]);
  if (exit === null) started.child.kill('SIGKILL');
  check(exit !== null && exit.code === 0, `the server exits 0 on SIGTERM (${JSON.stringify(exit)})`);
}

// The end of a test: the browser closed, the server stopped (its exit
// checked), `dir` removed, the server's log shown after a failure, and the
// process's exit status.
export async function finish({ browser, started, check, failures, dir, what }) {
  if (browser) await browser.close();
  await stopServer(started, check);
  if (dir) rmSync(dir, { recursive: true, force: true });
  if (failures.length) console.log(`--- server log ---\n${started.log().slice(-3000)}`);
  console.log(failures.length ? `${failures.length} check(s) failed` : `all ${what} checks passed`);
  process.exit(failures.length ? 1 : 0);
}

// Debian's Chromium, headless; root in a container has no user namespace
// for the sandbox.
export function launchChromium(chromium, executablePath) {
  return chromium.launch({ executablePath, headless: true, args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'] });
}
