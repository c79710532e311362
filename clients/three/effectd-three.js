// effectd's answers as three.js objects. An ES module that imports 'three' by its bare name, so an
// import map or a bundler chooses the build; tested with three r187 (tests/browser/three_kit.mjs).
//
//   bolt      boltFromGltf(gltf) / boltFromAnswer(answer): the ribbons of /v1/lightning (format glb,
//             or include mesh) drawn additively; with a timeline, bolt.setTime(t) plays the strike
//   bubble    bubbleFromAnswer(answer, { environment }): /v1/bubble's own GLSL ES 3.00 as raw
//             shader materials, its uniforms and textures, in the draws the answer names; the GLB
//             (format glb) needs nothing: GLTFLoader reads its iridescent material
//   fog       fogTexture(answer) and applyFog(material, answer): /v1/fog's table as a DataTexture,
//             applied per fragment to any built-in material through onBeforeCompile
//   tangents  /v1/tangents' GLB needs nothing: GLTFLoader reads TANGENT and normal maps use it
//   glow      apsfGlow(renderer, fogAnswer.glow): a bolt seen through fog, its core dimmed and its
//             glow the fog's point spread function, as the preview draws it
//
// Colours: effectd's shaders and tables work in the values its previews write (no sRGB encoding
// of their own), so the raw shaders here write them unchanged, and fog is applied after three's
// colour-space conversion, where the preview applies it.
import * as THREE from 'three';

const bytesOf = (base64) => Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));

// ---- lightning --------------------------------------------------------------------------------

// The strike as docs/effects.md §1.6 plays it, per vertex in the vertex shader: dark before the
// leader reaches it (or if it never does), the leader channel until its stroke arrives, then
// the main or branches channel at t - strokeDelay; times the vertex's intensity. The keyframes
// (t, leader, main, branches) are a 1-row float texture searched by bisection.
const BOLT_VS = `
attribute float _leader;
attribute float _stroke_delay;
attribute vec3 _across;  // from the ribbon's middle to this edge, without the join's mitre (the kit adds it)
uniform float uWiden;    // 1: the core; more: the glow around it
uniform sampler2D uKeys;
uniform int uKeyCount;
uniform float uTime, uConnect;
uniform bool uTimed, uMain;
varying vec2 vUv;
varying float vBrightness;
vec4 keyAt(int i) { return texelFetch(uKeys, ivec2(i, 0), 0); }
vec3 channels(float t) {  // (leader, main, branches) at t: linear between keyframes, 0 outside
  if (t < keyAt(0).x || t > keyAt(uKeyCount - 1).x) return vec3(0.0);
  int lo = 0, hi = uKeyCount - 1;
  for (int k = 0; k < 16 && hi - lo > 1; ++k) {
    int mid = (lo + hi) / 2;
    if (keyAt(mid).x <= t) lo = mid; else hi = mid;
  }
  vec4 a = keyAt(lo), b = keyAt(hi);
  return mix(a.yzw, b.yzw, clamp((t - a.x) / max(b.x - a.x, 1e-30), 0.0, 1.0));
}
void main() {
  vUv = uv;
  float b = color.r;  // the vertex's intensity
  if (uTimed) {
    if (_leader > uConnect || uTime < _leader) b = 0.0;
    else if (uTime < uConnect + _stroke_delay) b *= channels(uTime).x;
    else { vec3 c = channels(uTime - _stroke_delay); b *= uMain ? c.y : c.z; }
  }
  vBrightness = b;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position + _across * (uWiden - 1.0), 1.0);
}`;
// The core: the profile across the ribbon. The glow: a Gaussian across a ribbon uWiden times as
// wide, uGain as bright (a bloom without a post-process; the preview blurs its core instead).
const BOLT_FS = `
uniform sampler2D uProfile;
uniform vec3 uColor;
uniform bool uGlow;
uniform float uGain;
uniform float uThrough;  // what the fog between the camera and the bolt lets through (apsfGlow sets it)
varying vec2 vUv;
varying float vBrightness;
void main() {
  float v = 2.0 * vUv.y - 1.0;
  float across = uGlow ? uGain * exp(-4.0 * v * v) : texture2D(uProfile, vec2(0.5, vUv.y)).a;
  gl_FragColor = vec4(uColor * (vBrightness * across * uThrough), 1.0);
}`;

