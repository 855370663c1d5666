#!/usr/bin/env python3
"""The fault matrix: `qvr server` and `qvr client` on loopback under one fault each,
measured from the client's own telemetry.

For every case a fresh server (the link emulator on its media egress set by the case's --net
spec) and a client (design ffr unless --design says otherwise, so every frame needs the
network) run FRAMES frames; faults that are events (SIGSTOP, SIGKILL, a pre-auth
flood) start once the server has served its first frames. From telemetry.csv:

  fresh      frames shown with this frame's own content: its remote layers arrived in time (or
             the policy drew the whole frame locally; counted apart for --design qvr)
  reused     frames whose display re-warped older layers (late or lost streams)
  all-local  frames rendered entirely on the headset (no session)
  gap        the longest time between two fresh frames' scan-outs, ms
  recovery   from the end of an event fault to the next fresh frame's scan-out, ms

Usage: fault_matrix.py QVR OUT [--frames N] [--cases a,b] [--check]
Writes OUT/matrix.json and OUT/matrix.md; each case's files in OUT/<case>/. With --check, exits
1 when a case breaks the invariants every fault must keep (every frame shown, fresh frames
again after the fault, the server alive), so the matrix doubles as a test (label chaos).
"""
import argparse
import csv
import json
import os
import re
import resource
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
TRACES = os.path.normpath(os.path.join(HERE, "..", "..", "shared", "data", "network"))
KEY = "pass:fault-matrix"

# name: (server --net spec, event fault or None). Random seeds fixed so a case is repeatable.
CASES = {
    "clean": ("wifi", None),
    "loss_1": ("wifi,loss=0.01,seed=11", None),
    "loss_2": ("wifi,loss=0.02,seed=12", None),
    "loss_5": ("wifi,loss=0.05,seed=15", None),
    "loss_10": ("wifi,loss=0.10,seed=20", None),
    "loss_20": ("wifi,loss=0.20,seed=30", None),
    # Gilbert-Elliott: into a burst 1% of packets, out of it 25% (mean burst 4 packets), every
    # packet in a burst lost: 3.8% lost in all, in runs.
    "burst_ge": ("wifi,ge=0.01:0.25,seed=13", None),
    "reorder": ("wifi,reorder=0.05:5,seed=14", None),
    "duplicate": ("wifi,dup=0.05,seed=16", None),
    "delay_spikes": ("wifi,spike=1000:100:80", None),
    "trace_att": ("trace:" + os.path.join(TRACES, "ATT-LTE-driving-2016.down"), None),
    "trace_tmobile": ("trace:" + os.path.join(TRACES, "TMobile-LTE-short.down"), None),
    "trace_verizon": ("trace:" + os.path.join(TRACES, "Verizon-LTE-short.down"), None),
    "server_sigstop_2s": ("wifi", "sigstop"),
    "server_sigkill_restart": ("wifi", "sigkill"),
    "client_sigkill": ("wifi", "client_kill"),
    "preauth_flood_400": ("wifi", "flood:400"),
    "preauth_flood_4000": ("wifi", "flood:4000"),
}


def start_server(qvr, spec, port, folder, tag="server"):
    out = open(os.path.join(folder, tag + "_out.txt"), "w")
    err = open(os.path.join(folder, tag + "_err.txt"), "w")
    stamps = os.path.join(folder, tag + "_stamps.csv")
    p = subprocess.Popen(
        [qvr, "server", "--key", KEY, "--port", str(port), "--profile", "small", "--codec",
         "x264", "--net", spec, "--stats-json", os.path.join(folder, tag + "_stats.json"),
         "--stamps-csv", stamps],
        stdout=out, stderr=err)
    for _ in range(600):
        if p.poll() is not None:
            return p, None, stamps
        m = re.search(r"listening on 127\.0\.0\.1:(\d+)", open(out.name).read())
        if m:
            return p, int(m.group(1)), stamps
        time.sleep(0.05)
    return p, None, stamps


DESIGN = "ffr"  # every frame needs the network (qvr may render a frame all-locally by choice)


def start_client(qvr, port, frames, folder, tag="client"):
    return subprocess.Popen(
        [qvr, "client", "--key", KEY, "--connect", "127.0.0.1:%d" % port, "--profile", "small",
         "--codec", "x264", "--design", DESIGN, "--frames", str(frames), "--out",
         os.path.join(folder, tag)],
        stdout=open(os.path.join(folder, tag + "_out.txt"), "w"),
        stderr=open(os.path.join(folder, tag + "_err.txt"), "w"))


