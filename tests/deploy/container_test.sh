#!/usr/bin/env bash
# The render server's container image end to end (label "container", outside the default
# suite; ctest -L container): builds the image from deploy/Containerfile, runs `qvr server
# --agones` in it beside a loopback stand-in for the Agones SDK sidecar's REST routes (written
# here, not Agones' sidecar), connects a headset (`qvr client` on the host) with the
# pre-shared key, and checks that the server sent Ready, Health and, when stopped, Shutdown.
#   bash tests/deploy/container_test.sh QVR_BINARY      (about 15 min on 2 cores, mostly the build)
set -euo pipefail
qvr=$(readlink -f "$1")
root=$(cd "$(dirname "$0")/../.." && pwd)
image=${QVR_IMAGE:-localhost/qvr-server:test}
podman=(podman)
# crun refuses hosts whose cgroups are in hybrid mode; runc runs there.
if command -v runc > /dev/null; then podman+=(--runtime runc); fi
# Containers get limits they may lower but not raise (podman's defaults are higher than some
# sandboxes allow).
limits=(--ulimit nofile=1024:1024 --ulimit nproc=4096:4096)
base=${QVR_BASE_IMAGE:-}
if [ -z "$base" ]; then
    base=localhost/qvr-debian:bookworm
    bash "$root/deploy/debian-base.sh" "$base"
fi
"${podman[@]}" build -f "$root/deploy/Containerfile" --build-arg "BASE=$base" -t "$image" "$root"

tmp=$(mktemp -d)
name=qvr-container-test-$$
cleanup() {
    "${podman[@]}" rm -f "$name" > /dev/null 2>&1 || true
    [ -n "${sidecar_pid:-}" ] && kill "$sidecar_pid" 2> /dev/null || true
    rm -rf "$tmp"
}
trap cleanup EXIT
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
sdk_port=$(free_port)
qvr_port=$(free_port)
python3 - "$sdk_port" "$tmp/sidecar.log" <<'PY' &
import http.server, sys
port, log = int(sys.argv[1]), sys.argv[2]
class StandIn(http.server.BaseHTTPRequestHandler):
    def do_POST(self):
        self.rfile.read(int(self.headers.get("Content-Length", 0)))
        with open(log, "a") as f:
            f.write(self.path + "\n")
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", "2")
        self.end_headers()
        self.wfile.write(b"{}")
    def log_message(self, *args):
        pass
http.server.HTTPServer(("127.0.0.1", port), StandIn).serve_forever()
PY
sidecar_pid=$!
mkdir -p "$tmp/key"
head -c 32 /dev/urandom | od -An -tx1 | tr -d ' \n' > "$tmp/key/psk"
chmod 755 "$tmp/key"
chmod 644 "$tmp/key/psk"
"${podman[@]}" run -d --name "$name" "${limits[@]}" --network host -e AGONES_SDK_HTTP_PORT="$sdk_port" \
    -v "$tmp/key:/etc/qvr:ro" "$image" \
    --bind 127.0.0.1 --port "$qvr_port" --key-file /etc/qvr/psk --agones > /dev/null
for _ in $(seq 1 120); do
    grep -q /ready "$tmp/sidecar.log" 2> /dev/null && break
    sleep 0.5
done
grep -q /ready "$tmp/sidecar.log" || { "${podman[@]}" logs "$name"; echo "no Ready"; exit 1; }
"$qvr" client --connect "127.0.0.1:$qvr_port" --key-file "$tmp/key/psk" --frames 30 \
    --design ffr --out "$tmp/client"
python3 -c "import json,sys; s=json.load(open('$tmp/client/summary.json')); sys.exit(0 if s else 1)"
"${podman[@]}" stop -t 20 "$name" > /dev/null
"${podman[@]}" logs "$name" | tail -3
for route in /ready /health /shutdown; do
    grep -q "^$route\$" "$tmp/sidecar.log" || { echo "the sidecar never saw $route"; exit 1; }
done
echo "container: image $image served a headset; sidecar saw $(sort "$tmp/sidecar.log" | uniq -c | tr -s ' ' | tr '\n' ',')"
echo "1 passed, 0 failed"
