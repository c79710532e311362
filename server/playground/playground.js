// The playground's page logic: the chosen effect and its request (from an example, the form,
// the raw JSON or the URL), and, a moment after each change, three requests to this server:
//   the answer     the effect's own endpoint, exactly the request shown (what "copy as curl" sends)
//   the preview    /v1/render of a small scene around the request (for a scene: the request)
//   the live view  the same request asking for what the WebGL2 view draws (timeline, table,
//                  mesh and shader); the answer itself when it already has them
// window.playground exposes the state and a run counter for the browser test.
// The live view loads apart (it imports three.js): without it, everything else works and the
// live pane says why it is empty.
import { Schemas, SchemaForm } from './schema-form.js';
import { readGlb } from './glb.js';

const EFFECTS = {
  lightning: { endpoint: '/v1/lightning', schema: 'lightning.json', animates: true },
  fog: { endpoint: '/v1/fog', schema: 'fog.json' },
  bubble: { endpoint: '/v1/bubble', schema: 'bubble.json', animates: true },
  tangents: { endpoint: '/v1/tangents', schema: 'tangents.json' },
  scene: { endpoint: '/v1/render', schema: 'scene.json' },
};
const SIZE = 384;
const $ = (id) => document.getElementById(id);
const state = { effect: 'lightning', request: {}, glb: null, runs: 0, last: null, job: null, jobRequest: null };
// The live view once three.js has loaded; until then, or when it cannot, a view that draws
// nothing (and runLive asks for nothing).
const NO_VIEW = { clear() {}, showLightning() {}, showFog() {}, showBubble() {}, showTangents() {} };
let view = NO_VIEW;
state.live = 'loading';
const liveLoaded = import('./live-view.js').then(({ LiveView }) => {
  view = new LiveView($('live'), { box: $('player'), play: $('play'), scrub: $('scrub'), clock: $('clock') });
  state.live = 'ready';
}, (err) => {
  state.live = `unavailable: ${err.message || err}`;
  $('live').hidden = true;
  $('live-off').hidden = false;
  $('live-off').textContent = `The live view is off: three.js did not load (${err.message || err}). It is built into ` +
    'effectd by scripts/setup.sh (npm), or given with --playground-three URL. The preview, answer and form work without it.';
});
let examples = {}, schemas, form, timer = 0, inFlight = null;

// ---- the small scenes the preview draws a single effect in ----

// Example 02's corridor: quads at many distances, so the fog shows depth. Its far end is 56
// units from FOG_CAMERA; fogStage scales it about the camera to the table's range.
const FOG_CAMERA = { position: [0, 1.2, 6], target: [0, 1, -10], fovY: 60 };
const FOG_STAGE = [
  { center: [0, 0, -20], normal: [0, 1, 0], up: [0, 0, -1], size: [8, 60], color: [0.35, 0.3, 0.25] },
  { center: [-4, 2, -20], normal: [1, 0, 0], size: [60, 4], up: [0, 1, 0], color: [0.6, 0.25, 0.2] },
  { center: [4, 2, -20], normal: [-1, 0, 0], size: [60, 4], up: [0, 1, 0], color: [0.2, 0.35, 0.6] },
  { center: [0, 1.5, 0], size: [1.2, 1.2], color: [0.9, 0.8, 0.2] },
  { center: [-1.5, 1.5, -12], size: [1.2, 1.2], color: [0.9, 0.8, 0.2] },
  { center: [1.5, 1.5, -30], size: [1.2, 1.2], color: [0.9, 0.8, 0.2] },
];
// The stage scaled about the camera so that its far end lies at the request's table.range[1]
// (the distances the table says the scene spans): the same picture, with the fog the request's
// own distances give. Without a range, as it stands.
function fogStage(req) {
  const far = req.table && Array.isArray(req.table.range) ? Number(req.table.range[1]) : NaN;
  const s = far > 0 && Number.isFinite(far) ? far / 56 : 1, eye = FOG_CAMERA.position;
  return FOG_STAGE.map((q) => ({ ...q, center: q.center.map((c, i) => eye[i] + (c - eye[i]) * s), size: q.size.map((v) => v * s) }));
}
// /v1/render's camera where a scene names none (scene.json's defaults).
const DEFAULT_CAMERA = { position: [0, 1, 6], target: [0, 0.5, 0], fovY: 45 };
const NIGHT = { gradient: { top: [0.03, 0.03, 0.08], bottom: [0.12, 0.12, 0.2] } };
const SKY = { zenith: [0.35, 0.6, 1.0], horizon: [1.0, 0.98, 0.95], ground: [0.16, 0.18, 0.12] };