// Each vertex's offset from its ribbon's middle: the ribbons' vertices come in pairs (2k, 2k + 1),
// the two edges at one polyline vertex (server/api/bolt_ribbons.cpp). A sharp join's offset is
// mitred (up to twice the half width); cut back to the ribbon's median half width, the glow
// `width` times as wide does not grow the mitre's point `width` times as long.
function acrossAttribute(geometry) {
  const p = geometry.attributes.position, out = new Float32Array(p.count * 3), lengths = new Float32Array(p.count);
  for (let i = 0; i < p.count; ++i) {
    for (let k = 0; k < 3; ++k) out[3 * i + k] = 0.5 * (p.getComponent(i, k) - p.getComponent(i ^ 1, k));
    lengths[i] = Math.hypot(out[3 * i], out[3 * i + 1], out[3 * i + 2]);
  }
  const half = [...lengths].sort((a, b) => a - b)[p.count >> 1] || 0;
  for (let i = 0; i < p.count; ++i)
    if (lengths[i] > half) for (let k = 0; k < 3; ++k) out[3 * i + k] *= half / lengths[i];
  geometry.setAttribute('_across', new THREE.BufferAttribute(out, 3));
}

// The channel's cross-section over v, as the GLB embeds it (server/api/bolt_glb.cpp): 1 x 32 texels,
// alpha 1 over the middle third, smoothstep to 0 at the edges, 8 bits.
function profileTexture() {
  const data = new Uint8Array(32 * 4).fill(255);
  for (let y = 0; y < 32; ++y) {
    const x = Math.min(Math.max(3 * (1 - Math.abs(2 * ((y + 0.5) / 32) - 1)), 0), 1);
    data[4 * y + 3] = Math.round(255 * x * x * (3 - 2 * x));
  }
  return Object.assign(new THREE.DataTexture(data, 1, 32), { magFilter: THREE.LinearFilter, minFilter: THREE.LinearFilter, needsUpdate: true });
}

function keyTexture(timeline) {
  const k = timeline.keyframes, n = k.t.length, data = new Float32Array(n * 4);
  for (let i = 0; i < n; ++i) data.set([k.t[i], k.leader[i], k.main[i], k.branches[i]], 4 * i);
  const texture = new THREE.DataTexture(data, n, 1, THREE.RGBAFormat, THREE.FloatType);
  texture.needsUpdate = true;
  return texture;
}

// parts: [{ main, geometry (position, uv, color; _leader and _stroke_delay with a timeline) }].
// glow: null, or {width (times the core's), strength}: a soft wider ribbon drawn under the core.
function makeBolt(parts, timeline, { color = [0.75, 0.85, 1.0], profile = null, glow = null } = {}) {
  const group = new THREE.Group();
  group.name = 'effectd bolt';
  const keys = timeline ? keyTexture(timeline) : null;
  const materials = [];
  for (const { main, geometry } of parts) {
    acrossAttribute(geometry);
    for (const layer of glow ? ['glow', 'core'] : ['core']) {
      const material = new THREE.ShaderMaterial({
        vertexShader: BOLT_VS,
        fragmentShader: BOLT_FS,
        vertexColors: true,
        uniforms: {
          uKeys: { value: keys }, uKeyCount: { value: timeline ? timeline.keyframes.t.length : 0 },
          uTime: { value: 0 }, uConnect: { value: timeline ? timeline.connect : 0 }, uTimed: { value: Boolean(timeline) },
          uMain: { value: main }, uProfile: { value: profile || profileTexture() },
          uColor: { value: new THREE.Color(...color) },  // display values, as the preview's
          uGlow: { value: layer === 'glow' }, uWiden: { value: layer === 'glow' ? glow.width : 1 },
          uGain: { value: layer === 'glow' ? glow.strength : 1 }, uThrough: { value: 1 },
        },
        blending: THREE.AdditiveBlending, transparent: true, depthWrite: false, side: THREE.DoubleSide,
      });
      materials.push(material);
      const mesh = new THREE.Mesh(geometry, material);
      mesh.name = (main ? 'main' : 'branches') + (layer === 'glow' ? ' glow' : '');
      mesh.frustumCulled = false;
      group.add(mesh);
    }
  }
  return {
    object: group,
    timeline,
    duration: timeline ? timeline.duration : 0,
    // Game seconds since the leader set off (the answer's timeline times).
    setTime(t) { for (const m of materials) m.uniforms.uTime.value = t; },
    // The share of its light the fog lets through to the eye (1: clear air); apsfGlow sets it.
    setThrough(f) { for (const m of materials) m.uniforms.uThrough.value = f; },
    dispose() { for (const m of materials) m.dispose(); for (const c of group.children) c.geometry.dispose(); if (keys) keys.dispose(); },
  };
}

