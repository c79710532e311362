// deploy/k8s must agree with the server it deploys: flags the binary accepts, the ports it
// listens on, probe paths it serves, the user and entrypoint of the Dockerfile, the edge
// sidecar's nginx (its edge.conf the same bytes as deploy/nginx/edge.conf), and the shared store
// (redis.yaml's StatefulSet, store.yaml's Secrets). Starts redis-server with the StatefulSet's
// arguments, two effectd with the Deployment's own arguments and environment (free ports and
// this Redis instead), the sidecar's nginx in front of one, and calls them as the cluster would:
// probes on the admin port, clients through the edge, a job submitted to one pod and fetched
// from the other. Then a Redis with a password, as store.yaml's url may name one.
//   node check.mjs EFFECTD_BINARY REPO_ROOT
import { spawn, spawnSync } from "node:child_process";
import { createHash } from "node:crypto";
import { mkdtempSync, mkdirSync, readFileSync, writeFileSync, rmSync } from "node:fs";
import { createServer } from "node:net";
import { tmpdir } from "node:os";
import yaml from "js-yaml";

const [bin, root] = process.argv.slice(2);
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); };
const load = (f) => yaml.loadAll(readFileSync(`${root}/${f}`, "utf8"));

const [deployment] = load("deploy/k8s/deployment.yaml");
const [service] = load("deploy/k8s/service.yaml");
const [hpa] = load("deploy/k8s/hpa.yaml");
const [edgeConfig] = load("deploy/k8s/edge-config.yaml");
const [redisService, redisSet, redisPolicy] = load("deploy/k8s/redis.yaml");
const [storeSecret, keysSecret] = load("deploy/k8s/store.yaml");
const pod = deployment.spec.template.spec;
const container = pod.containers.find((c) => c.name === "effectd");
const edge = pod.containers.find((c) => c.name === "edge");
const dockerfile = readFileSync(`${root}/Dockerfile`, "utf8");
const openapi = yaml.load(readFileSync(`${root}/proto/openapi.yaml`, "utf8"));

// Flags: every --flag the Deployment passes is one the binary documents.
const help = spawnSync(bin, ["--help"], { encoding: "utf8" }).stdout;
const args = container.args;
check(args[0] === "serve", `args[0] must be the serve sub-command, got ${args[0]}`);
for (const a of args.slice(1)) {
  const flag = a.replace(/=.*/, "");
  check(help.includes(`  ${flag} [`), `${flag} is not a flag of effectd (--help)`);
}
const flagValue = (name) => (args.find((a) => a.startsWith(`--${name}=`)) || "").split("=")[1];

// Ports: effectd on the pod's loopback only (the edge is the one way in), its admin port on every
// address for the kubelet and Prometheus.
check(flagValue("host") === "127.0.0.1", "--host must be 127.0.0.1: only the edge in the pod reaches effectd");
check(flagValue("admin-host") === "0.0.0.0", "--admin-host must be 0.0.0.0: probes come from outside the pod");
check(!container.ports.some((p) => p.name !== "admin"), "effectd must declare no port but the admin one");

// Probes: paths the server serves (in its contract), on the admin port (--admin-port).
const admin = container.ports.find((p) => p.name === "admin");
check(admin && String(admin.containerPort) === flagValue("admin-port"), "the admin containerPort must be --admin-port");
check(flagValue("playground") === "off", "--playground=off: the playground is not for the public");
for (const [name, path] of [["startupProbe", "/readyz"], ["readinessProbe", "/readyz"], ["livenessProbe", "/healthz"]]) {
  const probe = container[name];
  check(probe && probe.httpGet.path === path, `${name} must GET ${path}`);
  check(probe && openapi.paths[probe.httpGet.path], `${name} path ${probe && probe.httpGet.path} is not in openapi.yaml`);
  check(probe && probe.httpGet.port === "admin", `${name} must use the admin port`);
}