function previewScene(effect, req, animate) {
  const frames = (fps) => (animate ? { count: 36, fps, format: 'gif' } : undefined);
  switch (effect) {
    case 'lightning':
      return { width: SIZE, height: SIZE, background: NIGHT, lightning: req, frames: frames(24) };
    case 'fog':
      return { width: SIZE, height: SIZE, camera: FOG_CAMERA,
               background: { color: (req.fog && req.fog.color) || [0.55, 0.6, 0.68] }, quads: fogStage(req), fog: req };
    case 'bubble': {
      const { camera, format, ...bubble } = req;  // the scene's camera draws it
      return { width: SIZE, height: SIZE, camera: { position: [0, 0.3, 4], target: [0, 0, 0], fovY: 45 },
               background: { color: [0.1, 0.12, 0.1] }, environment: SKY, bubble, frames: frames(12) };
    }
    case 'scene': return req;
    default: return null;
  }
}

const withInclude = (req, extra, fallback) => [...new Set([...(req.include || fallback), ...extra])];

// The request whose answer the live view draws, or null when it cannot draw the effect.
function liveRequest(effect, req) {
  switch (effect) {
    case 'lightning': { const { format, ...bolt } = req; return { ...bolt, include: withInclude(req, ['mesh', 'timeline'], ['polylines']) }; }
    case 'fog': return { ...req, table: { ...(req.table || {}), encoding: 'rgba16f' }, include: withInclude(req, ['table'], ['table']) };
    case 'bubble': {
      const { format, ...b } = req;
      b.shader = { ...(req.shader || {}), language: 'glsl-es-300' };
      const table = { ...b, thinFilm: { ...(req.thinFilm || {}), encoding: 'rgba16f' } };
      if (req.shading === 'paper')  // the paper's iridescence reads the thin-film table too
        return req.features && req.features.iridescence ? { ...table, include: ['mesh', 'uniforms', 'shader', 'thinFilm'] }
                                                        : { ...b, include: ['mesh', 'uniforms', 'shader'] };
      return { ...table, film: { ...(req.film || {}), encoding: 'r32f' }, include: ['mesh', 'uniforms', 'shader', 'thinFilm', 'thickness'] };
    }
    default: return null;
  }
}

// ---- talking to the server ----

async function post(path, body, signal) {
  const binary = body instanceof ArrayBuffer;
  const started = performance.now();
  const res = await fetch(path, {
    method: 'POST', signal, body: binary ? body : JSON.stringify(body),
    headers: { 'Content-Type': binary ? 'model/gltf-binary' : 'application/json' },
  });
  const blob = await res.blob();
  return { res, blob, ms: performance.now() - started };
}

const isJson = (res) => /json/.test(res.headers.get('Content-Type') || '');

// A request over the server's synchronous limits (its 413 names the limit a job lifts) runs as a
// job: queued with Prefer: respond-async, followed through its events with a progress bar, the
// ETA and a cancel button, and its answer fetched once done (docs/api.md, "Jobs").
const overSyncLimit = (problem) => /--max-solver-(grid|volume)-cells/.test((problem && problem.detail) || '');

function seconds(s) {
  return s < 60 ? `${s.toFixed(1)} s` : `${Math.floor(s / 60)} min ${String(Math.floor(s % 60)).padStart(2, '0')} s`;
}

