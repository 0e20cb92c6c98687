#!/usr/bin/env python3
"""Renders deploy/k8s (base and the nvidia and cpu overlays) with `kubectl
kustomize` and checks the objects against what the server really does: the
probes hit the container's ports (gRPC health for readiness, /healthz for
liveness, --port and --grpc-port as declared), the token comes from
a Secret, the pod runs non-root on a read-only root filesystem with writable
cache and /tmp volumes, the grace period covers the server's drain, the
HPA's metric is a gauge the server exports (read from a running server's
/metrics when --haarcast is given, else from metrics.cpp), and each overlay asks for its
backend (and the nvidia one for one GPU).

Every kubectl given renders every target and the objects must be the same
(kustomize v2.0 in Debian's kubectl 1.20 and v5 in current ones read the
same files). Exit 77 (skip) when no kubectl or no PyYAML is installed.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import urllib.request

SKIP = 77
TARGETS = ("base", "overlays/nvidia", "overlays/cpu")

try:
    import yaml
except ImportError:
    print("SKIP: no PyYAML (apt-get install python3-yaml)")
    sys.exit(SKIP)

failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
    return ok


def source_number(path, name):
    """The default of a ServerOptions field, e.g. `double drainSeconds = 3.0;`."""
    with open(path, encoding="utf-8") as f:
        m = re.search(rf"\b{name}\s*=\s*([0-9.]+)", f.read())
    if not m:
        sys.exit(f"error: no '{name} = NUMBER' in {path}")
    return float(m.group(1))


def exported_gauges(metrics_cpp):
    """Gauge names in Metrics::prometheusText: metric("NAME", "gauge", …)."""
    with open(metrics_cpp, encoding="utf-8") as f:
        names = set(re.findall(r'metric\("([a-z_:]+)",\s*"gauge"', f.read()))
    if not names:
        sys.exit(f"error: no gauge found in {metrics_cpp}")
    return names


def served_gauges(haarcast):
    """Gauge names a running server exports: `# TYPE NAME gauge` in /metrics."""
    server = subprocess.Popen([haarcast, "serve", "--port", "0", "--bind", "127.0.0.1", "--quiet", "--cache-dir", "none"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = server.stdout.readline()  # "listening on http://127.0.0.1:PORT/", flushed once bound
        m = re.match(r"listening on (http://\S+/)", line)
        if not m:
            sys.exit(f"error: {haarcast} serve printed {line!r}, not its listening line:\n{server.stderr.read()}")
        with urllib.request.urlopen(m.group(1) + "metrics", timeout=10) as reply:
            text = reply.read().decode()
    finally:
        server.terminate()
        server.wait(timeout=30)
    names = set(re.findall(r"^# TYPE (\S+) gauge$", text, re.M))
    if not names:
        sys.exit(f"error: no gauge in {haarcast}'s /metrics:\n{text}")
    return names


def render(kubectl, directory):
    run = subprocess.run([kubectl, "kustomize", directory], capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"error: {kubectl} kustomize {directory} exited {run.returncode}:\n{run.stderr}")
    return [d for d in yaml.safe_load_all(run.stdout) if d]


def one(objects, kind, where):
    found = [o for o in objects if o["kind"] == kind]
    if not check(len(found) == 1, f"{where}: {len(found)} {kind} objects, expected 1"):
        return {}
    return found[0]


def arg_after(args, flag):
    """The value after `flag` in a container's args; None when absent."""
    values = [args[i + 1] for i, a in enumerate(args[:-1]) if a == flag]
    return values[-1] if values else None


