// The viewer page as a person sees it, in headless Chromium: a rolling disk's
// run is written as a page, shown from above with an orthographic camera at
// two times, and the screenshots' pixels must put the disk where the CSV says.
//
// Top view, span S metres across W pixels, centred on (cx, cy): a world point
// (x, y) is drawn at pixel (W/2 + (x − cx)·W/S, H/2 − (y − cy)·W/S). A thin
// disk seen from above is an ellipse centred on the projection of its centre,
// so the centroid of the disk-coloured pixels must land on the projected
// q:root_joint.x/.y of the sample (to within 1.5 px: anti-aliased edges).
// The red force arrow must stand on the contact point (point:rim.x/.y) and
// vanish with #contacts=0, and the two times must give different pictures.
// Then a car over a bump (examples/car_bump) with URDF materials added: the
// terrain mesh must be drawn (its colour where the ground is) and the
// chassis and wheels in their materials' colours. Last, the tumbling crate
// at rest: the overlay (read from the page's DOM) lists its 8 corner contacts
// as one line with the net force, its weight.
//
// usage: node test_viewer.mjs APPELL SOURCE_DIR WORK_DIR      (exit 77: skipped)
import { execFileSync } from 'node:child_process';
import { copyFileSync, existsSync, mkdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { inflateSync } from 'node:zlib';
import { join } from 'node:path';

const [appell, source, work] = process.argv.slice(2);
let failures = 0, checks = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'}  ${what}`);
  ++checks;
  if (!ok) ++failures;
}

const chromium = ['/usr/bin/chromium', '/usr/bin/chromium-browser'].find(existsSync);
if (!chromium) {
  console.log('SKIP: Debian chromium is not installed (scripts/install-viewer-deps.sh --browser installs it)');
  process.exit(77);
}

// ---- PNG: 8-bit RGB or RGBA, not interlaced (what Chromium writes)
function readPng(path) {
  const buf = readFileSync(path);
  if (buf.readUInt32BE(0) !== 0x89504e47) throw new Error(`${path}: not a PNG`);
  let off = 8, width = 0, height = 0, channels = 0;
  const idat = [];
  while (off < buf.length) {
    const len = buf.readUInt32BE(off), type = buf.toString('latin1', off + 4, off + 8);
    const body = buf.subarray(off + 8, off + 8 + len);
    if (type === 'IHDR') {
      width = body.readUInt32BE(0); height = body.readUInt32BE(4);
      if (body[8] !== 8 || body[12] !== 0) throw new Error(`${path}: only 8-bit, non-interlaced`);
      channels = { 2: 3, 6: 4 }[body[9]];
      if (!channels) throw new Error(`${path}: colour type ${body[9]}`);
    } else if (type === 'IDAT') idat.push(body);
    off += 12 + len;
  }
  const raw = inflateSync(Buffer.concat(idat)), stride = width * channels;
  const px = Buffer.alloc(height * stride);
  for (let y = 0; y < height; ++y) {
    const f = raw[y * (stride + 1)], src = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let i = 0; i < stride; ++i) {
      const a = i >= channels ? px[y * stride + i - channels] : 0;
      const b = y > 0 ? px[(y - 1) * stride + i] : 0;
      const c = y > 0 && i >= channels ? px[(y - 1) * stride + i - channels] : 0;
      let p;
      switch (f) {
        case 0: p = 0; break;
        case 1: p = a; break;
        case 2: p = b; break;
        case 3: p = (a + b) >> 1; break;
        case 4: {
          const pa = Math.abs(b - c), pb = Math.abs(a - c), pc = Math.abs(a + b - 2 * c);
          p = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
          break;
        }
        default: throw new Error(`${path}: filter ${f}`);
      }
      px[y * stride + i] = (src[i] + p) & 255;
    }
  }
  return { width, height, at: (x, y) => px.subarray(y * stride + x * channels, y * stride + x * channels + 3) };
}

// Centroid and count of the pixels a predicate picks.
function centroid(img, pick) {
  let n = 0, sx = 0, sy = 0;
  for (let y = 0; y < img.height; ++y)
    for (let x = 0; x < img.width; ++x)
      if (pick(...img.at(x, y))) { ++n; sx += x + 0.5; sy += y + 0.5; }
  return { n, x: sx / n, y: sy / n };
}
// The disk's orange (0xe08a00) under any shading: red over green over blue, no blue.
const isDisk = (r, g, b) => r > 50 && r > 1.25 * g && g > b + 25 && b < 0.4 * g;
// The arrow's red (0xc02030): green and blue low and alike.
const isArrow = (r, g, b) => r > 100 && g < 0.45 * r && b < 0.55 * r && Math.abs(g - b) < 30;

