// cellsim replay: the run in 3D (three.js) linked to its charts (uPlot).
// Reads the JSON in #cellsim-replay-data (written by sim/analysis/replay/payload.py).
// World coordinates are MuJoCo's (z up). Test hooks: window.cellsimReplay.
import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";

const D = JSON.parse(document.getElementById("cellsim-replay-data").textContent);
const root = document.getElementById("cellsim-replay");

function bytes(s) {
  const b = atob(s), u = new Uint8Array(b.length);
  for (let i = 0; i < b.length; i++) u[i] = b.charCodeAt(i);
  return u;
}
function arr(o) {
  if (o.f32 !== undefined) return new Float32Array(bytes(o.f32).buffer);
  if (o.i32 !== undefined) return new Int32Array(bytes(o.i32).buffer);
  return bytes(o.u8);
}
const quatOf = (q) => new THREE.Quaternion(q[1], q[2], q[3], q[0]); // MuJoCo (w,x,y,z)

// ---- scene ----
const canvas = root.querySelector("canvas.replay-canvas");
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xeef1f5);
scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(3, -2, 6);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 200);
camera.up.set(0, 0, 1);
const controls = new OrbitControls(camera, canvas);

const bodyGroups = D.bodies.map((name) => {
  const g = new THREE.Group();
  g.name = name;
  scene.add(g);
  return g;
});
const staticPos = arr(D.static.pos), staticQuat = arr(D.static.quat);
bodyGroups.forEach((g, b) => {
  g.position.set(staticPos[3 * b], staticPos[3 * b + 1], staticPos[3 * b + 2]);
  g.quaternion.set(staticQuat[4 * b + 1], staticQuat[4 * b + 2], staticQuat[4 * b + 3], staticQuat[4 * b]);
});
const meshGeoms = D.meshes.map((m) => {
  const geo = new THREE.BufferGeometry();
  geo.setAttribute("position", new THREE.BufferAttribute(arr(m.vert), 3));
  geo.setIndex(new THREE.BufferAttribute(new Uint32Array(arr(m.face)), 1));
  const flat = geo.toNonIndexed();
  flat.computeVertexNormals();
  return flat;
});
const Z_UP = new THREE.Matrix4().makeRotationX(Math.PI / 2); // three's Y axis to MuJoCo's Z
function geometryOf(g) {
  const s = g.size;
  switch (g.type) {
    case 0: return new THREE.PlaneGeometry(2 * s[0], 2 * s[1]);
    case 2: return new THREE.SphereGeometry(s[0], 24, 16);
    case 3: return new THREE.CapsuleGeometry(s[0], 2 * s[1], 8, 16).applyMatrix4(Z_UP);
    case 4: return new THREE.SphereGeometry(1, 24, 16).scale(s[0], s[1], s[2]);
    case 5: return new THREE.CylinderGeometry(s[0], s[0], 2 * s[1], 24).applyMatrix4(Z_UP);
    case 6: return new THREE.BoxGeometry(2 * s[0], 2 * s[1], 2 * s[2]);
    case 7: return meshGeoms[g.mesh];
  }
  return null;
}
const geomObjects = new Map(); // geom name -> mesh
for (const g of D.geoms) {
  const geo = geometryOf(g);
  if (!geo) continue;
  const mat = new THREE.MeshStandardMaterial({
    color: new THREE.Color(g.rgba[0], g.rgba[1], g.rgba[2]), roughness: 0.65, metalness: 0.1,
    transparent: g.rgba[3] < 1, opacity: g.rgba[3], side: g.type === 0 ? THREE.DoubleSide : THREE.FrontSide,
  });
  const mesh = new THREE.Mesh(geo, mat);
  mesh.position.set(g.pos[0], g.pos[1], g.pos[2]);
  mesh.quaternion.copy(quatOf(g.quat));
  mesh.userData = { geom: g.name, body: g.body, color: mat.color.clone() };
  bodyGroups[g.body].add(mesh);
  geomObjects.set(g.name, mesh);
}