// A /v1/lightning GLB as GLTFLoader gives it (format glb; include timeline for setTime).
export function boltFromGltf(gltf, options = {}) {
  const parts = [];
  let profile = null;
  gltf.scene.traverse((o) => {
    if (!o.isMesh) return;
    const g = o.geometry;
    if (g.attributes.color && g.attributes.color.itemSize === 4) {  // three may widen COLOR_0
      const c = g.attributes.color, rgb = new Float32Array(c.count * 3);
      for (let i = 0; i < c.count; ++i) rgb.set([c.getX(i), c.getY(i), c.getZ(i)], 3 * i);
      g.setAttribute('color', new THREE.BufferAttribute(rgb, 3));
    }
    profile = profile || o.material.map || null;
    parts.push({ main: o.name === 'main', geometry: g });  // nodes main and branches
  });
  return makeBolt(parts, gltf.scene.userData.timeline || null, { ...options, profile });
}

// A /v1/lightning JSON answer with include mesh (and timeline for setTime).
export function boltFromAnswer(answer, options = {}) {
  if (!answer.mesh) throw new Error('the answer has no mesh: ask for include ["mesh"]');
  const timed = Boolean(answer.timeline);
  const parts = answer.mesh.primitives.map((p) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(p.positions, 3));
    g.setAttribute('uv', new THREE.Float32BufferAttribute(p.uvs, 2));
    g.setAttribute('color', new THREE.Float32BufferAttribute(p.intensity.flatMap((i) => [i, i, i]), 3));
    const zeros = () => new THREE.Float32BufferAttribute(new Float32Array(p.intensity.length), 1);
    g.setAttribute('_leader', timed ? new THREE.Float32BufferAttribute(p.leader, 1) : zeros());
    g.setAttribute('_stroke_delay', timed ? new THREE.Float32BufferAttribute(p.strokeDelay, 1) : zeros());
    g.setIndex(p.indices);
    return { main: p.channel === 'main', geometry: g };
  });
  return makeBolt(parts, answer.timeline || null, options);
}

// ---- the glow through fog -----------------------------------------------------------------------

const SCREEN_VS = `in vec3 position;
out vec2 vUv;
void main() { vUv = position.xy * 0.5 + 0.5; gl_Position = vec4(position.xy, 0.0, 1.0); }`;
const BLUR_FS = `precision highp float;
uniform sampler2D uSource;
uniform float uLod;
uniform vec2 uStep;
uniform int uRadius;
uniform float uWeights[65];
in vec2 vUv;
out vec4 fragColor;
void main() {
  vec4 sum = uWeights[0] * textureLod(uSource, vUv, uLod);
  for (int i = 1; i <= uRadius; ++i)
    sum += uWeights[i] * (textureLod(uSource, vUv + float(i) * uStep, uLod) + textureLod(uSource, vUv - float(i) * uStep, uLod));
  fragColor = sum;
}`;
const GLOW_FS = `precision highp float;
uniform sampler2D uGlow0, uGlow1, uGlow2;
uniform vec3 uWeights;
uniform vec3 uColor;
in vec2 vUv;
out vec4 fragColor;
void main() {
  float light = uWeights.x * texture(uGlow0, vUv).r + uWeights.y * texture(uGlow1, vUv).r + uWeights.z * texture(uGlow2, vUv).r;
  fragColor = vec4(uColor * light, 1.0);
}`;