// ---- the run and the page
rmSync(work, { recursive: true, force: true });
mkdirSync(work, { recursive: true });
const scene = join(source, 'examples/rolling_disk/rolling_disk.urdf');
const csv = join(work, 'disk.csv'), page = join(work, 'disk.html');
execFileSync(appell, ['run', scene, '--duration', '3', '--quiet', '--out', csv]);
execFileSync(appell, ['view', scene, '--trajectory', csv, '--out', page]);
const html = readFileSync(page, 'utf8');
check(!/\b(src|href)\s*=\s*["']?(https?:|\/\/)/i.test(html) && !/import\s*\(/.test(html),
      'the page refers to nothing outside itself');

const lines = readFileSync(csv, 'utf8').trim().split('\n');
const cols = lines[0].split(',');
const rows = lines.slice(1).map((l) => l.split(',').map(Number));
const col = (name) => { const i = cols.indexOf(name); if (i < 0) throw new Error('no column ' + name); return i; };
const [ix, iy, icx, icy] = ['q:root_joint.x', 'q:root_joint.y', 'point:rim.x', 'point:rim.y'].map(col);

// Frame every position of the run, with a margin for the disk (radius 0.3 m).
const xs = rows.map((r) => r[ix]), ys = rows.map((r) => r[iy]);
const cx = (Math.min(...xs) + Math.max(...xs)) / 2, cy = (Math.min(...ys) + Math.max(...ys)) / 2;
const span = 1.5 * Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys)) + 1.5;
const W = 800, H = 800;

function shoot(t, extra, name, at = { page, cx, cy, span }) {
  const png = join(work, name);
  const url = `file://${at.page}#t=${t}&view=top&center=${at.cx},${at.cy}&span=${at.span}${extra}`;
  execFileSync(chromium, ['--headless', '--no-sandbox', '--disable-gpu', '--use-angle=swiftshader',
    '--enable-unsafe-swiftshader', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--hide-scrollbars', `--user-data-dir=${join(work, 'profile')}`,
    `--window-size=${W},${H}`, '--virtual-time-budget=3000', `--screenshot=${png}`, url],
    { stdio: 'ignore', timeout: 120000 });
  return readPng(png);
}
const toPixel = (x, y, img, at = { cx, cy, span }) => ({ x: img.width / 2 + (x - at.cx) * img.width / at.span,
                                                         y: img.height / 2 - (y - at.cy) * img.width / at.span });

// Two samples of the CSV (exact sample times: the page then shows the sample itself).
const samples = [Math.floor(rows.length * 0.3), Math.floor(rows.length * 0.8)];
const shots = [];
for (const s of samples) {
  const r = rows[s], t = r[0];
  const img = shoot(t, '&contacts=0', `top_${s}.png`);
  check(img.width === W && img.height === H, `screenshot is ${W}×${H} (got ${img.width}×${img.height})`);
  const disk = centroid(img, isDisk), want = toPixel(r[ix], r[iy], img);
  const err = Math.hypot(disk.x - want.x, disk.y - want.y);
  check(disk.n > 200, `t = ${t}: the disk is drawn (${disk.n} pixels)`);
  check(err < 1.5, `t = ${t}: disk centroid (${disk.x.toFixed(2)}, ${disk.y.toFixed(2)}) px vs CSV ` +
        `(${want.x.toFixed(2)}, ${want.y.toFixed(2)}) px: ${err.toFixed(2)} px off`);
  const withArrows = shoot(t, '', `top_${s}_contacts.png`);
  const arrow = centroid(withArrows, isArrow), foot = toPixel(r[icx], r[icy], withArrows);
  const aerr = Math.hypot(arrow.x - foot.x, arrow.y - foot.y);
  // From above one sees the arrow's head, carried sideways by the friction part of f
  // (|f_t|/f_n ≤ 0.05 here, on an arrow about a metre long: ≤ 5 cm, about 5 px).
  check(arrow.n > 20 && aerr < 8 && centroid(img, isArrow).n === 0,
        `t = ${t}: the force arrow stands on the contact point ` +
        `(${arrow.n} red pixels, ${aerr.toFixed(2)} px from point:rim; none with contacts=0)`);
  shots.push(img);
}
// Scrubbing changes the picture.
let differ = 0;
for (let y = 0; y < H; ++y)
  for (let x = 0; x < W; ++x) {
    const a = shots[0].at(x, y), b = shots[1].at(x, y);
    if (Math.abs(a[0] - b[0]) + Math.abs(a[1] - b[1]) + Math.abs(a[2] - b[2]) > 30) ++differ;
  }
check(differ > 500, `the two times give different pictures (${differ} pixels differ)`);

