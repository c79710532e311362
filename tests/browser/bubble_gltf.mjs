// The bubble's GLB judged by an engine that consumes it: three.js (npm `three`, its own
// GLTFLoader and MeshPhysicalMaterial's KHR_materials_iridescence) in headless chromium (WebGL2
// on SwiftShader) draws /v1/bubble's `format: "glb"` under an environment map over a neutral
// grey backdrop, and the film's part of the frame is measured: how much the iridescence changes
// the bubble's disc (on against off, mean per channel) and how much of the disc it colours
// (chroma, max - min channel, above 8/255). The same GLB with its base ior set back to the
// film's (the old material, which three drew almost clear) is measured beside it.
// effectd's /v1/render preview of the same bubble and camera (under effectd's sky, not three's
// RoomEnvironment) is measured the same way: three must colour at least half the share of the
// disc the preview colours (seen: 36.6 % against 39.2 %; the old GLB 5.6 %).
// Usage: node bubble_gltf.mjs EFFECTD_BINARY [CHROMIUM]
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import puppeteer from 'puppeteer-core';
import { check, results, startEffectd } from '../node/effectd.mjs';

const [binary, chromium = '/usr/bin/chromium'] = process.argv.slice(2);
const here = path.dirname(fileURLToPath(import.meta.url));
const threeRoot = path.join(here, 'node_modules', 'three');

