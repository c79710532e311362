// The bolt's GLB (/v1/lightning format glb) judged by an engine that consumes it: three.js (npm
// `three`, its own GLTFLoader) in headless chromium draws the ribbons additively over a dark
// scene, as a game would, and the frame is compared with effectd's /v1/render preview of the same
// bolt (core only, glow off: the glow is a bloom pass in an engine):
//   - a 2-D bolt through an orthographic camera over the grid: the lit pixels (max channel above
//     48/255) of each frame found in the other within one pixel (recall and precision), and the
//     mean colour where both are lit;
//   - a 3-D bolt's crossed ribbons: seen from the front and from above, each view lights a
//     comparable share of the frame (no view is edge-on);
//   - the timeline's attributes: three loads _LEADER and _STROKE_DELAY as geometry attributes.
// Usage: node bolt_gltf.mjs EFFECTD_BINARY [CHROMIUM]
import fs from 'node:fs';
import path from 'node:path';
import { launchWebGl2Chromium, openLoggedPage } from './chromium.mjs';
import { servePages } from './page_server.mjs';
import { check, results, startEffectd } from '../node/effectd.mjs';

const [binary, chromium = '/usr/bin/chromium'] = process.argv.slice(2);
const { origin, close: closePages } = await servePages('effectd bolt GLB in three.js', ['gl', 'png']);
const { url: api, process: server } = await startEffectd(binary, ['--cors-origins', origin]);

const view = { size: 192, grid: 96, dark: [0.02, 0.02, 0.03],
               bolt: { grid: { width: 96, height: 96 }, start: [48, 1], targets: [[40, 94]], seed: 5 },
               volume: { grid: { width: 32, height: 32, depth: 32 }, start: [16, 1, 16], targets: [[16, 30, 16]], seed: 5 } };