// ---- a terrain and URDF materials: examples/car_bump (a car over a bump in a
// terrain mesh), its chassis given a robot-level material by name and its
// wheels a colour of their own, as URDF allows.
{
  const car = join(source, 'examples/car_bump');
  const urdf = readFileSync(join(car, 'car_bump.urdf'), 'utf8')
    .replace('<robot name="car_bump">',
             '<robot name="car_bump">\n  <material name="paint"><color rgba="0.1 0.3 0.85 1"/></material>')
    .replace('<geometry><box size="1.0 0.6 0.2"/></geometry>\n    </visual>',
             '<geometry><box size="1.0 0.6 0.2"/></geometry>\n      <material name="paint"/>\n    </visual>')
    .replaceAll('<geometry><cylinder radius="0.15" length="0.06"/></geometry>\n    </visual>',
                '<geometry><cylinder radius="0.15" length="0.06"/></geometry>\n' +
                '      <material name="tyre"><color rgba="0.1 0.1 0.1 1"/></material>\n    </visual>');
  check((urdf.match(/<material name="(paint|tyre)"/g) || []).length === 6, 'the test scene has its 6 materials');
  copyFileSync(join(car, 'bump.obj'), join(work, 'bump.obj'));
  const scene2 = join(work, 'car_bump.urdf'), csv2 = join(work, 'car.csv'), page2 = join(work, 'car.html');
  writeFileSync(scene2, urdf);
  execFileSync(appell, ['run', scene2, '--duration', '0.5', '--quiet', '--out', csv2]);
  execFileSync(appell, ['view', scene2, '--trajectory', csv2, '--out', page2]);
  const l2 = readFileSync(csv2, 'utf8').trim().split('\n'), c2 = l2[0].split(',');
  const last = l2[l2.length - 1].split(',').map(Number);
  const [x, y] = ['q:root_joint.x', 'q:root_joint.y'].map((n) => last[c2.indexOf(n)]);
  // From above: the whole bump (x 2 … 3.5 m) and the car, 6 m across.
  const at = { page: page2, cx: 2, cy: 0, span: 6 };
  const img = shoot(last[0], '&contacts=0', 'car_top.png', at);
  const rgb = (wx, wy) => { const p = toPixel(wx, wy, img, at); return [...img.at(Math.round(p.x), Math.round(p.y))]; };
  // The terrain's sand colour (0xc8b07a) under any shading: red over green over a blue
  // that is still present (not the disk's orange, not the grey background).
  const isTerrain = (r, g, b) => r > 90 && r - b > 35 && g - b > 20 && b > 0.35 * r;
  const ground = [[-0.5, 1.2], [1.5, -2.2], [2.25, 1.8], [3.25, -1.5], [4.5, 2.2]];
  const terrainAt = ground.filter(([wx, wy]) => isTerrain(...rgb(wx, wy)));
  check(terrainAt.length === ground.length,
        `terrain pixels where the mesh is (${terrainAt.length}/${ground.length}: ` +
        ground.map(([wx, wy]) => `(${wx}, ${wy}) → ${rgb(wx, wy)}`).join(', ') + ')');
  const terrainPixels = centroid(img, isTerrain).n;
  check(terrainPixels > 0.5 * img.width * img.height, `the terrain covers the ground (${terrainPixels} pixels)`);
  // The chassis (its centre 0.1 m ahead of the root) in the robot-level colour.
  const paint = rgb(x + 0.1, y), [r, g, b] = paint;
  check(b > 120 && b > 2 * r && b > 1.4 * g, `the chassis is drawn in its material's blue (${paint} at x = ${x.toFixed(3)} m)`);
  // A wheel's top, in its own near-black.
  const tyre = rgb(x + 0.4, y + 0.35);
  check(Math.max(...tyre) < 70, `the front left wheel is drawn in its own colour (${tyre})`);
}

// ---- the overlay lists a shape's vertex contacts as one line: the tumbling
// crate (examples/tumbling_crate, 3 kg, its box's 8 corners as contacts) at
// rest on a face: 4 corners closed, carrying its weight 3 g = 29.430 N.
{
  const crate = join(source, 'examples/tumbling_crate/tumbling_crate.urdf');
  const csv3 = join(work, 'crate.csv'), page3 = join(work, 'crate.html');
  execFileSync(appell, ['run', crate, '--quiet', '--out', csv3]);
  execFileSync(appell, ['view', crate, '--trajectory', csv3, '--out', page3]);
  const dom = execFileSync(chromium, ['--headless', '--no-sandbox', '--disable-gpu', '--use-angle=swiftshader',
    '--enable-unsafe-swiftshader', '--no-first-run', '--disable-background-networking', '--disable-component-update',
    '--disable-sync', `--user-data-dir=${join(work, 'profile')}`, '--window-size=800,800',
    '--virtual-time-budget=3000', '--dump-dom', `file://${page3}#t=1e9`],
    { encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'], timeout: 120000 });
  const info = (dom.match(/<div id="info">([^<]*)<\/div>/) || [, ''])[1];
  check(/^corners \(8 vertices, 4 closed\): \|Σf\| = 29\.430 N$/m.test(info) && !info.includes('corners/v'),
        `the crate's corners are one line of the overlay (${JSON.stringify(info)})`);
}

console.log(`${checks - failures} passed, ${failures} failed`);
process.exit(failures ? 1 : 0);