// ---- frames ----
const F = D.frames, frameT = arr(F.t), framePos = arr(F.pos), frameQuat = arr(F.quat);
const nMoving = F.bodies.length, nFrames = frameT.length;
const qa = new THREE.Quaternion(), qb = new THREE.Quaternion();
function frameAt(t) { // last frame at or before t
  let lo = 0, hi = nFrames - 1;
  if (t <= frameT[0]) return 0;
  if (t >= frameT[hi]) return hi;
  while (hi - lo > 1) { const m = (lo + hi) >> 1; if (frameT[m] <= t) lo = m; else hi = m; }
  return lo;
}
function applyPoses(t) {
  const i = frameAt(t), j = Math.min(i + 1, nFrames - 1);
  const a = j > i ? Math.min(1, Math.max(0, (t - frameT[i]) / (frameT[j] - frameT[i]))) : 0;
  for (let k = 0; k < nMoving; k++) {
    const g = bodyGroups[F.bodies[k]], pi = 3 * (i * nMoving + k), pj = 3 * (j * nMoving + k);
    const qi = 4 * (i * nMoving + k), qj = 4 * (j * nMoving + k);
    g.position.set(framePos[pi] + a * (framePos[pj] - framePos[pi]),
      framePos[pi + 1] + a * (framePos[pj + 1] - framePos[pi + 1]),
      framePos[pi + 2] + a * (framePos[pj + 2] - framePos[pi + 2]));
    qa.set(frameQuat[qi + 1], frameQuat[qi + 2], frameQuat[qi + 3], frameQuat[qi]);
    qb.set(frameQuat[qj + 1], frameQuat[qj + 2], frameQuat[qj + 3], frameQuat[qj]);
    g.quaternion.slerpQuaternions(qa, qb, a);
  }
}

// ---- tool paths and beads ----
// the bead: a tube of BEAD_R around each arc-on segment (its ends' rings square to the segment),
// BEAD_SIDES quads round, so it keeps its width on screen as a weld bead does
const BEAD_R = 0.003, BEAD_SIDES = 6, BEAD_IDX = 6 * BEAD_SIDES;
function beadTube(pos, seg) {
  const v = new Float32Array(seg.length * 2 * BEAD_SIDES * 3), n = new Float32Array(v.length);
  const idx = new Uint32Array(seg.length * BEAD_IDX);
  const a = new THREE.Vector3(), b = new THREE.Vector3(), d = new THREE.Vector3();
  const u = new THREE.Vector3(), w = new THREE.Vector3(), r = new THREE.Vector3();
  seg.forEach((o, k) => {
    a.fromArray(pos, o); b.fromArray(pos, o + 3); d.subVectors(b, a);
    if (d.lengthSq() < 1e-18) d.set(1, 0, 0);
    d.normalize();
    u.set(Math.abs(d.z) < 0.9 ? 0 : 1, 0, Math.abs(d.z) < 0.9 ? 1 : 0).cross(d).normalize();
    w.crossVectors(d, u);
    for (let j = 0; j < BEAD_SIDES; j++) {
      const ang = (2 * Math.PI * j) / BEAD_SIDES;
      r.copy(u).multiplyScalar(Math.cos(ang)).addScaledVector(w, Math.sin(ang));
      for (const [e, p] of [[0, a], [1, b]]) {
        const vi = 3 * ((2 * k + e) * BEAD_SIDES + j);
        v[vi] = p.x + BEAD_R * r.x; v[vi + 1] = p.y + BEAD_R * r.y; v[vi + 2] = p.z + BEAD_R * r.z;
        n[vi] = r.x; n[vi + 1] = r.y; n[vi + 2] = r.z;
      }
      const j1 = (j + 1) % BEAD_SIDES, s0 = 2 * k * BEAD_SIDES, s1 = s0 + BEAD_SIDES;
      idx.set([s0 + j, s0 + j1, s1 + j, s1 + j, s0 + j1, s1 + j1], k * BEAD_IDX + 6 * j);
    }
  });
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", new THREE.BufferAttribute(v, 3));
  g.setAttribute("normal", new THREE.BufferAttribute(n, 3));
  g.setIndex(new THREE.BufferAttribute(idx, 1));
  return g;
}
const overlays = [];
const paths = D.paths.map((p) => {
  const t = arr(p.t), pos = arr(p.pos), arc = arr(p.arc);
  const line = new THREE.BufferGeometry();
  line.setAttribute("position", new THREE.BufferAttribute(pos, 3));
  const pathLine = new THREE.Line(line, new THREE.LineBasicMaterial({ color: 0x3a7d44, transparent: true, opacity: 0.55 }));
  const seg = [], segT = [];
  for (let i = 0; i + 1 < t.length; i++) {
    if (arc[i] && arc[i + 1]) { seg.push(3 * i); segT.push(t[i + 1]); }
  }
  const bead = new THREE.Mesh(beadTube(pos, seg), new THREE.MeshStandardMaterial({ color: 0xd4a017, roughness: 0.45, metalness: 0.3 }));
  scene.add(pathLine, bead);
  overlays.push(pathLine, bead);
  return { bead, segT: Float32Array.from(segT) };
});
function showBeads(t) {
  for (const p of paths) {
    let n = 0, hi = p.segT.length;
    while (n < hi) { const m = (n + hi) >> 1; if (p.segT[m] <= t) n = m + 1; else hi = m; }
    p.bead.geometry.setDrawRange(0, BEAD_IDX * n);
  }
}

