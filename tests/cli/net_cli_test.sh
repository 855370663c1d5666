#!/usr/bin/env bash
# `qvr server`, `qvr client` and `qvr run` refuse bad options and mismatched settings (issue 12,
# item 6): every malformed option exits 2 with a message before any work; a client whose codec
# or display profile differs from the server's is refused in the handshake, both sides print the
# reason and the client exits non-zero. Usage: net_cli_test.sh /path/to/qvr
set -u

QVR=${1:?usage: net_cli_test.sh /path/to/qvr}
passed=0
failed=0
tmp=$(mktemp -d "${TMPDIR:-/tmp}/qvr_net_cli_test.XXXXXX")
server_pid=
cleanup() {
    [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null
    rm -rf "$tmp"
}
trap cleanup EXIT

pass() {
    passed=$((passed + 1))
    echo "ok   $1"
}
fail() {
    failed=$((failed + 1))
    echo "FAIL $1"
    [ $# -gt 1 ] && echo "     $2"
}

# expect_exit2 NAME ARGS...: must exit exactly 2, quickly, with a message on stderr.
expect_exit2() {
    local name=$1
    shift
    timeout 60 "$QVR" "$@" >"$tmp/out.txt" 2>"$tmp/err.txt"
    local rc=$?
    if [ $rc -ne 2 ]; then
        fail "$name" "exit $rc (want 2) for: $* -- $(head -c 200 "$tmp/err.txt")"
    elif [ ! -s "$tmp/err.txt" ]; then
        fail "$name" "exit 2 but nothing on stderr for: $*"
    else
        pass "$name (exit 2: $(head -n 1 "$tmp/err.txt" | cut -c1-100))"
    fi
}

K=(--key pass:net-cli-test)
expect_exit2 "client --codec foo" client "${K[@]}" --codec foo --frames 3 --out "$tmp/c"
expect_exit2 "client --connect 127.0.0.1:7400abc" client "${K[@]}" --connect 127.0.0.1:7400abc --frames 3 --out "$tmp/c"
expect_exit2 "client --connect :7400" client "${K[@]}" --connect :7400 --frames 3 --out "$tmp/c"
expect_exit2 "client --connect 256.1.1.1:7400" client "${K[@]}" --connect 256.1.1.1:7400 --frames 3 --out "$tmp/c"
expect_exit2 "client --connect 127.0.0.1:0" client "${K[@]}" --connect 127.0.0.1:0 --frames 3 --out "$tmp/c"
expect_exit2 "client --connect 127.0.0.1:65536" client "${K[@]}" --connect 127.0.0.1:65536 --frames 3 --out "$tmp/c"
expect_exit2 "client --connect 127.0.0.1:-1" client "${K[@]}" --connect 127.0.0.1:-1 --frames 3 --out "$tmp/c"
expect_exit2 "client --connect 127.0.0.1" client "${K[@]}" --connect 127.0.0.1 --frames 3 --out "$tmp/c"
expect_exit2 "client --connect ::1:7400 (no brackets)" client "${K[@]}" --connect ::1:7400 --frames 3 --out "$tmp/c"
expect_exit2 "client --connect [zz]:7400" client "${K[@]}" --connect '[zz]:7400' --frames 3 --out "$tmp/c"
expect_exit2 "client --connect no.such.host.invalid:7400" client "${K[@]}" --connect no.such.host.invalid:7400 --frames 3 --out "$tmp/c"
touch "$tmp/a_file"
expect_exit2 "client --out under a file" client "${K[@]}" --frames 3 --out "$tmp/a_file/sub"
expect_exit2 "client --frames 0" client "${K[@]}" --frames 0 --out "$tmp/c"
expect_exit2 "client --profile bogus" client "${K[@]}" --profile bogus --frames 3 --out "$tmp/c"
expect_exit2 "client --server-stamps /nonexistent" client "${K[@]}" --server-stamps /nonexistent.csv --frames 3 --out "$tmp/c"

expect_exit2 "server --stats-json into a missing folder" server "${K[@]}" --port 0 --duration-s 1 --stats-json "$tmp/missing/stats.json"
expect_exit2 "server --stats-json a folder" server "${K[@]}" --port 0 --duration-s 1 --stats-json "$tmp"
expect_exit2 "server --stamps-csv into a missing folder" server "${K[@]}" --port 0 --duration-s 1 --stamps-csv "$tmp/missing/stamps.csv"
for d in -5 nan 1e300 inf; do
    expect_exit2 "server --duration-s $d" server "${K[@]}" --port 0 --duration-s "$d"
done
expect_exit2 "server --net rate:1e-300" server "${K[@]}" --port 0 --duration-s 1 --net rate:1e-300
expect_exit2 "server --net rate:0" server "${K[@]}" --port 0 --duration-s 1 --net rate:0
expect_exit2 "server --net wifi,ge=junk" server "${K[@]}" --port 0 --duration-s 1 --net wifi,ge=junk
expect_exit2 "server --net wifi,reorder=1" server "${K[@]}" --port 0 --duration-s 1 --net wifi,reorder=1
expect_exit2 "server --net wifi,spike=100:200:5" server "${K[@]}" --port 0 --duration-s 1 --net wifi,spike=100:200:5
for f in ge=0.1:0 ge=0.1 dup=nan reorder=0.1:-5 spike=1000:100:20000 ge=0.1:0.2:junk; do
    expect_exit2 "server --net wifi,$f" server "${K[@]}" --port 0 --duration-s 1 --net "wifi,$f"
done
expect_exit2 "server --codec foo" server "${K[@]}" --port 0 --duration-s 1 --codec foo
expect_exit2 "server --bind 256.1.1.1" server "${K[@]}" --port 0 --duration-s 1 --bind 256.1.1.1
expect_exit2 "server --bind localhost (names are not bound)" server "${K[@]}" --port 0 --duration-s 1 --bind localhost
expect_exit2 "server --port 70000" server "${K[@]}" --port 70000 --duration-s 1
expect_exit2 "server --profile bogus" server "${K[@]}" --port 0 --duration-s 1 --profile bogus

expect_exit2 "run --codec foo" run --codec foo --frames 12 --warmup-frames 0 --out "$tmp/r"
expect_exit2 "run --net rate:1e-300" run --net rate:1e-300 --frames 12 --warmup-frames 0 --out "$tmp/r"
expect_exit2 "run --net wifi,dup=1" run --net wifi,dup=1 --frames 12 --warmup-frames 0 --out "$tmp/r"
expect_exit2 "run --out under a file" run --frames 12 --warmup-frames 0 --out "$tmp/a_file/sub"

# --- bad input refused when parsed, before any work -------------------------------------------
# expect_exit2_no_work NAME OUTPUT ARGS...: as expect_exit2, and OUTPUT (what the work would make)
# does not exist afterwards, nor did a server say it was listening.
expect_exit2_no_work() {
    local name=$1 output=$2
    shift 2
    expect_exit2 "$name" "$@"
    if [ -e "$output" ]; then
        fail "$name: before any work" "$output exists"
    elif grep -q "listening on" "$tmp/out.txt"; then
        fail "$name: before any work" "the server started: $(head -c 200 "$tmp/out.txt")"
    else
        pass "$name: before any work"
    fi
}
R=(--frames 12 --warmup-frames 0)
expect_exit2_no_work "run --remote-timeout-ms nan" "$tmp/r_nan" run "${R[@]}" --remote-timeout-ms nan --out "$tmp/r_nan"
expect_exit2_no_work "run --remote-timeout-ms inf" "$tmp/r_nan" run "${R[@]}" --remote-timeout-ms inf --out "$tmp/r_nan"
expect_exit2_no_work "run --headset-share nan" "$tmp/r_nan" run "${R[@]}" --headset-share nan --out "$tmp/r_nan"
expect_exit2_no_work "run --lod-px nan" "$tmp/r_nan" run "${R[@]}" --lod-px nan --out "$tmp/r_nan"
expect_exit2_no_work "run --lod-px -inf" "$tmp/r_nan" run "${R[@]}" --lod-px -inf --out "$tmp/r_nan"
expect_exit2_no_work "run --seed -1" "$tmp/r_nan" run "${R[@]}" --seed -1 --out "$tmp/r_nan"
: >"$tmp/empty.toml"
printf '# a comment, no field\nname = "nothing"\n' >"$tmp/fieldless.toml"
expect_exit2_no_work "run --profile <empty file>" "$tmp/r_nan" run "${R[@]}" --profile "$tmp/empty.toml" --out "$tmp/r_nan"
expect_exit2_no_work "server --profile <file with no field>" "$tmp/none" server "${K[@]}" --port 0 --duration-s 1 --profile "$tmp/fieldless.toml"
expect_exit2_no_work "client --profile <empty file>" "$tmp/c_bad" client "${K[@]}" --frames 3 --profile "$tmp/empty.toml" --out "$tmp/c_bad"
expect_exit2_no_work "server --core 99999" "$tmp/none" server "${K[@]}" --port 0 --duration-s 1 --core 99999
expect_exit2_no_work "server --core -2" "$tmp/none" server "${K[@]}" --port 0 --duration-s 1 --core -2
expect_exit2_no_work "client --core 99999" "$tmp/c_bad" client "${K[@]}" --frames 3 --core 99999 --out "$tmp/c_bad"
expect_exit2_no_work "client --seed -1" "$tmp/c_bad" client "${K[@]}" --frames 3 --seed -1 --out "$tmp/c_bad"
expect_exit2_no_work "client --lod-px nan" "$tmp/c_bad" client "${K[@]}" --frames 3 --lod-px nan --out "$tmp/c_bad"
mkfifo "$tmp/key_fifo"
expect_exit2_no_work "server --key-file <a FIFO>" "$tmp/none" server --key-file "$tmp/key_fifo" --port 0 --duration-s 1
expect_exit2_no_work "client --key-file <a FIFO>" "$tmp/c_bad" client --key-file "$tmp/key_fifo" --frames 3 --out "$tmp/c_bad"
expect_exit2_no_work "server --key-file <a directory>" "$tmp/none" server --key-file "$tmp" --port 0 --duration-s 1
expect_exit2_no_work "client --server-stamps <a directory>" "$tmp/c_bad" client "${K[@]}" --frames 3 --server-stamps "$tmp" --out "$tmp/c_bad"
printf 'not,a,stamps,header\n' >"$tmp/bad_stamps.csv"
expect_exit2_no_work "client --server-stamps <not a stamps file>" "$tmp/c_bad" client "${K[@]}" --frames 3 --server-stamps "$tmp/bad_stamps.csv" --out "$tmp/c_bad"
expect_exit2_no_work "server --frames-csv into a missing folder" "$tmp/missing" server "${K[@]}" --port 0 --duration-s 1 --frames-csv "$tmp/missing/frames.csv"
expect_exit2_no_work "server --frames-csv a folder" "$tmp/none" server "${K[@]}" --port 0 --duration-s 1 --frames-csv "$tmp"
expect_exit2_no_work "calibrate --out into a missing folder" "$tmp/missing" calibrate --quick --out "$tmp/missing/cal.toml"
expect_exit2_no_work "calibrate --json into a missing folder" "$tmp/cal.toml" calibrate --quick --out "$tmp/cal.toml" --json "$tmp/missing/cal.json"
expect_exit2_no_work "calibrate --core 99999" "$tmp/cal.toml" calibrate --quick --core 99999 --out "$tmp/cal.toml"

# --- settings negotiated in the handshake -----------------------------------------------------
"$QVR" server "${K[@]}" --port 0 --profile small --codec x264 --duration-s 120 \
    --stats-json "$tmp/server_stats.json" --stamps-csv "$tmp/stamps.csv" \
    >"$tmp/server_out.txt" 2>"$tmp/server_err.txt" &
server_pid=$!
port=
for _ in $(seq 1 200); do
    port=$(sed -n 's/.*listening on 127\.0\.0\.1:\([0-9]*\).*/\1/p' "$tmp/server_out.txt")
    [ -n "$port" ] && break
    sleep 0.1
done
if [ -z "$port" ]; then
    fail "server starts" "$(head -c 300 "$tmp/server_err.txt")"
else
    pass "server listens on port $port"
    # expect_refused NAME SERVER_TEXT ARGS...: the client exits non-zero naming the reason, and the
    # server printed SERVER_TEXT.
    expect_refused() {
        local name=$1 server_text=$2
        shift 2
        timeout 60 "$QVR" client "${K[@]}" --connect "127.0.0.1:$port" --frames 5 \
            --out "$tmp/c" "$@" >"$tmp/out.txt" 2>"$tmp/err.txt"
        local rc=$?
        sleep 0.2
        if [ $rc -eq 0 ] || [ $rc -ge 124 ]; then
            fail "$name" "client exit $rc: $(head -c 300 "$tmp/err.txt")"
        elif ! grep -q "mismatch" "$tmp/err.txt"; then
            fail "$name" "client did not name the reason: $(head -c 300 "$tmp/err.txt")"
        elif ! grep -qF "$server_text" "$tmp/server_err.txt"; then
            fail "$name" "server did not print '$server_text': $(tail -c 300 "$tmp/server_err.txt")"
        else
            pass "$name (client exit $rc: $(head -n 1 "$tmp/err.txt" | cut -c1-110))"
        fi
    }
    expect_refused "client --codec raw against an x264 server" \
        "codec mismatch (client raw, server x264)" --profile small --codec raw
    expect_refused "client --profile run against a small server" \
        "display profile mismatch (client run-480x540" --profile run --codec x264
    if timeout 120 "$QVR" client "${K[@]}" --connect "127.0.0.1:$port" --frames 5 --profile small \
        --out "$tmp/ok" >"$tmp/out.txt" 2>"$tmp/err.txt" &&
        python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['connects'] >= 1 and d['incompatible_refusals'] == 0, d
assert d['media_forged'] == 0 and d['media_replayed'] >= 0, d
assert d['control_forged'] == 0 and d['control_replayed'] == 0, d
" "$tmp/ok/summary.json"; then
        pass "client with the server's settings connects"
    else
        fail "client with the server's settings connects" "$(head -c 300 "$tmp/err.txt")"
    fi
    # Ctrl-C keeps the data: a client stopped after N frames leaves a summary of N frames and N
    # telemetry rows, and says it was interrupted (exit 130, as `qvr trace record`).
    "$QVR" client "${K[@]}" --connect "127.0.0.1:$port" --frames 100000 --profile small \
        --out "$tmp/int" >"$tmp/int_out.txt" 2>"$tmp/int_err.txt" &
    client_pid=$!
    # SIGINT only once the server has sent this client 20 layers (a stamps line each, flushed
    # every frame), not after a fixed sleep: the client installs its handler just before its
    # first frame and a background job of a script ignores SIGINT until then, so a slow start (an
    # ASan build takes longer than 4 s) lost the signal and the client ran its 100000 frames
    # until ctest's timeout.
    stamps_before=$(wc -l <"$tmp/stamps.csv")
    for _ in $(seq 1 1200); do
        [ "$(wc -l <"$tmp/stamps.csv")" -ge $((stamps_before + 20)) ] && break
        sleep 0.1
    done
    kill -INT "$client_pid"
    wait "$client_pid"
    rc=$?
    if [ $rc -eq 130 ] && python3 -c "
import csv, json, sys
d = json.load(open(sys.argv[1] + '/summary.json'))
rows = list(csv.DictReader(open(sys.argv[1] + '/telemetry.csv')))
assert d['interrupted'] is True, d
assert 0 < d['frames'] < 100000, d['frames']
assert len(rows) == d['frames'], (len(rows), d['frames'])
assert [int(r['frame']) for r in rows] == list(range(len(rows))), 'rows are not frames 0..N-1'
" "$tmp/int"; then
        pass "SIGINT keeps the summary and every finished frame's telemetry row ($(head -n 1 "$tmp/int_err.txt" | cut -c1-80))"
    else
        fail "SIGINT keeps the summary and every finished frame's telemetry row" \
            "exit $rc: $(head -c 300 "$tmp/int_err.txt"); $(head -c 300 "$tmp/int/summary.json" 2>/dev/null)"
    fi
    # The clients above connected twice (the good one, the interrupted one).
    kill -INT "$server_pid"
    wait "$server_pid"
    rc=$?
    server_pid=
    if [ $rc -eq 0 ] && python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['settings_refusals'] == 2, d
assert d['clients_accepted'] == 2, d
for k in ('connections', 'handshake_timeouts', 'refused_full', 'protocol_errors',
          'version_mismatches', 'nacks', 'packets_retransmitted', 'bytes_retransmitted',
          'retransmissions_refused', 'pending_evicted', 'idle_timeouts', 'route_failures',
          'control_forged', 'control_replayed'):
    assert k in d, k
assert d['route_failures'] == 0 and d['control_forged'] == 0 and d['control_replayed'] == 0, d
" "$tmp/server_stats.json"; then
        pass "server stats count the refusals"
    else
        fail "server stats count the refusals" "exit $rc; $(cat "$tmp/server_stats.json" 2>/dev/null | head -c 400)"
    fi
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
