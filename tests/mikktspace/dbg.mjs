// /v1/tangents against an independent MikkTSpace: the npm package `mikktspace` (the reference
// mikktspace.c, via the Rust port, compiled to WebAssembly). For each mesh, every corner's
// tangent from the service (tangents[indices[c]]) is compared with the oracle's tangent for
// that corner of the de-indexed mesh: >= 99.9 % of corners within 0.1 degrees, same handedness.
// Where the reference has no frame (no UV-valid triangle at the vertex) it writes the
// placeholder (1, 0, 0, -1), which is not orthogonal to the normal; there the service must
// write that placeholder projected into the normal's plane (effects/tangents.h). Such corners
// are counted apart, and every one of them must hold the projected placeholder.
//
// usage: node oracle.mjs <base-url> [obj files...]
import { readFileSync } from 'node:fs';
import { generateTangents } from 'mikktspace';

const base = process.argv[2];
const objFiles = process.argv.slice(3);

// seam at u = 0/1 (duplicated column), poles per segment. With `poleSlivers` every band keeps
// both triangles: at the poles one of them joins two pole vertices sin(pi) ~ 1.2e-16 apart, a
// triangle of area ~1e-16 that is not degenerate to MikkTSpace (its corners differ).
function uvSphere(rings, segments, poleSlivers = false) {
  const p = [], n = [], uv = [], idx = [];
  for (let r = 0; r <= rings; r++) {
    const th = Math.PI * r / rings;
    for (let s = 0; s <= segments; s++) {
      const ph = 2 * Math.PI * s / segments;
      const x = Math.sin(th) * Math.cos(ph), y = Math.cos(th), z = Math.sin(th) * Math.sin(ph);
      p.push(x, y, z); n.push(x, y, z); uv.push(s / segments, 1 - r / rings);
    }
  }
  const row = segments + 1;
  for (let r = 0; r < rings; r++)
    for (let s = 0; s < segments; s++) {
      const a = r * row + s, b = a + row;
      if (r > 0 || poleSlivers) idx.push(a, a + 1, b);
      if (r < rings - 1 || poleSlivers) idx.push(a + 1, b + 1, b);
    }
  return { name: poleSlivers ? 'uv sphere with 1e-16-area pole triangles' : 'uv sphere with seam', positions: p, normals: n,
           uvs: uv, indices: idx };
}

function torus(R, r, nu, nv) {  // seams in both directions
  const p = [], n = [], uv = [], idx = [];
  for (let i = 0; i <= nu; i++) {
    const u = 2 * Math.PI * i / nu;
    for (let j = 0; j <= nv; j++) {
      const v = 2 * Math.PI * j / nv;
      const cx = Math.cos(u), cz = Math.sin(u);
      p.push((R + r * Math.cos(v)) * cx, r * Math.sin(v), (R + r * Math.cos(v)) * cz);
      n.push(Math.cos(v) * cx, Math.sin(v), Math.cos(v) * cz);
      uv.push(i / nu * 3, j / nv);
    }
  }
  const row = nv + 1;
  for (let i = 0; i < nu; i++)
    for (let j = 0; j < nv; j++) {
      const a = i * row + j, b = a + row;
      idx.push(a, b, a + 1, a + 1, b, b + 1);
    }
  return { name: 'torus', positions: p, normals: n, uvs: uv, indices: idx };
}

// A wavy sheet whose left half mirrors the right half's UV island (u = |x|), shared centre
// column: handedness flips across the mirror line. Normals are left to the service.
function mirrored(nx, ny) {
  const p = [], uv = [], idx = [];
  for (let j = 0; j <= ny; j++)
    for (let i = 0; i <= nx; i++) {
      const x = 2 * i / nx - 1, y = j / ny;
      p.push(x, y, 0.2 * Math.sin(3 * x) * Math.cos(2 * y));
      uv.push(Math.abs(x), y);
    }
  const row = nx + 1;
  for (let j = 0; j < ny; j++)
    for (let i = 0; i < nx; i++) {
      const a = j * row + i;
      idx.push(a, a + 1, a + row, a + 1, a + row + 1, a + row);
    }
  return { name: 'mirrored UV islands', positions: p, uvs: uv, indices: idx };
}

