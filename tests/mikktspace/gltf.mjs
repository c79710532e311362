// /v1/tangents on binary glTF, checked by the Khronos glTF validator (npm gltf-validator) and
// the MikkTSpace oracle (npm mikktspace):
//   - every GLB the service writes has 0 errors and 0 warnings, no unused accessor or buffer
//     view the input did not have, and no bytes nothing reads: the binary chunk is compacted
//     after vertex splits;
//   - tangents follow the UV set the material's normal texture names (texCoord 1 here): every
//     corner against MikkTSpace run on that set (w negated: glTF's UV origin is top-left);
//   - a TANGENT the input already has is kept unless ?overwrite=true, and X-Tangents says which;
//   - /v1/bubble's GLB passes too, and its mesh's tangent w follows /v1/tangents' convention.
// Models: Debian's assimp-testmodels (GLB, and .gltf packed into GLB here) and generated ones.
// usage: node gltf.mjs <base-url>
import fs from 'node:fs';
import path from 'node:path';
import { generateTangents } from 'mikktspace';
import validator from 'gltf-validator';
import { check, results } from '../node/effectd.mjs';

const base = process.argv[2];

// ---- GLB in and out ---------------------------------------------------------------------------
function parseGlb(bytes) {
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const jsonLength = dv.getUint32(12, true);
  const doc = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
  const binStart = 20 + jsonLength;
  const bin = binStart < bytes.length ? bytes.subarray(binStart + 8, binStart + 8 + dv.getUint32(binStart, true)) : new Uint8Array();
  return { doc, bin };
}
function buildGlb(doc, bin) {
  const pad = (n) => (4 - (n % 4)) % 4;
  let text = JSON.stringify(doc);
  text += ' '.repeat(pad(Buffer.byteLength(text)));
  const json = Buffer.from(text);
  const binPadded = Buffer.concat([Buffer.from(bin), Buffer.alloc(pad(bin.length))]);
  const header = Buffer.alloc(12), jh = Buffer.alloc(8), bh = Buffer.alloc(8);
  const total = 12 + 8 + json.length + (bin.length ? 8 + binPadded.length : 0);
  header.write('glTF', 0); header.writeUInt32LE(2, 4); header.writeUInt32LE(total, 8);
  jh.writeUInt32LE(json.length, 0); jh.write('JSON', 4);
  bh.writeUInt32LE(binPadded.length, 0); bh.write('BIN\0', 4);
  return new Uint8Array(Buffer.concat(bin.length ? [header, jh, json, bh, binPadded] : [header, jh, json]));
}
// A .gltf with external buffers and images as one GLB: every file becomes a buffer view.
function packGltf(file) {
  const doc = JSON.parse(fs.readFileSync(file, 'utf8'));
  const dir = path.dirname(file);
  const parts = [];
  let offset = 0;
  const add = (bytes) => {
    const start = offset;
    parts.push(bytes, Buffer.alloc((4 - (bytes.length % 4)) % 4));
    offset += bytes.length + ((4 - (bytes.length % 4)) % 4);
    return start;
  };
  const bufferStart = (doc.buffers || []).map((b) => add(fs.readFileSync(path.join(dir, decodeURIComponent(b.uri)))));
  for (const v of doc.bufferViews || []) { v.byteOffset = (v.byteOffset || 0) + bufferStart[v.buffer]; v.buffer = 0; }
  for (const img of doc.images || []) {
    if (!img.uri) continue;
    const bytes = fs.readFileSync(path.join(dir, decodeURIComponent(img.uri)));
    doc.bufferViews.push({ buffer: 0, byteOffset: add(bytes), byteLength: bytes.length });
    img.bufferView = doc.bufferViews.length - 1;
    img.mimeType = img.uri.endsWith('.png') ? 'image/png' : 'image/jpeg';
    delete img.uri;
  }
  const bin = Buffer.concat(parts);
  doc.buffers = [{ byteLength: bin.length }];
  return buildGlb(doc, bin);
}
const kComponents = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };
const kTypes = { 5121: Uint8Array, 5123: Uint16Array, 5125: Uint32Array, 5126: Float32Array };
function readAccessor({ doc, bin }, index) {
  const a = doc.accessors[index], v = doc.bufferViews[a.bufferView], T = kTypes[a.componentType];
  const n = kComponents[a.type], stride = v.byteStride || n * T.BYTES_PER_ELEMENT;
  const out = new Float64Array(a.count * n), dv = new DataView(bin.buffer, bin.byteOffset + (v.byteOffset || 0) + (a.byteOffset || 0));
  const get = { 5121: (o) => dv.getUint8(o), 5123: (o) => dv.getUint16(o, true), 5125: (o) => dv.getUint32(o, true), 5126: (o) => dv.getFloat32(o, true) }[a.componentType];
  for (let i = 0; i < a.count; i++) for (let c = 0; c < n; c++) out[i * n + c] = get(i * stride + c * T.BYTES_PER_ELEMENT);
  return out;
}

