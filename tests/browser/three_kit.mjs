// The three.js kit (clients/three/effectd-three.js) in headless chromium with npm three: each
// effect drawn through the kit from the service's answers, the pixels compared with effectd's
// /v1/render preview of the same scene.
//   - bolt: the GLB (boltFromGltf) and the JSON mesh (boltFromAnswer) draw the same frame; its
//     lit pixels match the preview's core within a pixel; with a timeline, setTime() plays the
//     strike: dark before the leader, the main channel lit at the first stroke, dark after it ends;
//   - bubble: the film and the paper model from the answer's GLSL, uniforms and textures under a
//     cube map of effectd's sky, drawn into a half-float target as an HDR engine does (the
//     paper's rim exceeds 1 before blending): mean and 99th percentile of the largest channel
//     difference;
//   - fog: the preview's quads as MeshBasicMaterial fogged by applyFog from the table: mean
//     difference over the frame;
//   - tangents: /v1/tangents' GLB in GLTFLoader carries its TANGENT as three's `tangent`.
// Usage: node three_kit.mjs EFFECTD_BINARY [CHROMIUM]
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { launchWebGl2Chromium, openLoggedPage } from './chromium.mjs';
import { servePages } from './page_server.mjs';
import { check, results, startEffectd } from '../node/effectd.mjs';

const [binary, chromium = '/usr/bin/chromium'] = process.argv.slice(2);
const kit = path.join(path.dirname(fileURLToPath(import.meta.url)), '../../clients/three/effectd-three.js');
const { origin, close: closePages } = await servePages('effectd three.js kit', ['gl', 'png'], { '/effectd-three.js': kit });
const { url: api, process: server } = await startEffectd(binary, ['--cors-origins', origin]);