// The glow of a bolt seen through fog, as effectd's preview draws it (docs/rendering.md "The bolt
// in fog"): `glow` is /v1/fog's answer.glow (include ["glow"], the camera and the bolt's middle
// as its ray, or the optical thickness). render(scene, camera, bolt) draws the scene with the
// bolt's core dimmed to glow.direct, then adds glowStrength x radiance x glow.scattered x each
// fitted Gaussian's weight x the bolt's light blurred by that Gaussian (sigma in radians times
// the camera's focal length in pixels, at the mip level where it is 8 to 16 texels wide).
// The bolt is a boltFromGltf / boltFromAnswer object already in `scene`. Simplified: one
// transmittance for the whole core (the preview's is per vertex), and the glow is not hidden by
// the scene's geometry (neither is the preview's).
export function apsfGlow(renderer, glow, { radiance = 100, glowStrength = 1.5, color = [0.75, 0.85, 1.0] } = {}) {
  if (!glow || !glow.gaussians) throw new Error('glow: /v1/fog answer.glow with a gaussian kernel (include ["glow"])');
  const half = { type: THREE.HalfFloatType, depthBuffer: false };
  const core = new THREE.WebGLRenderTarget(1, 1, { ...half, generateMipmaps: true, minFilter: THREE.LinearMipmapNearestFilter });
  const temps = glow.gaussians.map(() => new THREE.WebGLRenderTarget(1, 1, half));
  const outs = glow.gaussians.map(() => new THREE.WebGLRenderTarget(1, 1, half));
  const quad = new THREE.Mesh(new THREE.PlaneGeometry(2, 2));
  quad.frustumCulled = false;
  const screen = new THREE.Scene().add(quad), screenCamera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1);
  const blur = new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3, vertexShader: SCREEN_VS, fragmentShader: BLUR_FS, depthTest: false, depthWrite: false,
    uniforms: { uSource: { value: null }, uLod: { value: 0 }, uStep: { value: new THREE.Vector2() }, uRadius: { value: 1 },
                uWeights: { value: new Array(65).fill(0) } },
  });
  const add = new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3, vertexShader: SCREEN_VS, fragmentShader: GLOW_FS, depthTest: false, depthWrite: false,
    blending: THREE.AdditiveBlending, transparent: true,
    uniforms: { uGlow0: { value: null }, uGlow1: { value: null }, uGlow2: { value: null }, uWeights: { value: new THREE.Vector3() },
                uColor: { value: new THREE.Color(...color) } },
  });
  const size = new THREE.Vector2();
  const pass = (material, target) => {
    quad.material = material;
    renderer.setRenderTarget(target);
    renderer.render(screen, screenCamera);
  };
  return {
    render(scene, camera, bolt) {
      const output = renderer.getRenderTarget(), autoClear = renderer.autoClear, clear = renderer.getClearColor(new THREE.Color());
      const clearAlpha = renderer.getClearAlpha();
      renderer.getDrawingBufferSize(size);
      const w = size.x, h = size.y, maxLevel = Math.floor(Math.log2(Math.max(w, h)));
      // The bolt's light as emitted, alone, with its mip levels.
      const parent = bolt.object.parent, alone = new THREE.Scene();
      alone.add(bolt.object);
      bolt.setThrough(1);
      core.setSize(w, h);
      renderer.setClearColor(0x000000, 0);
      renderer.setRenderTarget(core);
      renderer.clear();
      renderer.render(alone, camera);
      if (parent) parent.add(bolt.object);
      const focal = 0.5 * h / Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2);
      const weights = [0, 0, 0];
      glow.gaussians.slice(0, 3).forEach((g, k) => {
        const sigma = Math.max(0.5, THREE.MathUtils.degToRad(g.sigmaDeg) * focal);
        const level = Math.min(Math.max(Math.floor(Math.log2(sigma / 8)), 0), maxLevel);
        const tw = Math.max(1, Math.ceil(w / 2 ** level)), th = Math.max(1, Math.ceil(h / 2 ** level));
        temps[k].setSize(tw, th), outs[k].setSize(tw, th);
        const s = sigma / 2 ** level, radius = Math.min(64, Math.max(1, Math.ceil(3 * s)));
        const taps = Array.from({ length: 65 }, (_, i) => (i <= radius ? Math.exp(-i * i / (2 * s * s)) : 0));
        const total = taps.reduce((a, x, i) => a + (i ? 2 : 1) * x, 0);
        blur.uniforms.uWeights.value = taps.map((x) => x / total);
        blur.uniforms.uRadius.value = radius;
        Object.assign(blur.uniforms.uSource, { value: core.texture });
        blur.uniforms.uLod.value = level;
        blur.uniforms.uStep.value.set(1 / tw, 0);
        pass(blur, temps[k]);
        blur.uniforms.uSource.value = temps[k].texture;
        blur.uniforms.uLod.value = 0;
        blur.uniforms.uStep.value.set(0, 1 / th);
        pass(blur, outs[k]);
        weights[k] = glowStrength * radiance * glow.scattered * g.weight;
      });
      // The frame, the core dimmed by the fog, then the glow added over it.
      renderer.setClearColor(clear, clearAlpha);
      bolt.setThrough(glow.direct);
      renderer.setRenderTarget(output);
      renderer.render(scene, camera);
      renderer.autoClear = false;
      outs.forEach((o, k) => { add.uniforms[`uGlow${k}`].value = o.texture; });
      for (let k = outs.length; k < 3; ++k) add.uniforms[`uGlow${k}`].value = outs[0].texture;
      add.uniforms.uWeights.value.set(...weights);
      pass(add, output);
      renderer.autoClear = autoClear;
    },
    dispose() {
      for (const t of [core, ...temps, ...outs]) t.dispose();
      blur.dispose(), add.dispose(), quad.geometry.dispose();
    },
  };
}