def wait_lines(path, n, seconds):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            with open(path) as f:
                if sum(1 for _ in f) >= n:
                    return True
        except OSError:
            pass
        time.sleep(0.05)
    return False


def stop(p, sig=signal.SIGINT, seconds=30):
    if p.poll() is None:
        p.send_signal(sig)
        try:
            p.wait(seconds)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()
    return p.returncode


class Flood:
    """Silent TCP connections to the server, each reopened as soon as the server drops it:
    an attacker without the key holding as many half-open connections as it can."""

    def __init__(self, port, count):
        self.port, self.count = port, count
        self.opened = 0
        self.dropped = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def __enter__(self):
        soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        want = min(hard, self.count + 256)
        if soft < want:
            resource.setrlimit(resource.RLIMIT_NOFILE, (want, hard))
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()

    def _open(self):
        s = socket.socket()
        s.setblocking(False)
        try:
            s.connect(("127.0.0.1", self.port))
        except BlockingIOError:
            pass
        except OSError:
            s.close()
            return None
        self.opened += 1
        return s

    def _run(self):
        import selectors
        sel = selectors.DefaultSelector()
        socks = []
        while not self._stop.is_set():
            while len(socks) < self.count and not self._stop.is_set():
                s = self._open()
                if s is None:
                    break
                socks.append(s)
                sel.register(s, selectors.EVENT_READ)
            for key, _ in sel.select(timeout=0.02):
                s = key.fileobj
                try:
                    data = s.recv(4096)
                except OSError:
                    data = b""
                if not data:  # dropped by the server: reopen on the next pass
                    sel.unregister(s)
                    s.close()
                    socks.remove(s)
                    self.dropped += 1
        for s in socks:
            sel.unregister(s)
            s.close()


def analyse(folder, events):
    """Counts from the client's telemetry; events are (name, start_s, end_s) on CLOCK_MONOTONIC."""
    summary = json.load(open(os.path.join(folder, "summary.json")))
    rows = list(csv.DictReader(open(os.path.join(folder, "telemetry.csv"))))
    origin = summary["clock_origin_ns"]
    fresh_ns = []
    shown = reused = local = fresh = by_choice = 0
    for r in rows:
        d = int(r["display_ns"])
        if d < 0:
            continue
        shown += 1
        if r["fallback_local"] == "1":
            local += 1
        elif r["reused"] == "1":
            reused += 1
        else:
            fresh += 1
            fresh_ns.append(origin + d)
            # Fresh without the network: the policy drew the whole frame on the headset.
            by_choice += r["remote_requested"] == "0"
    gap = max((b - a for a, b in zip(fresh_ns, fresh_ns[1:])), default=0) * 1e-6
    recovery = None
    if events:
        # An event without an end (a new client) counts from the client's first frame.
        end_ns = max(origin if e[2] is None else int(e[2] * 1e9) for e in events)
        after = [t for t in fresh_ns if t >= end_ns]
        recovery = (after[0] - end_ns) * 1e-6 if after else float("inf")
    return {"frames": len(rows), "shown": shown, "fresh": fresh, "reused": reused,
            "all_local": local, "fresh_pct": 100.0 * fresh / max(1, len(rows)),
            "fresh_local_by_choice": by_choice, "connects_seen": summary.get("connects", 0),
            "keepalives": summary.get("keepalives_sent", 0),
            "longest_gap_ms": gap, "recovery_ms": recovery,
            "fps": summary.get("fps_mean", 0.0), "mtp_p99_ms": summary.get("mtp_ms_p99", 0.0),
            "connects": summary.get("connects", 0),
            "key_frame_requests": summary.get("key_frame_requests", 0),
            "fec_recoveries": summary.get("fec_recoveries", 0),
            "nacks_sent": summary.get("nacks_sent", 0),
            "media_forged": summary.get("media_forged", 0)}


def rss_kb(pid):
    try:
        for line in open("/proc/%d/status" % pid):
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    except OSError:
        pass
    return None


