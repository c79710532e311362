// The playground at / in a real browser (Debian's chromium, headless, WebGL2 on SwiftShader):
// the page loads with no console errors; every example of every effect runs (answer 200, a
// preview image, a live canvas that is not blank); changing eta re-requests and changes the
// picture; an invalid value shows the server's problem at the field it names; a GLB upload
// gets tangents; the shareable URL restores the request; "copy as curl" is a command that
// works; --playground and the bind address turn the page off; the page asks nothing of another
// origin (three.js is built in), and with three.js unreachable everything but the live view
// works and says why. A screenshot of each effect is
// saved (PLAYGROUND_SCREENSHOTS, default $TMPDIR/effectd-playground); docs/playground/ holds
// the ones README.md and docs/playground.md show.
// Usage: node playground.mjs EFFECTD_BINARY [CHROMIUM]
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { launchWebGl2Chromium } from './chromium.mjs';
import { check, results, startEffectd } from '../node/effectd.mjs';

const [binary, chromium = '/usr/bin/chromium'] = process.argv.slice(2);
const shots = process.env.PLAYGROUND_SCREENSHOTS || path.join(os.tmpdir(), 'effectd-playground');
fs.mkdirSync(shots, { recursive: true });

// The page is on, and only on, where it should be.
for (const [args, expect] of [[[], 200], [['--playground', 'off'], 404], [['--host', '0.0.0.0'], 404],
                              [['--host', '0.0.0.0', '--playground', 'on'], 200]]) {
  const { url, process: p } = await startEffectd(binary, args);
  const res = await fetch(`${url.replace('0.0.0.0', '127.0.0.1')}/`);
  const csp = res.headers.get('content-security-policy') || '';
  check(res.status === expect, `GET / with [${args.join(' ')}] answers ${expect}`, res.status);
  if (expect === 200) check(/script-src 'self'/.test(csp), 'the page has a Content-Security-Policy', csp);
  p.kill();
}

// The server as it is built: three.js from its own origin. The browser reaches nothing else
// (every other origin's request is aborted), as on a machine behind a firewall.
// The solver limit at 128^2 (the examples' bolts are smaller): a 240^2 bolt is over it and runs
// as a job in about a second here, half a minute under ASan.
const { url: api, process: server } = await startEffectd(binary, ['--max-solver-grid-cells', '16384']);
const browser = await launchWebGl2Chromium(chromium);
const problems = [], offOrigin = [];
let renders = 0;
async function open(url, { quiet = [] } = {}) {
  const page = await browser.newPage();
  await page.setViewport({ width: 1400, height: 900 });
  await page.setRequestInterception(true);
  page.on('request', (r) => {
    if (new URL(r.url()).origin === new URL(url).origin || r.url().startsWith('data:') || r.url().startsWith('blob:')) return r.continue();
    offOrigin.push(r.url());
    return r.abort('blockedbyclient');
  });
  page.on('console', (m) => {
    if ((m.type() === 'error' || m.type() === 'warning') && !quiet.some((q) => q.test(m.text()))) problems.push(`${m.type()}: ${m.text()}`);
  });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('request', (r) => { if (r.url().endsWith('/v1/render')) renders++; });
  await page.goto(url);
  return page;
}
// Resolves once the page has finished a run after `since` runs.
async function settled(page, since, timeout = 60000) {
  await page.waitForFunction((n) => Number(document.body.dataset.runs || 0) > n && !document.body.dataset.busy,
                             { timeout }, since);
  return page.evaluate(() => window.playground.state.last);
}
const runs = (page) => page.evaluate(() => Number(document.body.dataset.runs || 0));
// Pixels of the live canvas that differ from its corner (the clear colour), and a hash of them.
const canvasStats = (page) => page.evaluate(() => {
  const c = document.getElementById('live');
  const g = Object.assign(document.createElement('canvas'), { width: c.width, height: c.height }).getContext('2d');
  g.drawImage(c, 0, 0);
  const d = g.getImageData(0, 0, c.width, c.height).data;
  let lit = 0, hash = 0;
  for (let i = 0; i < d.length; i += 4) {
    if (Math.abs(d[i] - d[0]) + Math.abs(d[i + 1] - d[1]) + Math.abs(d[i + 2] - d[2]) > 24) lit++;
    hash = (hash * 31 + d[i] + d[i + 1] * 7 + d[i + 2] * 13) | 0;
  }
  return { lit, fraction: lit / (d.length / 4), hash };
});
// The live canvas against the preview image, both drawn at 128 x 128: the mean difference per
// channel (0-255). The same scene drawn two ways differs by the table's resolution; different
// scenes (the fog tab once showed a corridor in one and a checkerboard in the other) by far more.
const liveAgainstPreview = (page) => page.evaluate(() => {
  const pixels = (el) => {
    const g = Object.assign(document.createElement('canvas'), { width: 128, height: 128 }).getContext('2d');
    g.drawImage(el, 0, 0, 128, 128);
    return g.getImageData(0, 0, 128, 128).data;
  };
  const a = pixels(document.getElementById('live')), b = pixels(document.getElementById('preview'));
  let sum = 0;
  for (let i = 0; i < a.length; i += 4) for (let k = 0; k < 3; ++k) sum += Math.abs(a[i + k] - b[i + k]);
  return sum / (128 * 128 * 3);
});
// The preview image's size, a hash of its pixels and the colour near its centre.
const previewBytes = (page) => page.evaluate(() => {
  const img = document.getElementById('preview');
  if (img.hidden || !img.src || !img.naturalWidth) return null;
  const g = Object.assign(document.createElement('canvas'), { width: img.naturalWidth, height: img.naturalHeight }).getContext('2d');
  g.drawImage(img, 0, 0);
  const d = g.getImageData(0, 0, img.naturalWidth, img.naturalHeight).data;
  let h = 0;
  for (let i = 0; i < d.length; ++i) h = (h * 31 + d[i]) | 0;
  const c = 4 * (img.naturalWidth * Math.floor(img.naturalHeight * 0.45) + Math.floor(img.naturalWidth / 2));
  return { hash: h, width: img.naturalWidth, centre: [d[c], d[c + 1], d[c + 2]] };  // centre: a little above the middle
});

