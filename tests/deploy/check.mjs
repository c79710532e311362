// deploy/k8s must agree with the server it deploys: flags the binary accepts, the ports it
// listens on, probe paths it serves, the user and entrypoint of the Dockerfile, and the edge
// sidecar's nginx (its edge.conf the same bytes as deploy/nginx/edge.conf). Starts the binary
// with the Deployment's own arguments (free ports instead) and the sidecar's nginx in front of
// it, and calls both as the cluster would: probes on the admin port, clients through the edge.
//   node check.mjs EFFECTD_BINARY REPO_ROOT
import { spawn, spawnSync } from "node:child_process";
import { mkdtempSync, readFileSync, writeFileSync, rmSync } from "node:fs";
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

// The binary accepts these exact arguments and answers its probes.
const freePort = () => new Promise((resolve) => {
  const s = createServer().listen(0, "127.0.0.1", () => { const p = s.address().port; s.close(() => resolve(p)); });
});
const adminPort = await freePort(), edgePort = await freePort();
const runArgs = args.slice(1).map((a) => (a.startsWith("--port=") ? "--port=0" : a.startsWith("--host=") ? "--host=127.0.0.1"
  : a.startsWith("--admin-port=") ? `--admin-port=${adminPort}` : a));
const server = spawn(bin, runArgs, { env: { ...process.env, ...Object.fromEntries(container.env.map((e) => [e.name, e.value])) } });
let log = "";
server.stderr.on("data", (d) => (log += d));
const exited = new Promise((resolve) => server.on("exit", (c) => resolve(c)));
const listening = await new Promise((resolve) => {
  const t = setInterval(() => {
    const m = log.match(/"port":(\d+)/);
    if (m) { clearInterval(t); resolve(Number(m[1])); }
  }, 50);
  setTimeout(() => { clearInterval(t); resolve(0); }, 10000);
});
check(listening > 0, `effectd did not start with the Deployment's arguments: ${log}`);
let nginx;
if (listening) {
  for (const path of ["/healthz", "/readyz", "/metrics"]) {
    const r = await fetch(`http://127.0.0.1:${adminPort}${path}`);
    check(r.status === 200, `${path} on the admin port answered ${r.status}`);
  }
  check((await fetch(`http://127.0.0.1:${listening}/metrics`)).status === 404, "/metrics must not be on effectd's public port");
  // The sidecar's nginx, as the pod runs it, in front of this effectd.
  const dir = mkdtempSync(`${tmpdir()}/effectd-edge.`);
  writeFileSync(`${dir}/edge.conf`, edgeConf);
  writeFileSync(`${dir}/nginx.conf`, edgeNginx.replace(`listen ${publicPort.containerPort};`, `listen 127.0.0.1:${edgePort};`)
    .replace(`server 127.0.0.1:${flagValue("port")};`, `server 127.0.0.1:${listening};`));
  const asRoot = process.getuid() === 0 ? " user root root;" : "";
  nginx = spawn("nginx", ["-p", `${dir}/`, "-e", "stderr", "-c", `${dir}/nginx.conf`, "-g", `daemon off;${asRoot}`]);
  let nginxLog = "";
  nginx.stderr.on("data", (d) => (nginxLog += d));
  let up = false;
  for (let i = 0; i < 100 && !up; ++i) {
    up = await fetch(`http://127.0.0.1:${edgePort}/healthz`).then((r) => r.status === 200, () => false);
    if (!up) await new Promise((r) => setTimeout(r, 50));
  }
  check(up, `the edge's nginx did not serve /healthz: ${nginxLog}`);
  if (up) {
    const fog = await fetch(`http://127.0.0.1:${edgePort}/v1/fog`, {
      method: "POST", headers: { "Content-Type": "application/json" },
      body: JSON.stringify({ fog: { fogType: "GL_EXP2", density: 0.05 }, table: { size: 16 } }) });
    check(fog.status === 200, `POST /v1/fog through the edge answered ${fog.status}`);
    for (const path of ["/readyz", "/metrics", "/"]) {
      const r = await fetch(`http://127.0.0.1:${edgePort}${path}`);
      check(r.status === 404, `${path} through the edge answered ${r.status}, not 404`);
    }
  }
  nginx.kill("SIGTERM");
  rmSync(dir, { recursive: true, force: true });
}
server.kill("SIGTERM");
const code = await exited;
check(code === 0, `exit code ${code} after SIGTERM`);

if (failures.length) {
  console.error("deploy/k8s disagrees with the server:\n  " + failures.join("\n  "));
  process.exit(1);
}
console.log(`deploy/k8s ok: effectd on loopback ${flagValue("port")} behind the edge on ${publicPort.containerPort}, probes /readyz /healthz on admin ${admin.containerPort}, ${args.length - 1} flags, user ${user}, memory budget ${budgetMb} of ${limitMb} MiB`);