class RssSampler:
    """VmRSS of the server and the client every `every` seconds into rss.csv."""

    def __init__(self, path, every, procs):
        self.path, self.every, self.procs = path, every, procs
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self.rows = []

    def start(self):
        if self.every > 0:
            self._thread.start()
        return self

    def stop(self):
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
        with open(self.path, "w") as f:
            f.write("t_s,server_kb,client_kb\n")
            for r in self.rows:
                f.write("%.1f,%s,%s\n" % r)

    def _run(self):
        t0 = time.monotonic()
        while not self._stop.wait(self.every):
            kb = [rss_kb(p().pid) for p in self.procs]
            if None in kb:
                continue
            self.rows.append((time.monotonic() - t0, kb[0], kb[1]))

    def growth(self, warmup_s):
        """Each side's RSS at the end over its RSS after the warm-up, in percent."""
        after = [r for r in self.rows if r[0] >= warmup_s]
        if len(after) < 2:
            return None
        return {"server_pct": 100.0 * (after[-1][1] / after[0][1] - 1.0),
                "client_pct": 100.0 * (after[-1][2] / after[0][2] - 1.0),
                "server_kb": [after[0][1], max(r[1] for r in after), after[-1][1]],
                "client_kb": [after[0][2], max(r[2] for r in after), after[-1][2]],
                "warmup_s": warmup_s, "samples": len(after)}


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def run_case(qvr, name, spec, fault, frames, out, rss_every=0.0, rss_warmup_s=300.0,
             duration_s=0.0):
    folder = os.path.join(out, name)
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    port = free_port()
    server, port_got, stamps = start_server(qvr, spec, port, folder)
    if port_got is None:
        err = open(os.path.join(folder, "server_err.txt")).read().strip()
        stop(server)
        return {"case": name, "net": spec, "error": "server did not start: " + err[:200]}
    events = []
    result = {"case": name, "net": spec}
    client = start_client(qvr, port, frames, folder)
    flood = None
    rss = RssSampler(os.path.join(folder, "rss.csv"), rss_every,
                     [lambda: server, lambda: client]).start()
    try:
        if not wait_lines(stamps, 20, 120):
            raise RuntimeError("no frames served")
        if fault == "sigstop":
            time.sleep(2.0)
            t = time.monotonic()
            server.send_signal(signal.SIGSTOP)
            time.sleep(2.0)
            server.send_signal(signal.SIGCONT)
            events.append(("server SIGSTOP 2 s", t, time.monotonic()))
        elif fault == "sigkill":
            time.sleep(2.0)
            t = time.monotonic()
            server.kill()
            server.wait()
            time.sleep(1.0)
            server, got, stamps = start_server(qvr, spec, port, folder, "server2")
            if got is None:
                raise RuntimeError("server did not restart on port %d" % port)
            events.append(("server SIGKILL, restarted 1 s later", t, time.monotonic()))
        elif fault == "client_kill":
            # A client killed mid-session; a new client must get in and be served.
            time.sleep(2.0)
            client.kill()
            client.wait()
            t = time.monotonic()
            client = start_client(qvr, port, frames, folder, "client2")
            events.append(("client SIGKILL, new client", t, None))
        elif fault and fault.startswith("flood:"):
            flood = Flood(port, int(fault.split(":")[1])).__enter__()
        if duration_s > 0:
            # A session of a given length: SIGINT ends the client at a frame boundary with
            # everything written (exit 130).
            try:
                client.wait(timeout=duration_s)
            except subprocess.TimeoutExpired:
                client.send_signal(signal.SIGINT)
            code = client.wait(timeout=300)
            code = 0 if code == 130 else code
        else:
            code = client.wait(timeout=frames / 10 + 300)
        result["client_exit"] = code
    except Exception as e:  # a broken case is a row with its error, not a lost matrix
        result["error"] = str(e)
        stop(client, signal.SIGKILL)
    finally:
        rss.stop()
        if flood:
            flood.__exit__(None, None, None)
            result["flood_opened"] = flood.opened
            result["flood_dropped"] = flood.dropped
    result["server_alive"] = server.poll() is None
    result["server_exit"] = stop(server)
    client_dir = os.path.join(folder, "client2" if fault == "client_kill" else "client")
    if "error" not in result:
        try:
            result.update(analyse(client_dir, events))
        except (OSError, KeyError, ValueError) as e:
            result["error"] = "no telemetry: %s" % e
    for tag in ("server2_stats.json", "server_stats.json"):
        path = os.path.join(folder, tag)
        if os.path.exists(path):
            s = json.load(open(path))
            result["server"] = {k: s.get(k, 0) for k in (
                "clients_accepted", "handshake_timeouts", "pending_evicted", "idle_timeouts",
                "nacks", "bytes_retransmitted", "fec_parity_bytes", "control_drops")}
            break
    result["events"] = [e[0] for e in events]
    if rss_every > 0:
        result["rss"] = rss.growth(rss_warmup_s)
    return result