async function runJob(path, body, signal) {
  const started = performance.now();
  const queued = await fetch(path, { method: 'POST', signal, body: JSON.stringify(body),
                                     headers: { 'Content-Type': 'application/json', Prefer: 'respond-async' } });
  if (queued.status !== 202) return { res: queued, blob: await queued.blob(), ms: performance.now() - started };
  const job = queued.headers.get('Location');
  const panel = $('job'), bar = $('job-progress'), text = $('job-text');
  state.job = { location: job, state: 'queued', fraction: 0 };
  panel.hidden = false;
  bar.value = 0;
  text.textContent = 'queued';
  const cancel = () => fetch(job, { method: 'DELETE' }).catch(() => {});
  $('job-cancel').onclick = cancel;
  $('job-cancel').disabled = false;
  signal.addEventListener('abort', cancel);  // a newer request replaces this one
  try {
    const final = await new Promise((resolve) => {
      const events = new EventSource(`${job}/events`);
      const show = (e) => {
        const s = JSON.parse(e.data), p = s.progress;
        state.job = { location: job, state: s.state, fraction: p.fraction };
        bar.value = p.fraction;
        text.textContent = `${(100 * p.fraction).toFixed(0)} %  ${s.state}  ${p.cells} cells  ${seconds(s.runningS)}` +
          (s.state === 'running' && p.etaS !== null ? `, at least ${seconds(p.etaS)} left` : '');
        if (s.state === 'done' || s.state === 'failed' || s.state === 'cancelled') {
          events.close();
          resolve(s.state);
        }
      };
      for (const name of ['progress', 'done', 'failed', 'cancelled']) events.addEventListener(name, show);
      events.onerror = () => { if (events.readyState === EventSource.CLOSED) resolve('lost'); };
      signal.addEventListener('abort', () => { events.close(); resolve('replaced'); });
    });
    $('job-cancel').disabled = true;
    if (final === 'cancelled' || final === 'replaced' || final === 'lost') {
      text.textContent += final === 'cancelled' ? ' (cancelled)' : '';
      return null;
    }
    const res = await fetch(`${job}/result`, { signal });
    return { res, blob: await res.blob(), ms: performance.now() - started };
  } finally {
    signal.removeEventListener('abort', cancel);
  }
}

function serverTiming(res) {
  const h = res.headers.get('Server-Timing');
  if (!h) return '';
  return h.split(',').map((part) => {
    const [name, ...params] = part.trim().split(';');
    const dur = params.map((p) => p.trim()).find((p) => p.startsWith('dur='));
    return dur ? `${name} ${Number(dur.slice(4)).toFixed(3)} ms` : name;
  }).join(', ');
}

// The answer's error against its reference, wherever the effect reports it.
function errorFigure(answer) {
  const e = answer && (answer.error || (answer.table && answer.table.maxError !== undefined && { maxError: answer.table.maxError }));
  if (!e) return 'not asked for (add "error" to include, where the effect has it)';
  if (typeof e !== 'object') return String(e);
  const main = ['maxError', 'meanError', 'rmsError', 'hausdorff', 'maxAngleDegrees'].filter((k) => e[k] !== undefined)
    .map((k) => `${k} ${Number(e[k]).toPrecision(3)}`);
  const rest = [e.metric, e.reference && `against ${e.reference}`].filter(Boolean).join(', ');
  return (main.length ? main.join(', ') : JSON.stringify(e).slice(0, 240)) + (rest ? ` (${rest})` : '');
}

function showAnswer({ res, blob, ms }, answer) {
  $('a-status').textContent = `${res.status} ${res.statusText}`;
  $('a-method').textContent = (answer && answer.method) || res.headers.get('X-Effect-Method') || res.headers.get('X-Renderer') || '';
  $('a-time').textContent = `${serverTiming(res)}${serverTiming(res) ? '; ' : ''}round trip ${ms.toFixed(1)} ms`;
  $('a-error').textContent = res.ok ? (state.effect === 'scene' ? 'see each effect' : errorFigure(answer)) : '';
  const wire = res.headers.get('Content-Length'), coding = res.headers.get('Content-Encoding');
  $('a-size').textContent = `${blob.size} bytes ${res.headers.get('Content-Type') || ''}` +
    (coding && wire ? `; ${wire} bytes on the wire (${coding})` : '');
}

function showProblems(problem) {
  const list = $('problems');
  list.replaceChildren();
  const errors = problem ? (problem.errors && problem.errors.length ? problem.errors : [{ pointer: '', message: problem.detail || problem.title }]) : [];
  const homeless = form.showErrors(errors);
  for (const e of problem ? errors : []) {
    const li = document.createElement('li');
    li.textContent = `${e.pointer || '/'}: ${e.message}`;
    list.append(li);
  }
  return homeless;
}

function noPreview(why) {
  $('preview').hidden = true;
  $('preview-note').textContent = why;
  return { status: 0 };
}

