// The three.js kit's README snippet as written (clients/three/README.md's first html block), run
// in headless chromium from a page on another origin, as a game's page would run it:
//   - with effectd started as the README says (--cors-origins <the page's origin>), the snippet
//     runs without an error and its bolt draws: the canvas is lit once the strike has played;
//   - without --cors-origins, the browser blocks its fetch, as the README warns.
// The only edits: the import map's CDN URLs point at npm's three on the page's own origin (this
// machine reaches no CDN), the server's URL is the test's, and the three objects the snippet
// assumes (scene, camera, renderer) are made first; its setAnimationLoop also renders, on a clock of
// 60 frames a second whatever the machine's speed, and counts the lit pixels of each frame.
// Usage: node kit_readme.mjs EFFECTD_BINARY [CHROMIUM]
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { launchWebGl2Chromium } from './chromium.mjs';
import { check, results, startEffectd } from '../node/effectd.mjs';

const [binary, chromium = '/usr/bin/chromium'] = process.argv.slice(2);
const here = path.dirname(fileURLToPath(import.meta.url));
const readme = fs.readFileSync(path.join(here, '../../clients/three/README.md'), 'utf8');
const snippet = /```html\n([\s\S]*?)```/.exec(readme)[1];
check(snippet.includes('--cors-origins') || readme.includes('--cors-origins'), "the kit's README says how to allow a page's origin");

const modules = path.join(here, 'node_modules');
function page(api) {
  const setup = `
const scene = new THREE.Scene();
const camera = new THREE.OrthographicCamera(0, 96, 0, -96, -10, 10);
const renderer = new THREE.WebGLRenderer({ canvas: document.getElementById('gl'), preserveDrawingBuffer: true });
renderer.setSize(96, 96, false);
const loop = renderer.setAnimationLoop.bind(renderer);
const gl = renderer.getContext(), pixels = new Uint8Array(96 * 96 * 4);
window.frames = 0; window.lit = 0;
renderer.setAnimationLoop = (f) => loop(() => {
  f(window.frames++ * 1000 / 60);
  renderer.render(scene, camera);
  gl.readPixels(0, 0, 96, 96, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  let n = 0;
  for (let i = 0; i < pixels.length; i += 4) n += pixels[i + 2] > 60;
  window.lit = Math.max(window.lit, n);
});
window.snippet = 'running';
`;
  return snippet
    .replaceAll('https://unpkg.com/three@0.187.0/', '/nm/three/')
    .replaceAll('http://localhost:8080', api)
    .replace("from './effectd-three.js';\n", "from './effectd-three.js';\n" + setup)
    .replace(/<\/script>\n$/, "window.snippet = 'done';\n</script>\n");
}
const pages = http.createServer((req, res) => {
  const url = new URL(req.url, 'http://x');
  if (url.pathname === '/favicon.ico') return res.writeHead(204).end();
  if (url.pathname === '/') {
    res.writeHead(200, { 'Content-Type': 'text/html' });
    return res.end(`<!doctype html><canvas id="gl" width="96" height="96"></canvas>\n${page(pages.api)}`);
  }
  const file = url.pathname === '/effectd-three.js' ? path.join(here, '../../clients/three/effectd-three.js')
    : url.pathname.startsWith('/nm/') ? path.normalize(path.join(modules, url.pathname.slice(4))) : null;
  if (!file || !fs.existsSync(file)) return res.writeHead(404).end();
  res.writeHead(200, { 'Content-Type': 'text/javascript' });
  res.end(fs.readFileSync(file));
});
await new Promise((r) => pages.listen(0, '127.0.0.1', r));
const origin = `http://localhost:${pages.address().port}`;

const browser = await launchWebGl2Chromium(chromium);
try {
  for (const allowed of [true, false]) {
    const { url: api, process: server } = await startEffectd(binary, allowed ? ['--cors-origins', origin] : []);
    pages.api = api;
    const tab = await browser.newPage();
    const errors = [];
    tab.on('pageerror', (e) => errors.push(e.message));
    tab.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
    await tab.goto(`${origin}/`);
    await tab.waitForFunction(() => window.snippet !== 'running' || document.readyState === 'complete', { timeout: 30000 });
    // The strike flashes and goes dark, over and over. The loop's clock is the frame count at 60 Hz,
    // not the wall clock, so a slow machine still renders every phase: the most pixels lit over 3 s
    // of game time (the strike's duration + 0.5 s is well under it), counted after each frame.
    // Blocked by CORS the snippet never finishes: 5 s is enough to see it has not.
    const seen = await tab.evaluate(async (waits) => {
      for (let k = 0; k < waits && !(window.snippet === 'done' && window.frames >= 180); ++k) {
        await new Promise((r) => setTimeout(r, 100));
      }
      return { state: window.snippet, frames: window.frames, lit: window.lit };
    }, allowed ? 600 : 50);
    if (allowed) {
      check(seen.state === 'done' && errors.length === 0, 'the README snippet runs from another origin with --cors-origins',
            { seen, errors });
      check(seen.lit > 20, "... and its bolt draws", seen);
    } else {
      check(seen.state !== 'done' && errors.some((e) => /CORS|Failed to fetch/i.test(e)),
            'without --cors-origins the browser blocks it, as the README says', { seen, errors });
    }
    console.log(`  ${allowed ? 'with' : 'without'} --cors-origins: ${JSON.stringify(seen)}; ${errors.length} errors`);
    await tab.close();
    server.kill();
  }
} finally {
  await browser.close();
  pages.close();
}
process.exit(results.failures ? 1 : 0);
