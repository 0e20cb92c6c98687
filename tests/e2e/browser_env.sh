# Sourced by the browser tests' CTest drivers (run_browser_e2e.sh,
# run_h264_webcodecs.sh): sets $repo, $web and $chromium, exits 77 (CTest's
# skip code) when node, npm or chromium is absent, and vendors the browser
# client's npm packages with `npm ci` when they are missing or stale. The lock
# file pins every package; never a browser download: playwright-core drives
# Debian's Chromium.
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

export PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1
if [[ ! -d "$web/node_modules/playwright-core" || ! -f "$web/vendor/protobuf.min.js" ||
      "$web/package-lock.json" -nt "$web/node_modules/.package-lock.json" ]]; then
  echo "npm ci in $web"
  (cd "$web" && npm ci --no-audit --no-fund)
fi
