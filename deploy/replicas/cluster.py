"""Redis, effectd replicas and nginx on loopback, as README.md runs them: the pieces test.py
(ctest deploy_replicas) and soak.py start, stop and kill.

    cluster = Cluster(binary, work, keys={"id": "secret", ...}, signing_key="...")
    cluster.start_redis(); cluster.start_replicas(3, max_connections=32); cluster.start_nginx()
    ... cluster.lb (nginx's port), cluster.ports[i], cluster.admin[cluster.ports[i]] ...
    cluster.stop()
"""
import hashlib
import http.client
import json
import os
import shutil
import socket
import subprocess
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def answers(port, path="/healthz", seconds=10.0):
    """Whether a GET of `path` on 127.0.0.1:`port` answers 200 within `seconds`."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            c = http.client.HTTPConnection("127.0.0.1", port, timeout=2)
            c.request("GET", path)
            if c.getresponse().status == 200:
                return True
        except OSError:
            pass
        time.sleep(0.05)
    return False


def rss_mib(pid):
    """A process's resident memory in MiB (VmRSS), 0 once it is gone."""
    try:
        for line in open(f"/proc/{pid}/status"):
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return 0.0


class Cluster:
    def __init__(self, binary, work, keys, signing_key, key_quota=lambda key_id: (600, 20)):
        """`keys`: id -> secret; `key_quota(id)` -> (perMinute, burst)."""
        self.binary, self.work = binary, work
        self.procs, self.ports, self.admin = {}, [], {}
        self.redis_port, self.lb = free_port(), 0
        self.replica_flags = []
        open(os.path.join(work, "signing.txt"), "w").write(signing_key + "\n")
        json.dump({"keys": [{"id": k, "sha256": hashlib.sha256(s.encode()).hexdigest(),
                             "perMinute": key_quota(k)[0], "burst": key_quota(k)[1]} for k, s in keys.items()]},
                  open(os.path.join(work, "keys.json"), "w"))

    def start_redis(self, data="redis"):
        """Redis as README.md runs it: its append-only file in work/`data`, fsync'd every second."""
        data = os.path.join(self.work, data)
        os.makedirs(data, exist_ok=True)
        self.procs["redis"] = subprocess.Popen(
            ["redis-server", "--port", str(self.redis_port), "--bind", "127.0.0.1", "--save", "", "--appendonly",
             "yes", "--appendfsync", "everysec", "--dir", data], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        for _ in range(100):
            try:
                socket.create_connection(("127.0.0.1", self.redis_port), timeout=1).close()
                return
            except OSError:
                time.sleep(0.05)

    def start_replicas(self, n, *flags):
        """n replicas on ports of their own (kept across a restart), each with `flags` added."""
        self.replica_flags = list(flags)
        for _ in range(n):
            port = free_port()
            self.ports.append(port)
            self.admin[port] = free_port()
        for i in range(n):
            self.start_replica(i)
        return all(answers(self.admin[p]) for p in self.ports)

    def start_replica(self, i):
        """Replica i (again, after a kill), as README.md runs it: the playground off, operations
        on the admin port, quotas and jobs in Redis."""
        redis = f"redis://127.0.0.1:{self.redis_port}"
        port = self.ports[i]
        self.procs[f"effectd{i}"] = subprocess.Popen(
            [self.binary, "--host", "127.0.0.1", "--port", str(port), "--threads", "8", "--access-log", "0",
             "--quota-redis", redis, "--jobs-redis", redis, "--api-keys", os.path.join(self.work, "keys.json"),
             "--url-signing-key-file", os.path.join(self.work, "signing.txt"), "--playground", "off",
             "--admin-port", str(self.admin[port]), *self.replica_flags],
            stderr=open(os.path.join(self.work, f"effectd{i}.log"), "a"))
        return answers(self.admin[port])

    def start_nginx(self):
        """deploy/replicas/nginx.conf (with deploy/nginx/edge.conf beside it) on a free port, its
        upstreams the replicas' ports."""
        self.lb = free_port()
        conf = open(os.path.join(HERE, "nginx.conf")).read().replace("listen 8080;", f"listen 127.0.0.1:{self.lb};")
        for i, p in enumerate(self.ports):
            conf = conf.replace(f"127.0.0.1:808{i + 1}", f"127.0.0.1:{p}")
        for d in ("tmp", "cache"):
            os.makedirs(os.path.join(self.work, d), exist_ok=True)
        open(os.path.join(self.work, "nginx.conf"), "w").write(conf)
        shutil.copy(os.path.join(HERE, "..", "nginx", "edge.conf"), os.path.join(self.work, "edge.conf"))
        user = "user root root;" if os.getuid() == 0 else ""
        self.procs["nginx"] = subprocess.Popen(
            ["nginx", "-p", self.work, "-c", os.path.join(self.work, "nginx.conf"), "-g", f"daemon off; {user}"],
            stderr=open(os.path.join(self.work, "nginx.log"), "w"))
        return answers(self.lb)

    def kill(self, name, sig):
        self.procs[name].send_signal(sig)
        self.procs[name].wait()

    def alive(self, i):
        return self.procs[f"effectd{i}"].poll() is None

    def stop(self):
        for p in self.procs.values():
            if p.poll() is None:
                p.terminate()
        for p in self.procs.values():
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()

    def logs(self, tail=2000):
        return "".join(f"--- {name}\n" + open(os.path.join(self.work, name)).read()[-tail:]
                       for name in sorted(os.listdir(self.work)) if name.endswith(".log"))