// The edge: nginx with edge.conf in front, the only port the Service reaches.
const edgeConf = edgeConfig.data["edge.conf"], edgeNginx = edgeConfig.data["nginx.conf"];
check(edgeConf === readFileSync(`${root}/deploy/nginx/edge.conf`, "utf8"), "edge-config.yaml's edge.conf must be deploy/nginx/edge.conf");
check(edgeNginx === readFileSync(`${root}/deploy/nginx/pod.conf`, "utf8"), "edge-config.yaml's nginx.conf must be deploy/nginx/pod.conf");
const publicPort = edge?.ports.find((p) => p.name === "public");
check(publicPort && edgeNginx.includes(`listen ${publicPort.containerPort};`), "the edge's public port must be its nginx's listen port");
check(edgeNginx.includes(`server 127.0.0.1:${flagValue("port")};`), "the edge's upstream must be effectd's --port");
check(pod.volumes.some((v) => v.configMap?.name === edgeConfig.metadata.name), "the edge's ConfigMap must be mounted");

// Image: the Deployment runs the Dockerfile's runtime target (effectd alone, its entrypoint the
// binary, so the args above are effectd's); the default target is the edge, published on the
// same public port as the sidecar's.
const stage = (name) => (dockerfile.split(/^FROM /m).find((t) => new RegExp(`^\\S+ AS ${name}\\n`).test(t)) || "");
check(/ENTRYPOINT \["\/usr\/local\/bin\/effectd"\]/.test(stage("runtime")), "the Dockerfile's runtime ENTRYPOINT must be the effectd binary");
check(/^FROM scratch AS edge\n/m.test(dockerfile.split(/^(?=FROM )/m).pop()), "the Dockerfile's last (default) target must be the edge");
check(stage("edge").includes(`EXPOSE ${publicPort.containerPort} ${flagValue("admin-port")}`), "the edge image must expose the public and admin ports");
check(new RegExp(`HEALTHCHECK .*127\\.0\\.0\\.1:${publicPort.containerPort}/healthz`).test(stage("edge")),
      "the edge image's HEALTHCHECK must call /healthz on the public port");
check(/^effectd-runtime:/.test(container.image), "the effectd container must run the runtime target");
check(!container.command, "command would override the image's ENTRYPOINT");
const user = (dockerfile.match(/^USER (\d+)/m) || [])[1];
check(String(pod.securityContext.runAsUser) === user, `runAsUser ${pod.securityContext.runAsUser} != Dockerfile USER ${user}`);
check(pod.securityContext.runAsNonRoot === true, "runAsNonRoot");

// Bounded resources; wiring of Service and HPA.
check(container.resources?.limits?.cpu && container.resources?.limits?.memory, "CPU and memory limits are required");
// The memory budget (what requests may reserve at their estimated peaks) is derived from the
// container's memory limit: below it, with room for what the budget does not count.
const mib = (q) => { const m = /^(\d+)(Mi|Gi)$/.exec(String(q)); return m ? Number(m[1]) * (m[2] === "Gi" ? 1024 : 1) : NaN; };
const limitMb = mib(container.resources?.limits?.memory);
const budgetMb = Number(flagValue("memory-budget-mb"));
check(budgetMb >= 0.4 * limitMb && budgetMb <= 0.75 * limitMb,
      `--memory-budget-mb=${flagValue("memory-budget-mb")} must be 40-75 % of limits.memory (${limitMb} MiB)`);
check(container.resources?.requests?.cpu, "a CPU request is required for the HPA's utilisation target");
const labels = deployment.spec.template.metadata.labels;
for (const [k, v] of Object.entries(deployment.spec.selector.matchLabels)) check(labels[k] === v, `selector ${k} does not match the pod`);
for (const [k, v] of Object.entries(service.spec.selector)) check(labels[k] === v, `Service selector ${k} does not match the pod`);
check(service.spec.ports[0].targetPort === "public", "the Service must target the edge's public port, not effectd");
check(hpa.spec.scaleTargetRef.kind === "Deployment" && hpa.spec.scaleTargetRef.name === deployment.metadata.name, "HPA target");
check(hpa.spec.minReplicas >= 2 && hpa.spec.maxReplicas >= hpa.spec.minReplicas, "HPA replica bounds");
check(pod.terminationGracePeriodSeconds >= 10, "grace period for in-flight requests");

