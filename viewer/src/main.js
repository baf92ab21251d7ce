// The replay page of `appell view`: draws the scene's visual geometry at the
// body poses the CLI computed (forward kinematics of each CSV sample, so
// nothing is re-derived here), the contact points, the reaction forces
// f = Σ_r λ_r d_r as arrows (d_r the row directions), the paths traced by the
// bodies and the contacts, a ground grid and the supports (terrain meshes as
// their triangles); visuals in their URDF material colours. Between samples,
// positions are interpolated linearly and orientations by slerp.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const data = JSON.parse(document.getElementById('appell-data').textContent);
const nb = data.bodies.length, nc = data.contacts.length, ns = data.times.length;
const t0 = data.times[0], t1 = data.times[ns - 1];

// ---- options from the URL hash: #t=2.5&view=top&center=x,y&span=S&play=1&contacts=0
const opts = Object.fromEntries(new URLSearchParams(location.hash.slice(1)));

// ---- renderer, scene, lights (z is up, as in appell)
const host = document.getElementById('scene');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(host.clientWidth, host.clientHeight);
host.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f4f2);
scene.add(new THREE.HemisphereLight(0xffffff, 0x808080, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(0.3, -0.5, 1);
scene.add(sun);

// ---- extent of the motion: frames the camera, sizes the grid and the arrows
const box = new THREE.Box3();
for (let s = 0; s < ns; ++s)
  for (let b = 0; b < nb; ++b) {
    const o = data.poses[s], k = 7 * b;
    box.expandByPoint(new THREE.Vector3(o[k], o[k + 1], o[k + 2]));
  }
box.expandByScalar(data.size);
data.supports.forEach((s, k) => {              // a bowl or a globe: frame all of it
  if (s.type !== 'sphere') return;
  const o = data.supportPoses[0], c = new THREE.Vector3().fromArray(s.centre)
    .applyQuaternion(new THREE.Quaternion().fromArray(o, 7 * k + 3)).add(new THREE.Vector3().fromArray(o, 7 * k));
  box.union(new THREE.Box3().setFromCenterAndSize(c, new THREE.Vector3().setScalar(2 * s.radius)));
});
const centre = box.getCenter(new THREE.Vector3());
const extent = Math.max(box.getSize(new THREE.Vector3()).length(), 1e-3);

// ---- terrain meshes: their triangles, in the support frame (placed per sample
// below, as every support); flat-shaded faces in a sand colour, with the
// creases (faces meeting at more than 1°) and the boundary drawn as lines.
const terrainColour = 0xc8b07a;
function terrainMesh(s) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(s.vertices, 3));
  g.setIndex(s.triangles);
  const faces = g.toNonIndexed();                 // one normal per face: flat shading
  faces.computeVertexNormals();
  const group = new THREE.Group();
  group.add(new THREE.Mesh(faces, new THREE.MeshLambertMaterial({
    color: terrainColour, side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1,
    polygonOffsetUnits: 1 })));
  group.add(new THREE.LineSegments(new THREE.EdgesGeometry(g, 1),
                                   new THREE.LineBasicMaterial({ color: 0x7d6a45 })));
  return group;
}
// Lowest world z of the terrains at the first sample (the grid goes under them).
let terrainBottom = Infinity;
data.supports.forEach((s, k) => {
  if (s.type !== 'terrain') return;
  const o = data.supportPoses[0], r = new THREE.Quaternion().fromArray(o, 7 * k + 3), v = new THREE.Vector3();
  for (let i = 0; i < s.vertices.length; i += 3)
    terrainBottom = Math.min(terrainBottom, v.fromArray(s.vertices, i).applyQuaternion(r).z + o[7 * k + 2]);
});

// ---- ground grid: in the scene's horizontal ground plane, else under everything
{
  const z = data.ground !== null ? data.ground : Math.min(box.min.z, terrainBottom - 1e-3 * extent);
  const n = Math.ceil(extent / 0.5) * 2;
  const grid = new THREE.GridHelper(n * 0.5, n, 0x9a9a9a, 0xcfcfcf);
  grid.rotation.x = Math.PI / 2;                  // GridHelper lies in xz
  grid.position.set(Math.round(centre.x), Math.round(centre.y), z);
  scene.add(grid);
}

