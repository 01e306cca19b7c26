// The 3D view of an activecal report folder (src/render/page/). The data
// (page-data) holds every link's placement per pose, computed by activecal:
// this script only poses what it is given, draws and reports.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

// Milliseconds since navigation at each step of opening (the read-out's
// `timings`): where the time to interactive goes.
const timings = { boot: window.activecalBoot ?? null, module: performance.now() };
const data = JSON.parse(document.getElementById('page-data').textContent);
timings.parsed = performance.now();
const el = (id) => document.getElementById(id);
const host = el('canvas');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(host.clientWidth, host.clientHeight);
renderer.setClearColor(0xffffff);
host.appendChild(renderer.domElement);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(45, host.clientWidth / host.clientHeight, 0.01, 100);
camera.up.set(0, 0, 1);
const controls = new OrbitControls(camera, renderer.domElement);
scene.add(new THREE.HemisphereLight(0xffffff, 0x888888, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(2, -3, 4);
scene.add(sun);

// Base64 to bytes in one pass over a preallocated array (a callback per
// character, as Uint8Array.from takes, is several times slower on meshes
// of megabytes).
function bytes(b64) {
  const s = atob(b64);
  const out = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) out[i] = s.charCodeAt(i);
  return out.buffer;
}
const matrix = (m) => new THREE.Matrix4().fromArray(m);

function meshGeometry(m) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(bytes(m.positions)), 3));
  g.setIndex(new THREE.BufferAttribute(new Uint32Array(bytes(m.indices)), 1));
  return g;
}

function shapeGeometry(v, meshes) {
  if (v.kind === 'mesh') return meshes[v.mesh];
  if (v.kind === 'box') return new THREE.BoxGeometry(...v.size);
  if (v.kind === 'sphere') return new THREE.SphereGeometry(v.radius, 24, 16);
  const c = new THREE.CylinderGeometry(v.radius, v.radius, v.length, 24);
  return c.rotateX(Math.PI / 2);
}

// One robot: a group per link (placed by its matrix), its visuals inside.
function makeRobot(meshes, tint) {
  const links = data.links.map(() => {
    const o = new THREE.Group();
    o.matrixAutoUpdate = false;
    return o;
  });
  for (const v of data.visuals) {
    const rgba = tint ?? v.rgba ?? [0.72, 0.74, 0.78, 1];
    const mat = new THREE.MeshStandardMaterial({
      color: new THREE.Color(rgba[0], rgba[1], rgba[2]),
      flatShading: true,
      transparent: rgba[3] < 1,
      opacity: rgba[3],
    });
    const mesh = new THREE.Mesh(shapeGeometry(v, meshes), mat);
    mesh.matrixAutoUpdate = false;
    const s = v.kind === 'mesh' ? v.scale : [1, 1, 1];
    mesh.matrix.copy(matrix(v.origin)).scale(new THREE.Vector3(...s));
    links[v.link].add(mesh);
  }
  if (!data.urdf) {
    for (const o of links) o.add(new THREE.AxesHelper(0.08));
  }
  const group = new THREE.Group();
  links.forEach((o) => group.add(o));
  scene.add(group);
  return { group, links };
}

function addScene() {
  const z = data.floor ?? 0;
  const grid = new THREE.GridHelper(4, 40, 0x999999, 0xdddddd);
  grid.rotateX(Math.PI / 2);
  grid.position.z = z;
  scene.add(grid);
  for (const b of data.obstacles) {
    const m = new THREE.Mesh(
      new THREE.BoxGeometry(...b.size),
      new THREE.MeshStandardMaterial({ color: 0xcc4444, transparent: true, opacity: 0.45 }),
    );
    m.position.set(...b.center);
    scene.add(m);
  }
}

const meshes = data.meshes.map(meshGeometry);
timings.meshes = performance.now();
const robot = makeRobot(meshes, null);
const fitted = data.poses.some((p) => p.calibrated)
  ? makeRobot(meshes, [1.0, 0.55, 0.1, 0.35])
  : null;