// The shared store. Redis: one pod of a StatefulSet, its --dir on the claim's volume, the
// append-only file fsync'd every second, never evicting; its headless Service the one the url
// names; reachable from effectd's pods only.
const kinds = [redisService, redisSet, redisPolicy, storeSecret, keysSecret].map((d) => d?.kind).join(" ");
check(kinds === "Service StatefulSet NetworkPolicy Secret Secret", `redis.yaml and store.yaml hold ${kinds}`);
const redisPod = redisSet.spec.template.spec;
const redis = redisPod.containers[0];
const redisArgs = redis.args;
const redisFlag = (name) => { const i = redisArgs.indexOf(`--${name}`); return i < 0 ? undefined : redisArgs[i + 1]; };
check(redisArgs[0] === "redis-server", "the Redis container must run redis-server");
check(redisFlag("appendonly") === "yes" && redisFlag("appendfsync") === "everysec",
      "Redis must keep its append-only file, fsync'd every second");
check(redisFlag("maxmemory-policy") === "noeviction", "Redis must not evict jobs or buckets (noeviction)");
check(redisSet.spec.replicas === 1, "one Redis primary");
check(redisSet.spec.serviceName === redisService.metadata.name, "the StatefulSet's serviceName must be its Service");
const claim = redisSet.spec.volumeClaimTemplates?.[0];
const dataMount = redis.volumeMounts?.find((m) => m.name === claim?.metadata.name);
check(claim && dataMount && dataMount.mountPath === redisFlag("dir"), "Redis's --dir must be the claim's mount");
check(claim?.spec.accessModes?.includes("ReadWriteOnce") && claim?.spec.resources?.requests?.storage,
      "the claim must be ReadWriteOnce with a size");
const redisPort = redis.ports.find((p) => p.name === "redis");
check(String(redisPort?.containerPort) === redisFlag("port"), "the Redis containerPort must be its --port");
const redisLabels = redisSet.spec.template.metadata.labels;
for (const [k, v] of Object.entries(redisSet.spec.selector.matchLabels)) check(redisLabels[k] === v, `Redis selector ${k}`);
for (const [k, v] of Object.entries(redisService.spec.selector)) check(redisLabels[k] === v, `Redis Service selector ${k}`);
check(redisService.spec.ports[0].targetPort === "redis", "the Redis Service must target the redis port");
check(String(redisPod.securityContext.fsGroup) === String(redisPod.securityContext.runAsUser), "the volume must belong to Redis's user");
for (const [k, v] of Object.entries(redisPolicy.spec.podSelector.matchLabels)) check(redisLabels[k] === v, "the policy must select Redis");
const allowed = redisPolicy.spec.ingress[0].from[0].podSelector.matchLabels;
for (const [k, v] of Object.entries(allowed)) check(labels[k] === v, "the policy must admit effectd's pods");
// store.yaml's url names the in-cluster Redis as shipped; effectd reads it by --jobs-redis' and
// --quota-redis' environment variables.
const storeUrl = new URL(storeSecret.stringData.url);
check(storeUrl.protocol === "redis:" && storeUrl.hostname === redisService.metadata.name &&
      storeUrl.port === String(redisService.spec.ports[0].port), `the store url ${storeSecret.stringData.url} must name redis.yaml's Service`);