// ---- collisions and clearance ----
const red = new THREE.Color(0xe01010);
function showCollisions(t) {
  const hit = new Set();
  for (const c of D.collisions) if (t >= c.t0 - 1e-9 && t <= c.t1 + 1e-9) c.geoms.forEach((g) => hit.add(g));
  for (const [name, m] of geomObjects) m.material.color.copy(hit.has(name) ? red : m.userData.color);
  return hit.size;
}
const NEAR_S = 1.0;
const clearMarks = D.clearance.map((c) => {
  const g = new THREE.Group();
  const a = new THREE.Vector3(...c.a), b = new THREE.Vector3(...c.b);
  const lg = new THREE.BufferGeometry().setFromPoints([a, b]);
  g.add(new THREE.Line(lg, new THREE.LineBasicMaterial({ color: 0xff00aa })));
  for (const p of [a, b]) {
    const s = new THREE.Mesh(new THREE.SphereGeometry(0.006, 12, 8), new THREE.MeshBasicMaterial({ color: 0xff00aa }));
    s.position.copy(p);
    g.add(s);
  }
  scene.add(g);
  overlays.push(g);
  return { g, t: c.t };
});
function showClearance(t) { for (const m of clearMarks) m.g.visible = Math.abs(t - m.t) <= NEAR_S; }

// ---- views ----
const box = new THREE.Box3();
bodyGroups.forEach((g) => g.children.forEach((m) => { if (m.userData.geom && m.geometry.type !== "PlaneGeometry") box.expandByObject(m); }));
function fitView() {
  const c = box.getCenter(new THREE.Vector3()), r = Math.max(0.5, box.getSize(new THREE.Vector3()).length() / 2);
  camera.fov = 45;
  camera.position.set(c.x + 1.6 * r, c.y - 1.6 * r, c.z + 1.1 * r);
  controls.target.copy(c);
  camera.updateProjectionMatrix();
  controls.update();
}
let follow = null; // camera preset attached to a moving body
function placeCamera(cam) {
  const g = bodyGroups[cam.body];
  g.updateMatrixWorld();
  const pos = new THREE.Vector3(...cam.pos).applyMatrix4(g.matrixWorld);
  const q = g.quaternion.clone().multiply(quatOf(cam.quat));
  camera.position.copy(pos);
  camera.quaternion.copy(q);
  camera.fov = cam.fovy;
  camera.updateProjectionMatrix();
  const fwd = new THREE.Vector3(0, 0, -1).applyQuaternion(q);
  const d = Math.max(0.3, box.getCenter(new THREE.Vector3()).sub(pos).dot(fwd));
  controls.target.copy(pos.clone().addScaledVector(fwd, d));
}
function setView(name) {
  const cam = D.cameras.find((c) => c.name === name);
  follow = cam && F.bodies.includes(cam.body) ? cam : null;
  if (cam) placeCamera(cam); else fitView();
  draw();
}
controls.addEventListener("start", () => { follow = null; });
controls.addEventListener("change", () => draw());

// ---- time, controls ----
const t0 = D.t0, duration = D.duration;
let time = t0, playing = false, speed = 1, last = null;
const slider = root.querySelector("input.replay-slider");
const label = root.querySelector(".replay-time");
slider.min = t0; slider.max = t0 + duration; slider.step = "any";
function phaseAt(t) { const p = D.phases.find((p) => t >= p.t0 && t <= p.t1); return p ? p.name : ""; }
function setTime(t) {
  time = Math.min(t0 + duration, Math.max(t0, t));
  slider.value = time;
  applyPoses(time);
  showBeads(time);
  const hits = showCollisions(time);
  showClearance(time);
  label.textContent = `${time.toFixed(3)} s / ${(t0 + duration).toFixed(2)} s ${phaseAt(time)}${hits ? "  COLLISION" : ""}`;
  if (follow) placeCamera(follow);
  charts.forEach((c) => c.cursor());
  draw();
}
function draw() { renderer.render(scene, camera); }
function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  draw();
}
slider.addEventListener("input", () => { playing = false; playBtn.textContent = "Play"; setTime(parseFloat(slider.value)); });
const playBtn = root.querySelector("button.replay-play");
playBtn.addEventListener("click", () => {
  playing = !playing; playBtn.textContent = playing ? "Pause" : "Play"; last = null;
  if (playing && time >= t0 + duration) setTime(t0);
});
root.querySelector("select.replay-speed").addEventListener("change", (e) => { speed = parseFloat(e.target.value); });
const viewSel = root.querySelector("select.replay-view");
for (const name of ["fit", ...D.cameras.map((c) => c.name)]) {
  const o = document.createElement("option"); o.value = o.textContent = name; viewSel.appendChild(o);
}
viewSel.addEventListener("change", () => setView(viewSel.value));
function tick(now) {
  if (playing) {
    if (last !== null) setTime(time + speed * (now - last) / 1000);
    last = now;
    if (time >= t0 + duration) { playing = false; playBtn.textContent = "Play"; }
  }
  requestAnimationFrame(tick);
}