const pages = http.createServer((req, res) => {
  const url = new URL(req.url, 'http://x');
  if (url.pathname.startsWith('/three/')) {  // three's ES modules, as a page would load them
    const file = path.normalize(path.join(threeRoot, url.pathname.slice('/three/'.length)));
    if (!file.startsWith(threeRoot) || !fs.existsSync(file)) return res.writeHead(404).end();
    res.writeHead(200, { 'Content-Type': 'text/javascript' });
    return res.end(fs.readFileSync(file));
  }
  res.writeHead(200, { 'Content-Type': 'text/html' });
  res.end('<!doctype html><title>effectd bubble GLB in three.js</title>' +
          '<script type="importmap">{"imports":{"three":"/three/build/three.module.js",' +
          '"three/addons/":"/three/examples/jsm/"}}</script><canvas id="gl"></canvas><canvas id="png"></canvas>');
});
await new Promise((r) => pages.listen(0, '127.0.0.1', r));
const origin = `http://localhost:${pages.address().port}`;
const { url: api, process: server } = await startEffectd(binary, ['--cors-origins', origin]);

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
         '--ignore-gpu-blocklist'],
});
try {
  const page = await browser.newPage();
  page.on('console', (m) => console.log(`  page: ${m.text()}`));
  page.on('pageerror', (e) => console.log(`  page error: ${e.message}`));
  await page.goto(`${origin}/`);
  const r = await page.evaluate(async (api) => {
    const out = {};
    const size = 160, eye = [0, 0.3, 4], fovY = 45;
    const backdrop = [0.5, 0.5, 0.5];
    const bubble = { mesh: { level: 4 }, features: { wobble: false } };
    const json = { 'Content-Type': 'application/json' };
    const post = (route, body) => fetch(`${api}${route}`, { method: 'POST', headers: json, body: JSON.stringify(body) });
    // The bubble's disc: centre and radius in pixels (radius 1 at the camera's distance), 0.85 of it.
    const dist = Math.hypot(...eye), rPx = (size / 2) / (dist * Math.tan((fovY / 2) * Math.PI / 180)) * 0.85;
    const colouredShare = (px, flipY) => {
      let n = 0, coloured = 0, sum = [0, 0, 0];
      for (let y = 0; y < size; ++y)
        for (let x = 0; x < size; ++x) {
          if (Math.hypot(x + 0.5 - size / 2, y + 0.5 - size / 2) > rPx) continue;
          const i = ((flipY ? size - 1 - y : y) * size + x) * 4;
          const c = [px[i], px[i + 1], px[i + 2]];
          ++n, coloured += Math.max(...c) - Math.min(...c) > 8;
          for (let k = 0; k < 3; ++k) sum[k] += c[k];
        }
      return { share: coloured / n, mean: sum.map((s) => s / n) };
    };

    // effectd's preview of the bubble, under a sky.
    const png = await post('/v1/render', { width: size, height: size, time: 0, camera: { position: eye, target: [0, 0, 0], fovY },
                                           background: { color: [...backdrop, 1] },
                                           environment: { zenith: [0.35, 0.6, 1.0], horizon: [1.0, 0.98, 0.95], ground: [0.16, 0.18, 0.12] },
                                           bubble });
    out.render = png.status;
    const c2 = document.getElementById('png');
    c2.width = c2.height = size;
    const ctx = c2.getContext('2d');
    ctx.drawImage(await createImageBitmap(await png.blob()), 0, 0);
    out.preview = colouredShare(ctx.getImageData(0, 0, size, size).data, false);

    // three.js: the GLB as a glTF viewer loads it, under three's RoomEnvironment.
    const THREE = await import('three');
    const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
    const { RoomEnvironment } = await import('three/addons/environments/RoomEnvironment.js');
    const canvas = document.getElementById('gl');
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
    renderer.setSize(size, size, false);
    renderer.setPixelRatio(1);
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(...backdrop);
    scene.environment = new THREE.PMREMGenerator(renderer).fromScene(new RoomEnvironment(), 0.04).texture;
    const camera = new THREE.PerspectiveCamera(fovY, 1, 0.1, 100);
    camera.position.set(...eye);
    camera.lookAt(0, 0, 0);
    const glb = await post('/v1/bubble', { ...bubble, format: 'glb' });
    out.glb = glb.status;
    const gltf = await new GLTFLoader().parseAsync(await glb.arrayBuffer(), '');
    scene.add(gltf.scene);
    let material = null;
    gltf.scene.traverse((o) => { if (o.isMesh) material = o.material; });
    out.material = { type: material.type, ior: material.ior, iridescence: material.iridescence,
                     iridescenceIOR: material.iridescenceIOR, transmission: material.transmission,
                     thicknessRange: material.iridescenceThicknessRange };
    const frame = () => {
      renderer.render(scene, camera);
      const gl = renderer.getContext();
      const px = new Uint8Array(size * size * 4);
      gl.readPixels(0, 0, size, size, gl.RGBA, gl.UNSIGNED_BYTE, px);
      return px;
    };
    // The film's part: the disc with iridescence against without it.
    const filmPart = () => {
      material.iridescence = 1;
      const on = frame();
      material.iridescence = 0;
      const off = frame();
      let diff = 0, n = 0;
      for (let y = 0; y < size; ++y)
        for (let x = 0; x < size; ++x) {
          if (Math.hypot(x + 0.5 - size / 2, y + 0.5 - size / 2) > rPx) continue;
          const i = (y * size + x) * 4;
          for (let k = 0; k < 3; ++k) diff += Math.abs(on[i + k] - off[i + k]);
          n += 3;
        }
      return { change: diff / n, on: colouredShare(on, true), off: colouredShare(off, true) };
    };
    out.three = filmPart();
    material.iridescence = 1;
    frame();
    out.pictures = { three: canvas.toDataURL('image/png'), preview: c2.toDataURL('image/png') };
    material.ior = material.iridescenceIOR;  // the old material: base ior equal to the film's
    out.oldIor = filmPart();
    return out;
  }, api);
  if (process.env.EFFECTD_PICTURES)  // a folder to write both frames into, to look at them
    for (const [name, url] of Object.entries(r.pictures))
      fs.writeFileSync(path.join(process.env.EFFECTD_PICTURES, `bubble-gltf-${name}.png`), Buffer.from(url.split(',')[1], 'base64'));
  delete r.pictures;
  console.log(JSON.stringify(r));
  check(r.render === 200 && r.glb === 200, '/v1/render and /v1/bubble (glb) answer 200', r);
  check(r.material.type === 'MeshPhysicalMaterial' && r.material.iridescence === 1 && r.material.ior === 1 &&
        Math.abs(r.material.iridescenceIOR - 1.33) < 1e-6, 'three loads an iridescent physical material, base ior 1, film ior 1.33', r.material);
  console.log(`  effectd's preview: ${(100 * r.preview.share).toFixed(1)} % of the disc coloured; three.js: ` +
              `${(100 * r.three.on.share).toFixed(1)} % with the film, ${(100 * r.three.off.share).toFixed(1)} % without`);
  check(r.three.change >= 5, `the film changes three.js's disc by ${r.three.change.toFixed(2)}/255 on average (≥ 5)`, r.three);
  check(r.three.on.share >= r.three.off.share + 0.2, `the film colours ${(100 * (r.three.on.share - r.three.off.share)).toFixed(1)} ` +
        '% more of the disc (≥ 20 points)', r.three);
  check(r.three.on.share >= 0.5 * r.preview.share, `three.js colours at least half the share of the disc effectd's preview does`,
        { three: r.three.on.share, preview: r.preview.share });
  check(r.three.change >= 3 * r.oldIor.change, `with the base ior at the film's (the old GLB) the film changed the disc by ` +
        `${r.oldIor.change.toFixed(2)}/255: the base ior of 1 shows it at least 3 times as strongly`, r.oldIor);
} finally {
  await browser.close();
  server.kill();
  pages.close();
}
process.exit(results.failures ? 1 : 0);