// ---- bubble -----------------------------------------------------------------------------------

// The draws /v1/bubble's shader.draw and shader.blend name: the film's far side (unless
// features.backFace is off: shader.draw then says front faces only) then its near side, each what
// passes through (multiplied) then what it reflects (added); the paper model's near side,
// alpha-blended.
const FILM_PASSES = [
  { side: THREE.BackSide, pass: 0 }, { side: THREE.BackSide, pass: 1 },
  { side: THREE.FrontSide, pass: 0 }, { side: THREE.FrontSide, pass: 1 },
];
function blendOf(material, film, pass) {
  material.blending = THREE.CustomBlending;
  material.blendEquation = material.blendEquationAlpha = THREE.AddEquation;
  if (!film) Object.assign(material, { blendSrc: THREE.SrcAlphaFactor, blendDst: THREE.OneMinusSrcAlphaFactor,
                                       blendSrcAlpha: THREE.OneFactor, blendDstAlpha: THREE.OneMinusSrcAlphaFactor });
  else if (pass === 0) Object.assign(material, { blendSrc: THREE.ZeroFactor, blendDst: THREE.SrcColorFactor,
                                                 blendSrcAlpha: THREE.ZeroFactor, blendDstAlpha: THREE.SrcAlphaFactor });
  else Object.assign(material, { blendSrc: THREE.OneFactor, blendDst: THREE.OneFactor, blendSrcAlpha: THREE.OneFactor,
                                 blendDstAlpha: THREE.OneFactor });
}