async function runPreview(signal) {
  const img = $('preview'), note = $('preview-note');
  const scene = previewScene(state.effect, state.request, $('animate').checked);
  if (!scene || state.glb) {
    img.hidden = true;
    note.textContent = 'tangents have no picture of their own: the live view shows each vertex\'s frame';
    return { status: 0 };
  }
  const r = await post('/v1/render', scene, signal);
  if (!r.res.ok) {
    img.hidden = true;
    const p = isJson(r.res) ? JSON.parse(await r.blob.text()) : null;
    note.textContent = `preview: ${r.res.status} ${p ? p.detail : ''}`;
    return { status: r.res.status, r };
  }
  if (img.src) URL.revokeObjectURL(img.src);
  img.src = URL.createObjectURL(r.blob);
  await img.decode().catch(() => {});
  img.hidden = false;
  note.textContent = '';
  return { status: r.res.status, r };
}

async function runLive(answer, signal) {
  const effect = state.effect, req = state.request;
  $('live-note').textContent = '';
  await liveLoaded;
  if (view === NO_VIEW) return;  // nothing to draw with: no requests for it either
  if (effect === 'tangents') {
    if (!answer) return view.clear();
    if (state.glb) return view.showTangents(answer);
    // Without a split the answer keeps the request's vertices and triangles.
    const remap = answer.remap || Array.from({ length: answer.vertexCount }, (_, i) => i);
    const pick = (src, n) => src && Float32Array.from({ length: remap.length * n }, (_, i) => src[remap[Math.floor(i / n)] * n + (i % n)]);
    return view.showTangents({ positions: pick(req.mesh.positions, 3), normals: pick(req.mesh.normals, 3),
                               tangents: answer.tangents, indices: answer.indices || req.mesh.indices });
  }
  // A scene: its bolt, else its bubble, else its fog.
  let kind = effect, sub = req;
  if (effect === 'scene') {
    const first = req.bubble || (req.bubbles && req.bubbles.length && req.bubbles[0].bubble);
    [kind, sub] = [['lightning', req.lightning], ['bubble', first], ['fog', req.fog]].find(([, v]) => v) || [null, null];
  }
  const live = kind && liveRequest(kind, sub);
  if (!live) return view.clear();
  const same = effect === kind && JSON.stringify(live) === JSON.stringify(state.jobRequest || req);
  let data = same ? answer : null;
  if (!data) {
    const r = await post(EFFECTS[kind].endpoint, live, signal);
    if (!r.res.ok) {
      $('live-note').textContent = `(${r.res.status})`;
      return view.clear();
    }
    data = JSON.parse(await r.blob.text());
  }
  if (kind === 'lightning') view.showLightning(data);
  else if (kind === 'fog') {
    // The preview's scene: a scene's own quads, camera and backdrop where it has them.
    const stage = previewScene('fog', sub);
    if (effect === 'scene') {
      if (req.quads) stage.quads = req.quads;
      if (req.camera) stage.camera = { ...DEFAULT_CAMERA, ...req.camera };
      if (req.background && req.background.color) stage.background = req.background;
    }
    view.showFog(data, stage);
    const onlyInPreview = [sub.fog && sub.fog.directional && 'the directional glow', sub.regions && sub.regions.length && 'the local regions'].filter(Boolean);
    if (onlyInPreview.length) $('live-note').textContent = `(${onlyInPreview.join(' and ')}: in the preview only)`;
  }
  else view.showBubble(data);
}

