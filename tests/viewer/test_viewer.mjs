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
//
// usage: node test_viewer.mjs APPELL SOURCE_DIR WORK_DIR      (exit 77: skipped)
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, rmSync } from 'node:fs';
import { inflateSync } from 'node:zlib';
import { join } from 'node:path';

const [appell, source, work] = process.argv.slice(2);
let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'}  ${what}`);
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

function shoot(t, extra, name) {
  const png = join(work, name);
  const url = `file://${page}#t=${t}&view=top&center=${cx},${cy}&span=${span}${extra}`;
  execFileSync(chromium, ['--headless', '--no-sandbox', '--disable-gpu', '--use-angle=swiftshader',
    '--enable-unsafe-swiftshader', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--hide-scrollbars', `--user-data-dir=${join(work, 'profile')}`,
    `--window-size=${W},${H}`, '--virtual-time-budget=3000', `--screenshot=${png}`, url],
    { stdio: 'ignore', timeout: 120000 });
  return readPng(png);
}
const toPixel = (x, y, img) => ({ x: img.width / 2 + (x - cx) * img.width / span,
                                  y: img.height / 2 - (y - cy) * img.width / span });

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

console.log(`${samples.length * 4 + 2 - failures} passed, ${failures} failed`);
process.exit(failures ? 1 : 0);