const browser = await launchWebGl2Chromium(chromium);
try {
  const page = await openLoggedPage(browser, `${origin}/`);
  const r = await page.evaluate(async (api) => {
    const THREE = await import('three');
    const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
    const kit = await import('/effectd-three.js');
    const { foundWithinAPixel, litMask, readTopDown, skyCubeFaces } = await import('/page_helpers.mjs');
    const size = 128, out = { pictures: {} };
    const post = (route, body) => fetch(`${api}${route}`, { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                                            body: JSON.stringify(body) });
    const canvas = document.getElementById('gl');
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
    renderer.setSize(size, size, false);
    renderer.setPixelRatio(1);
    const frame = (scene, camera) => {  // RGBA rows from the top
      renderer.render(scene, camera);
      return readTopDown(renderer.getContext(), size);
    };
    const preview = async (scene) => {
      const res = await post('/v1/render', { width: size, height: size, ...scene });
      const c = document.getElementById('png');
      c.width = c.height = size;
      const ctx = c.getContext('2d');
      ctx.drawImage(await createImageBitmap(await res.blob()), 0, 0);
      return ctx.getImageData(0, 0, size, size).data;
    };
    // Largest channel difference over the pixels where the preview differs from `backdrop` (all
    // pixels without one): mean, 99th percentile, count.
    const compare = (a, b, backdrop) => {
      const d = [];
      for (let i = 0; i < a.length; i += 4) {
        if (backdrop && Math.max(...[0, 1, 2].map((k) => Math.abs(b[i + k] - Math.round(backdrop[k] * 255)))) <= 2) continue;
        d.push(Math.max(...[0, 1, 2].map((k) => Math.abs(a[i + k] - b[i + k]))));
      }
      d.sort((x, y) => x - y);
      return { pixels: d.length, mean: d.reduce((s, x) => s + x, 0) / Math.max(d.length, 1), p99: d[Math.floor(0.99 * (d.length - 1))] };
    };
    // An HDR frame, as an engine drawing into a float target (the bubble's colours exceed 1 before
    // blending, as in the preview's RGBA16F frame), to 8 bits as the preview's PNG.
    const target = new THREE.WebGLRenderTarget(size, size, { type: THREE.HalfFloatType });
    const hdrFrame = (scene, camera) => {
      renderer.setRenderTarget(target);
      renderer.render(scene, camera);
      const half = new Uint16Array(size * size * 4), top = new Uint8Array(size * size * 4);
      renderer.readRenderTargetPixels(target, 0, 0, size, size, half);
      renderer.setRenderTarget(null);
      for (let y = 0; y < size; ++y)
        for (let i = 0; i < size * 4; ++i)
          top[y * size * 4 + i] = Math.round(255 * Math.min(Math.max(THREE.DataUtils.fromHalfFloat(half[(size - 1 - y) * size * 4 + i]), 0), 1));
      return top;
    };
    const dark = [0.02, 0.02, 0.03];
    const background = (c) => new THREE.Color().setRGB(...c, THREE.SRGBColorSpace);  // the preview's display value

    // ---- bolt ----
    const bolt = { grid: { width: 64, height: 64 }, start: [32, 1], targets: [[26, 62]], seed: 9 };
    const boltScene = new THREE.Scene();
    boltScene.background = background(dark);
    const flatCamera = new THREE.OrthographicCamera(0, 64, 0, -64, -10, 10);
    const glb = await post('/v1/lightning', { ...bolt, format: 'glb' });
    const fromGltf = kit.boltFromGltf(await new GLTFLoader().parseAsync(await glb.arrayBuffer(), ''));
    boltScene.add(fromGltf.object);
    const a = frame(boltScene, flatCamera);
    boltScene.remove(fromGltf.object);
    const boltJson = await (await post('/v1/lightning', { ...bolt, include: ['mesh'] })).json();
    const fromJson = kit.boltFromAnswer(boltJson);
    boltScene.add(fromJson.object);
    const b = frame(boltScene, flatCamera);
    boltScene.remove(fromJson.object);
    // The glow 6 times as wide: no lit pixel farther from the core's than about 5 cells (the
    // glow's half width is 6 cells, its Gaussian dims below the lit level past ~5), where mitred
    // joins pushed 6 times outward once made points reaching 8.5.
    const glowing = kit.boltFromAnswer(boltJson, { glow: { width: 6, strength: 1 } });
    boltScene.add(glowing.object);
    const glowLit = litMask(frame(boltScene, flatCamera), size), coreLit = litMask(b, size);
    boltScene.remove(glowing.object);
    const cores = [];
    for (let i = 0; i < size * size; ++i) if (coreLit[i]) cores.push([i % size, Math.floor(i / size)]);
    let farthest = 0;
    for (let i = 0; i < size * size; ++i)
      if (glowLit[i]) {
        const x = i % size, y = Math.floor(i / size);
        farthest = Math.max(farthest, Math.min(...cores.map(([u, v]) => Math.hypot(u - x, v - y))));
      }
    out.glow = { farthestCells: farthest / (size / 64), lit: glowLit.filter(Boolean).length, core: cores.length };
    out.boltSame = compare(a, b, null);
    const p = await preview({ background: { color: [...dark, 1] }, lightning: bolt, lightningStyle: { coreWidth: size / 64, glowSigma: 0 } });
    const lit = (px) => litMask(px, size);
    const mk = lit(a), mp = lit(p);
    out.boltRecall = foundWithinAPixel(mp, mk, size).share, out.boltPrecision = foundWithinAPixel(mk, mp, size).share;
    // The strike through setTime().
    const timed = kit.boltFromGltf(await new GLTFLoader().parseAsync(await (await post('/v1/lightning', { ...bolt, format: 'glb', include: ['timeline'] })).arrayBuffer(), ''));
    boltScene.add(timed.object);
    const litShare = (t) => { timed.setTime(t); return lit(frame(boltScene, flatCamera)).filter(Boolean).length / (size * size); };
    const tl = timed.timeline;
    out.strike = { before: litShare(-1), stroke: litShare(tl.strokes[0].t + 1e-4), after: litShare(tl.duration + 1), whole: mk.filter(Boolean).length / (size * size) };

    // ---- glow through fog ----
    // examples/09's 3-D bolt through GL_EXP fog, no geometry: the glow alone (the frame minus the
    // frame without glow) from apsfGlow with /v1/fog's glow for the camera and the bolt's middle,
    // against the preview's glow alone (glowStrength 1.5 minus 0). Its total light and the radius
    // that holds half of it.
    {
      const lightning = { grid: { width: 64, height: 64, depth: 32 }, world: { origin: [-8, 14, 4], cellSize: 0.25 },
                          start: [12, 0, 28], targets: [[48, 39, 18]], eta: 2, seed: 4 };
      const fogDef = { fog: { fogType: 'GL_EXP', color: [0, 0, 0], density: 0.08 } };
      const eyeG = [4, 4.5, 19], look = [0, 6.5, 0], fovY = 70;
      const boltAnswer = await (await post('/v1/lightning', { ...lightning, include: ['mesh'] })).json();
      const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
      for (const prim of boltAnswer.mesh.primitives)
        for (let i = 0; i < prim.positions.length; ++i) lo[i % 3] = Math.min(lo[i % 3], prim.positions[i]), hi[i % 3] = Math.max(hi[i % 3], prim.positions[i]);
      const middle = lo.map((l, k) => (l + hi[k]) / 2);
      const fogGlow = (await (await post('/v1/fog', { ...fogDef, glow: { camera: eyeG, source: middle }, include: ['glow'] })).json()).glow;
      const glowCamera = new THREE.PerspectiveCamera(fovY, 1, 0.05, 1000);
      glowCamera.position.set(...eyeG);
      glowCamera.lookAt(...look);
      const glowScene = new THREE.Scene();
      glowScene.background = new THREE.Color(0, 0, 0);
      const drawnBolt = kit.boltFromAnswer(boltAnswer);
      glowScene.add(drawnBolt.object);
      const glowPass = kit.apsfGlow(renderer, fogGlow, { radiance: 20 });  // unsaturated: compared per ring
      glowPass.render(glowScene, glowCamera, drawnBolt);
      const kitWith = readTopDown(renderer.getContext(), size);
      drawnBolt.setThrough(fogGlow.direct);
      const kitWithout = frame(glowScene, glowCamera);
      out.pictures['glow-kit'] = (glowPass.render(glowScene, glowCamera, drawnBolt), canvas.toDataURL('image/png'));
      const sceneG = { camera: { position: eyeG, target: look, fovY }, background: { color: [0, 0, 0, 1] }, fog: fogDef, lightning };
      const previewWith = await preview({ ...sceneG, lightningStyle: { glowStrength: 1.5, radiance: 20 } });
      const previewWithout = await preview({ ...sceneG, lightningStyle: { glowStrength: 0, radiance: 20 } });
      const measure = (a, b) => {  // the glow's light (blue channel, 0-255 summed), and its half-light radius
        let total = 0, cx = 0, cy = 0;
        const light = [];
        for (let i = 0; i < size * size; ++i) {
          const v = Math.max(0, a[4 * i + 2] - b[4 * i + 2]);
          light.push(v), total += v, cx += v * (i % size), cy += v * Math.floor(i / size);
        }
        cx /= total, cy /= total;
        const byDistance = light.map((v, i) => [Math.hypot((i % size) - cx, Math.floor(i / size) - cy), v]).sort((x, y) => x[0] - y[0]);
        let sum = 0, radius = 0;
        for (const [d, v] of byDistance) if ((sum += v) >= total / 2) { radius = d; break; }
        const rings = Array(8).fill(0), counts = Array(8).fill(0);  // the mean glow in rings 8 px wide
        for (const [d, v] of byDistance) if (d < 64) rings[Math.floor(d / 8)] += v, counts[Math.floor(d / 8)] += 1;
        return { total, radius, cx, cy, rings: rings.map((x, i) => x / Math.max(counts[i], 1)) };
      };
      out.apsf = { kit: measure(kitWith, kitWithout), preview: measure(previewWith, previewWithout), T: fogGlow.opticalThickness,
                   gaussians: fogGlow.gaussians.length };
      glowPass.dispose(), drawnBolt.dispose();
    }

    // ---- bubble ----
    const sky = { zenith: [0.35, 0.6, 1.0], horizon: [1.0, 0.98, 0.95], ground: [0.16, 0.18, 0.12] };
    const faces = skyCubeFaces(sky, 128).map((px) => Object.assign(new THREE.DataTexture(px, 128, 128, THREE.RGBAFormat, THREE.FloatType), { needsUpdate: true }));
    const environment = new THREE.CubeTexture(faces);
    Object.assign(environment, { format: THREE.RGBAFormat, type: THREE.FloatType, generateMipmaps: false,
                                 magFilter: THREE.LinearFilter, minFilter: THREE.LinearFilter, needsUpdate: true });
    const eye = [0, 0.3, 4], backdrop = [0.1, 0.12, 0.1];
    const camera = new THREE.PerspectiveCamera(45, 1, 0.05, 1000);
    camera.position.set(...eye);
    camera.lookAt(0, 0, 0);
    out.bubble = {};
    for (const [name, request] of [
      ['film', { mesh: { level: 4 }, features: { wobble: false }, time: 3 }],
      ['paper', { shading: 'paper', mesh: { level: 4 }, features: { wobble: false, textureFlow: false, iridescence: true }, time: 3 }],
      // The mesh at rest, the shader wobbles it: one wobble, as the preview draws it (not two).
      ['film, wobbling', { mesh: { level: 4 }, params: { wobbleAmplitude: 0.12 }, time: 3 }],
      // Without back faces the answer draws the near side only: so must the kit.
      ['film, front faces only', { mesh: { level: 4 }, features: { wobble: false, backFace: false }, time: 3 }],
    ]) {
      const film = name.startsWith('film');
      const answer = await (await post('/v1/bubble', { ...request, shader: { language: 'glsl-es-300' }, thinFilm: { encoding: 'rgba16f' },
                                                       film: { encoding: 'r32f' },
                                                       include: film ? ['mesh', 'uniforms', 'shader', 'thinFilm', 'thickness'] : ['mesh', 'uniforms', 'shader', 'thinFilm'] })).json();
      const drawn = kit.bubbleFromAnswer(answer, { environment });
      const scene = new THREE.Scene();
      scene.background = new THREE.Color(...backdrop);  // a render target holds the values as given
      scene.add(drawn.object);
      const got = hdrFrame(scene, camera);
      const want = await preview({ time: 3, camera: { position: eye, target: [0, 0, 0], fovY: 45 }, background: { color: [...backdrop, 1] },
                                   environment: sky, bubble: request });
      out.bubble[name] = compare(got, want, backdrop);
      // The silhouettes: pixels off the backdrop in one frame and not the other, over those in either.
      const off = (px, i) => Math.max(...[0, 1, 2].map((k) => Math.abs(px[i + k] - Math.round(backdrop[k] * 255)))) > 2;
      let either = 0, one = 0;
      for (let i = 0; i < got.length; i += 4) { const a = off(got, i), b = off(want, i); either += a || b; one += a !== b; }
      out.bubble[name].silhouette = one / either;
      drawn.dispose();
    }

    // ---- fog ----
    const quads = [
      { center: [0, 0, -20], normal: [0, 1, 0], up: [0, 0, -1], size: [8, 60], color: [0.35, 0.3, 0.25] },
      { center: [-4, 2, -20], normal: [1, 0, 0], size: [60, 4], up: [0, 1, 0], color: [0.6, 0.25, 0.2] },
      { center: [4, 2, -20], normal: [-1, 0, 0], size: [60, 4], up: [0, 1, 0], color: [0.2, 0.35, 0.6] },
      { center: [-1.5, 1.5, -12], size: [1.2, 1.2], color: [0.9, 0.8, 0.2] },
    ];
    // A distance fog in a linear table, and a two-layer height fog in a warped 64 x 32 one.
    out.fog = {};
    for (const [name, fog, table] of [
      ['EXPONENTIAL', { fog: { fogType: 'EXPONENTIAL', color: [0.55, 0.6, 0.68], visibilityRange: 40 } }, { size: 256, range: [0, 80] }],
      ['HEIGHT warped', { fog: { fogType: 'HEIGHT', color: [0.55, 0.6, 0.68], density: 0.08, heightFalloff: 0.5, startDistance: 2,
                                 maxOpacity: 0.95, secondLayer: { density: 0.02, heightFalloff: 0.05 } } },
       { size: 64, cameraHeight: 1.2, layout: 'warped' }],
    ]) {
      const fogAnswer = await (await post('/v1/fog', { ...fog, table: { ...table, encoding: 'rgba16f' } })).json();
      const fogScene = new THREE.Scene();
      fogScene.background = background(fog.fog.color);
      const texture = kit.fogTexture(fogAnswer);
      for (const q of quads) {  // three's plane faces +z with +y up: turned to the quad's normal and up
        const material = kit.applyFog(new THREE.MeshBasicMaterial({ color: background(q.color), side: THREE.DoubleSide }), fogAnswer, texture);
        const m = new THREE.Mesh(new THREE.PlaneGeometry(q.size[0], q.size[1]), material);
        const n = new THREE.Vector3(...(q.normal || [0, 0, 1])).normalize(), up = new THREE.Vector3(...(q.up || [0, 1, 0]));
        up.sub(n.clone().multiplyScalar(up.dot(n))).normalize();
        m.matrixAutoUpdate = false;
        m.matrix.makeBasis(new THREE.Vector3().crossVectors(up, n), up, n).setPosition(...q.center);
        fogScene.add(m);
      }
      const fogCamera = new THREE.PerspectiveCamera(60, 1, 0.05, 1000);
      fogCamera.position.set(0, 1.2, 6);
      fogCamera.lookAt(0, 1, -10);
      out.fog[name] = compare(frame(fogScene, fogCamera),
                              await preview({ camera: { position: [0, 1.2, 6], target: [0, 1, -10], fovY: 60 }, background: { color: fog.fog.color },
                                              quads, fog }), null);
      out.fog[name].maxError = fogAnswer.table.maxError;
      out.pictures[`fog-${name.split(' ')[0].toLowerCase()}`] = canvas.toDataURL('image/png');
    }

    // ---- tangents ----
    // Built with three's own GLTFExporter: a plane with UVs, then through /v1/tangents.
    const { GLTFExporter } = await import('three/addons/exporters/GLTFExporter.js');
    const plane = new THREE.Mesh(new THREE.PlaneGeometry(1, 1, 2, 2), new THREE.MeshStandardMaterial());
    const exported = await new GLTFExporter().parseAsync(plane, { binary: true });
    const tangentsRes = await fetch(`${api}/v1/tangents`, { method: 'POST', headers: { 'Content-Type': 'model/gltf-binary' }, body: exported });
    const withTangents = await new GLTFLoader().parseAsync(await tangentsRes.arrayBuffer(), '');
    let attribute = null;
    withTangents.scene.traverse((o) => { if (o.isMesh) attribute = o.geometry.attributes.tangent; });
    out.tangents = { status: tangentsRes.status, itemSize: attribute && attribute.itemSize, count: attribute && attribute.count,
                     unit: attribute ? Array.from({ length: attribute.count }, (_, i) => Math.hypot(attribute.getX(i), attribute.getY(i), attribute.getZ(i))).every((l) => Math.abs(l - 1) < 1e-3) : false };
    return out;
  }, api);
  if (process.env.EFFECTD_PICTURES)
    for (const [name, url] of Object.entries(r.pictures))
      fs.writeFileSync(path.join(process.env.EFFECTD_PICTURES, `three-kit-${name}.png`), Buffer.from(url.split(',')[1], 'base64'));
  delete r.pictures;
  console.log(JSON.stringify(r));
  check(r.boltSame.mean === 0, `the bolt's GLB and its JSON mesh draw the same frame through the kit (mean difference ${r.boltSame.mean})`, r.boltSame);
  check(r.boltRecall >= 0.9 && r.boltPrecision >= 0.9, `the kit's bolt lights ${(100 * r.boltRecall).toFixed(1)} % of the preview's lit pixels ` +
        `and the preview ${(100 * r.boltPrecision).toFixed(1)} % of the kit's, within a pixel (≥ 90 %)`);
  check(r.glow.lit > 2 * r.glow.core && r.glow.farthestCells <= 5.6, `a glow 6 times as wide stays within 5.6 cells of the core ` +
        `(farthest lit pixel ${r.glow.farthestCells.toFixed(2)} cells; ${r.glow.lit} pixels lit, the core ${r.glow.core})`, r.glow);
  check(r.strike.before === 0 && r.strike.stroke >= 0.5 * r.strike.whole && r.strike.after === 0,
        `setTime plays the strike: lit share ${r.strike.before} before the leader, ${r.strike.stroke.toFixed(4)} at the first stroke ` +
        `(the whole bolt ${r.strike.whole.toFixed(4)}), ${r.strike.after} after the end`, r.strike);
  {
    const { kit: k, preview: p } = r.apsf, total = k.total / p.total, radius = k.radius / p.radius;
    const ring = Math.max(...k.rings.map((x, i) => Math.abs(x / p.rings[i] - 1)));
    check(p.total > 1000 && Math.abs(total - 1) < 0.12 && Math.abs(radius - 1) < 0.05 && ring < 0.15,
          `the bolt's glow through fog (T ${r.apsf.T.toFixed(3)}, ${r.apsf.gaussians} Gaussians) by apsfGlow against the preview's: ` +
          `light ×${total.toFixed(3)}, half-light radius ${k.radius.toFixed(1)} px against ${p.radius.toFixed(1)} (×${radius.toFixed(3)}), ` +
          `the mean glow in 8-px rings around its centre at most ${(100 * ring).toFixed(1)} % apart ` +
          `(tolerances 12 %, 5 %, 15 %)`, r.apsf);
  }
  for (const [name, d] of Object.entries(r.bubble))
    check(d.pixels > 1500 && d.mean < 1 && d.p99 <= 6 && d.silhouette < 0.02, `the ${name} bubble through the kit against the preview: ${d.pixels} ` +
          `pixels, mean ${d.mean.toFixed(2)}, p99 ${d.p99}, silhouettes apart on ${(100 * d.silhouette).toFixed(2)} % (tolerances 1, 6, 2 %)`, d);
  for (const [name, d] of Object.entries(r.fog))
    check(d.mean < 0.5 && d.p99 <= 2, `${name} fog through applyFog against the preview: mean ${d.mean.toFixed(2)}, p99 ${d.p99} over the frame ` +
          `(tolerances 0.5, 2; the table's maxError ${d.maxError.toFixed(4)})`, d);
  check(r.tangents.status === 200 && r.tangents.itemSize === 4 && r.tangents.count > 0 && r.tangents.unit,
        '/v1/tangents\' GLB gives three a unit tangent per vertex (itemSize 4, w the handedness)', r.tangents);
} finally {
  await browser.close();
  server.kill();
  closePages();
}
process.exit(results.failures ? 1 : 0);
