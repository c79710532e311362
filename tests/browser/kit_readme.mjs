// The three.js kit's README snippet exactly as written (clients/three/README.md's first html
// block), run in headless chromium from a page on another origin, as a game's page would run it:
//   - with effectd started as the README says (--cors-origins <the page's origin>), the snippet
//     runs without an error and its bolt draws: the canvas is lit once the strike has played
//     (read from the canvas as the page shows it: remove the snippet's render call and it stays
//     black);
//   - without --cors-origins, the browser blocks its fetch, as the README warns.
// The one edit: the server's URL is the test's. The page's origin serves what the snippet names
// beside it: ./node_modules (npm's three, this directory's) and ./effectd-three.js.
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
// Before the snippet: a WebGL canvas keeps its last frame, so that the test can read what it shows.
const keepFrames = `<script>
const getContext = HTMLCanvasElement.prototype.getContext;
HTMLCanvasElement.prototype.getContext = function (kind, options) {
  return getContext.call(this, kind, kind.startsWith('webgl') ? { ...options, preserveDrawingBuffer: true } : options);
};
</script>
`;
const page = (api) => keepFrames + snippet.replaceAll('http://localhost:8080', api);
const pages = http.createServer((req, res) => {
  const url = new URL(req.url, 'http://x');
  if (url.pathname === '/favicon.ico') return res.writeHead(204).end();
  if (url.pathname === '/') {
    res.writeHead(200, { 'Content-Type': 'text/html' });
    return res.end(`<!doctype html>\n${page(pages.api)}`);
  }
  const file = url.pathname === '/effectd-three.js' ? path.join(here, '../../clients/three/effectd-three.js')
    : url.pathname.startsWith('/node_modules/') ? path.normalize(path.join(modules, url.pathname.slice(14))) : null;
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
    // The strike flashes and goes dark, over and over: the most pixels lit on the canvas, read
    // every 50 ms for 8 s (many strikes; swiftshader draws a frame in a few ms). Blocked by CORS
    // the snippet draws nothing: 3 s is enough to see it.
    const seen = await tab.evaluate(async (samples) => {
      const view = document.querySelector('canvas');
      const copy = document.createElement('canvas');
      copy.width = view.width, copy.height = view.height;
      const ctx = copy.getContext('2d', { willReadFrequently: true });
      let lit = 0, frames = 0;
      for (let k = 0; k < samples; ++k) {
        await new Promise((r) => setTimeout(r, 50));
        ctx.clearRect(0, 0, copy.width, copy.height);
        ctx.drawImage(view, 0, 0);
        const px = ctx.getImageData(0, 0, copy.width, copy.height).data;
        let n = 0;
        for (let i = 0; i < px.length; i += 4) n += px[i + 2] > 60;
        lit = Math.max(lit, n), frames += n > 0;
      }
      return { lit, litSamples: frames, samples };
    }, allowed ? 160 : 60);
    if (allowed) {
      check(errors.length === 0, 'the README snippet runs from another origin with --cors-origins', { seen, errors });
      check(seen.lit > 100, "... and its bolt draws on the canvas", seen);
    } else {
      check(seen.lit === 0 && errors.some((e) => /CORS|Failed to fetch/i.test(e)),
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