try {
  const page = await open(`${api}/`);
  await settled(page, 0);
  // At 1280 px the header is one row: the copy buttons sit beside the title.
  await page.setViewport({ width: 1280, height: 800 });
  const rows = await page.evaluate(() => ['h1', '#copy-curl', '#copy-answer-url'].map((q) => document.querySelector(q).getBoundingClientRect())
    .map((r) => Math.round(r.top + r.height / 2)));
  check(Math.max(...rows) - Math.min(...rows) < 8, 'at 1280 px the header is one row (title, copy buttons)', rows);
  await page.setViewport({ width: 1400, height: 900 });
  const examples = await page.evaluate(() => fetch('/playground/examples.json').then((r) => r.json()));
  const effects = await page.$$eval('#effects button', (bs) => bs.map((b) => b.dataset.effect));
  check(effects.join() === 'lightning,fog,bubble,tangents,scene', 'every effect can be chosen', effects);
  const shown = { lightning: '07-strike-timeline', fog: '06-engine-terms-sunset', bubble: '05-film-thickness-lights-and-gltf',
                  tangents: '02-mirrored-uvs-split', scene: '09-bolt-3d' };
  for (const effect of effects) {
    check((examples[effect] || []).length > 0, `${effect} has examples`);
    for (const { name } of examples[effect]) {
      const before = await runs(page);
      await page.evaluate((e, n) => {
        document.querySelector(`#effects button[data-effect="${e}"]`).click();
        const s = document.getElementById('example');
        s.value = n;
        s.dispatchEvent(new Event('change'));
      }, effect, name);
      const last = await settled(page, before);
      await new Promise((r) => setTimeout(r, 150));  // the live view draws on the next frame
      const live = await canvasStats(page);
      const preview = await previewBytes(page);
      const wantPreview = effect !== 'tangents';
      check(last.status === 200 && !last.error && (!wantPreview || (last.preview === 200 && preview && preview.width > 0)) &&
            live.lit > 20,
            `${effect} ${name}: answer, preview and live view`, { last, preview, live });
      // A fog preview's stage lies within the request's table.range: the paper's worked example
      // (range 0-16, fog nearly complete at 6) shows its near yellow quad at the centre, where a
      // stage 3.5 times deeper than the range once showed almost uniform grey (saturation 14).
      if (effect === 'fog' && name.startsWith('01-')) {
        const [r, g, b] = preview ? preview.centre : [0, 0, 0];
        check(Math.max(r, g, b) - Math.min(r, g, b) > 60, `${effect} ${name}: the near quad shows through the fog`, preview);
      }
      const regions = effect === 'fog' && (await page.evaluate(() => (window.playground.state.request.regions || []).length));
      if (effect === 'fog' && !regions) {  // the live view draws the global fog's table only
        const apart = await liveAgainstPreview(page);
        check(apart <= 12, `fog ${name}: the live view shows the preview's scene (mean difference ${apart.toFixed(1)}/255, at most 12)`);
      }
      if (shown[effect] === name) await page.screenshot({ path: path.join(shots, `${effect}.png`) });
    }
  }

  // The preview and the live view sit centred in their frames (an empty note beside the
  // preview once pushed it 28 px to the left).
  const offsets = await page.evaluate(() => ['preview', 'live'].map((id) => {
    const el = document.getElementById(id), frame = el.parentElement.getBoundingClientRect(), r = el.getBoundingClientRect();
    return { id, dx: (r.left + r.right) / 2 - (frame.left + frame.right) / 2, dy: (r.top + r.bottom) / 2 - (frame.top + frame.bottom) / 2 };
  }));
  check(offsets.every((o) => Math.abs(o.dx) <= 1 && Math.abs(o.dy) <= 1), 'the preview and the live view are centred in their frames', offsets);

  // Knobs: eta re-requests and changes both pictures.
  const lightning = async (example) => {
    const before = await runs(page);
    await page.evaluate((n) => {
      document.querySelector('#effects button[data-effect="lightning"]').click();
      const s = document.getElementById('example');
      s.value = n;
      s.dispatchEvent(new Event('change'));
    }, example);
    await settled(page, before);
  };
  await lightning('01-fast-128');
  const setEta = async (value) => {
    const before = await runs(page);
    await page.evaluate((v) => {
      const input = document.querySelector('input[data-pointer="/eta"]');
      input.value = v;
      input.dispatchEvent(new Event('input', { bubbles: true }));
    }, value);
    return settled(page, before);
  };
  await new Promise((r) => setTimeout(r, 150));
  const [p0, c0, r0] = [await previewBytes(page), await canvasStats(page), renders];
  const last = await setEta('0.5');
  await new Promise((r) => setTimeout(r, 150));
  const [p1, c1] = [await previewBytes(page), await canvasStats(page)];
  check(last.status === 200 && renders > r0 && p1.hash !== p0.hash && c1.hash !== c0.hash,
        'changing eta re-renders the preview and redraws the live view', { renders: renders - r0, p0, p1, c0, c1 });
  const request = await page.evaluate(() => window.playground.state.request);
  check(request.eta === 0.5, 'the form edits the request', request.eta);

  // An invalid value: the problem appears at the field it names (the browser logs the 400).
  const quiet = problems.length;
  const bad = await setEta('-3');
  problems.splice(quiet, problems.length - quiet, ...problems.slice(quiet).filter((m) => !/status of 400/.test(m)));
  const fieldError = await page.$eval('.field[data-pointer="/eta"]', (f) => ({
    invalid: f.classList.contains('invalid'), text: (f.querySelector('.field-error') || {}).textContent || '' }));
  check(bad.status === 400 && fieldError.invalid && /\/eta/.test(fieldError.text), 'an invalid eta shows its problem at the eta field',
        { bad, fieldError });
  await page.screenshot({ path: path.join(shots, 'field-error.png') });
  await setEta('2');

  // The shareable URL restores the request; "copy as curl" is a working command.
  const shared = await page.evaluate(() => location.href);
  const wanted = await page.evaluate(() => JSON.stringify(window.playground.state.request));
  const curl = await page.$eval('#curl', (e) => e.textContent);
  const second = await open(shared);
  await settled(second, 0);
  const restored = await second.evaluate(() => JSON.stringify(window.playground.state.request));
  check(restored === wanted, 'the page URL restores the request', { shared, restored });
  await second.close();
  const out = JSON.parse(execFileSync('bash', ['-c', curl], { encoding: 'utf8' }));
  check(Array.isArray(out.polylines) && out.method === 'fast', '"copy as curl" runs as a command and answers', curl.slice(0, 200));
  // "copy image URL": the answer by GET, the same bytes as the POST (the clipboard read from the
  // page's own writeText).
  const answerUrl = await page.evaluate(async () => {
    let copied = '';
    navigator.clipboard.writeText = async (text) => { copied = text; };
    document.querySelector('#copy-answer-url').click();
    await new Promise((r) => setTimeout(r, 50));
    return copied;
  });
  const byUrl = await fetch(answerUrl);
  const byPost = await fetch(`${api}/v1/lightning`, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: wanted });
  const [urlBytes, postBytes] = [Buffer.from(await byUrl.arrayBuffer()), Buffer.from(await byPost.arrayBuffer())];
  check(byUrl.status === 200 && urlBytes.equals(postBytes) && byUrl.headers.get('etag') === byPost.headers.get('etag'),
        '"copy image URL" is a GET URL answering what the POST answers, same ETag', { answerUrl: answerUrl.slice(0, 120), status: byUrl.status });

  // A GLB upload: the bubble's own glTF, sent as model/gltf-binary, answered with tangents.
  const glb = path.join(os.tmpdir(), `effectd-playground-${process.pid}.glb`);
  const res = await fetch(`${api}/v1/bubble`, { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                                body: JSON.stringify({ mesh: { level: 2 }, format: 'glb' }) });
  fs.writeFileSync(glb, Buffer.from(await res.arrayBuffer()));
  await page.evaluate(() => document.querySelector('#effects button[data-effect="tangents"]').click());
  await settled(page, await runs(page));
  const before = await runs(page);
  await (await page.$('#glb')).uploadFile(glb);
  const uploaded = await settled(page, before);
  await new Promise((r) => setTimeout(r, 150));
  const glbLive = await canvasStats(page);
  check(uploaded.status === 200 && glbLive.fraction > 0.01, 'an uploaded GLB gets tangents, drawn live', { uploaded, glbLive });
  fs.rmSync(glb);

  // A request over the synchronous limit (its 413 names --max-solver-grid-cells) runs as a job:
  // a progress bar with the ETA moves, then the answer is drawn; cancel stops a long one. Waits
  // are long for the sanitizer build, where these bolts take 30 times as long.
  const hero = (n) => ({ grid: { width: n, height: n }, method: 'dbm', neighbourhood: 4, start: [n / 2, 0],
                         targetRegion: { rows: [{ y: n - 1, runs: [[0, n]] }] }, include: ['polylines'] });
  const setRaw = (request) => page.evaluate((r) => {
    const raw = document.getElementById('raw');
    raw.value = JSON.stringify(r);
    raw.dispatchEvent(new Event('input'));
  }, request);
  await page.evaluate(() => document.querySelector('#effects button[data-effect="lightning"]').click());
  await settled(page, await runs(page));
  const quietFrom = problems.length;
  let since = await runs(page);
  await setRaw(hero(240));
  const moving = await (await page.waitForFunction(() => {
    const bar = document.getElementById('job-progress');
    return !document.getElementById('job').hidden && bar.value > 0 && bar.value < 1 &&
      { value: bar.value, text: document.getElementById('job-text').textContent };
  }, { timeout: 240000, polling: 10 })).jsonValue();
  const asJob = await settled(page, since, 240000);
  await new Promise((r) => setTimeout(r, 150));
  const [jobLive, jobState, jobBar] = [await canvasStats(page), await page.evaluate(() => window.playground.state.job),
                                       await page.$eval('#job-progress', (b) => b.value)];
  await page.screenshot({ path: path.join(shots, 'job.png') });
  check(asJob.status === 200 && jobState.state === 'done' && jobBar === 1 && /%.*cells/.test(moving.text) && jobLive.lit > 20,
        'a 240^2 dbm bolt (over the synchronous limit) runs as a job: the bar moves, then the answer is drawn',
        { moving, asJob, jobState, jobBar, jobLive });
  since = await runs(page);
  await setRaw(hero(400));
  await page.waitForFunction(() => { const j = window.playground.state.job; return j && j.state === 'running' && j.fraction > 0.03; },
                             { timeout: 240000, polling: 20 });
  const eta = await page.$eval('#job-text', (t) => t.textContent);
  await page.click('#job-cancel');
  await settled(page, since, 60000);
  const cancelled = await page.evaluate(() => window.playground.state.job);
  const jobMetrics = await (await fetch(`${api}/metrics`)).text();
  check(cancelled.state === 'cancelled' && /left/.test(eta) && /effectd_jobs_finished_total\{state="cancelled"\} 1/.test(jobMetrics),
        'a 400^2 job shows its ETA, and cancel stops it on the server', { eta, cancelled });
  // The browser logs each first answer, the 413 that sent the request to a job.
  problems.splice(quietFrom, problems.length - quietFrom, ...problems.slice(quietFrom).filter((m) => !/status of 413/.test(m)));

  check(problems.length === 0, 'no console errors or warnings', problems);
  check(offOrigin.length === 0, 'the page asks nothing of any other origin', offOrigin.slice(0, 5));
  check((await page.evaluate(() => window.playground.state.live)) === 'ready', 'the live view loaded three.js from this server');
  const csp = (await fetch(`${api}/`)).headers.get('content-security-policy');
  check(/script-src 'self';/.test(csp), "the page's scripts come from its own origin only", csp);
} finally {
  await browser.close();
  server.kill();
}

