#!/usr/bin/env bash
# The container's entrypoint: runs `haarcast ARGS…` from this folder, but
# refuses to serve without a token. A container binds 0.0.0.0, so without a
# token anyone who reaches the port can open sessions (docs/service.md,
# "Authentication").
#
#   HAARCAST_TOKEN=T            the token (`haarcast serve` reads it; kept out of ps)
#   HAARCAST_ALLOW_NO_TOKEN=1   serve without a token anyway (a trusted network)
#   HAARCAST_BIN=PATH           the binary (default: haarcast beside this script)
#
# Other subcommands (render, bench-frame, …) run as they are.
set -euo pipefail

here="$(dirname "$(readlink -f "${BASH_SOURCE[0]}")")"
haarcast="${HAARCAST_BIN:-$here/haarcast}"

if [[ "${1:-}" == serve && -z "${HAARCAST_TOKEN:-}" ]]; then
  has_token_flag=0
  for arg in "$@"; do
    [[ "$arg" == --token || "$arg" == --token=* ]] && has_token_flag=1
  done
  if ((!has_token_flag)); then
    if [[ "${HAARCAST_ALLOW_NO_TOKEN:-}" == 1 ]]; then
      echo "entrypoint: WARNING: serving without a token (HAARCAST_ALLOW_NO_TOKEN=1): anyone who reaches the port can open sessions" >&2
    else
      echo "entrypoint: error: no token: set HAARCAST_TOKEN (or pass --token), or set HAARCAST_ALLOW_NO_TOKEN=1 to serve without one" >&2
      exit 64
    fi
  fi
fi
exec "$haarcast" "$@"
