# Sourced by the scripts that run fovea-server on loopback (load-curve,
# soak, valgrind-server). Expects $bin, the folder with fovea-client.

# A port no one listens on: asks the kernel.
free_port() {
  /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'
}

# wait_serving PORT TRIES PAUSE: polls `fovea-client health` on
# 127.0.0.1:PORT up to TRIES times, PAUSE seconds apart, until SERVING.
# Returns 1 if it never was.
wait_serving() {
  local port="$1" tries="$2" pause="$3"
  for _ in $(seq 1 "$tries"); do
    "$bin/fovea-client" --server "127.0.0.1:$port" health >/dev/null 2>&1 && return 0
    sleep "$pause"
  done
  return 1
}