for (const [name, flag] of [["EFFECTD_JOBS_REDIS", "--jobs-redis"], ["EFFECTD_QUOTA_REDIS", "--quota-redis"]]) {
  const env = container.env.find((e) => e.name === name);
  check(env?.valueFrom?.secretKeyRef?.name === storeSecret.metadata.name && env.valueFrom.secretKeyRef.key === "url",
        `${name} must come from the ${storeSecret.metadata.name} Secret's url`);
  check(help.includes(`  ${flag} [${name}]`), `${name} must be ${flag}'s environment (--help)`);
}
// The key file: --api-keys inside the mount of the keys Secret, a file the Secret holds.
const keysPath = flagValue("api-keys") || "";
const keysVolume = pod.volumes.find((v) => v.secret?.secretName === keysSecret.metadata.name);
const keysMount = container.volumeMounts.find((m) => m.name === keysVolume?.name);
check(keysMount && keysPath === `${keysMount.mountPath}/keys.json` && keysSecret.stringData["keys.json"],
      `--api-keys=${keysPath} must be keys.json of the ${keysSecret.metadata.name} Secret's mount`);

// Redis as the StatefulSet runs it (its port and --dir here instead), then two pods' effectd
// with the Deployment's arguments and environment: the store's url pointing at this Redis, the
// shipped key file with one key added, free ports.
const freePort = () => new Promise((resolve) => {
  const s = createServer().listen(0, "127.0.0.1", () => { const p = s.address().port; s.close(() => resolve(p)); });
});
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const work = mkdtempSync(`${tmpdir()}/effectd-k8s.`);
const children = [];
const started = (cmd, argv, env) => {
  const child = spawn(cmd, argv, env ? { env: { ...process.env, ...env } } : undefined);
  child.log = "";
  child.stderr.on("data", (d) => (child.log += d));
  child.stdout.on("data", (d) => (child.log += d));
  child.exited = new Promise((resolve) => child.on("exit", (c) => resolve(c)));
  children.push(child);
  return child;
};
const until = async (what, ms = 10000) => {
  for (const end = Date.now() + ms; Date.now() < end; await sleep(50)) {
    const v = await what().catch(() => undefined);
    if (v) return v;
  }
  return undefined;
};
const redisUp = (port, ...auth) => until(() => new Promise((resolve) => {
  const p = spawnSync("redis-cli", ["-p", String(port), ...auth, "ping"], { encoding: "utf8" });
  resolve(p.stdout.trim() === "PONG");
}));

const storePort = await freePort();
mkdirSync(`${work}/data`);
started("redis-server", redisArgs.slice(1).map((a, i, all) =>
  all[i - 1] === "--port" ? String(storePort) : all[i - 1] === "--dir" ? `${work}/data` : a).concat(["--bind", "127.0.0.1"]));
check(await redisUp(storePort), "redis-server did not start with the StatefulSet's arguments");

const SECRET = "k8s-check-secret";
const keys = JSON.parse(keysSecret.stringData["keys.json"]);
check(Array.isArray(keys.keys) && keys.keys.length === 0, "the shipped key file must hold no key (every request refused until one is added)");
keys.keys.push({ id: "check", sha256: createHash("sha256").update(SECRET).digest("hex"), perMinute: 600, burst: 60 });
writeFileSync(`${work}/keys.json`, JSON.stringify(keys));
const auth = { Authorization: `Bearer ${SECRET}`, "Content-Type": "application/json" };
const podEnv = (url) => Object.fromEntries(container.env.map((e) => [e.name, e.valueFrom?.secretKeyRef ? url : e.value]));
// store.yaml's url with its host this machine's Redis on `port`, and `userinfo` ("" or ":password@").
const localUrl = (port, userinfo = "") => storeSecret.stringData.url.replace(`//${storeUrl.host}`, `//${userinfo}127.0.0.1:${port}`);