// A /v1/bubble JSON answer with include mesh, uniforms, shader (language glsl-es-300) and, for
// the film, thinFilm (encoding rgba16f) and thickness (film.encoding r32f). `environment`: a
// THREE.CubeTexture the bubble reflects and refracts (the client's sky); `flow`: the paper
// model's flow texture (textureFlow, eqn 9; repeat wrapping), the client's own too. Returns a
// THREE.Group whose meshes draw in the answer's order (renderOrder), and update(answer) for a
// new time.
export function bubbleFromAnswer(answer, { environment = null, flow = null } = {}) {
  const { mesh, shader } = answer;
  if (!mesh || !shader || !answer.uniforms) throw new Error('the answer needs include ["mesh", "uniforms", "shader"]');
  if (shader.language !== 'glsl-es-300') throw new Error('the kit draws shader.language glsl-es-300');
  const film = shader.uniforms.includes('uPass');
  const geometry = new THREE.BufferGeometry();
  const add = (name, data, n) => geometry.setAttribute(name, new THREE.Float32BufferAttribute(data, n));
  add('aPosition', mesh.positions, 3), add('aNormal', mesh.normals, 3), add('aUv', mesh.uvs, 2);
  add('position', mesh.positions, 3);  // three's bounds
  geometry.setIndex(mesh.indices);
  const textures = {};
  if (answer.thinFilm) {
    const t = answer.thinFilm;
    textures.uThinFilm = new THREE.DataTexture(new Uint16Array(bytesOf(t.data).buffer), t.width, t.height,
                                               THREE.RGBAFormat, THREE.HalfFloatType);
  }
  if (answer.thickness) {
    const t = answer.thickness;
    textures.uThicknessField = new THREE.DataTexture(new Float32Array(bytesOf(t.data).buffer), t.width, t.height,
                                                     THREE.RedFormat, THREE.FloatType);
    textures.uThicknessField.wrapS = THREE.RepeatWrapping;  // u wraps around the sphere
  }
  for (const t of Object.values(textures)) Object.assign(t, { magFilter: THREE.LinearFilter, minFilter: THREE.LinearFilter, needsUpdate: true });
  // Every texture the variant reads must be there: an unbound sampler would read another's unit.
  const given = { ...textures, uEnvironment: environment, uFlowTexture: flow };
  const ask = { uThinFilm: 'include "thinFilm" (thinFilm.encoding "rgba16f")', uThicknessField: 'include "thickness" (film.encoding "r32f")',
                uEnvironment: 'the environment option (a THREE.CubeTexture)', uFlowTexture: 'the flow option (a repeating THREE.Texture)' };
  for (const name of Object.keys(ask))
    if (shader.uniforms.includes(name) && !given[name]) throw new Error(`the bubble's shader reads ${name}: give ${ask[name]}`);
  const strip = (source) => source.replace(/^#version[^\n]*\n/, '');
  const group = new THREE.Group();
  group.name = 'effectd bubble';
  const materials = [];
  const backFaces = film && shader.draw.startsWith('back faces');
  const passes = film ? (backFaces ? FILM_PASSES : FILM_PASSES.filter((p) => p.side === THREE.FrontSide))
                      : [{ side: THREE.FrontSide, pass: 0 }];
  for (const [order, { side, pass }] of passes.entries()) {
    const uniforms = {
      uModel: { value: new THREE.Matrix4() }, uViewProjection: { value: new THREE.Matrix4() },
      uCameraPosition: { value: new THREE.Vector3() }, uEnvironment: { value: environment }, uFlowTexture: { value: flow },
    };
    for (const [name, texture] of Object.entries(textures)) uniforms[name] = { value: texture };
    const material = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: strip(shader.vertex), fragmentShader: strip(shader.fragment), uniforms,
      side, transparent: true, depthWrite: false, depthTest: true,
    });
    blendOf(material, film, pass);
    material.userData.pass = pass;
    materials.push(material);
    const m = new THREE.Mesh(geometry, material);
    m.renderOrder = order;
    m.frustumCulled = false;
    m.onBeforeRender = (renderer, scene, camera) => {  // the client's own uniforms
      material.uniforms.uModel.value.copy(m.matrixWorld);
      material.uniforms.uViewProjection.value.multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse);
      camera.getWorldPosition(material.uniforms.uCameraPosition.value);
    };
    group.add(m);
  }
  // A vec3 array uniform's declared length (the shader's uniform vec3 name[N]): three uploads
  // every element, so the answer's shorter list (one light of four) is padded with zeros.
  const declared = (name) => Number((`${shader.vertex}\n${shader.fragment}`.match(new RegExp(`uniform\\s+vec3\\s+${name}\\[(\\d+)\\]`)) || [])[1] || 0);
  const vectors = (name, list) => {
    const v = list.map((x) => new THREE.Vector3(...x));
    while (v.length < declared(name)) v.push(new THREE.Vector3());
    return v;
  };
  const update = (next) => {  // the answer's uniforms (a later time: new phases, film, thickness)
    for (const material of materials)
      for (const [name, value] of Object.entries(next.uniforms)) {
        const v = name === 'uPass' ? material.userData.pass : value;
        const wrapped = Array.isArray(v) && Array.isArray(v[0]) ? vectors(name, v)
                      : Array.isArray(v) && v.length === 2 && name === 'uThicknessRange' ? new THREE.Vector2(...v)
                      : Array.isArray(v) && v.length === 4 && name === 'uBaseColor' ? new THREE.Vector4(...v) : v;
        material.uniforms[name] = { value: wrapped };
      }
  };
  update(answer);
  return { object: group, update, dispose() { geometry.dispose(); for (const m of materials) m.dispose(); for (const t of Object.values(textures)) t.dispose(); } };
}

// ---- fog --------------------------------------------------------------------------------------

