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

source "$(dirname "${BASH_SOURCE[0]}")/browser_env.sh"

args=(--haarcast "$haarcast" --chromium "$chromium")
[[ -n "$out" ]] && args+=(--out "$out")
# E2E_SCRIPT: another test of the page in this folder (browser_h264.mjs).
exec node "$repo/tests/e2e/${E2E_SCRIPT:-browser_e2e.mjs}" "${args[@]}" -- "$@"