// ---- bodies: one group per body, its visuals placed in the body frame
const palette = [0xe08a00, 0x3a7dc9, 0x8e5bb5, 0x2a9d8f, 0xb0413e, 0x6b8e23];
function geometryOf(g) {
  switch (g.type) {
    case 'box': return new THREE.BoxGeometry(g.size[0], g.size[1], g.size[2]);
    case 'sphere': return new THREE.SphereGeometry(g.radius, 48, 24);
    case 'cylinder': {                            // URDF cylinders lie along z, three's along y
      const c = new THREE.CylinderGeometry(g.radius, g.radius, g.length, 64);
      c.rotateX(Math.PI / 2);
      return c;
    }
    case 'mesh': {
      const m = new THREE.BufferGeometry();
      m.setAttribute('position', new THREE.Float32BufferAttribute(g.vertices, 3));
      m.setIndex(g.triangles);
      m.computeVertexNormals();
      return m;
    }
  }
  throw new Error('unknown geometry ' + g.type);
}
// A visual's URDF material colour (sRGB, as RViz shows it; alpha < 1 see-through),
// else the body's colour from the palette.
function materialOf(g, fallback) {
  if (!g.rgba) return fallback;
  const [r, gr, b, a] = g.rgba;
  return new THREE.MeshLambertMaterial({ color: new THREE.Color().setRGB(r, gr, b, THREE.SRGBColorSpace),
                                         transparent: a < 1, opacity: a });
}
const bodies = data.bodies.map((body, b) => {
  const group = new THREE.Group();
  const material = new THREE.MeshLambertMaterial({ color: palette[b % palette.length] });
  for (const g of body.geometry) {
    const mesh = new THREE.Mesh(geometryOf(g), materialOf(g, material));
    mesh.position.fromArray(g.p);
    mesh.quaternion.fromArray(g.q);
    group.add(mesh);
  }
  scene.add(group);
  return group;
});

// ---- supports other than the ground: a disc with spokes for a plane (so that
// a turntable's turn shows), a wire sphere for a globe or a bowl, the
// triangles of a terrain; each in its
// support frame, placed per sample (moving supports, supports on bodies)
const supportMaterial = new THREE.LineBasicMaterial({ color: 0x6a7f99, transparent: true, opacity: 0.7 });
const supports = data.supports.map((s) => {
  const group = new THREE.Group();
  if (s.type === 'plane') {
    const disc = new THREE.PolarGridHelper(0.5 * extent, 16, 8, 64, 0x6a7f99, 0x9fb0c4);
    disc.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), new THREE.Vector3(...s.normal));
    disc.position.fromArray(s.point);
    group.add(disc);
  } else if (s.type === 'sphere') {
    // A bowl (rolled on inside) is drawn as its lower half, a globe whole.
    const g = s.inside ? new THREE.SphereGeometry(s.radius, 24, 8, 0, 2 * Math.PI, Math.PI / 2, Math.PI / 2)
                       : new THREE.SphereGeometry(s.radius, 24, 16);
    g.rotateX(Math.PI / 2);                      // three's pole is y, the support frame's z
    const wire = new THREE.LineSegments(new THREE.WireframeGeometry(g), supportMaterial);
    wire.position.fromArray(s.centre);
    group.add(wire);
  } else if (s.type === 'terrain') {
    group.add(terrainMesh(s));
  }
  scene.add(group);
  return group;
});

// ---- paths: every body origin and every contact point, drawn up to the current time
function path(stride, offset, source, colour) {
  const xyz = new Float32Array(3 * ns);
  for (let s = 0; s < ns; ++s)
    for (let i = 0; i < 3; ++i) xyz[3 * s + i] = source[s][stride * offset + i];
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
  const line = new THREE.Line(g, new THREE.LineBasicMaterial({ color: colour }));
  scene.add(line);
  return line;
}
const paths = [];
for (let b = 0; b < nb; ++b)
  if (data.bodies[b].moves) paths.push(path(7, b, data.poses, 0x1f5fbf));
for (let c = 0; c < nc; ++c) paths.push(path(3, c, data.points, 0x555555));

// ---- contacts: a dot at the point, an arrow for the reaction force
let fmax = 0;
for (let s = 0; s < ns; ++s)
  for (let c = 0; c < nc; ++c) {
    const f = data.forces[s];
    fmax = Math.max(fmax, Math.hypot(f[3 * c], f[3 * c + 1], f[3 * c + 2]));
  }