// Each link joined to its parent: the robot where meshes are missing,
// and the calibrated robot's outline.
const bones = data.parents.flatMap((p, i) => (p == null ? [] : [[p, i]]));
function makeSkeleton(color) {
  const g = new THREE.BufferGeometry().setFromPoints(bones.flatMap(() => [new THREE.Vector3(), new THREE.Vector3()]));
  const l = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color }));
  scene.add(l);
  return l;
}
const skeleton = makeSkeleton(0x3355aa);
const fittedSkeleton = fitted ? makeSkeleton(0xff8800) : null;
addScene();
const marks = new THREE.Group();
scene.add(marks);
let shown = 0;

function setLinks(r, mats) {
  mats.forEach((m, i) => r.links[i].matrix.fromArray(m));
}

// The least clearance (a pose's or a move's): its links drawn red.
function highlight(c) {
  const near = new Set(c ? c.links : []);
  robot.links.forEach((o, i) => {
    for (const m of o.children) if (m.material.emissive) m.material.emissive.setHex(near.has(i) ? 0xcc0000 : 0);
  });
}

const clearanceText = (c) => (c ? `least clearance ${(1000 * c.distance).toFixed(1)} mm (${c.between[0]} – ${c.between[1]})` : '');

// The calibrated robot with its difference from the nominal magnified.
function magnified(p) {
  const k = data.magnify_robot ?? 1;
  return p.calibrated.map((c, i) => {
    const n = p.links[i];
    const out = c.slice();
    for (const j of [12, 13, 14]) out[j] = n[j] + k * (c[j] - n[j]);
    return out;
  });
}

function dot(pos, color, r) {
  const m = new THREE.Mesh(
    new THREE.SphereGeometry(r, 16, 12),
    new THREE.MeshBasicMaterial({ color }),
  );
  m.position.set(...pos);
  marks.add(m);
}

function line(points, color) {
  const g = new THREE.BufferGeometry().setFromPoints(points.map((p) => new THREE.Vector3(...p)));
  marks.add(new THREE.Line(g, new THREE.LineBasicMaterial({ color })));
}

function drawMarks(k) {
  marks.clear();
  const p = data.poses[k];
  const s = data.sensor;
  if (p.measured && p.fitted) {
    const m = data.magnify ?? 1;
    const tip = p.fitted.map((f, i) => f + m * (p.measured[i] - f));
    dot(p.fitted, 0x2255dd, 0.008);
    dot(tip, 0x22aa22, 0.008);
    line([p.fitted, tip], 0xdd2222);
    // The scale bar: 1 mm at the residuals' magnification, beside the point.
    const [x, y, z] = p.fitted;
    line([[x, y, z + 0.03], [x + 0.001 * m, y, z + 0.03]], 0x000000);
  }
  if (s && s.kind === 'tracker') {
    dot(s.position, 0x333333, 0.03);
    const end = p.links[p.links.length - 1];
    line([s.position, [end[12], end[13], end[14]]], 0x999999);
  }
  if (s && s.kind === 'camera') drawCamera(s, k);
  if (s && s.kind === 'contacts') drawContacts(s);
}

// The lines of sight the library checked at pose k: green where it held,
// red where the robot or an obstacle blocks it (one draw call each).
function drawRays(rays) {
  for (const [clear, color] of [[true, 0x22aa44], [false, 0xdd2222]]) {
    const pts = rays.filter((r) => r.clear === clear).flatMap((r) => [r.from, r.to]);
    if (!pts.length) continue;
    const g = new THREE.BufferGeometry().setFromPoints(pts.map((p) => new THREE.Vector3(...p)));
    const l = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color }));
    l.userData.rays = pts.length / 2;
    l.userData.clear = clear;
    marks.add(l);
  }
}

