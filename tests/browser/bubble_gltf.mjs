// The bubble's GLB judged by the engines that consume it: three.js (npm `three`, its own
// GLTFLoader and MeshPhysicalMaterial's KHR_materials_iridescence) and Babylon.js (npm
// `@babylonjs/core` + `@babylonjs/loaders`, its glTF loader and PBRMaterial iridescence) in
// headless chromium (WebGL2 on SwiftShader) draw /v1/bubble's `format: "glb"` under a cube map
// of effectd's sky over the preview's grey backdrop. On the bubble's disc:
//   - how much the iridescence changes it (on against off, mean per channel);
//   - how much of it the film colours (chroma, max - min channel, above 8/255), against
//     effectd's /v1/render preview of the same bubble and camera: at least half its share;
//   - the mean ΔE*ab (CIE76) from the preview, at most 8 (seen: three 4.7, Babylon 5.3 with the
//     film; 4.0 and 4.0 without it: the bands lie elsewhere than ours);
//   - the same GLB with its base ior set back to the film's (the old material, which three drew
//     almost clear) shows the film at most a third as strongly.
// Usage: node bubble_gltf.mjs EFFECTD_BINARY [CHROMIUM]
import fs from 'node:fs';
import path from 'node:path';
import { launchWebGl2Chromium, openLoggedPage } from './chromium.mjs';
import { servePages } from './page_server.mjs';
import { check, results, startEffectd } from '../node/effectd.mjs';

const [binary, chromium = '/usr/bin/chromium'] = process.argv.slice(2);

const { origin, close: closePages } = await servePages('effectd bubble GLB in three.js and Babylon.js', ['gl', 'png', 'bjs']);
const { url: api, process: server } = await startEffectd(binary, ['--cors-origins', origin]);

// The scene both engines and the preview draw: the default bubble (wobble off) 4 units away, a
// grey backdrop, effectd's sky; the disc measured is 0.85 of the bubble's radius in pixels.
const view = { size: 160, eye: [0, 0.3, 4], fovY: 45, backdrop: [0.5, 0.5, 0.5],
               sky: { zenith: [0.35, 0.6, 1.0], horizon: [1.0, 0.98, 0.95], ground: [0.16, 0.18, 0.12] },
               bubble: { mesh: { level: 4 }, features: { wobble: false } } };
view.rPx = (view.size / 2) / (Math.hypot(...view.eye) * Math.tan((view.fovY / 2) * Math.PI / 180)) * 0.85;

