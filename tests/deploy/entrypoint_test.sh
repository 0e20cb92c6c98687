#!/usr/bin/env bash
# deploy/entrypoint.sh, the container's entrypoint, with the built haarcast:
# `serve` without a token is refused (exit 64, naming both ways out); with
# HAARCAST_ALLOW_NO_TOKEN=1 or HAARCAST_TOKEN it execs the server, which then
# is the process a SIGTERM reaches (it drains and exits 0); other
# subcommands pass through without a token.
#
#   tests/deploy/entrypoint_test.sh ENTRYPOINT HAARCAST
set -euo pipefail
entrypoint="$1"
export HAARCAST_BIN="$2"
work="$(mktemp -d -t haarcast-entrypoint.XXXXXX)"
pid=""
trap '[[ -n "$pid" ]] && kill -KILL "$pid" 2>/dev/null; rm -rf "$work"' EXIT
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
unset HAARCAST_TOKEN HAARCAST_ALLOW_NO_TOKEN

# 1. No token: refused before the server starts.
rc=0
timeout 30 "$entrypoint" serve --port 0 --bind 127.0.0.1 >"$work/out" 2>"$work/err" || rc=$?
((rc == 64)) || fail "serve without a token exited $rc, expected 64"
if ! grep -q HAARCAST_TOKEN "$work/err" || ! grep -q HAARCAST_ALLOW_NO_TOKEN "$work/err"; then
  fail "the refusal does not name HAARCAST_TOKEN and HAARCAST_ALLOW_NO_TOKEN: $(cat "$work/err")"
fi
[[ ! -s "$work/out" ]] || fail "the server started anyway: $(cat "$work/out")"
echo "no token: refused (64): $(cat "$work/err")"

# 2, 3. Opt-out, then a token: the server starts in the entrypoint's own process.
serve_and_stop() {
  local what="$1"
  shift
  env "$@" "$entrypoint" serve --port 0 --bind 127.0.0.1 --quiet --cache-dir none >"$work/out" 2>"$work/err" &
  pid=$!
  for _ in $(seq 1 100); do
    grep -q '^listening on http://' "$work/out" && break
    kill -0 "$pid" 2>/dev/null || fail "$what: the server exited: $(cat "$work/err")"
    sleep 0.1
  done
  grep -q '^listening on http://' "$work/out" || fail "$what: no listening line in 10 s"
  # exec: the entrypoint's pid is the server's, so SIGTERM drains it.
  [[ "$(readlink "/proc/$pid/exe")" == "$(readlink -f "$HAARCAST_BIN")" ]] ||
    fail "$what: pid $pid runs $(readlink "/proc/$pid/exe"), not $HAARCAST_BIN (no exec)"
  kill -TERM "$pid"
  local rc=0
  wait "$pid" || rc=$?
  pid=""
  ((rc == 0)) || fail "$what: the server exited $rc after SIGTERM, expected 0"
  echo "$what: served, SIGTERM → 0"
}
serve_and_stop "HAARCAST_ALLOW_NO_TOKEN=1" HAARCAST_ALLOW_NO_TOKEN=1
grep -q 'WARNING: serving without a token' "$work/err" || fail "no warning when serving without a token"
serve_and_stop "HAARCAST_TOKEN" HAARCAST_TOKEN=secret

# 4. Other subcommands need no token.
"$entrypoint" render --help >/dev/null || fail "render --help through the entrypoint failed"
echo "PASS"