// The sockets of a contact design as spheres, its planes as translucent
// squares.
function drawContacts(s) {
  for (const p of s.sockets) {
    dot(p.position, 0xcc7700, 0.012);
    marks.children[marks.children.length - 1].userData.socket = p.name;
  }
  for (const p of s.planes) {
    const g = new THREE.BufferGeometry().setFromPoints(p.corners.map((c) => new THREE.Vector3(...c)));
    g.setIndex([0, 1, 2, 0, 2, 3]);
    const m = new THREE.Mesh(
      g,
      new THREE.MeshBasicMaterial({ color: 0x3377cc, transparent: true, opacity: 0.3, side: THREE.DoubleSide }),
    );
    m.userData.plane = p.name;
    marks.add(m);
    line([...p.corners, p.corners[0]], 0x3377cc);
  }
}

// What the marks of the shown pose hold: rays (clear, blocked), sockets,
// planes.
function drawn() {
  const count = (f) => marks.children.reduce((n, o) => n + f(o.userData), 0);
  return {
    rays_clear: count((u) => (u.clear === true ? u.rays : 0)),
    rays_blocked: count((u) => (u.clear === false ? u.rays : 0)),
    sockets: count((u) => (u.socket === undefined ? 0 : 1)),
    planes: count((u) => (u.plane === undefined ? 0 : 1)),
  };
}

function drawCamera(s, k) {
  const c = matrix(s.placements[k]);
  const d = 0.3;
  const tx = Math.tan(s.fov[0] / 2) * d;
  const ty = Math.tan(s.fov[1] / 2) * d;
  const o = new THREE.Vector3().setFromMatrixPosition(c);
  const corners = [[-tx, -ty], [tx, -ty], [tx, ty], [-tx, ty]].map(
    ([x, y]) => new THREE.Vector3(x, y, d).applyMatrix4(c),
  );
  for (const q of corners) line([o.toArray(), q.toArray()], 0x8844aa);
  line([...corners, corners[0]].map((v) => v.toArray()), 0x8844aa);
  const b = s.boards[k];
  if (b && b.length) line([...b, b[0]], 0x111111);
  if (s.rays && s.rays[k]) drawRays(s.rays[k]);
}

function readout() {
  scene.updateMatrixWorld(true);
  const r = renderer.domElement.getBoundingClientRect();
  el('readout').textContent = JSON.stringify({
    poses: data.poses.length,
    link_names: data.links,
    links: data.links.length,
    meshes: data.meshes.length,
    triangles: data.meshes.reduce((n, m) => n + m.triangles, 0),
    moves: data.moves.length,
    shown,
    world: robot.links.map((o) => Array.from(o.matrixWorld.elements)),
    drawn: renderer.info.render.triangles,
    canvas: [r.left, r.top, r.width, r.height],
    readyMs: Math.round(performance.now()),
    timings,
    clearance: data.poses[shown]?.clearance ?? null,
    red: robot.links.flatMap((o, i) => (o.children.some((m) => m.material.emissive?.getHex()) ? [i] : [])),
    marks: drawn(),
  });
}

function setSkeleton(line, mats) {
  const pos = line.geometry.attributes.position;
  bones.forEach(([a, b], i) => {
    pos.setXYZ(2 * i, mats[a][12], mats[a][13], mats[a][14]);
    pos.setXYZ(2 * i + 1, mats[b][12], mats[b][13], mats[b][14]);
  });
  pos.needsUpdate = true;
  line.geometry.computeBoundingSphere();
}

function showPose(k) {
  shown = Math.max(0, Math.min(data.poses.length - 1, k));
  const p = data.poses[shown];
  setLinks(robot, p.links);
  setSkeleton(skeleton, p.links);
  if (fitted) {
    fitted.group.visible = true;
    fittedSkeleton.visible = true;
    const m = magnified(p);
    setLinks(fitted, m);
    setSkeleton(fittedSkeleton, m);
  }
  drawMarks(shown);
  highlight(p.clearance);
  el('slider').value = String(shown);
  const c = clearanceText(p.clearance);
  el('shown').textContent = `${p.label} (${shown + 1} of ${data.poses.length})${c ? `, ${c}` : ''}`;
  document.querySelectorAll('#poses li').forEach((li, i) => li.classList.toggle('on', i === shown));
  render();
  readout();
}

