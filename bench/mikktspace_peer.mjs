// The MikkTSpace peer measured beside tangents_bench: the npm package `mikktspace` (the
// reference mikktspace.c via its Rust port, WebAssembly, one thread) on the same 99 500-
// triangle UV sphere as BM_MikkTSpace100k (fixtures::uvSphere(200, 250), de-indexed as the
// package takes it). Prints {"peer": ..., "ms": median, "runs": [...]} as one JSON line.
//   node bench/mikktspace_peer.mjs [runs]   (installs nothing: tests/mikktspace's npm ci does)
import { createRequire } from 'node:module';

const require = createRequire(new URL('../tests/mikktspace/', import.meta.url));
const { generateTangents } = require('mikktspace');

function uvSphere(rings, segments) {  // fixtures::uvSphere, in float32 as the C++ mesh holds it
  const p = [], uv = [], idx = [];
  for (let r = 0; r <= rings; r++)
    for (let s = 0; s <= segments; s++) {
      const th = Math.PI * r / rings, ph = 2 * Math.PI * s / segments;
      const st = r === 0 || r === rings ? 0 : Math.sin(th);
      p.push(st * Math.cos(ph), Math.cos(th), st * Math.sin(ph));
      uv.push(s / segments, 1 - r / rings);
    }
  const row = segments + 1;
  for (let r = 0; r < rings; r++)
    for (let s = 0; s < segments; s++) {
      const a = r * row + s, b = a + row;
      if (r > 0) idx.push(a, a + 1, b);
      if (r + 1 < rings) idx.push(a + 1, b + 1, b);
    }
  const P = new Float32Array(idx.length * 3), N = new Float32Array(idx.length * 3), T = new Float32Array(idx.length * 2);
  idx.forEach((v, c) => {
    for (let k = 0; k < 3; k++) P[3 * c + k] = N[3 * c + k] = p[3 * v + k];
    T[2 * c] = uv[2 * v]; T[2 * c + 1] = uv[2 * v + 1];
  });
  return { P, N, T, triangles: idx.length / 3 };
}

const runs = Number(process.argv[2] || 7);
const { P, N, T, triangles } = uvSphere(200, 250);
generateTangents(P, N, T);  // warm-up: WebAssembly compilation
const times = [];
for (let i = 0; i < runs; i++) {
  const t0 = process.hrtime.bigint();
  generateTangents(P, N, T);
  times.push(Number(process.hrtime.bigint() - t0) / 1e6);
}
const sorted = [...times].sort((a, b) => a - b);
console.log(JSON.stringify({ peer: 'npm mikktspace 1.1.1 (WebAssembly, 1 thread)', triangles,
                             ms: sorted[Math.floor(runs / 2)], runs: times.map((t) => +t.toFixed(2)) }));
