# Sourced by the end-to-end shell tests. start_server CMD… runs a
# `haarcast serve --port 0 …` command line in the background with its output
# in $work/server.out and $work/server.err, waits for its "listening on" line
# and sets $server_pid and $port; when the server exits or prints no such
# line within 60 s, it prints FAIL with the server's output and exits 1.
start_server() {
  "$@" >"$work/server.out" 2>"$work/server.err" </dev/null &
  server_pid=$!
  port=""
  local i
  for ((i = 0; i < 600; i++)); do
    # (server.out may not exist yet: the background redirect races this loop)
    port="$(sed -n 's#.*listening on http://[^:]*:\([0-9]*\)/.*#\1#p' "$work/server.out" 2>/dev/null | head -1 || true)"
    [[ -n "$port" ]] && return 0
    kill -0 "$server_pid" 2>/dev/null || break
    sleep 0.1
  done
  echo "FAIL: the server did not start:"
  cat "$work/server.out" "$work/server.err"
  exit 1
}