function render() {
  renderer.render(scene, camera);
  timings.rendered ??= performance.now();
}

// Plays the moves of the tour from pose `from`, sample by sample.
function play() {
  const frames = data.moves.map((m) => new Float32Array(bytes(m.frames)));
  const n = data.links.length;
  let mv = 0;
  let s = 0;
  if (fitted) {
    fitted.group.visible = false;
    fittedSkeleton.visible = false;
  }
  const step = () => {
    if (mv >= data.moves.length) return showPose(data.poses.length - 1);
    const m = data.moves[mv];
    const mats = [];
    for (let i = 0; i < n; i++) {
      const f = frames[mv].subarray((s * n + i) * 12, (s * n + i + 1) * 12);
      mats.push([f[0], f[1], f[2], 0, f[3], f[4], f[5], 0, f[6], f[7], f[8], 0, f[9], f[10], f[11], 1]);
    }
    setLinks(robot, mats);
    setSkeleton(skeleton, mats);
    highlight(m.clearance);
    if (s === 0) el('shown').textContent = `move to ${data.poses[m.to].label}${m.clearance ? `, ${clearanceText(m.clearance)}` : ''}`;
    marks.clear();
    render();
    s += 1;
    if (s >= m.samples) {
      s = 0;
      mv += 1;
    }
    requestAnimationFrame(step);
  };
  step();
}

function frameView() {
  const box = new THREE.Box3();
  for (const p of data.poses) for (const m of p.links) box.expandByPoint(new THREE.Vector3(m[12], m[13], m[14]));
  if (box.isEmpty()) box.expandByPoint(new THREE.Vector3());
  const c = box.getCenter(new THREE.Vector3());
  const r = Math.max(0.4, box.getSize(new THREE.Vector3()).length());
  camera.position.set(c.x + 0.6 * r, c.y - 0.8 * r, c.z + 0.45 * r);
  controls.target.copy(c);
  controls.update();
}

function buildList() {
  const list = el('poses');
  data.poses.forEach((p, i) => {
    const li = document.createElement('li');
    li.textContent = p.mark ? `${p.label} (${p.mark})` : p.label;
    if (p.clearance) li.title = clearanceText(p.clearance);
    if (p.mark) li.classList.add(p.mark === 'held out' ? 'held' : 'flagged');
    li.addEventListener('click', () => showPose(i));
    list.appendChild(li);
  });
  el('slider').max = String(Math.max(0, data.poses.length - 1));
  el('slider').addEventListener('input', (e) => showPose(Number(e.target.value)));
  el('play').addEventListener('click', play);
  el('play').disabled = data.moves.length === 0;
  if (data.magnify) {
    el('legend').textContent = `Residuals (red: fitted point, blue → measured point, green) magnified ×${data.magnify}: 1 mm is drawn as ${data.magnify} mm (the black bar above the fitted point). The calibrated robot (orange) differs from the nominal (blue) by its changes magnified ×${data.magnify_robot}.`;
  }
}

const hashPose = () => {
  const m = /pose=(\d+)/.exec(location.hash);
  return m ? Number(m[1]) : 0;
};

// `#click=k`: clicks the k-th entry of the list, as a user would (tests).
function hashClick() {
  const m = /click=(\d+)/.exec(location.hash);
  if (m) document.querySelectorAll('#poses li')[Number(m[1])]?.click();
}

timings.scene = performance.now();
buildList();
frameView();
controls.addEventListener('change', render);
window.addEventListener('hashchange', () => showPose(hashPose()));
window.addEventListener('resize', () => {
  renderer.setSize(host.clientWidth, host.clientHeight);
  camera.aspect = host.clientWidth / host.clientHeight;
  camera.updateProjectionMatrix();
  render();
});
window.activecalPage = { showPose, play };
if (data.poses.length) showPose(hashPose());
else {
  render();
  readout();
}
hashClick();