const browser = await launchWebGl2Chromium(chromium);
try {
  const page = await openLoggedPage(browser, `${origin}/`);
  const r = await page.evaluate(async ({ api, view }) => {
    const { colouredShare, flipRows, partChange, skyCubeFaces } = await import('/page_helpers.mjs');
    const out = {};
    const { size, eye, fovY, backdrop, sky, bubble, rPx } = view;
    const json = { 'Content-Type': 'application/json' };
    const post = (route, body) => fetch(`${api}${route}`, { method: 'POST', headers: json, body: JSON.stringify(body) });

    // effectd's preview of the bubble, under its sky.
    const png = await post('/v1/render', { width: size, height: size, time: 0, camera: { position: eye, target: [0, 0, 0], fovY },
                                           background: { color: [...backdrop, 1] }, environment: sky, bubble });
    out.render = png.status;
    const c2 = document.getElementById('png');
    c2.width = c2.height = size;
    const ctx = c2.getContext('2d');
    ctx.drawImage(await createImageBitmap(await png.blob()), 0, 0);
    const top = ctx.getImageData(0, 0, size, size).data;
    out.preview = colouredShare(top, size, rPx);
    // The preview's rows bottom-up, as the engines' frames are read back.
    const up = flipRows(top, size);
    out.previewUp = Array.from(up);

    // three.js: the GLB as a glTF viewer loads it, under effectd's sky (its displayed colours,
    // decoded to three's linear working space) over the preview's displayed grey.
    const THREE = await import('three');
    const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
    const canvas = document.getElementById('gl');
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
    renderer.setSize(size, size, false);
    renderer.setPixelRatio(1);
    const scene = new THREE.Scene();
    scene.background = new THREE.Color().setRGB(...backdrop, THREE.SRGBColorSpace);
    const linear = (c) => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);
    const faces = skyCubeFaces(sky, 64).map((px) => {
      for (let i = 0; i < px.length; ++i) if (i % 4 !== 3) px[i] = linear(px[i]);
      return Object.assign(new THREE.DataTexture(px, 64, 64, THREE.RGBAFormat, THREE.FloatType), { needsUpdate: true });
    });
    const cube = Object.assign(new THREE.CubeTexture(faces), { format: THREE.RGBAFormat, type: THREE.FloatType, generateMipmaps: false,
                                                                magFilter: THREE.LinearFilter, minFilter: THREE.LinearFilter, needsUpdate: true });
    scene.environment = new THREE.PMREMGenerator(renderer).fromCubemap(cube).texture;
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
    const filmPart = () => partChange((on) => { material.iridescence = on ? 1 : 0; }, frame, size, rPx, up);
    out.three = await filmPart();
    material.iridescence = 1;
    frame();
    out.pictures = { three: canvas.toDataURL('image/png'), preview: c2.toDataURL('image/png') };
    material.ior = material.iridescenceIOR;  // the old material: base ior equal to the film's
    out.oldIor = await filmPart();
    return out;
  }, { api, view });
  const previewUp = r.previewUp;
  delete r.previewUp;
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
  console.log(`  mean ΔE*ab over the disc from effectd's preview: three.js ${r.three.deltaE.on.toFixed(1)} with the film, ` +
              `${r.three.deltaE.off.toFixed(1)} without`);
  check(r.three.deltaE.on <= 8, `three.js's disc is within a mean ΔE*ab of 8 of the preview's (${r.three.deltaE.on.toFixed(1)})`, r.three.deltaE);
  check(r.three.change >= 3 * r.oldIor.change, `with the base ior at the film's (the old GLB) the film changed the disc by ` +
        `${r.oldIor.change.toFixed(2)}/255: the base ior of 1 shows it at least 3 times as strongly`, r.oldIor);

  // Babylon.js: its own glTF loader and PBRMaterial iridescence, under a cube map of effectd's sky.
  const page2 = await browser.newPage();
  page2.on('pageerror', (e) => console.log(`  page error: ${e.message}`));
  await page2.goto(`${origin}/`);
  const b = await page2.evaluate(async ({ api, view, previewUp }) => {
    const { partChange, skyCubeFaces } = await import('/page_helpers.mjs');
    const out = {};
    const { size, eye, fovY, backdrop, sky, bubble, rPx } = view;
    const { Engine } = await import('@babylonjs/core/Engines/engine.js');
    const { Scene } = await import('@babylonjs/core/scene.js');
    const { FreeCamera } = await import('@babylonjs/core/Cameras/freeCamera.js');
    const { Vector3 } = await import('@babylonjs/core/Maths/math.vector.js');
    const { Color4 } = await import('@babylonjs/core/Maths/math.color.js');
    const { RawCubeTexture } = await import('@babylonjs/core/Materials/Textures/rawCubeTexture.js');
    const { LoadAssetContainerAsync } = await import('@babylonjs/core/Loading/sceneLoader.js');
    await import('@babylonjs/loaders/glTF/index.js');  // registers the .glb loader and its extensions
    const canvas = document.getElementById('bjs');
    canvas.width = canvas.height = size;
    const engine = new Engine(canvas, false, { preserveDrawingBuffer: true });
    const scene = new Scene(engine);
    scene.clearColor = new Color4(...backdrop, 1);
    scene.useRightHandedSystem = true;  // glTF's
    const camera = new FreeCamera('camera', new Vector3(...eye), scene);
    camera.fov = fovY * Math.PI / 180;
    camera.fovMode = 0;  // vertical
    camera.setTarget(Vector3.Zero());
    // effectd's sky (render::skyAt) as the environment cube.
    scene.environmentTexture = new RawCubeTexture(scene, skyCubeFaces(sky, 32), 32, 5, 1);  // RGBA, float
    const res = await fetch(`${api}/v1/bubble`, { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                                  body: JSON.stringify({ ...bubble, format: 'glb' }) });
    const container = await LoadAssetContainerAsync(new Uint8Array(await res.arrayBuffer()), scene, { pluginExtension: '.glb' });
    container.addAllToScene();
    const material = container.materials.find((m) => m.iridescence);
    out.material = { type: material.getClassName(), ior: material.indexOfRefraction, iridescence: material.iridescence.isEnabled,
                     iridescenceIor: material.iridescence.indexOfRefraction };
    const frame = async () => {
      await scene.whenReadyAsync();
      scene.render();
      return new Uint8Array(await engine.readPixels(0, 0, size, size));
    };
    const filmPart = () => partChange((on) => { material.iridescence.isEnabled = on; }, frame, size, rPx, previewUp);
    out.babylon = await filmPart();
    material.iridescence.isEnabled = true;
    await frame();
    out.picture = canvas.toDataURL('image/png');
    material.indexOfRefraction = material.iridescence.indexOfRefraction;  // the old material
    out.oldIor = await filmPart();
    return out;
  }, { api, view, previewUp });
  if (process.env.EFFECTD_PICTURES)
    fs.writeFileSync(path.join(process.env.EFFECTD_PICTURES, 'bubble-gltf-babylon.png'), Buffer.from(b.picture.split(',')[1], 'base64'));
  delete b.picture;
  console.log(JSON.stringify(b));
  check(b.material.iridescence && Math.abs(b.material.ior - 1) < 1e-6 && Math.abs(b.material.iridescenceIor - 1.33) < 1e-6,
        'Babylon loads the iridescent material: base ior 1, film ior 1.33', b.material);
  check(b.babylon.change >= 2, `the film changes Babylon's disc by ${b.babylon.change.toFixed(2)}/255 on average (≥ 2)`, b.babylon);
  check(b.babylon.on.share >= 0.5 * r.preview.share, `Babylon colours ${(100 * b.babylon.on.share).toFixed(1)} % of the disc, at least half ` +
        `effectd's preview's ${(100 * r.preview.share).toFixed(1)} %`, b.babylon);
  console.log(`  mean ΔE*ab over the disc from effectd's preview: Babylon.js ${b.babylon.deltaE.on.toFixed(1)} with the film, ` +
              `${b.babylon.deltaE.off.toFixed(1)} without`);
  check(b.babylon.deltaE.on <= 8, `Babylon.js's disc is within a mean ΔE*ab of 8 of the preview's (${b.babylon.deltaE.on.toFixed(1)})`, b.babylon.deltaE);
  check(b.babylon.change >= 3 * b.oldIor.change, `with the old base ior Babylon's film changed the disc by ` +
        `${b.oldIor.change.toFixed(2)}/255 and coloured ${(100 * b.oldIor.on.share).toFixed(1)} % of it`, b.oldIor);
} finally {
  await browser.close();
  server.kill();
  closePages();
}
process.exit(results.failures ? 1 : 0);