const arrowScale = fmax > 0 ? 0.25 * extent / fmax : 0;   // metres per newton
const contacts = data.contacts.map(() => {
  const dot = new THREE.Mesh(new THREE.SphereGeometry(Math.min(0.012 * extent, 0.08 * data.size), 16, 8),
                             new THREE.MeshBasicMaterial({ color: 0x111111 }));
  const arrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, 0xc02030);
  if (opts.contacts !== '0') scene.add(dot, arrow);   // contacts=0: the bodies alone
  return { dot, arrow };
});

// ---- the overlay lists a shape's vertex contacts (a box's corners, a sole's
// rim) as one line: the declaration, how many vertices touch, and the net
// force Σf they carry
const vertexGroups = data.vertexGroups || [];
const groupOf = new Array(nc).fill(-1);
vertexGroups.forEach((g, k) => { for (let c = g.first; c < g.first + g.count; ++c) groupOf[c] = k; });

// ---- cameras: a perspective one the mouse orbits, or a fixed one from above
const aspect = host.clientWidth / host.clientHeight;
let camera;
if (opts.view === 'top') {
  const [cx, cy] = opts.center ? opts.center.split(',').map(Number) : [centre.x, centre.y];
  const span = opts.span ? Number(opts.span) : extent;     // visible width in metres
  camera = new THREE.OrthographicCamera(-span / 2, span / 2, span / 2 / aspect, -span / 2 / aspect,
                                        0.01, 1000);
  camera.userData.span = span;
  camera.position.set(cx, cy, box.max.z + 100);
  camera.up.set(0, 1, 0);
  camera.lookAt(cx, cy, 0);
} else {
  camera = new THREE.PerspectiveCamera(40, aspect, extent / 1000, extent * 100);
  camera.up.set(0, 0, 1);
  camera.position.copy(centre).add(new THREE.Vector3(0.45, -0.8, 0.5).multiplyScalar(extent));
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.copy(centre);
  controls.update();
  controls.addEventListener('change', () => render());
}

// ---- the state at time t
const p0 = new THREE.Vector3(), p1 = new THREE.Vector3(), q0 = new THREE.Quaternion(),
      q1 = new THREE.Quaternion(), f = new THREE.Vector3();
function sampleAt(t) {                          // i with times[i] ≤ t < times[i+1], and the weight
  let lo = 0, hi = ns - 1;
  if (t <= data.times[0]) return [0, 0];
  if (t >= data.times[hi]) return [hi, 0];
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (data.times[mid] <= t) lo = mid; else hi = mid;
  }
  return [lo, (t - data.times[lo]) / (data.times[hi] - data.times[lo])];
}
function lerp3(out, a, b, k, w) { return out.set(a[k], a[k + 1], a[k + 2]).lerp(p1.set(b[k], b[k + 1], b[k + 2]), w); }

const info = document.getElementById('info');
function show(t) {
  const [i, w] = sampleAt(t), j = Math.min(i + 1, ns - 1);
  for (let b = 0; b < nb; ++b) {
    const A = data.poses[i], B = data.poses[j], k = 7 * b;
    lerp3(p0, A, B, k, w);
    q0.fromArray(A, k + 3).slerp(q1.fromArray(B, k + 3), w);
    bodies[b].position.copy(p0);
    bodies[b].quaternion.copy(q0);
  }
  for (let k = 0; k < supports.length; ++k) {
    const A = data.supportPoses[i], B = data.supportPoses[j], o = 7 * k;
    lerp3(p0, A, B, o, w);
    q0.fromArray(A, o + 3).slerp(q1.fromArray(B, o + 3), w);
    supports[k].position.copy(p0);
    supports[k].quaternion.copy(q0);
  }
  const lines = [], groupSum = vertexGroups.map(() => ({ f: new THREE.Vector3(), closed: 0 }));
  for (let c = 0; c < nc; ++c) {
    lerp3(p0, data.points[i], data.points[j], 3 * c, w);
    lerp3(f, data.forces[i], data.forces[j], 3 * c, w);
    // An open contact (lifted off, in flight: closed = 0 at this sample) has
    // no contact point and no force.
    const closed = !data.closed || data.closed[w < 1 ? i : j][c] !== 0;
    contacts[c].dot.position.copy(p0);
    contacts[c].dot.visible = closed;
    const a = contacts[c].arrow, len = f.length() * arrowScale;
    a.visible = closed && len > 1e-9;
    if (a.visible) {
      a.position.copy(p0);
      a.setDirection(f.clone().normalize());
      a.setLength(len, Math.min(0.3 * len, 0.04 * extent), Math.min(0.15 * len, 0.02 * extent));
    }
    const k = groupOf[c];
    if (k >= 0) {                               // one of a declaration's vertices: summed below
      if (closed) { groupSum[k].f.add(f); ++groupSum[k].closed; }
      if (c === vertexGroups[k].first) lines.push(k);   // its line goes where its first vertex is
    } else lines.push(`${data.contacts[c].name}: ` + (closed ? `|f| = ${f.length().toFixed(3)} N` : 'open'));
  }
  for (let l = 0; l < lines.length; ++l) {
    if (typeof lines[l] !== 'number') continue;
    const g = vertexGroups[lines[l]], sum = groupSum[lines[l]];
    lines[l] = `${g.name} (${g.count} vertices, ${sum.closed} closed): ` +
      (sum.closed ? `|Σf| = ${sum.f.length().toFixed(3)} N` : 'open');
  }
  const drawn = Math.max(2, i + 2);
  for (const p of paths) p.geometry.setDrawRange(0, Math.min(drawn, ns));
  info.textContent = `${data.title}\n` + lines.join('\n') +
    (arrowScale > 0 ? `\narrows: 1 m = ${(1 / arrowScale).toPrecision(3)} N` : '');
  document.getElementById('time').textContent =
    `t = ${t.toFixed(3)} s / ${t1.toFixed(3)} s`;
  render();
}
function render() { renderer.render(scene, camera); }