// ---- generated models ----------------------------------------------------------------------
// A wavy grid with analytic normals; TEXCOORD_0 = (u, v), TEXCOORD_1 = (v, u): the two sets'
// tangents are 90 degrees apart with opposite handedness, so using the wrong one cannot pass.
function grid(n, { normalTexCoord = 1, tangents = false } = {}) {
  const P = [], N = [], UV0 = [], UV1 = [], I = [], TAN = [];
  for (let j = 0; j <= n; j++) for (let i = 0; i <= n; i++) {
    const x = i / n, y = j / n, h = 0.1 * Math.sin(6 * x) * Math.cos(5 * y);
    const dx = 0.6 * Math.cos(6 * x) * Math.cos(5 * y), dy = -0.5 * Math.sin(6 * x) * Math.sin(5 * y), l = Math.hypot(dx, dy, 1);
    P.push(x, y, h); N.push(-dx / l, -dy / l, 1 / l); UV0.push(x, y); UV1.push(y, x); TAN.push(0, 0, 1, 1);
  }
  for (let j = 0; j < n; j++) for (let i = 0; i < n; i++) {
    const a = j * (n + 1) + i;
    I.push(a, a + 1, a + n + 2, a, a + n + 2, a + n + 1);
  }
  const png = fs.readFileSync('/usr/share/assimp/models/glTF2/ClearCoat-glTF/RibsNormal.png');
  const chunks = [], views = [], accessors = [];
  let offset = 0;
  const view = (bytes, target) => {
    chunks.push(Buffer.from(bytes.buffer, bytes.byteOffset, bytes.byteLength), Buffer.alloc((4 - (bytes.byteLength % 4)) % 4));
    views.push({ buffer: 0, byteOffset: offset, byteLength: bytes.byteLength, ...(target ? { target } : {}) });
    offset += bytes.byteLength + ((4 - (bytes.byteLength % 4)) % 4);
    return views.length - 1;
  };
  const floats = (data, type) => {
    const f = new Float32Array(data), n = kComponents[type];
    const acc = { bufferView: view(f, 34962), componentType: 5126, count: f.length / n, type };
    if (type === 'VEC3') {
      acc.min = [0, 1, 2].map((c) => Math.min(...f.filter((_, k) => k % 3 === c)));
      acc.max = [0, 1, 2].map((c) => Math.max(...f.filter((_, k) => k % 3 === c)));
    }
    accessors.push(acc);
    return accessors.length - 1;
  };
  const attributes = { POSITION: floats(P, 'VEC3'), NORMAL: floats(N, 'VEC3'), TEXCOORD_0: floats(UV0, 'VEC2'), TEXCOORD_1: floats(UV1, 'VEC2') };
  if (tangents) attributes.TANGENT = floats(TAN, 'VEC4');
  const ind = new Uint32Array(I);
  accessors.push({ bufferView: view(ind, 34963), componentType: 5125, count: ind.length, type: 'SCALAR' });
  const image = view(png);
  const bin = Buffer.concat(chunks);
  const doc = {
    asset: { version: '2.0', generator: 'effectd tests/mikktspace/gltf.mjs' },
    scene: 0, scenes: [{ nodes: [0] }], nodes: [{ mesh: 0 }],
    meshes: [{ primitives: [{ attributes, indices: accessors.length - 1, material: 0 }] }],
    materials: [{ normalTexture: { index: 0, texCoord: normalTexCoord } }],
    textures: [{ source: 0, sampler: 0 }], samplers: [{}],
    images: [{ bufferView: image, mimeType: 'image/png' }],
    accessors, bufferViews: views, buffers: [{ byteLength: bin.length }],
  };
  return buildGlb(doc, bin);
}