const browser = await launchWebGl2Chromium(chromium);
try {
  const page = await openLoggedPage(browser, `${origin}/`);
  const r = await page.evaluate(async ({ api, view }) => {
    const { size, grid, dark, bolt, volume } = view;
    const out = {};
    const post = (route, body) => fetch(`${api}${route}`, { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                                            body: JSON.stringify(body) });
    const { foundWithinAPixel, litMask, readTopDown } = await import('/page_helpers.mjs');
    const lit = (px) => litMask(px, size), found = (a, b) => foundWithinAPixel(a, b, size);
    const meanLit = (px, m) => {
      const s = [0, 0, 0];
      let n = 0;
      for (let i = 0; i < size * size; ++i) if (m[i]) { ++n; for (let k = 0; k < 3; ++k) s[k] += px[4 * i + k]; }
      return s.map((x) => x / Math.max(n, 1));
    };

    // effectd's preview: the bolt over the whole frame, core only, one polyline width unit = one cell.
    const png = await post('/v1/render', { width: size, height: size, background: { color: [...dark, 1] }, lightning: bolt,
                                           lightningStyle: { coreWidth: size / grid, glowSigma: 0 } });
    out.render = png.status;
    const c2 = document.getElementById('png');
    c2.width = c2.height = size;
    const ctx = c2.getContext('2d');
    ctx.drawImage(await createImageBitmap(await png.blob()), 0, 0);
    const preview = ctx.getImageData(0, 0, size, size).data;

    // three.js: the GLB as its loader gives it, every material drawn additively.
    const THREE = await import('three');
    const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
    const canvas = document.getElementById('gl');
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
    renderer.setSize(size, size, false);
    renderer.setPixelRatio(1);
    const load = async (request) => {
      const res = await post('/v1/lightning', { ...request, format: 'glb' });
      const gltf = await new GLTFLoader().parseAsync(await res.arrayBuffer(), '');
      gltf.scene.traverse((o) => {
        if (!o.isMesh) return;
        Object.assign(o.material, { blending: THREE.AdditiveBlending, depthWrite: false, transparent: true });
      });
      return { status: res.status, gltf };
    };
    const frame = (scene, camera) => {
      renderer.render(scene, camera);
      return readTopDown(renderer.getContext(), size);
    };
    const flat = await load(bolt);
    out.glb = flat.status;
    let material = null, names = [];
    flat.gltf.scene.traverse((o) => { if (o.isMesh) material = o.material, names.push(o.name); });
    out.material = { type: material.type, vertexColors: material.vertexColors, map: Boolean(material.map), names };
    const scene = new THREE.Scene();
    scene.background = new THREE.Color().setRGB(...dark, THREE.SRGBColorSpace);  // the preview's display value
    scene.add(flat.gltf.scene);
    // glTF's axes: grid (x, y) at (x, -y); the camera looks down -z over [0, grid] x [-grid, 0].
    const camera = new THREE.OrthographicCamera(0, grid, 0, -grid, -10, 10);
    const three = frame(scene, camera);
    const a = lit(three), b = lit(preview);
    out.recall = found(b, a);     // the preview's lit pixels that three lights too
    out.precision = found(a, b);  // three's lit pixels that the preview lights too
    const both = a.map((x, i) => x & b[i]);  // the core, lit in both (the edges differ by their anti-aliasing)
    out.colour = { three: meanLit(three, both), preview: meanLit(preview, both) };
    out.pictures = { three: canvas.toDataURL('image/png'), preview: c2.toDataURL('image/png') };

    // A 3-D bolt: crossed ribbons from the front (down -z) and from above (down -y).
    const vol = await load(volume);
    out.glb3 = vol.status;
    const scene3 = new THREE.Scene();
    scene3.background = new THREE.Color().setRGB(...dark, THREE.SRGBColorSpace);
    scene3.add(vol.gltf.scene);
    const share = (px) => lit(px).reduce((s, x) => s + x, 0) / (size * size);
    const front = new THREE.OrthographicCamera(-2, 34, 2, -34, -100, 100);
    front.position.set(0, 0, 50);
    const above = new THREE.OrthographicCamera(-2, 34, 34, -2, -100, 100);  // up is -z: grid z at world -z
    above.position.set(0, 50, 0), above.up.set(0, 0, -1), above.lookAt(0, 0, 0);
    out.views = { front: share(frame(scene3, front)), above: share(frame(scene3, above)) };

    // The timeline's attributes reach three's geometry.
    const timed = await load({ ...bolt, include: ['timeline'] });
    let attributes = [];
    timed.gltf.scene.traverse((o) => { if (o.isMesh) attributes = Object.keys(o.geometry.attributes); });
    out.attributes = attributes;
    out.keyframes = (timed.gltf.scene.userData.timeline || { keyframes: { t: [] } }).keyframes.t.length;
    return out;
  }, { api, view });
  if (process.env.EFFECTD_PICTURES)  // a folder to write both frames into, to look at them
    for (const [name, url] of Object.entries(r.pictures))
      fs.writeFileSync(path.join(process.env.EFFECTD_PICTURES, `bolt-gltf-${name}.png`), Buffer.from(url.split(',')[1], 'base64'));
  delete r.pictures;
  console.log(JSON.stringify(r));
  check(r.render === 200 && r.glb === 200 && r.glb3 === 200, '/v1/render and /v1/lightning (glb) answer 200', r);
  check(r.material.type === 'MeshBasicMaterial' && r.material.vertexColors && r.material.map &&
        r.material.names.join() === 'main,branches',
        'three loads an unlit material with vertex colours (intensity) and the profile texture, nodes main and branches', r.material);
  check(r.recall.share >= 0.9, `three lights ${(100 * r.recall.share).toFixed(1)} % of the preview's ${r.recall.lit} lit pixels within one pixel (≥ 90 %)`, r.recall);
  check(r.precision.share >= 0.9, `the preview lights ${(100 * r.precision.share).toFixed(1)} % of three's ${r.precision.lit} lit pixels within one pixel (≥ 90 %)`, r.precision);
  const apart = Math.max(...r.colour.three.map((x, k) => Math.abs(x - r.colour.preview[k])));
  check(apart <= 12, `the mean colour where both frames are lit: three ${r.colour.three.map((x) => x.toFixed(0))}, preview ` +
        `${r.colour.preview.map((x) => x.toFixed(0))} (at most 12/255 apart per channel)`, r.colour);
  check(r.views.front > 0.005 && r.views.above > 0.005 && Math.min(r.views.front, r.views.above) >= 0.25 * Math.max(r.views.front, r.views.above),
        `a 3-D bolt's crossed ribbons light ${(100 * r.views.front).toFixed(2)} % of the frame from the front and ${(100 * r.views.above).toFixed(2)} % from above`, r.views);
  check(r.attributes.includes('_leader') && r.attributes.includes('_stroke_delay') && r.keyframes > 1,
        'with a timeline three has the _LEADER and _STROKE_DELAY attributes and the keyframes in the scene\'s userData', r.attributes);
} finally {
  await browser.close();
  server.kill();
  closePages();
}
process.exit(results.failures ? 1 : 0);
