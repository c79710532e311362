// The live view: each effect drawn in this browser from the service's own answer through the
// three.js kit (clients/three/effectd-three.js, served as /playground/effectd-three.js), the way a
// three.js game draws it.
//   lightning  the answer's ribbons (include mesh); with a timeline, the strike played as
//              docs/effects.md §1.6 says (leader, return stroke, re-strikes)
//   fog        the preview's scene (its quads, camera and backdrop), each material fogged per
//              fragment from the answer's table
//   bubble     the answer's mesh with its own GLSL ES 3.00, uniforms, thin-film table and
//              thickness texture, in the draws the answer names
//   tangents   the mesh with each vertex's tangent (red), bitangent (green) and normal (blue)
// Drag to turn the 3-D views. three.js itself comes from --playground-three.
import * as THREE from 'three';
import { applyFog, boltFromAnswer, bubbleFromAnswer, fogTexture } from './effectd-three.js';

// Sky colour by direction, as scene.json documents the renderer's environment (render::skyAt).
const SKY = { zenith: [0.35, 0.6, 1.0], horizon: [1.0, 0.98, 0.95], ground: [0.16, 0.18, 0.12] };
function skyAt(d) {
  const mix = (a, b, w) => a.map((x, i) => x + (b[i] - x) * w);
  return d[1] >= 0 ? mix(SKY.horizon, SKY.zenith, Math.sqrt(d[1])) : mix(SKY.horizon, SKY.ground, Math.sqrt(Math.min(-4 * d[1], 1)));
}
// The sky as a cube map (faces +x, -x, +y, -y, +z, -z) of float texels.
function skyCube(n) {
  const faces = [];
  for (let face = 0; face < 6; ++face) {
    const px = new Float32Array(n * n * 4);
    for (let j = 0; j < n; ++j)
      for (let i = 0; i < n; ++i) {
        const s = (2 * (i + 0.5)) / n - 1, t = (2 * (j + 0.5)) / n - 1;
        const d = [[1, -t, -s], [-1, -t, s], [s, 1, t], [s, -1, -t], [s, -t, 1], [-s, -t, -1]][face];
        const l = Math.hypot(...d);
        px.set([...skyAt(d.map((x) => x / l)), 1], (j * n + i) * 4);
      }
    faces.push(Object.assign(new THREE.DataTexture(px, n, n, THREE.RGBAFormat, THREE.FloatType), { needsUpdate: true }));
  }
  return Object.assign(new THREE.CubeTexture(faces), { format: THREE.RGBAFormat, type: THREE.FloatType, generateMipmaps: false,
                                                        magFilter: THREE.LinearFilter, minFilter: THREE.LinearFilter, needsUpdate: true });
}
// The paper's flow texture (eqn 9): a soft pattern, as the renderer's default.
function flowTexture() {
  const data = new Uint8Array(64 * 64 * 4);
  for (let y = 0; y < 64; ++y)
    for (let x = 0; x < 64; ++x) {
      const v = 0.8 + 0.2 * Math.sin((x / 64) * 6 * Math.PI + 2 * Math.sin((y / 64) * 4 * Math.PI));
      data.set([v * 255, (0.9 + 0.1 * Math.cos((y / 64) * 8 * Math.PI)) * 255, 255, 255], (y * 64 + x) * 4);
    }
  return Object.assign(new THREE.DataTexture(data, 64, 64), { wrapS: THREE.RepeatWrapping, wrapT: THREE.RepeatWrapping,
                                                             magFilter: THREE.LinearFilter, minFilter: THREE.LinearFilter, needsUpdate: true });
}
// A colour as the preview writes it (display values).
const display = (rgb) => new THREE.Color().setRGB(rgb[0], rgb[1], rgb[2], THREE.SRGBColorSpace);

// Bounds of flat xyz positions: centre and diagonal.
function bounds(lists) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const p of lists)
    for (let i = 0; i < p.length; i += 3) for (let k = 0; k < 3; ++k) lo[k] = Math.min(lo[k], p[i + k]), hi[k] = Math.max(hi[k], p[i + k]);
  return { center: lo.map((x, k) => (x + hi[k]) / 2), size: Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1 };
}

