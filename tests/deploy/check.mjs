// deploy/k8s must agree with the server it deploys: flags the binary accepts, the port it
// listens on, probe paths it serves, the user and entrypoint of the Dockerfile. Starts the
// binary with the Deployment's own arguments (port 0 instead) and calls its probes.
//   node check.mjs EFFECTD_BINARY REPO_ROOT
import { spawn, spawnSync } from "node:child_process";
import { readFileSync } from "node:fs";
import yaml from "js-yaml";

const [bin, root] = process.argv.slice(2);
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); };
const load = (f) => yaml.loadAll(readFileSync(`${root}/${f}`, "utf8"));

const [deployment] = load("deploy/k8s/deployment.yaml");
const [service] = load("deploy/k8s/service.yaml");
const [hpa] = load("deploy/k8s/hpa.yaml");
const pod = deployment.spec.template.spec;
const [container] = pod.containers;
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

// Port: the container port is the one the server is told to listen on, and the image's.
const port = container.ports.find((p) => p.name === "http");
check(String(port.containerPort) === flagValue("port"), `containerPort ${port.containerPort} != --port ${flagValue("port")}`);
check(flagValue("host") === "0.0.0.0", "--host must be 0.0.0.0 inside a pod");
check(dockerfile.includes(`EXPOSE ${port.containerPort}`), "Dockerfile EXPOSE differs from containerPort");
check(new RegExp(`EFFECTD_PORT=${port.containerPort}\\b`).test(dockerfile), "Dockerfile EFFECTD_PORT differs");

// Probes: paths the server serves (in its contract), on the named port.
for (const [name, path] of [["startupProbe", "/readyz"], ["readinessProbe", "/readyz"], ["livenessProbe", "/healthz"]]) {
  const probe = container[name];
  check(probe && probe.httpGet.path === path, `${name} must GET ${path}`);
  check(probe && openapi.paths[probe.httpGet.path], `${name} path ${probe && probe.httpGet.path} is not in openapi.yaml`);
  check(probe && probe.httpGet.port === "http", `${name} must use the http port`);
}

// Image: entrypoint and user as the Dockerfile builds them.
check(/ENTRYPOINT \["\/usr\/local\/bin\/effectd"\]/.test(dockerfile), "Dockerfile ENTRYPOINT must be the effectd binary");
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
check(new RegExp(`HEALTHCHECK .*127\\.0\\.0\\.1:${port.containerPort}/healthz`).test(dockerfile),
      "Dockerfile HEALTHCHECK must call /healthz on the container port");
check(container.resources?.requests?.cpu, "a CPU request is required for the HPA's utilisation target");
const labels = deployment.spec.template.metadata.labels;
for (const [k, v] of Object.entries(deployment.spec.selector.matchLabels)) check(labels[k] === v, `selector ${k} does not match the pod`);
for (const [k, v] of Object.entries(service.spec.selector)) check(labels[k] === v, `Service selector ${k} does not match the pod`);
check(service.spec.ports[0].targetPort === "http", "Service targetPort must be the named container port");
check(hpa.spec.scaleTargetRef.kind === "Deployment" && hpa.spec.scaleTargetRef.name === deployment.metadata.name, "HPA target");
check(hpa.spec.minReplicas >= 2 && hpa.spec.maxReplicas >= hpa.spec.minReplicas, "HPA replica bounds");
check(pod.terminationGracePeriodSeconds >= 10, "grace period for in-flight requests");

// The binary accepts these exact arguments and answers its probes.
const runArgs = args.slice(1).map((a) => (a.startsWith("--port=") ? "--port=0" : a.startsWith("--host=") ? "--host=127.0.0.1" : a));
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
if (listening) {
  for (const path of ["/healthz", "/readyz"]) {
    const r = await fetch(`http://127.0.0.1:${listening}${path}`);
    check(r.status === 200, `${path} answered ${r.status}`);
  }
}
server.kill("SIGTERM");
const code = await exited;
check(code === 0, `exit code ${code} after SIGTERM`);

if (failures.length) {
  console.error("deploy/k8s disagrees with the server:\n  " + failures.join("\n  "));
  process.exit(1);
}
console.log(`deploy/k8s ok: port ${port.containerPort}, probes /readyz /healthz, ${args.length - 1} flags, user ${user}, memory budget ${budgetMb} of ${limitMb} MiB`);