// ---- play / pause / scrub
const slider = document.getElementById('slider'), button = document.getElementById('play');
let t = opts.t !== undefined ? Math.min(Math.max(Number(opts.t), t0), t1) : t0;
let playing = false, wall = 0;
const toSlider = (x) => Math.round(1000 * (x - t0) / Math.max(t1 - t0, 1e-12));
function setPlaying(on) {
  playing = on && ns > 1;
  button.textContent = playing ? 'pause' : 'play';
  wall = performance.now();
  if (playing) requestAnimationFrame(tick);
}
function tick(now) {
  if (!playing) return;
  t += (now - wall) / 1000;
  wall = now;
  if (t >= t1) { t = t1; setPlaying(false); }
  slider.value = toSlider(t);
  show(t);
  if (playing) requestAnimationFrame(tick);
}
button.addEventListener('click', () => {
  if (!playing && t >= t1) t = t0;
  setPlaying(!playing);
});
slider.addEventListener('input', () => {
  setPlaying(false);
  t = t0 + (t1 - t0) * slider.value / 1000;
  show(t);
});
window.addEventListener('keydown', (e) => { if (e.key === ' ') button.click(); });
window.addEventListener('resize', () => {
  renderer.setSize(host.clientWidth, host.clientHeight);
  const a = host.clientWidth / host.clientHeight;
  if (camera.isPerspectiveCamera) camera.aspect = a;
  else {                                        // keep the width in metres; the height follows
    camera.top = camera.userData.span / 2 / a;
    camera.bottom = -camera.top;
  }
  camera.updateProjectionMatrix();
  render();
});
// ---- contact events on the time line: a tick per event time (touchdown
// green, bounce blue, lift-off red, slip orange, stick purple, a change of
// terrain piece grey); clicking one shows that instant.
{
  const marks = document.getElementById('marks'),
    colour = { touchdown: '#2a9d2a', bounce: '#3a7dc9', lift_off: '#c0392b', slip: '#e08a00', stick: '#8e5bb5',
      feature: '#8a8a8a' };
  const byTime = new Map();
  for (const [te, c, kind] of data.events) {
    if (!byTime.has(te)) byTime.set(te, []);
    byTime.get(te).push(`${kind} ${data.contacts[c].name}`);
  }
  for (const [te, what] of byTime) {
    const tick = document.createElement('div');
    tick.className = 'mark';
    tick.style.left = `${100 * toSlider(te) / 1000}%`;
    tick.style.background = colour[what[0].split(' ')[0]] || '#555';
    tick.title = `t = ${te.toPrecision(12)} s: ` + what.join(', ');
    tick.addEventListener('click', () => { setPlaying(false); t = te; slider.value = toSlider(t); show(t); });
    marks.appendChild(tick);
  }
}
slider.value = toSlider(t);
show(t);
if (opts.play === '1') setPlaying(true);