// One pod's effectd: its public and admin ports once it listens.
const startPod = async (url) => {
  const adminPort = await freePort();
  const runArgs = args.slice(1).map((a) => (a.startsWith("--port=") ? "--port=0" : a.startsWith("--host=") ? "--host=127.0.0.1"
    : a.startsWith("--admin-port=") ? `--admin-port=${adminPort}` : a.startsWith("--api-keys=") ? `--api-keys=${work}/keys.json` : a));
  const server = started(bin, runArgs, podEnv(url));
  const port = await until(async () => Number((server.log.match(/"port":(\d+)/) || [])[1]));
  return { server, port: port || 0, admin: adminPort };
};
const json = async (r) => ({ status: r.status, body: await r.json().catch(() => ({})), headers: r.headers });

const pods = [await startPod(localUrl(storePort)), await startPod(localUrl(storePort))];
check(pods.every((p) => p.port > 0), `effectd did not start with the Deployment's arguments: ${pods.map((p) => p.server.log).join("\n")}`);
const [podA, podB] = pods;
let nginx;
if (podA.port && podB.port) {
  for (const path of ["/healthz", "/readyz", "/metrics"]) {
    const r = await fetch(`http://127.0.0.1:${podA.admin}${path}`);
    check(r.status === 200, `${path} on the admin port answered ${r.status}`);
  }
  for (const pod of pods) {
    const ready = await json(await fetch(`http://127.0.0.1:${pod.admin}/readyz`));
    const parts = ready.body.components || {};
    check(ready.body.status === "ready" && parts.jobStore === "ready" && parts.quotaStore === "ready",
          `/readyz must name jobStore and quotaStore, both ready: ${JSON.stringify(ready.body)}`);
  }
  check((await fetch(`http://127.0.0.1:${podA.port}/metrics`)).status === 404, "/metrics must not be on effectd's public port");
  // The sidecar's nginx, as the pod runs it, in front of pod A.
  const edgePort = await freePort();
  const dir = mkdtempSync(`${tmpdir()}/effectd-edge.`);
  writeFileSync(`${dir}/edge.conf`, edgeConf);
  writeFileSync(`${dir}/nginx.conf`, edgeNginx.replace(`listen ${publicPort.containerPort};`, `listen 127.0.0.1:${edgePort};`)
    .replace(`server 127.0.0.1:${flagValue("port")};`, `server 127.0.0.1:${podA.port};`));
  const asRoot = process.getuid() === 0 ? " user root root;" : "";
  nginx = started("nginx", ["-p", `${dir}/`, "-e", "stderr", "-c", `${dir}/nginx.conf`, "-g", `daemon off;${asRoot}`]);
  const up = await until(() => fetch(`http://127.0.0.1:${edgePort}/healthz`).then((r) => r.status === 200), 5000);
  check(up, `the edge's nginx did not serve /healthz: ${nginx.log}`);
  const fogBody = JSON.stringify({ fog: { fogType: "GL_EXP2", density: 0.05 }, table: { size: 16 } });
  if (up) {
    const open = await fetch(`http://127.0.0.1:${edgePort}/v1/fog`, { method: "POST", headers: { "Content-Type": "application/json" }, body: fogBody });
    check(open.status === 401, `POST /v1/fog without a key through the edge answered ${open.status}, not 401`);
    const fog = await fetch(`http://127.0.0.1:${edgePort}/v1/fog`, { method: "POST", headers: auth, body: fogBody });
    check(fog.status === 200, `POST /v1/fog with a key through the edge answered ${fog.status}`);
    for (const path of ["/readyz", "/metrics", "/"]) {
      const r = await fetch(`http://127.0.0.1:${edgePort}${path}`);
      check(r.status === 404, `${path} through the edge answered ${r.status}, not 404`);
    }
  }
  // A job submitted to pod A, followed and fetched from pod B: the jobs live in the store.
  const n = 96;
  const bolt = { grid: { width: n, height: n }, method: "dbm", neighbourhood: 4, start: [n / 2, 0],
                 targetRegion: { rows: [{ y: n - 1, runs: [[0, n]] }] } };
  const submitted = await json(await fetch(`http://127.0.0.1:${podA.port}/v1/jobs`,
    { method: "POST", headers: auth, body: JSON.stringify({ effect: "lightning", request: bolt }) }));
  const location = submitted.headers.get("location") || "";
  check(submitted.status === 202 && location.startsWith("/v1/jobs/"), `a job submitted to pod A: ${submitted.status} ${location}`);
  const done = location && await until(async () => {
    const s = await json(await fetch(`http://127.0.0.1:${podB.port}${location}`, { headers: auth }));
    return ["done", "failed", "cancelled"].includes(s.body.state) && s;
  }, 60000);
  check(done?.body.state === "done", `the job followed on pod B must end done: ${JSON.stringify(done?.body)}`);
  const result = await json(await fetch(`http://127.0.0.1:${podB.port}${location}/result`, { headers: auth }));
  check(result.status === 200 && result.body.cellCount > 0, `the job's answer fetched from pod B: ${result.status}`);
  // The key's quota is charged in the store.
  const metrics = await (await fetch(`http://127.0.0.1:${podA.admin}/metrics`)).text();
  check(/effectd_quota_charges_total\{store="redis"\} [1-9]/.test(metrics), "pod A's quota charges must go to Redis");
  rmSync(dir, { recursive: true, force: true });

  // A Redis of your own with a password, as store.yaml's url may name it (percent-encoded):
  // the right password is ready, a wrong one says the store refused it, and stays 200.
  const passwordPort = await freePort();
  const password = "p@ss:w/rd";
  started("redis-server", ["--port", String(passwordPort), "--bind", "127.0.0.1", "--save", "", "--requirepass", password]);
  check(await redisUp(passwordPort, "-a", password, "--no-auth-warning"), "redis-server with a password did not start");
  const encoded = `:${encodeURIComponent(password)}@`;
  const [right, wrong] = [await startPod(localUrl(passwordPort, encoded)), await startPod(localUrl(passwordPort, ":not-the-password-42@"))];
  const rightReady = await json(await fetch(`http://127.0.0.1:${right.admin}/readyz`));
  check(rightReady.body.status === "ready" && rightReady.body.components?.jobStore === "ready", `a Redis with a password, the url with it: ${JSON.stringify(rightReady.body)}`);
  const wrongReady = await until(async () => {
    await fetch(`http://127.0.0.1:${wrong.port}/v1/jobs`, { method: "POST", headers: auth, body: "{}" });
    const r = await json(await fetch(`http://127.0.0.1:${wrong.admin}/readyz`));
    return r.body.status === "degraded" && r;
  }, 5000);
  check(wrongReady?.status === 200 && /refused AUTH/.test(JSON.stringify(wrongReady.body)) && !JSON.stringify(wrongReady.body).includes("not-the-password"),
        `a wrong password: /readyz 200, degraded, saying AUTH was refused and not the password: ${JSON.stringify(wrongReady?.body)}`);
}
const codes = await Promise.all(children.filter((c) => c.spawnfile === bin).map((c) => { c.kill("SIGTERM"); return c.exited; }));
check(codes.every((c) => c === 0), `exit codes ${codes} after SIGTERM`);
for (const c of children) c.kill("SIGTERM");
await Promise.all(children.map((c) => c.exited));
rmSync(work, { recursive: true, force: true });

if (failures.length) {
  console.error("deploy/k8s disagrees with the server:\n  " + failures.join("\n  "));
  process.exit(1);
}
console.log(`deploy/k8s ok: effectd on loopback ${flagValue("port")} behind the edge on ${publicPort.containerPort}, probes /readyz /healthz on admin ${admin.containerPort}, ${args.length - 1} flags, user ${user}, memory budget ${budgetMb} of ${limitMb} MiB; ` +
            `Redis (append-only, everysec) on a ${claim.spec.resources.requests.storage} claim: a job submitted to one pod fetched from the other, quotas charged in Redis, a password'd Redis reached by its url`);
