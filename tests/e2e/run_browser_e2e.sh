#!/usr/bin/env bash
# CTest driver of the browser end-to-end test (browser_e2e.mjs): vendors the
# browser client's npm packages with `npm ci` when they are missing, then runs
# the test with node against Debian's Chromium. Exits 77 (CTest's skip code)
# only when node, npm or chromium is absent; deploy/run.sh installs all three,
# so in CI this test runs.
#
# usage: run_browser_e2e.sh HAARCAST_BINARY [OUT_DIR] [-- extra `serve` args]
set -euo pipefail

haarcast="${1:?usage: run_browser_e2e.sh HAARCAST_BINARY [OUT_DIR] [-- serve args]}"
shift
out=""
if (($# > 0)) && [[ "$1" != "--" ]]; then
  out="$1"
  shift
fi
[[ "${1:-}" == "--" ]] && shift

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
web="$repo/client/web"
chromium="${CHROMIUM:-/usr/bin/chromium}"

for tool in node npm; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is not installed (deploy/run.sh installs it)"
    exit 77
  fi
done
if [[ ! -x "$chromium" ]]; then
  echo "SKIP: no Chromium at $chromium (apt-get install chromium, or set CHROMIUM)"
  exit 77
fi

# The lock file pins every package; `npm ci` installs exactly those, from the
# configured registry, and its postinstall copies protobufjs into vendor/.
# Never a browser download: playwright-core drives the Chromium above.
export PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1
if [[ ! -d "$web/node_modules/playwright-core" || ! -f "$web/vendor/protobuf.min.js" ||
      "$web/package-lock.json" -nt "$web/node_modules/.package-lock.json" ]]; then
  echo "npm ci in $web"
  (cd "$web" && npm ci --no-audit --no-fund)
fi

args=(--haarcast "$haarcast" --chromium "$chromium")
[[ -n "$out" ]] && args+=(--out "$out")
# E2E_SCRIPT: another test of the page in this folder (browser_h264.mjs).
exec node "$repo/tests/e2e/${E2E_SCRIPT:-browser_e2e.mjs}" "${args[@]}" -- "$@"