// ---- checks --------------------------------------------------------------------------------------
async function tangents(glb, query = '') {
  const res = await fetch(`${base}/v1/tangents${query}`, { method: 'POST', headers: { 'Content-Type': 'model/gltf-binary' }, body: glb });
  return { status: res.status, said: res.headers.get('X-Tangents'), bytes: new Uint8Array(await res.arrayBuffer()) };
}
async function issues(bytes) {
  const r = await validator.validateBytes(bytes, { maxIssues: 1000, format: 'glb' });
  const unused = r.issues.messages.filter((m) => m.code === 'UNUSED_OBJECT' && /^\/(accessors|bufferViews)\//.test(m.pointer)).length;
  return { errors: r.issues.numErrors, warnings: r.issues.numWarnings, unused,
           messages: r.issues.messages.filter((m) => m.severity <= 1).slice(0, 5).map((m) => `${m.code} ${m.pointer}`) };
}
// Bytes of the binary chunk that nothing uses: buffer views no used accessor or image reads.
function unusedBytes(bytes) {
  const { doc, bin } = parseGlb(bytes);
  const accessors = new Set();
  for (const m of doc.meshes || []) for (const p of m.primitives) {
    Object.values(p.attributes).forEach((a) => accessors.add(a));
    if (p.indices !== undefined) accessors.add(p.indices);
    for (const t of p.targets || []) Object.values(t).forEach((a) => accessors.add(a));
  }
  for (const s of doc.skins || []) if (s.inverseBindMatrices !== undefined) accessors.add(s.inverseBindMatrices);
  for (const a of doc.animations || []) for (const s of a.samplers) { accessors.add(s.input); accessors.add(s.output); }
  const views = new Set((doc.images || []).filter((i) => i.bufferView !== undefined).map((i) => i.bufferView));
  for (const i of accessors) {
    const a = doc.accessors[i];
    if (a.bufferView !== undefined) views.add(a.bufferView);
    if (a.sparse) { views.add(a.sparse.indices.bufferView); views.add(a.sparse.values.bufferView); }
  }
  let used = 0;
  for (const v of views) used += doc.bufferViews[v].byteLength + 3;  // up to 3 bytes of alignment each
  return Math.max(0, bin.length - used);
}
async function written(name, glb, query = '') {
  const out = await tangents(glb, query);
  if (!check(out.status === 200, `${name}: 200`, new TextDecoder().decode(out.bytes.subarray(0, 300)))) return undefined;
  const before = await issues(glb), after = await issues(out.bytes);
  check(after.errors === 0 && after.warnings === 0, `${name}: validator finds 0 errors, 0 warnings in the answer`, after.messages);
  check(after.unused <= before.unused, `${name}: no unused accessor or buffer view added (${before.unused} before, ${after.unused} after)`);
  const waste = unusedBytes(out.bytes);
  check(waste <= unusedBytes(glb), `${name}: compact, ${glb.length} -> ${out.bytes.length} bytes, ${waste} unused`);
  return out;
}

const models = [
  ['BoxTextured.glb', fs.readFileSync('/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb')],
  ['BoxTextured.gltf', packGltf('/usr/share/assimp/models/glTF2/BoxTextured-glTF/BoxTextured.gltf')],
  ['ClearCoatTest.gltf', packGltf('/usr/share/assimp/models/glTF2/ClearCoat-glTF/ClearCoatTest.gltf')],
];
for (const [name, glb] of models) await written(name, new Uint8Array(glb));

// The normal texture's UV set.
{
  const input = grid(12, { normalTexCoord: 1 });
  const out = await written('two UV sets, normalTexture.texCoord 1', input);
  if (out) {
    const g = parseGlb(out.bytes), prim = g.doc.meshes[0].primitives[0];
    const idx = readAccessor(g, prim.indices), tan = readAccessor(g, prim.attributes.TANGENT);
    const pos = readAccessor(g, prim.attributes.POSITION), nrm = readAccessor(g, prim.attributes.NORMAL), uv1 = readAccessor(g, prim.attributes.TEXCOORD_1);
    const c = idx.length, P = new Float32Array(3 * c), N = new Float32Array(3 * c), T = new Float32Array(2 * c);
    for (let k = 0; k < c; k++) {
      for (let d = 0; d < 3; d++) { P[3 * k + d] = pos[3 * idx[k] + d]; N[3 * k + d] = nrm[3 * idx[k] + d]; }
      T[2 * k] = uv1[2 * idx[k]]; T[2 * k + 1] = uv1[2 * idx[k] + 1];
    }
    const ref = generateTangents(P, N, T);
    let ok = 0, worst = 0;
    for (let k = 0; k < c; k++) {
      const a = tan.slice(4 * idx[k], 4 * idx[k] + 4), b = ref.slice(4 * k, 4 * k + 4);
      const deg = Math.acos(Math.max(-1, Math.min(1, (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / Math.hypot(b[0], b[1], b[2])))) * 180 / Math.PI;
      worst = Math.max(worst, deg);
      if (deg <= 0.1 && a[3] === -b[3]) ok++;
    }
    check(ok === c, `two UV sets: ${ok}/${c} corners match MikkTSpace on TEXCOORD_1 within 0.1 deg (worst ${worst.toFixed(3)} deg)`);
  }
}

// An existing TANGENT: kept, or replaced when asked.
{
  const input = grid(6, { tangents: true });
  const given = (() => { const g = parseGlb(input); return readAccessor(g, g.doc.meshes[0].primitives[0].attributes.TANGENT); })();
  const tangentOf = (bytes) => { const g = parseGlb(bytes); return readAccessor(g, g.doc.meshes[0].primitives[0].attributes.TANGENT); };
  const kept = await written('TANGENT given', input);
  if (kept) {
    check(tangentOf(kept.bytes).every((v, i) => v === given[i]), 'TANGENT given: kept as it was');
    check(/kept 1/.test(kept.said || ''), 'TANGENT given: X-Tangents says kept', kept.said);
  }
  const replaced = await written('TANGENT given, ?overwrite=true', input, '?overwrite=true');
  if (replaced) {
    check(!tangentOf(replaced.bytes).every((v, i) => v === given[i]), 'TANGENT given, ?overwrite=true: replaced');
    check(/generated 1/.test(replaced.said || ''), 'TANGENT given, ?overwrite=true: X-Tangents says generated', replaced.said);
  }
}

// The bubble: as a whole GLB (the paper model with and without iridescence; the film model
// with its thickness texture), and its mesh frames with /v1/tangents' convention.
for (const [name, request, iridescent, texture] of [
  ['paper, iridescence true', { shading: 'paper', features: { iridescence: true } }, true, false],
  ['paper, iridescence false', { shading: 'paper', features: { iridescence: false } }, false, false],
  ['film with thickness texture', {}, true, true],
]) {
  const res = await fetch(`${base}/v1/bubble`, { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                                 body: JSON.stringify({ format: 'glb', time: 2, mesh: { level: 3 }, ...request }) });
  const bytes = new Uint8Array(await res.arrayBuffer());
  if (!check(res.status === 200 && res.headers.get('Content-Type') === 'model/gltf-binary', `bubble GLB (${name}): 200 model/gltf-binary`, res.status)) continue;
  const v = await issues(bytes);
  check(v.errors === 0 && v.warnings === 0, `bubble GLB (${name}): validator finds 0 errors, 0 warnings`, v.messages);
  const { doc } = parseGlb(bytes);
  const ext = doc.materials[0].extensions.KHR_materials_iridescence;
  check(Boolean(ext) === iridescent, `bubble GLB (${name}): iridescence extension present exactly when on`);
  check(Boolean(ext && ext.iridescenceThicknessTexture) === texture && (!texture || (doc.images || []).length === 1),
        `bubble GLB (${name}): thickness texture ${texture ? 'embedded as a PNG' : 'absent'}`);
}
{
  const post = async (route, body) => (await fetch(`${base}${route}`, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) })).json();
  const bubble = await post('/v1/bubble', { mesh: { level: 2 }, features: { wobble: false }, uvOrigin: 'top-left', include: ['mesh'] });
  const m = bubble.mesh;
  const tangentsOf = await post('/v1/tangents', { mesh: { positions: m.positions, normals: m.normals, uvs: m.uvs, indices: m.indices },
                                                  uvOrigin: 'top-left', include: ['tangents', 'remap'] });
  let same = 0;
  for (let v = 0; v < m.vertexCount; v++) if (Math.sign(m.tangents[4 * v + 3]) === Math.sign(tangentsOf.tangents[4 * v + 3])) same++;
  check(same === m.vertexCount, `bubble mesh (uvOrigin top-left): tangent w as /v1/tangents gives it on ${same}/${m.vertexCount} vertices`);
}

