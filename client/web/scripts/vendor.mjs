// Copies protobufjs's browser build next to the page (vendor/), so that the
// server serves it like any other static file and the page never downloads
// code at run time. Runs as npm's postinstall, after `npm ci`.
import { copyFileSync, mkdirSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(dirname(fileURLToPath(import.meta.url)));
const from = join(here, 'node_modules', 'protobufjs', 'dist', 'protobuf.min.js');
const to = join(here, 'vendor', 'protobuf.min.js');
mkdirSync(dirname(to), { recursive: true });
copyFileSync(from, to);
console.log(`vendored ${from} -> ${to}`);