// ---- charts ----
const charts = D.charts.map((c) => {
  const el = document.createElement("div");
  el.className = "replay-chart";
  el.dataset.chart = c.id;
  root.querySelector(".replay-charts").appendChild(el);
  const x = arr(c.x), ys = c.y.map(arr);
  const colors = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];
  const spans = [...D.collisions.map((k) => [k.t0, k.t1, "rgba(224,16,16,0.25)"]),
    ...D.clearance.map((k) => [k.t - 0.05, k.t + 0.05, "rgba(255,0,170,0.5)"])];
  const u = new uPlot({
    title: `${c.title} (${c.unit})`, width: Math.max(300, root.clientWidth - 20), height: 190,
    cursor: { drag: { x: false, y: false } },
    scales: { x: { time: false } },
    series: [{ label: "t (s)" }, ...c.labels.map((l, i) => ({ label: l, stroke: colors[i % colors.length], width: 1 }))],
    hooks: { drawClear: [(u) => {
      const ctx = u.ctx;
      for (const [a, b, col] of spans) {
        const l = u.valToPos(a, "x", true), r = u.valToPos(b, "x", true);
        ctx.fillStyle = col; ctx.fillRect(l, u.bbox.top, Math.max(2, r - l), u.bbox.height);
      }
    }] },
  }, [x, ...ys], el);
  const line = document.createElement("div");
  line.className = "replay-cursor";
  u.over.appendChild(line);
  u.over.addEventListener("click", (e) => {
    playing = false; playBtn.textContent = "Play";
    setTime(u.posToVal(e.offsetX, "x"));
  });
  return { id: c.id, u, cursor: () => { line.style.left = `${u.valToPos(time, "x")}px`; } };
});

// ---- hooks for tests and scripts ----
function solo(names, withOverlays = false) { // only the given bodies' geoms (null: everything)
  const keep = names ? new Set(names) : null;
  for (const m of geomObjects.values()) m.visible = !keep || keep.has(D.bodies[m.userData.body]);
  overlays.forEach((o) => { o.visible = !keep || withOverlays; });
  if (!keep) showClearance(time);
  draw();
}
window.cellsimReplay = {
  time: () => time,
  setTime: (t) => { setTime(t); return time; },
  duration, t0,
  frameTimes: () => Array.from(frameT),
  fps: F.fps,
  bodies: D.bodies,
  movingBodies: F.bodies.map((b) => D.bodies[b]),
  cameras: D.cameras.map((c) => c.name),
  setView,
  look: (eye, target, fovy) => { // place the camera: eye and target in world coordinates (m)
    follow = null;
    camera.position.set(eye[0], eye[1], eye[2]);
    controls.target.set(target[0], target[1], target[2]);
    if (fovy) camera.fov = fovy;
    camera.updateProjectionMatrix();
    controls.update();
    draw();
  },
  solo,
  canvas,
  camera: () => {
    camera.updateMatrixWorld();
    return { projection: Array.from(camera.projectionMatrix.elements),
      view: Array.from(camera.matrixWorldInverse.elements),
      width: renderer.domElement.width, height: renderer.domElement.height };
  },
  chart: (id) => {
    const c = charts.find((c) => c.id === id);
    const r = c.u.over.getBoundingClientRect();
    return { left: r.left, top: r.top, width: r.width, height: r.height,
      min: c.u.scales.x.min, max: c.u.scales.x.max };
  },
  ready: false,
};
window.addEventListener("resize", resize);
resize();
setView(D.cameras.length ? D.cameras[0].name : "fit");
viewSel.value = D.cameras.length ? D.cameras[0].name : "fit";
setTime(t0);
requestAnimationFrame(tick);
window.cellsimReplay.ready = true;