def check(r):
    """The invariants every fault must keep; returns what broke."""
    broken = []
    if "error" in r:
        return [r["error"]]
    if r.get("client_exit") != 0:
        broken.append("client exit %s" % r.get("client_exit"))
    if r["shown"] != r["frames"]:
        broken.append("%d of %d frames shown" % (r["shown"], r["frames"]))
    if r["fresh"] == 0:
        broken.append("no fresh frame")
    if r["recovery_ms"] == float("inf"):
        broken.append("no fresh frame after the fault")
    if r["case"] != "server_sigkill_restart" and not r["server_alive"]:
        broken.append("server died")
    return broken


def table(results):
    head = ("| case | --net | frames | fresh | reused | all-local | fresh % | longest gap (ms) "
            "| recovery (ms) | FPS | MTP p99 (ms) | key-frame req. | FEC rebuilt | NACKs |")
    lines = [head, "|" + "---|" * 14]
    for r in results:
        if "error" in r:
            lines.append("| %s | `%s` | error: %s |" % (r["case"], r["net"], r["error"]))
            continue
        rec = r["recovery_ms"]
        lines.append("| %s | `%s` | %d | %d | %d | %d | %.1f | %.0f | %s | %.1f | %.0f | %d | %d | %d |" % (
            r["case"], os.path.basename(r["net"]) if r["net"].startswith("trace:") else r["net"],
            r["frames"], r["fresh"], r["reused"], r["all_local"], r["fresh_pct"],
            r["longest_gap_ms"], "—" if rec is None else "%.0f" % rec, r["fps"],
            r["mtp_p99_ms"], r["key_frame_requests"], r["fec_recoveries"], r["nacks_sent"]))
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("qvr")
    ap.add_argument("out")
    ap.add_argument("--frames", type=int, default=1350)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--design", default="ffr", help="the client's design (default ffr)")
    ap.add_argument("--duration-s", type=float, default=0.0,
                    help="run each session this long (--frames is then only a ceiling)")
    ap.add_argument("--rss-every", type=float, default=0.0,
                    help="sample both sides' RSS every S seconds (rss.csv, growth in matrix.json)")
    ap.add_argument("--rss-warmup", type=float, default=300.0,
                    help="growth is measured from the first sample after this many seconds")
    a = ap.parse_args()
    names = [c for c in a.cases.split(",") if c]
    unknown = [c for c in names if c not in CASES]
    if a.duration_s > 0:
        a.frames = max(a.frames, 1000000)
    if unknown or a.frames < 100:
        print("fault_matrix: unknown case(s) %s (known: %s) or --frames < 100"
              % (",".join(unknown), ",".join(CASES)), file=sys.stderr)
        return 2
    global DESIGN
    DESIGN = a.design
    os.makedirs(a.out, exist_ok=True)
    results = []
    for name in names:
        spec, fault = CASES[name]
        t0 = time.monotonic()
        r = run_case(a.qvr, name, spec, fault, a.frames, a.out, a.rss_every, a.rss_warmup,
                     a.duration_s)
        r["seconds"] = time.monotonic() - t0
        results.append(r)
        print("%-24s %s" % (name, "error: " + r["error"] if "error" in r else
                            "fresh %5.1f%%  reused %4d  local %4d  gap %6.0f ms  recovery %s" % (
                                r["fresh_pct"], r["reused"], r["all_local"], r["longest_gap_ms"],
                                "—" if r["recovery_ms"] is None else "%.0f ms" % r["recovery_ms"])),
              flush=True)
        if r.get("rss"):
            print("%-24s RSS growth after %.0f s: server %+.1f%%, client %+.1f%% (%s / %s kB)"
                  % ("", r["rss"]["warmup_s"], r["rss"]["server_pct"], r["rss"]["client_pct"],
                     r["rss"]["server_kb"], r["rss"]["client_kb"]), flush=True)
    json.dump(results, open(os.path.join(a.out, "matrix.json"), "w"), indent=2)
    open(os.path.join(a.out, "matrix.md"), "w").write(table(results))
    if a.check:
        bad = [(r["case"], check(r)) for r in results if check(r)]
        for case, why in bad:
            print("FAIL %s: %s" % (case, "; ".join(why)))
        return 1 if bad else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
