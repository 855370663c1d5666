#!/usr/bin/env python3
"""Checks qvr's Agones resources on the client side, with no cluster: each YAML document
against deploy/agones/schema.json (the subset of Agones' resources qvr writes), then what ties
them to each other and to `qvr server`: the autoscaler and the allocation name the fleet, the
server's --port is the GameServer's containerPort, --agones is on (or the sidecar never hears
Ready), --key-file lies in a read-only Secret mount, and the health period leaves room for the
server's 2-second pings.

    python3 scripts/check_agones.py [--schema FILE] FILE.yaml...

Exit 0 when every file holds, 2 with one line per problem otherwise."""
import argparse
import json
import os
import sys

SERVER_HEALTH_PING_S = 2  # qvr server --agones: Health every 2 s (net/agones_sdk.h, cmd_server)


def fail(problems):
    for p in problems:
        print(f"check_agones: {p}", file=sys.stderr)
    sys.exit(2)


def load(paths):
    try:
        import yaml
    except ImportError:
        fail(["python3-yaml is missing (scripts/deps.sh installs it)"])
    docs = []
    for path in paths:
        try:
            with open(path, encoding="utf-8") as f:
                for doc in yaml.safe_load_all(f):
                    if doc is not None:
                        docs.append((path, doc))
        except (OSError, yaml.YAMLError) as e:
            fail([f"{path}: {str(e).splitlines()[0]}"])
    return docs


def schema_problems(docs, schema_path):
    try:
        import jsonschema
    except ImportError:
        fail(["python3-jsonschema is missing (scripts/deps.sh installs it)"])
    with open(schema_path, encoding="utf-8") as f:
        schema = json.load(f)
    validator = jsonschema.Draft202012Validator(schema)
    problems = []
    for path, doc in docs:
        if not isinstance(doc, dict):
            problems.append(f"{path}: a document is not a mapping")
            continue
        kind = doc.get("kind", "?")
        for branch in schema["oneOf"]:
            if branch["properties"]["kind"]["const"] == kind:
                sub = dict(schema, oneOf=None)
                sub.pop("oneOf")
                sub.update(branch)
                for err in jsonschema.Draft202012Validator(sub).iter_errors(doc):
                    where = "/".join(str(p) for p in err.absolute_path) or "(top)"
                    problems.append(f"{path}: {kind} {where}: {err.message}")
                break
        else:
            if not validator.is_valid(doc):
                problems.append(f"{path}: unknown kind '{kind}'")
    return problems


def arg_after(args, flag):
    return args[args.index(flag) + 1] if flag in args and args.index(flag) + 1 < len(args) else None


def server_problems(path, spec):
    problems = []
    ports = {p["name"]: p for p in spec["ports"]}
    health = spec.get("health", {})
    if not health.get("disabled") and health.get("periodSeconds", 5) <= SERVER_HEALTH_PING_S:
        problems.append(f"{path}: health.periodSeconds must exceed the server's "
                        f"{SERVER_HEALTH_PING_S} s Health pings")
    pod = spec["template"]["spec"]
    for c in pod["containers"]:
        args = c.get("args", [])
        if "--agones" not in args:
            problems.append(f"{path}: container {c['name']}: no --agones, so Ready is never sent")
        port = arg_after(args, "--port")
        if "control" not in ports:
            problems.append(f"{path}: no port named 'control'")
        elif port is None or not port.isdigit() or int(port) != ports["control"]["containerPort"]:
            problems.append(f"{path}: container {c['name']}: --port {port} is not the control "
                            f"port's containerPort {ports['control']['containerPort']}")
        key = arg_after(args, "--key-file")
        secret_mounts = {v["name"] for v in pod.get("volumes", []) if "secret" in v}
        mounts = [m for m in c.get("volumeMounts", [])
                  if m["name"] in secret_mounts and m.get("readOnly")]
        if key is None or not any(key.startswith(m["mountPath"].rstrip("/") + "/") for m in mounts):
            problems.append(f"{path}: container {c['name']}: --key-file {key} is not in a "
                            "read-only Secret mount")
    return problems


def tie_problems(docs):
    problems = []
    fleets = {d["metadata"]["name"] for _, d in docs if d.get("kind") == "Fleet"}
    for path, d in docs:
        kind = d.get("kind")
        if kind == "GameServer":
            problems += server_problems(path, d["spec"])
        elif kind == "Fleet":
            problems += server_problems(path, d["spec"]["template"]["spec"])
        elif kind == "FleetAutoscaler":
            spec = d["spec"]
            if fleets and spec["fleetName"] not in fleets:
                problems.append(f"{path}: fleetName '{spec['fleetName']}' is no fleet here "
                                f"({', '.join(sorted(fleets))})")
            buf = spec["policy"].get("buffer", {})
            if buf.get("minReplicas", 0) > buf.get("maxReplicas", 1):
                problems.append(f"{path}: minReplicas exceeds maxReplicas")
            size = buf.get("bufferSize")
            if isinstance(size, int) and size >= buf.get("maxReplicas", 1):
                problems.append(f"{path}: bufferSize must be below maxReplicas")
        elif kind == "GameServerAllocation":
            for sel in d["spec"]["selectors"]:
                fleet = sel.get("matchLabels", {}).get("agones.dev/fleet")
                if fleets and fleet not in fleets:
                    problems.append(f"{path}: the selector's agones.dev/fleet '{fleet}' is no "
                                    "fleet here")
    return problems


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--schema", default=os.path.join(here, "..", "deploy", "agones", "schema.json"))
    ap.add_argument("files", nargs="+")
    a = ap.parse_args()
    docs = load(a.files)
    if not docs:
        fail(["no YAML documents in " + ", ".join(a.files)])
    problems = schema_problems(docs, a.schema)
    if not problems:
        problems = tie_problems(docs)
    if problems:
        fail(problems)
    print(f"check_agones: {len(docs)} resources hold ({', '.join(d['kind'] for _, d in docs)})")


if __name__ == "__main__":
    main()