def check_target(target, objects, gauges, drain_s, idle_s):
    w = target
    dep = one(objects, "Deployment", w)
    svc = one(objects, "Service", w)
    ing = one(objects, "Ingress", w)
    hpa = one(objects, "HorizontalPodAutoscaler", w)
    pdb = one(objects, "PodDisruptionBudget", w)
    if not dep:
        return
    pod = dep["spec"]["template"]
    spec = pod["spec"]
    labels = pod["metadata"]["labels"]
    check(dep["spec"]["selector"]["matchLabels"].items() <= labels.items(), f"{w}: the Deployment's selector misses its pods")
    containers = spec["containers"]
    check(len(containers) == 1, f"{w}: {len(containers)} containers, expected 1")
    c = containers[0]
    args = [str(a) for a in c.get("args", [])]

    # The port: the one the server is told, the one declared, the probes', the scrape's.
    ports = {p.get("name"): p["containerPort"] for p in c.get("ports", [])}
    port = ports.get("http")
    check(port is not None, f"{w}: no container port named http")
    check(arg_after(args, "--port") == str(port), f"{w}: --port {arg_after(args, '--port')} is not the containerPort {port}")
    check(arg_after(args, "--bind") == "0.0.0.0", f"{w}: --bind is {arg_after(args, '--bind')}, expected 0.0.0.0")
    check(args[:1] == ["serve"], f"{w}: args start with {args[:1]}, expected serve")

    def probe_port(probe):
        p = probe.get("httpGet", {}).get("port")
        return ports.get(p) if isinstance(p, str) else p

    probe = c.get("livenessProbe", {})
    check(probe.get("httpGet", {}).get("path") == "/healthz", f"{w}: livenessProbe path {probe.get('httpGet', {}).get('path')}, expected /healthz")
    check(probe_port(probe) == port, f"{w}: livenessProbe port {probe.get('httpGet', {}).get('port')} is not the container's {port}")

    # gRPC: the port the server is told, the one declared, the readiness
    # probe's (the health service, which follows /readyz). Kubernetes takes
    # only a number for a grpc probe's port.
    grpc_port = ports.get("grpc")
    check(grpc_port is not None, f"{w}: no container port named grpc")
    check(arg_after(args, "--grpc-port") == str(grpc_port), f"{w}: --grpc-port {arg_after(args, '--grpc-port')} is not the containerPort {grpc_port}")
    check(grpc_port != port, f"{w}: the gRPC port is the HTTP port {port}")
    ready = c.get("readinessProbe", {})
    check("grpc" in ready and "httpGet" not in ready, f"{w}: the readinessProbe is not a grpc probe ({sorted(ready)})")
    check(ready.get("grpc", {}).get("port") == grpc_port, f"{w}: readinessProbe grpc port {ready.get('grpc', {}).get('port')} is not the container's {grpc_port}")
    check(ready.get("grpc", {}).get("service", "") == "", f"{w}: the readinessProbe asks for service {ready.get('grpc', {}).get('service')}; the server's readiness is service \"\"")
    annotations = pod["metadata"].get("annotations", {})
    check(annotations.get("prometheus.io/port") == str(port), f"{w}: prometheus.io/port {annotations.get('prometheus.io/port')} is not {port}")
    check(annotations.get("prometheus.io/path") == "/metrics", f"{w}: prometheus.io/path is not /metrics")

    # The token: from a Secret, never a literal.
    token = [e for e in c.get("env", []) if e["name"] == "HAARCAST_TOKEN"]
    check(len(token) == 1, f"{w}: {len(token)} HAARCAST_TOKEN env entries, expected 1")
    if token:
        ref = token[0].get("valueFrom", {}).get("secretKeyRef", {})
        check("value" not in token[0], f"{w}: HAARCAST_TOKEN has a literal value")
        check(bool(ref.get("name")) and bool(ref.get("key")), f"{w}: HAARCAST_TOKEN is not from a Secret (secretKeyRef {ref})")
        check(ref.get("optional") is not True, f"{w}: the token's Secret is optional: the pod would start without a token")
    check("--token" not in args, f"{w}: --token in args (visible in the pod spec and ps)")

    # The Host rule: the Service's name and every Ingress host are allowed
    # (else their requests get 421).
    allowed = set(",".join(args[i + 1] for i, a in enumerate(args[:-1]) if a == "--allow-host").split(","))
    wanted = {o["metadata"]["name"] for o in objects if o.get("kind") == "Service"}
    wanted |= {r["host"] for o in objects if o.get("kind") == "Ingress" for r in o["spec"].get("rules", []) if "host" in r}
    check(wanted <= allowed, f"{w}: --allow-host {sorted(allowed)} lacks {sorted(wanted - allowed)}")

    # Security: non-root, read-only root, nothing to escalate to.
    psc, csc = spec.get("securityContext", {}), c.get("securityContext", {})
    check(csc.get("runAsNonRoot", psc.get("runAsNonRoot")) is True, f"{w}: runAsNonRoot is not true")
    check(csc.get("runAsUser", psc.get("runAsUser", 0)) != 0, f"{w}: runAsUser is 0 or unset")
    check(csc.get("readOnlyRootFilesystem") is True, f"{w}: readOnlyRootFilesystem is not true")
    check(csc.get("allowPrivilegeEscalation") is False, f"{w}: allowPrivilegeEscalation is not false")
    check("ALL" in csc.get("capabilities", {}).get("drop", []), f"{w}: capabilities do not drop ALL")

    # Writable places: --cache-dir and /tmp, each an emptyDir volume.
    volumes = {v["name"]: v for v in spec.get("volumes", [])}
    mounts = {m["mountPath"]: m["name"] for m in c.get("volumeMounts", [])}
    for path in (arg_after(args, "--cache-dir"), "/tmp"):
        name = mounts.get(path)
        check(name is not None and "emptyDir" in volumes.get(name, {}), f"{w}: {path} is not an emptyDir mount (mounts {mounts})")

    # Stopping: preStop's sleep plus the server's drain fit in the grace period.
    pre = c.get("lifecycle", {}).get("preStop", {}).get("exec", {}).get("command", [])
    pre_s = float(pre[1]) if pre[:1] == ["sleep"] and len(pre) == 2 else 0.0
    grace = spec.get("terminationGracePeriodSeconds", 30)
    check(grace > pre_s + drain_s, f"{w}: terminationGracePeriodSeconds {grace} <= preStop {pre_s} s + drain {drain_s} s")

    requests = c.get("resources", {}).get("requests", {})
    check("cpu" in requests and "memory" in requests, f"{w}: resources.requests lacks cpu or memory ({requests})")
    check("memory" in c.get("resources", {}).get("limits", {}), f"{w}: no memory limit")

    # Service → container port; Ingress → Service; PDB → pods.
    if svc:
        check(svc["spec"]["selector"].items() <= labels.items(), f"{w}: the Service's selector misses the pods")
        svc_ports = svc["spec"]["ports"]
        check(all(p["targetPort"] in ("http", port, "grpc", grpc_port) for p in svc_ports), f"{w}: a Service targetPort is not a container port")
        check(any(p["targetPort"] in ("grpc", grpc_port) for p in svc_ports), f"{w}: the Service has no port for gRPC")
    if ing and svc:
        backend = ing["spec"]["rules"][0]["http"]["paths"][0]["backend"]["service"]
        check(backend["name"] == svc["metadata"]["name"], f"{w}: the Ingress routes to {backend['name']}, not the Service")
        check(backend["port"].get("name") in [p.get("name") for p in svc_ports]
              or backend["port"].get("number") in [p["port"] for p in svc_ports], f"{w}: the Ingress's port is not the Service's")
        a = ing["metadata"].get("annotations", {})
        for key in ("proxy-read-timeout", "proxy-send-timeout"):
            value = float(a.get(f"nginx.ingress.kubernetes.io/{key}", 60))
            check(value > idle_s, f"{w}: {key} {value} s would cut sessions before the server's idle timeout {idle_s} s")
        check(a.get("nginx.ingress.kubernetes.io/affinity") == "cookie", f"{w}: no cookie affinity on the Ingress")
    if pdb:
        check(pdb["spec"]["selector"]["matchLabels"].items() <= labels.items(), f"{w}: the PDB's selector misses the pods")

    # The HPA: sessions per pod, a gauge the server exports, below the capacity.
    if hpa:
        check(hpa["apiVersion"] == "autoscaling/v2", f"{w}: HPA apiVersion {hpa['apiVersion']}, expected autoscaling/v2")
        scaled = hpa["spec"]["scaleTargetRef"]
        check((scaled["kind"], scaled["name"]) == ("Deployment", dep["metadata"]["name"]), f"{w}: the HPA scales {scaled}")
        metrics = hpa["spec"].get("metrics", [])
        check(len(metrics) == 1 and metrics[0]["type"] == "Pods", f"{w}: the HPA's metrics are not one Pods metric")
        if metrics and metrics[0]["type"] == "Pods":
            name = metrics[0]["pods"]["metric"]["name"]
            check(name in gauges, f"{w}: the HPA's metric {name} is not a gauge the server exports ({sorted(gauges)})")
            average = float(metrics[0]["pods"]["target"]["averageValue"])
            capacity = arg_after(args, "--max-sessions")
            check(capacity is not None and average < float(capacity),
                  f"{w}: the HPA's target {average} sessions per pod is not below --max-sessions {capacity}")

    # The overlays: their backend, said once; the GPU only where it belongs.
    gpu = c.get("resources", {}).get("limits", {}).get("nvidia.com/gpu")
    backends = [args[i + 1] for i, a in enumerate(args[:-1]) if a == "--backend"]
    env = {e["name"]: e.get("value") for e in c.get("env", [])}
    if target_name(w) == "nvidia":
        check(str(gpu) == "1", f"{w}: nvidia.com/gpu limit {gpu}, expected 1")
        check(backends == ["vulkan"], f"{w}: --backend {backends}, expected [vulkan]")
        check(arg_after(args, "--vulkan-device") == "NVIDIA", f"{w}: --vulkan-device is {arg_after(args, '--vulkan-device')}, expected NVIDIA")
        check("graphics" in (env.get("NVIDIA_DRIVER_CAPABILITIES") or "").split(","),
              f"{w}: NVIDIA_DRIVER_CAPABILITIES {env.get('NVIDIA_DRIVER_CAPABILITIES')} lacks graphics (no Vulkan ICD)")
        check(any(t.get("key") == "nvidia.com/gpu" for t in spec.get("tolerations", [])), f"{w}: no toleration for nvidia.com/gpu")
    else:
        check(gpu is None, f"{w}: asks for nvidia.com/gpu {gpu}")
    if target_name(w) == "cpu":
        check(backends == ["cpu"], f"{w}: --backend {backends}, expected [cpu]")