// Wavefront OBJ: every distinct v/vt/vn triple is a vertex; polygons are fanned.
function obj(path) {
  const v = [], vt = [], vn = [], p = [], n = [], uv = [], idx = [], seen = new Map();
  for (const line of readFileSync(path, 'utf8').split(/\r?\n/)) {
    const f = line.trim().split(/\s+/);
    if (f[0] === 'v') v.push(f.slice(1, 4).map(Number));
    else if (f[0] === 'vt') vt.push(f.slice(1, 3).map(Number));
    else if (f[0] === 'vn') vn.push(f.slice(1, 4).map(Number));
    else if (f[0] === 'f') {
      const corners = f.slice(1).map((c) => {
        if (!seen.has(c)) {
          const [a, b, d] = c.split('/').map((s) => (s ? Number(s) - 1 : -1));
          seen.set(c, p.length / 3);
          p.push(...v[a]); uv.push(...(b >= 0 ? vt[b] : [0, 0])); n.push(...(d >= 0 ? vn[d] : [0, 0, 1]));
        }
        return seen.get(c);
      });
      for (let k = 1; k + 1 < corners.length; k++) idx.push(corners[0], corners[k], corners[k + 1]);
    }
  }
  return { name: path.split('/').pop(), positions: p, normals: n, uvs: uv, indices: idx };
}

async function service(mesh) {
  const body = { mesh: { positions: mesh.positions, uvs: mesh.uvs, indices: mesh.indices }, include: ['tangents', 'indices', 'normals'] };
  if (mesh.normals) body.mesh.normals = mesh.normals;
  const res = await fetch(`${base}/v1/tangents`, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
  if (res.status !== 200) throw new Error(`${mesh.name}: HTTP ${res.status} ${await res.text()}`);
  return res.json();
}

const meshes = [uvSphere(24, 48), uvSphere(24, 48, true), torus(1, 0.35, 48, 24), mirrored(40, 20), ...objFiles.map(obj)];
let failed = false;
for (const mesh of meshes) {
  const out = await service(mesh);
  const corners = mesh.indices.length;
  const P = new Float32Array(corners * 3), N = new Float32Array(corners * 3), T = new Float32Array(corners * 2);
  for (let c = 0; c < corners; c++) {
    const v = mesh.indices[c], o = out.indices[c];
    for (let k = 0; k < 3; k++) {
      P[3 * c + k] = mesh.positions[3 * v + k];
      N[3 * c + k] = out.normals[3 * o + k];  // the normals the service used (given ones, normalised)
    }
    T[2 * c] = mesh.uvs[2 * v]; T[2 * c + 1] = mesh.uvs[2 * v + 1];
  }
  const ref = generateTangents(P, N, T);
  let ok = 0, worst = 0, flips = 0, placeholders = 0, placeholderOk = 0;
  for (let c = 0; c < corners; c++) {
    const o = out.indices[c];
    const a = out.tangents.slice(4 * o, 4 * o + 4), b = ref.slice(4 * c, 4 * c + 4);
    if (b[0] === 1 && b[1] === 0 && b[2] === 0 && b[3] === -1) {
      placeholders++;
      const n = out.normals.slice(3 * o, 3 * o + 3);
      const x = [1 - n[0] * n[0], -n[0] * n[1], -n[0] * n[2]], l = Math.hypot(...x);
      if (l > 1e-3 && a[3] === -1 && Math.abs(a[0] - x[0] / l) + Math.abs(a[1] - x[1] / l) + Math.abs(a[2] - x[2] / l) < 1e-4) placeholderOk++;
      continue;
    }
    const dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const lb = Math.hypot(b[0], b[1], b[2]);
    const deg = Math.acos(Math.max(-1, Math.min(1, dot / lb))) * 180 / Math.PI;
    worst = Math.max(worst, deg);
    if (a[3] !== b[3]) flips++;
    if (deg <= 0.1 && a[3] === b[3]) ok++; else if (process.env.DEBUG && mesh.name.includes("pole")) console.log(c, mesh.indices[c], Math.floor(mesh.indices[c] / 49), mesh.indices[c] % 49, deg.toFixed(2), Array.from(a).map(x=>x.toFixed(4)).join(","), Array.from(b).map(x=>x.toFixed(4)).join(","));
  }
  const defined = corners - placeholders;
  const share = defined ? ok / defined : 1;
  const pass = share >= 0.999 && placeholderOk === placeholders;
  failed ||= !pass;
  console.log(`${pass ? 'ok  ' : 'FAIL'} ${mesh.name}: ${corners} corners, ${out.vertexCount} output vertices ` +
              `(${mesh.positions.length / 3} in), ${(100 * share).toFixed(3)} % of ${defined} defined corners ` +
              `within 0.1 deg and same w, max ${worst.toFixed(4)} deg, ${flips} handedness differences; ` +
              `${placeholderOk}/${placeholders} reference placeholders projected`);
}
process.exit(failed ? 1 : 0);