async function run() {
  if (inFlight) inFlight.abort();
  const controller = new AbortController();
  inFlight = controller;
  const { signal } = controller;
  document.body.dataset.busy = '1';
  const body = state.glb ? state.glb.bytes : state.request;
  updateLinks();
  try {
    let answer = null, main;
    if (state.effect === 'scene') {
      const p = await runPreview(signal);
      main = p.r;
    } else {
      $('job').hidden = true;
      main = await post(EFFECTS[state.effect].endpoint, body, signal);
      state.jobRequest = null;
      if (main.res.status === 413 && !state.glb && isJson(main.res) && overSyncLimit(JSON.parse(await main.blob.text()))) {
        // The job asks for what the live view draws too (a bolt's mesh and strike), so that the
        // long work runs once: its answer holds the request's own fields and those.
        state.jobRequest = liveRequest(state.effect, body) || body;
        main = await runJob(EFFECTS[state.effect].endpoint, state.jobRequest, signal);
      }
      if (!main && signal.aborted) return;
    }
    if (main) {
      if (isJson(main.res)) answer = JSON.parse(await main.blob.text());
      else if (state.glb && main.res.ok) answer = readGlb(await main.blob.arrayBuffer());
      showAnswer(main, answer);
      $('answer-text').textContent = answer && !state.glb ? JSON.stringify(answer, null, 1).slice(0, 20000)
        : `${main.blob.size} bytes of ${main.res.headers.get('Content-Type')}`;
    }
    const failed = !main || !main.res.ok;
    const asJob = state.job && state.job.location && !$('job').hidden;
    showProblems(failed && answer ? answer : null);
    const [preview] = await Promise.all([
      state.effect === 'scene' ? Promise.resolve({ status: main ? main.res.status : 0 })
        : failed ? null : asJob ? noPreview('over the synchronous limits, this ran as a job (with the live view\'s mesh and strike): the live view draws its answer')
          : runPreview(signal),
      failed ? view.clear() : runLive(answer, signal),
    ]);
    state.last = { status: main ? main.res.status : 0, preview: preview ? preview.status : 0, error: null };
  } catch (err) {
    if (signal.aborted) return;
    state.last = { status: 0, error: String(err) };
    $('problems').replaceChildren(Object.assign(document.createElement('li'), { textContent: String(err) }));
  } finally {
    if (inFlight === controller) {
      inFlight = null;
      state.runs += 1;
      document.body.dataset.busy = '';
      document.body.dataset.runs = String(state.runs);
    }
  }
}

function schedule() {
  clearTimeout(timer);
  timer = setTimeout(run, 300);
}

// ---- the request shown: form, raw JSON, URL, curl ----

function renderRequest() {
  form.render(`${EFFECTS[state.effect].schema}#`, state.request);
  $('raw').value = JSON.stringify(state.request, null, 1);
  $('raw-error').hidden = true;
}

function edited() {
  if (document.activeElement !== $('raw')) $('raw').value = JSON.stringify(state.request, null, 1);
  schedule();
}

const base64url = (text) => btoa(String.fromCharCode(...new TextEncoder().encode(text))).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
const fromBase64url = (s) => new TextDecoder().decode(Uint8Array.from(atob(s.replace(/-/g, '+').replace(/_/g, '/')), (c) => c.charCodeAt(0)));

function shareUrl() {
  return `${location.origin}${location.pathname}#${state.effect}/${base64url(JSON.stringify(state.request))}`;
}

// The answer itself by URL (GET <endpoint>?r=): an <img src> for a scene's preview, cacheable by
// CDNs; a server with --url-signing-key-file needs it signed by the key's owner (docs/serving.md).
function answerUrl() {
  return `${location.origin}${EFFECTS[state.effect].endpoint}?r=${base64url(JSON.stringify(state.request))}`;
}

