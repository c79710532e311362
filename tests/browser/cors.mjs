// A page on another origin uses effectd as a browser game would: headless chromium (Debian's)
// driven by puppeteer-core. The page is served from http://localhost:P, effectd listens on
// http://127.0.0.1:Q with --cors-origins naming the page's origin, so every fetch is
// cross-origin and JSON bodies go through a preflight. Checked in the browser itself:
//   - POST /v1/fog: 200, the answer parses (whatever coding chromium negotiated), and the
//     exposed headers (ETag, Server-Timing, X-Request-ID, X-Effect-Method) are readable;
//   - If-None-Match with that ETag: 304;
//   - a bad body: the problem (400, application/problem+json, naming the field) is readable;
//   - POST /v1/render: a PNG that decodes to the requested size and is not one flat colour;
//   - a page on an origin not in the list cannot read anything (fetch rejects).
// Usage: node cors.mjs EFFECTD_BINARY [CHROMIUM]
import http from 'node:http';
import puppeteer from 'puppeteer-core';
import { check, results, startEffectd } from '../node/effectd.mjs';

const [binary, chromium = '/usr/bin/chromium'] = process.argv.slice(2);

// The page's origin: a static server for an empty page.
const pages = http.createServer((req, res) => {
  res.writeHead(200, { 'Content-Type': 'text/html' });
  res.end('<!doctype html><title>effectd from another origin</title><canvas id="c"></canvas>');
});
await new Promise((r) => pages.listen(0, '127.0.0.1', r));
const pagePort = pages.address().port;
const allowedOrigin = `http://localhost:${pagePort}`;  // same page, a different origin: 127.0.0.1
const refusedOrigin = `http://127.0.0.1:${pagePort}`;

// effectd, allowing only the page's origin.
const { url: api, process: server } = await startEffectd(binary, ['--cors-origins', allowedOrigin]);

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
});
try {
  const page = await browser.newPage();
  await page.goto(`${allowedOrigin}/`);
  const r = await page.evaluate(async (api) => {
    const out = { fog: {}, problem: {}, render: {} };
    try {
    const json = { 'Content-Type': 'application/json' };
    const fogBody = JSON.stringify({ fog: { fogType: 'GL_EXP', density: 0.05 }, table: { size: 16 } });
    let res = await fetch(`${api}/v1/fog`, { method: 'POST', headers: { ...json, 'X-Request-ID': 'browser-1' }, body: fogBody });
    out.fog = {
      status: res.status,
      etag: res.headers.get('ETag'),
      method: res.headers.get('X-Effect-Method'),
      timing: res.headers.get('Server-Timing'),
      requestId: res.headers.get('X-Request-ID'),
      body: await res.json(),
    };
    res = await fetch(`${api}/v1/fog`, { method: 'POST', cache: 'no-store', headers: { ...json, 'If-None-Match': out.fog.etag }, body: fogBody });
    out.revalidated = res.status;
    res = await fetch(`${api}/v1/fog`, { method: 'POST', headers: json, body: JSON.stringify({ fog: { fogType: 'GL_EXP', density: -1 } }) });
    out.problem = { status: res.status, type: res.headers.get('Content-Type'), body: await res.json() };
    const scene = {
      width: 96, height: 64, time: 1,
      camera: { position: [0, 0.3, 4], target: [0, 0, 0], fovY: 45 },
      background: { gradient: { top: [0.3, 0.55, 0.85], bottom: [0.9, 0.85, 0.7] } },
      bubble: { params: { wobbleAmplitude: 0.04 }, mesh: { level: 3, radius: 1 } },
    };
    res = await fetch(`${api}/v1/render`, { method: 'POST', headers: json, body: JSON.stringify(scene) });
    out.render = { status: res.status, type: res.headers.get('Content-Type'), renderer: res.headers.get('X-Renderer') };
    if (res.ok) {
      const bitmap = await createImageBitmap(await res.blob());
      const canvas = document.getElementById('c');
      canvas.width = bitmap.width;
      canvas.height = bitmap.height;
      const ctx = canvas.getContext('2d');
      ctx.drawImage(bitmap, 0, 0);
      const px = ctx.getImageData(0, 0, bitmap.width, bitmap.height).data;
      const colours = new Set();
      for (let i = 0; i < px.length; i += 4 * 7) colours.add(`${px[i]},${px[i + 1]},${px[i + 2]}`);
      Object.assign(out.render, { width: bitmap.width, height: bitmap.height, colours: colours.size });
    }
    } catch (e) {
      out.error = `${e.name}: ${e.message}`;
    }
    return out;
  }, api);

  check(!r.error, 'every fetch from the allowed origin completes', r.error);
  check(r.fog.status === 200, 'fog: 200 across origins (after a preflight)', r.fog.status);
  check(r.fog.body?.table?.factor?.length === 16, 'fog: the answer parses (16-entry table)', r.fog.body);
  check(/^"[^"]+"$/.test(r.fog.etag ?? ''), 'fog: ETag readable', r.fog.etag);
  check(!!r.fog.method, 'fog: X-Effect-Method readable', r.fog.method);
  check(/dur=/.test(r.fog.timing ?? ''), 'fog: Server-Timing readable', r.fog.timing);
  check(r.fog.requestId === 'browser-1', 'fog: X-Request-ID sent and read back', r.fog.requestId);
  check(r.revalidated === 304, 'fog: If-None-Match with the ETag gives 304', r.revalidated);
  check(r.problem.status === 400 && /problem\+json/.test(r.problem.type ?? ''), 'bad body: 400 problem readable', r.problem);
  check(JSON.stringify(r.problem.body ?? '').includes('/fog/density'), 'bad body: the problem names /fog/density', r.problem.body);
  check(r.render.status === 200 && r.render.type === 'image/png', 'render: 200 image/png', r.render);
  check(r.render.width === 96 && r.render.height === 64, 'render: decodes at the requested 96x64', r.render);
  check(r.render.colours > 20, 'render: not one flat colour', r.render);

  // The same page from an origin not in --cors-origins: the browser must not let it read.
  const other = await browser.newPage();
  await other.goto(`${refusedOrigin}/`);
  const refused = await other.evaluate(async (api) => {
    try {
      const res = await fetch(`${api}/v1/fog`, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{}' });
      return `read ${res.status}`;
    } catch (e) {
      return `rejected: ${e.name}`;
    }
  }, api);
  check(refused.startsWith('rejected'), `origin not allowed: fetch ${refused}`, refused);
} finally {
  await browser.close();
  server.kill('SIGTERM');
  pages.close();
}
console.log(results.failures ? `${results.failures} check(s) failed` : 'all browser checks passed');
process.exit(results.failures ? 1 : 0);