export class LiveView {
  constructor(canvas, player) {
    this.canvas = canvas;
    this.player = player;  // {box, play, scrub, clock}
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(1);
    this.renderer.setSize(canvas.width, canvas.height, false);
    this.owned = [];  // what the current effect made, disposed on the next
    this.yaw = 0.6;
    this.pitch = 0.25;
    this.playing = false;
    this.t = 0;
    this.last = performance.now();
    let drag = null;
    canvas.addEventListener('pointerdown', (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      this.yaw += (e.clientX - drag[0]) * 0.01;
      this.pitch = Math.max(-1.4, Math.min(1.4, this.pitch + (e.clientY - drag[1]) * 0.01));
      drag = [e.clientX, e.clientY];
      this.dirty = true;
    });
    player.play.addEventListener('click', () => {
      this.playing = !this.playing;
      player.play.textContent = this.playing ? 'pause' : 'play';
    });
    player.scrub.addEventListener('input', () => {
      this.t = (player.scrub.value / 1000) * (this.duration || 0);
      this.playing = false;
      player.play.textContent = 'play';
      this.dirty = true;
    });
    const tick = (now) => {
      const dt = (now - this.last) / 1000;
      this.last = now;
      if (this.scene && this.duration && this.playing) {
        // Strikes last a second or two of game time; play at that speed, with a pause to loop.
        this.t = (this.t + dt) % (this.duration + 0.5);
        this.player.scrub.value = Math.min(1000, (this.t / this.duration) * 1000);
        this.dirty = true;
      }
      if (this.scene && this.dirty) {
        this.dirty = false;
        if (this.beforeDraw) this.beforeDraw();
        this.renderer.render(this.scene, this.camera);
      }
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }

  // Drops the last effect's objects and stops its animation.
  reset() {
    for (const o of this.owned) o.dispose();
    this.owned = [];
    this.scene = null;
    this.beforeDraw = null;
    this.duration = 0;
    this.player.box.hidden = true;
  }

  clear() {
    this.reset();
    this.renderer.setClearColor(0x000000, 1);
    this.renderer.clear();
  }

  show(scene, camera, background) {
    scene.background = display(background);
    this.scene = scene;
    this.camera = camera;
    this.dirty = true;
  }

  // A camera circling `center` at `distance`, turned by dragging (set before each draw).
  orbit(camera, center, distance) {
    camera.near = distance * 0.01;
    camera.far = distance * 100;
    camera.position.set(center[0] + distance * Math.cos(this.pitch) * Math.sin(this.yaw), center[1] + distance * Math.sin(this.pitch),
                        center[2] + distance * Math.cos(this.pitch) * Math.cos(this.yaw));
    camera.lookAt(...center);
    camera.updateProjectionMatrix();
  }

  // answer: /v1/lightning with mesh (and a timeline when it has one). A 2-D bolt fills the view
  // (glTF's axes: grid (x, y) at (x, -y)); a 3-D one turns with the orbit camera.
  showLightning(answer) {
    this.reset();
    const bolt = boltFromAnswer(answer, { glow: { width: 3, strength: 0.4 } });
    this.owned.push(bolt);
    const scene = new THREE.Scene();
    scene.add(bolt.object);
    let camera;
    if (answer.grid.length === 2) {
      const [w, h] = answer.grid, half = 0.52 * Math.max(w, h);
      camera = new THREE.OrthographicCamera(w / 2 - half, w / 2 + half, -h / 2 + half, -h / 2 - half, -10, 10);
    } else {
      camera = new THREE.PerspectiveCamera(45, 1, 0.1, 100);
      const { center, size } = bounds(answer.mesh.primitives.map((p) => p.positions));
      this.beforeDraw = () => this.orbit(camera, center, size * 1.3);
    }
    const timeline = answer.timeline;
    if (timeline) {  // a new bolt waits, lit as at its brightest moment, until played
      this.duration = timeline.duration;
      const k = timeline.keyframes, peak = k.t[k.main.indexOf(Math.max(...k.main))];
      this.t = this.playing ? Math.min(this.t, this.duration) : peak;
      this.player.scrub.value = (this.t / this.duration) * 1000;
      this.player.box.hidden = false;
      const place = this.beforeDraw;
      this.beforeDraw = () => {
        if (place) place();
        bolt.setTime(this.t);
        this.player.clock.textContent = `${(this.t * 1000).toFixed(1)} ms of ${(this.duration * 1000).toFixed(0)} ms`;
      };
    }
    this.show(scene, camera, [0.03, 0.03, 0.07]);
  }

  // answer: /v1/fog with an rgba16f table; stage: the preview's {quads, camera, background}.
  showFog(answer, stage) {
    this.reset();
    const table = fogTexture(answer), scene = new THREE.Scene();
    this.owned.push(table);
    for (const q of stage.quads) {  // three's plane faces +z, +y up: turned to the quad's normal and up
      const material = applyFog(new THREE.MeshBasicMaterial({ color: display(q.color || [0.5, 0.5, 0.5]), side: THREE.DoubleSide }),
                                answer, table);
      const geometry = new THREE.PlaneGeometry(q.size[0], q.size[1]);
      this.owned.push(material, geometry);
      const mesh = new THREE.Mesh(geometry, material);
      const n = new THREE.Vector3(...(q.normal || [0, 0, 1])).normalize(), up = new THREE.Vector3(...(q.up || [0, 1, 0]));
      up.sub(n.clone().multiplyScalar(up.dot(n)));
      if (up.length() < 1e-9) up.set(...(Math.abs(n.y) < 0.9 ? [0, 1, 0] : [1, 0, 0])).sub(n.clone().multiplyScalar(Math.abs(n.y) < 0.9 ? n.y : n.x));
      up.normalize();
      mesh.matrixAutoUpdate = false;
      mesh.matrix.makeBasis(new THREE.Vector3().crossVectors(up, n), up, n).setPosition(...q.center);
      scene.add(mesh);
    }
    const { position: eye, target, fovY } = stage.camera;
    const camera = new THREE.PerspectiveCamera(fovY, 1, 0.05, 1000);
    camera.position.set(...eye);
    this.beforeDraw = () => {  // the preview's camera; dragging turns it about the vertical through the eye
      const turn = this.yaw - 0.6, look = target.map((x, k) => x - eye[k]);
      camera.lookAt(eye[0] + Math.cos(turn) * look[0] + Math.sin(turn) * look[2], eye[1] + look[1],
                    eye[2] - Math.sin(turn) * look[0] + Math.cos(turn) * look[2]);
    };
    this.show(scene, camera, stage.background.color);
  }

  // answer: /v1/bubble with mesh, uniforms, shader (GLSL ES 3.00), thinFilm (rgba16f) and
  // thickness (r32f) for the film model; mesh, uniforms and shader for the paper's.
  showBubble(answer) {
    this.reset();
    const environment = skyCube(64), flow = flowTexture();
    const bubble = bubbleFromAnswer(answer, { environment, flow });
    this.owned.push(bubble, environment, flow);
    const scene = new THREE.Scene();
    scene.add(bubble.object);
    const camera = new THREE.PerspectiveCamera(45, 1, 0.04, 400);
    this.beforeDraw = () => this.orbit(camera, [0, 0, 0], 4);
    this.show(scene, camera, [0.1, 0.12, 0.1]);
  }

  // mesh: {positions, normals (optional), tangents (xyzw per vertex), indices}.
  showTangents(mesh) {
    this.reset();
    const P = mesh.positions, T = mesh.tangents, I = mesh.indices, nv = P.length / 3;
    const surface = new THREE.BufferGeometry();
    surface.setAttribute('position', new THREE.Float32BufferAttribute(P, 3));
    surface.setIndex(Array.from(I));
    if (mesh.normals) surface.setAttribute('normal', new THREE.Float32BufferAttribute(mesh.normals, 3));
    else surface.computeVertexNormals();  // area-weighted from the faces
    const N = surface.attributes.normal;
    const lines = [], colours = [];
    const { size } = bounds([P]), len = size * 0.06;
    for (let i = 0; i < nv; ++i) {
      const p = new THREE.Vector3(P[3 * i], P[3 * i + 1], P[3 * i + 2]), n = new THREE.Vector3().fromBufferAttribute(N, i).normalize();
      const t = new THREE.Vector3(T[4 * i], T[4 * i + 1], T[4 * i + 2]);
      const b = new THREE.Vector3().crossVectors(n, t).multiplyScalar(T[4 * i + 3] < 0 ? -1 : 1);
      for (const [d, c] of [[t, [1, 0.25, 0.2]], [b, [0.3, 1, 0.3]], [n, [0.35, 0.5, 1]]]) {
        lines.push(p.x, p.y, p.z, p.x + d.x * len, p.y + d.y * len, p.z + d.z * len);
        colours.push(...c, ...c);
      }
    }
    const frames = new THREE.BufferGeometry();
    frames.setAttribute('position', new THREE.Float32BufferAttribute(lines, 3));
    frames.setAttribute('color', new THREE.Float32BufferAttribute(colours, 3));
    const shaded = new THREE.MeshLambertMaterial({ color: 0x8a8a90, flatShading: true, side: THREE.DoubleSide });
    const lineMaterial = new THREE.LineBasicMaterial({ vertexColors: true });
    this.owned.push(surface, frames, shaded, lineMaterial);
    const scene = new THREE.Scene();
    scene.add(new THREE.Mesh(surface, shaded), new THREE.LineSegments(frames, lineMaterial));
    scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 2.5));
    const camera = new THREE.PerspectiveCamera(45, 1, 0.1, 100);
    surface.computeBoundingSphere();
    const c = surface.boundingSphere.center;
    this.beforeDraw = () => this.orbit(camera, [c.x, c.y, c.z], size * 1.4);
    this.show(scene, camera, [0.08, 0.09, 0.11]);
  }
}