// The bolt as ribbons (/v1/lightning format glb): valid, and the same triangles as its JSON
// mesh form (include mesh), attribute for attribute.
for (const [name, request] of [
  ['2-D with timeline', { grid: { width: 64, height: 64 }, start: [32, 1], targets: [[20, 62]], include: ['timeline'] }],
  ['3-D in world units', { grid: { width: 24, height: 24, depth: 24 }, start: [12, 1, 12], targets: [[12, 22, 12]],
                           world: { origin: [-3, 6, 3], cellSize: 0.25 } }],
  ['no branches', { grid: { width: 8, height: 8 }, start: [4, 0], targets: [[4, 1]] }],
]) {
  const send = (body) => fetch(`${base}/v1/lightning`, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
  const res = await send({ ...request, format: 'glb' });
  const bytes = new Uint8Array(await res.arrayBuffer());
  if (!check(res.status === 200 && res.headers.get('Content-Type') === 'model/gltf-binary', `bolt GLB (${name}): 200 model/gltf-binary`, res.status)) continue;
  const v = await issues(bytes);
  check(v.errors === 0 && v.warnings === 0, `bolt GLB (${name}): validator finds 0 errors, 0 warnings`, v.messages);
  const { doc, bin } = parseGlb(bytes);
  const mesh = (await (await send({ ...request, include: [...(request.include || []), 'mesh'] })).json()).mesh;
  const read = (accessor) => {
    const a = doc.accessors[accessor], view = doc.bufferViews[a.bufferView];
    const n = a.count * { SCALAR: 1, VEC2: 2, VEC3: 3 }[a.type];
    const at = bin.byteOffset + (view.byteOffset || 0) + (a.byteOffset || 0);
    const Type = { 5126: Float32Array, 5123: Uint16Array, 5125: Uint32Array }[a.componentType];
    return Array.from(new Type(bin.buffer.slice(at, at + n * Type.BYTES_PER_ELEMENT)));
  };
  const same = (x, y) => x.length === y.length && x.every((e, i) => e === Math.fround(y[i]));  // JSON: shortest float32 form
  check(doc.meshes.length === mesh.primitives.length, `bolt GLB (${name}): ${doc.meshes.length} meshes, one per JSON primitive`);
  mesh.primitives.forEach((p, k) => {
    const g = doc.meshes[k].primitives[0];
    const colour = read(g.attributes.COLOR_0).filter((_, i) => i % 3 === 0);
    check(doc.meshes[k].name === (p.channel === 'main' ? 'main' : 'branches') && same(read(g.attributes.POSITION), p.positions) &&
          same(read(g.attributes.TEXCOORD_0), p.uvs) && same(colour, p.intensity) && same(read(g.indices), p.indices) &&
          (!p.leader || (same(read(g.attributes._LEADER), p.leader) && same(read(g.attributes._STROKE_DELAY), p.strokeDelay))),
          `bolt GLB (${name}): ${p.channel} is the JSON mesh's geometry (${p.positions.length / 3} vertices)`);
  });
  if (request.include) check(doc.scenes[0].extras.timeline.keyframes.t.length > 1, `bolt GLB (${name}): the timeline's keyframes in the scene's extras`);
}

console.log(results.failures ? `${results.failures} glTF check(s) failed` : 'glTF checks passed');
process.exit(results.failures ? 1 : 0);