function curl() {
  const url = `${location.origin}${EFFECTS[state.effect].endpoint}`;
  if (state.glb) return `curl -sS ${url} -H 'Content-Type: model/gltf-binary' --data-binary @'${state.glb.name.replace(/'/g, '')}' -o tangents.glb`;
  const quoted = JSON.stringify(state.request).replace(/'/g, `'\\''`);
  const frames = state.request.frames;
  const out = state.effect === 'scene' ? ` -o preview.${frames && frames.format !== 'flipbook' ? 'gif' : 'png'}` : '';
  return `curl -sS ${url} -H 'Content-Type: application/json' --data-binary '${quoted}'${out}`;
}

function updateLinks() {
  history.replaceState(null, '', state.glb ? location.pathname : shareUrl());
  $('curl').textContent = curl();
  $('copy-answer-url').disabled = Boolean(state.glb);  // a binary body has no URL form
}

async function copy(text, button) {
  try {
    await navigator.clipboard.writeText(text);
  } catch {
    const area = Object.assign(document.createElement('textarea'), { value: text });
    document.body.append(area);
    area.select();
    document.execCommand('copy');
    area.remove();
  }
  const label = button.textContent;
  button.textContent = 'copied';
  setTimeout(() => { button.textContent = label; }, 1200);
}

// ---- choosing effects and examples ----

function setEffect(effect, request, exampleName) {
  state.effect = effect;
  state.request = request;
  state.glb = null;
  for (const b of $('effects').children) b.setAttribute('aria-pressed', String(b.dataset.effect === effect));
  // The example the request is (a link's request may be one), else a first entry saying so.
  const select = $('example'), list = examples[effect] || [];
  const name = exampleName || (list.find((e) => JSON.stringify(e.request) === JSON.stringify(request)) || {}).name;
  const options = list.map((e) => Object.assign(document.createElement('option'), { textContent: e.name, value: e.name }));
  if (!name) options.unshift(Object.assign(document.createElement('option'), { textContent: '(your request)', value: '', disabled: true }));
  select.replaceChildren(...options);
  select.value = name || '';
  $('endpoint').textContent = `POST ${EFFECTS[effect].endpoint}`;
  $('upload').hidden = effect !== 'tangents';
  $('glb').value = '';
  $('glb-name').textContent = '';
  $('glb-clear').hidden = true;
  $('form').hidden = document.querySelector('[data-tab="form"]').getAttribute('aria-selected') !== 'true';
  $('animate').parentElement.hidden = !EFFECTS[effect].animates;
  renderRequest();
  schedule();
}

function loadExample(effect, name) {
  const e = (examples[effect] || []).find((x) => x.name === name) || (examples[effect] || [])[0];
  setEffect(effect, e ? structuredClone(e.request) : {}, e && e.name);
}

function fromHash() {
  const m = location.hash.match(/^#(\w+)\/([A-Za-z0-9_-]*)$/);
  if (!m || !EFFECTS[m[1]]) return false;
  try {
    setEffect(m[1], JSON.parse(fromBase64url(m[2])));
    return true;
  } catch {
    return false;
  }
}

async function main() {
  [examples, schemas] = await Promise.all([
    fetch('/playground/examples.json').then((r) => r.json()),
    Schemas.load('/v1/schemas/', ['common.json', ...new Set(Object.values(EFFECTS).map((e) => e.schema))]),
  ]);
  form = new SchemaForm($('form'), schemas, { onEdit: edited, onShape: () => { renderRequest(); schedule(); } });
  for (const effect of Object.keys(EFFECTS)) {
    $('effects').append(Object.assign(document.createElement('button'), {
      type: 'button', textContent: effect, onclick: () => loadExample(effect),
    }));
    $('effects').lastChild.dataset.effect = effect;
  }
  $('example').addEventListener('change', (e) => loadExample(state.effect, e.target.value));
  $('raw').addEventListener('input', (e) => {
    try {
      const value = JSON.parse(e.target.value);
      if (!value || typeof value !== 'object' || Array.isArray(value)) throw new Error('the request is a JSON object');
      state.request = value;
      $('raw-error').hidden = true;
      form.render(`${EFFECTS[state.effect].schema}#`, state.request);
      schedule();
    } catch (err) {
      $('raw-error').textContent = `JSON: ${err.message}`;
      $('raw-error').hidden = false;
    }
  });
  for (const tab of document.querySelectorAll('[data-tab]')) {
    tab.addEventListener('click', () => {
      for (const t of document.querySelectorAll('[data-tab]')) t.setAttribute('aria-selected', String(t === tab));
      for (const p of document.querySelectorAll('[data-tab-panel]')) p.hidden = p.dataset.tabPanel !== tab.dataset.tab;
      if (tab.dataset.tab === 'json') $('raw').value = JSON.stringify(state.request, null, 1);
    });
  }
  $('animate').addEventListener('change', schedule);
  $('copy-curl').addEventListener('click', (e) => copy(curl(), e.target));
  $('copy-json').addEventListener('click', (e) => copy(JSON.stringify(state.request, null, 1), e.target));
  $('copy-link').addEventListener('click', (e) => copy(shareUrl(), e.target));
  $('copy-answer-url').addEventListener('click', (e) => copy(answerUrl(), e.target));
  $('glb').addEventListener('change', async (e) => {
    const file = e.target.files[0];
    if (!file) return;
    state.glb = { name: file.name, bytes: await file.arrayBuffer() };
    $('glb-name').textContent = `${file.name}, ${state.glb.bytes.byteLength} bytes: sent as model/gltf-binary; the answer is the same glTF with TANGENT`;
    $('glb-clear').hidden = false;
    $('form').hidden = true;
    schedule();
  });
  $('glb-clear').addEventListener('click', () => loadExample('tangents'));
  if (!fromHash()) loadExample('lightning', '07-strike-timeline');
}

window.playground = { state, run };
main().catch((err) => {
  document.body.dataset.fatal = String(err);
  console.error(err);
});