def target_name(target):
    return target.rsplit("/", 1)[-1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--k8s", required=True, help="deploy/k8s")
    parser.add_argument("--metrics-source", required=True, help="server/net/src/metrics.cpp")
    parser.add_argument("--haarcast", help="the built haarcast: its /metrics, not the source, names the gauges")
    parser.add_argument("--server-header", required=True, help="server/net/include/haarcast/net/server.h")
    parser.add_argument("--kubectl", action="append", default=[],
                        help="a kubectl to render with (repeatable; default: kubectl on PATH, and $HAARCAST_KUBECTL)")
    opts = parser.parse_args()

    kubectls = opts.kubectl or [k for k in (shutil.which("kubectl"), os.environ.get("HAARCAST_KUBECTL")) if k]
    if not kubectls:
        print("SKIP: no kubectl (apt-get install kubernetes-client)")
        return SKIP
    gauges = served_gauges(opts.haarcast) if opts.haarcast else exported_gauges(opts.metrics_source)
    drain_s = source_number(opts.server_header, "drainSeconds")
    idle_s = source_number(opts.server_header, "idleSeconds")

    for target in TARGETS:
        directory = os.path.join(opts.k8s, target)
        rendered = {k: render(k, directory) for k in kubectls}
        first = kubectls[0]
        for k in kubectls[1:]:
            check(rendered[k] == rendered[first], f"{target}: {k} renders other objects than {first}")
        check_target(target, rendered[first], gauges, drain_s, idle_s)
        print(f"{target}: {len(rendered[first])} objects rendered by {', '.join(kubectls)}")

    if failures:
        for f in failures:
            print(f"FAIL: {f}")
        return 1
    print(f"PASS: {len(TARGETS)} targets; HPA metric among the server's gauges {sorted(gauges)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
