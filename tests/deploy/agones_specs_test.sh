#!/usr/bin/env bash
# The Agones resources in deploy/agones hold (scripts/check_agones.py, no cluster needed), and
# each kind of mistake in a copy of them is refused with exit 2 and a message naming it.
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
check="python3 $root/scripts/check_agones.py"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
passed=0
pass() { echo "ok: $1"; passed=$((passed + 1)); }
bad() { echo "FAIL: $1"; failures=$((failures + 1)); }

if $check "$root"/deploy/agones/*.yaml > "$tmp/out" 2>&1; then pass "the specs hold"
else bad "the specs do not hold: $(cat "$tmp/out")"; fi

# refused FILE-SED-EXPR EXPECTED-MESSAGE DESCRIPTION: a mutated copy must exit 2 with the message.
refused() {
    local file=$1 expr=$2 want=$3 what=$4
    cp "$root"/deploy/agones/*.yaml "$tmp/"
    sed -i "$expr" "$tmp/$file"
    $check "$tmp"/*.yaml > "$tmp/out" 2>&1
    local rc=$?
    if [ $rc -eq 2 ] && grep -q -- "$want" "$tmp/out"; then pass "$what"
    else bad "$what: exit $rc, $(cat "$tmp/out")"; fi
}
refused fleet.yaml 's/portPolicy: Dynamic/portPolicy: Dinamic/' "is not one of" "a misspelt port policy"
refused fleet.yaml 's/protocol: TCP/protocol: SCTP/' "is not one of" "an unknown protocol"
refused fleet.yaml 's/  scheduling: Packed/  schedulin: Packed/' "Additional properties" "an unknown key"
refused fleet.yaml 's/containerPort: 7400/containerPort: 7401/' "is not the control port" "--port not the containerPort"
refused fleet.yaml 's/, *"--agones"//; s/^ *"--agones"\]/]/' "no --agones" "a server without --agones"
refused fleet.yaml 's/periodSeconds: 5/periodSeconds: 1/' "periodSeconds must exceed" "a health period shorter than the pings"
refused fleet.yaml 's/readOnly: true/readOnly: false/' "read-only Secret mount" "a writable key mount"
refused fleetautoscaler.yaml 's/fleetName: qvr-servers/fleetName: other-fleet/' "is no fleet here" "an autoscaler of another fleet"
refused fleetautoscaler.yaml 's/minReplicas: 2/minReplicas: 30/' "minReplicas exceeds" "min above max"
refused allocation.yaml 's/agones.dev\/fleet: qvr-servers/agones.dev\/fleet: nobody/' "is no fleet here" "an allocation of another fleet"
refused gameserver.yaml 's/^  ports:/  portz:/' "required property" "a GameServer without ports"
refused gameserver.yaml '1i : : not yaml [' "gameserver.yaml" "a file that is not YAML"
$check "$tmp/missing.yaml" > "$tmp/out" 2>&1
if [ $? -eq 2 ] && grep -q "missing.yaml" "$tmp/out"; then pass "a missing file"
else bad "a missing file: $(cat "$tmp/out")"; fi

echo "$passed passed, $failures failed"
[ $failures -eq 0 ]