// three.js unreachable (a URL on an origin the browser cannot reach): everything but the live
// view works, and the live pane says why it is empty.
{
  const { url, process: p } = await startEffectd(binary, ['--playground-three', 'http://192.0.2.1/three.module.js']);
  const offline = await launchWebGl2Chromium(chromium);
  const before = problems.length;
  try {
    const page = await offline.newPage();
    await page.setViewport({ width: 1400, height: 900 });
    await page.setRequestInterception(true);
    page.on('request', (r) => (new URL(r.url()).origin === new URL(url).origin ? r.continue() : r.abort('blockedbyclient')));
    page.on('pageerror', (e) => problems.push(`page error without three.js: ${e.message}`));
    await page.goto(`${url}/#fog/${Buffer.from(JSON.stringify({ fog: { fogType: 'GL_EXP2', density: 0.05 } })).toString('base64url')}`);
    await page.waitForFunction(() => Number(document.body.dataset.runs || 0) > 0 && !document.body.dataset.busy, { timeout: 60000 });
    const seen = await page.evaluate(() => ({
      live: window.playground.state.live, last: window.playground.state.last,
      note: document.getElementById('live-off').textContent, noteShown: !document.getElementById('live-off').hidden,
      canvasHidden: document.getElementById('live').hidden, preview: document.getElementById('preview').naturalWidth,
      examples: document.getElementById('example').options.length, fields: document.querySelectorAll('.field').length,
      example: document.getElementById('example').selectedOptions[0]?.textContent }));
    check(seen.live.startsWith('unavailable') && seen.noteShown && seen.canvasHidden && /three\.js did not load/.test(seen.note),
          'without three.js the live pane says why it is empty', seen);
    check(seen.last && seen.last.status === 200 && seen.last.preview === 200 && seen.preview > 0 && seen.examples > 0 && seen.fields > 0,
          'without three.js the answer, preview, examples and form work', seen);
    check(problems.length === before, 'without three.js no page errors', problems.slice(before));
    check(seen.example === '(your request)', "a link's request that is no example says so in the example list", seen.example);
    await page.screenshot({ path: path.join(shots, 'no-three.png') });
  } finally {
    await offline.close();
    p.kill();
  }
}
console.log(`screenshots in ${shots}`);
process.exit(results.failures ? 1 : 0);