// /v1/fog's table (encoding rgba16f) as a texture: u = distance over table.range, v = the ray's
// direction y over [-1, 1] when the table has elevations; a warped HEIGHT table (table.layout
// "warped") has the axes of docs/using/fog.md section 4. RGB = in-scattered S, A = transmittance f.
export function fogTexture(answer) {
  const t = answer.table;
  if (!t || t.encoding !== 'rgba16f') throw new Error('the answer needs table.encoding rgba16f');
  const rows = t.elevations || 1;
  const texture = new THREE.DataTexture(new Uint16Array(bytesOf(t.data).buffer), t.size, rows, THREE.RGBAFormat, THREE.HalfFloatType);
  Object.assign(texture, { magFilter: THREE.LinearFilter, minFilter: THREE.LinearFilter, needsUpdate: true });
  return texture;
}

// Fogs a built-in material (MeshBasicMaterial, MeshStandardMaterial, ...) per fragment from the
// table: colour * f + S by the fragment's distance from the camera, as effectd's renderer does.
// Several materials may share one texture (fogTexture(answer)).
export function applyFog(material, answer, texture = fogTexture(answer)) {
  const t = answer.table;
  const uniforms = {
    uFogTable: { value: texture }, uFogRange: { value: new THREE.Vector2(t.range[0], t.range[1]) },
    uFogTexels: { value: new THREE.Vector2(t.size, t.elevations || 1) }, uFogCutoff: { value: t.cutoffDistance ?? 1e38 },
    // warped: (k, falloff, kappa, lambda) and (factorStart, end); k = 0 marks a linear table
    uFogWarp: { value: t.axes ? new THREE.Vector4(t.axes.k, t.axes.falloff, t.axes.kappa, t.axes.lambda) : new THREE.Vector4() },
    uFogWarpRange: { value: t.axes ? new THREE.Vector2(t.axes.factorStart, t.axes.end) : new THREE.Vector2() },
  };
  material.onBeforeCompile = (program) => {
    Object.assign(program.uniforms, uniforms);
    program.vertexShader = program.vertexShader
      .replace('void main() {', 'varying vec3 vEffectdWorld;\nvoid main() {')
      .replace('#include <project_vertex>', '#include <project_vertex>\n  vEffectdWorld = (modelMatrix * vec4(transformed, 1.0)).xyz;');
    program.fragmentShader = program.fragmentShader
      .replace('void main() {', `varying vec3 vEffectdWorld;
uniform sampler2D uFogTable; uniform vec2 uFogRange; uniform vec2 uFogTexels; uniform float uFogCutoff;
uniform vec4 uFogWarp; uniform vec2 uFogWarpRange;
vec2 effectdFogUv(float d, float y) {
  if (uFogWarp.x == 0.0) return vec2(clamp((min(d, uFogRange.y) - uFogRange.x) / (uFogRange.y - uFogRange.x), 0.0, 1.0),
                                     uFogTexels.y > 1.0 ? (y + 1.0) * 0.5 : 0.5);
  float start = uFogWarpRange.x, span = uFogWarpRange.y - start;
  if (y < 0.0 && uFogWarp.z > 0.0) {  // a downward row's columns end where its fog is complete
    float K = uFogWarp.z * exp(uFogWarp.y * y * start), x = -K * y;
    float own = uFogWarp.w * K * (x > 1e-4 ? log(1.0 + x) / x : 1.0 - 0.5 * x);
    float lo = min(span, own), hi = max(span, own);
    span = hi > 0.0 ? lo * pow(1.0 + pow(lo / hi, 8.0), -0.125) : 0.0;
  }
  return vec2(span > 0.0 ? clamp((d - start) / span, 0.0, 1.0) : 1.0, 0.5 + asinh(uFogWarp.x * y) / (2.0 * asinh(uFogWarp.x)));
}
void main() {`)
      .replace('#include <fog_fragment>', `{
    vec3 ray = vEffectdWorld - cameraPosition;
    float d = length(ray);
    if (d < uFogCutoff) {
      vec2 uv = effectdFogUv(d, clamp(ray.y / max(d, 1e-6), -1.0, 1.0));
      vec4 fog = texture2D(uFogTable, (uv * (uFogTexels - 1.0) + 0.5) / uFogTexels);
      gl_FragColor.rgb = gl_FragColor.rgb * fog.a + fog.rgb;
    }
  }`);
  };
  material.customProgramCacheKey = () => 'effectd-fog';
  material.needsUpdate = true;
  return material;
}
