// `pathstream serve`'s page for a 3-axis router, in Debian's Chromium (headless, playwright-core)
// against `pathstream serve` and the simulated device on loopback:
//
//   node serve_3d_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR
//
// With tests/data/machines/router_3axis.json (axes x, y, z, a 600 x 600 x 60 mm work volume): loads
// tests/data/router_pocket.json (three coordinates a point), fits it to the work area and checks
// that the preview is the isometric view path.svg draws (docs/serve.md): the canvas says so, the work volume's box
// gives the view's scale and offset, and at every vertex of the path, projected by the
// documented formula, the canvas shows the path; feed moves are solid in the layer's colour,
// rapids dashed; the legend says "rapids". A screenshot goes to OUT_DIR/serve-3d-preview.png.
import { spawn } from 'node:child_process';
import { mkdtempSync, rmSync, mkdirSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { chromium } from 'playwright-core';

const [bin, source, outDir] = process.argv.slice(2);
if (!bin || !source || !outDir) {
  console.error('usage: node serve_3d_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR');
  process.exit(2);
}
const machine = path.join(source, 'tests/data/machines/router_3axis.json');
const job = path.join(source, 'tests/data/router_pocket.json');
const work = mkdtempSync(path.join(tmpdir(), 'pathstream-browser-3d-'));
mkdirSync(outDir, { recursive: true });
const children = [];
let failures = 0;

function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures++;
}

// Starts a command and resolves with the first match of `pattern` in its standard output.
function startAndRead(args, pattern, name) {
  const child = spawn(bin, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  children.push(child);
  let text = '';
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`${name}: no ${pattern} in 10 s: ${text}`)), 10000);
    const look = chunk => {
      text += chunk;
      const m = text.match(pattern);
      if (m) { clearTimeout(timer); resolve({ child, match: m }); }
    };
    child.stdout.on('data', look);
    child.stderr.on('data', chunk => { text += chunk; });
    child.on('exit', code => reject(new Error(`${name} exited ${code}: ${text}`)));
  });
}

// The view of docs/serve.md: [right, up] in mm.
const iso = (x, y, z) => [(x + y) * Math.sqrt(3) / 2, z + (y - x) / 2];

async function main() {
  const device = await startAndRead(['device', '--tcp', '127.0.0.1:0', '-m', machine], /serving (modbus-tcp:\/\/\S+)/, 'device');
  const server = await startAndRead(['serve', '-m', machine, '-t', device.match[1], '--listen', '127.0.0.1:0',
    '--state-dir', path.join(work, 'state')], /(http:\/\/127\.0\.0\.1:\d+\/)/, 'serve');
  const browser = await chromium.launchPersistentContext(path.join(work, 'chromium'), {
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    viewport: { width: 1366, height: 768 },
  });
  try {
    const page = await browser.newPage();
    page.on('pageerror', e => check(false, `no script error on the page: ${e.message}`));
    await page.goto(server.match[1]);
    await page.waitForSelector('body[data-ready="true"]');
    await page.setInputFiles('#file', job);
    await page.waitForSelector('#fig-subpaths[data-value]', { timeout: 15000 }).catch(async e => {
      throw new Error(`no preview: ${await page.textContent('#error')} ${await page.textContent('#drawing-name')}`);
    });
    check(await page.getAttribute('#preview', 'data-view') === 'isometric', 'the preview is the isometric view');
    check((await page.textContent('#layers')).includes('rapids'), 'the legend names the rapids');
    // In the file's order (each cut plunges, runs and retracts where the file says: ordering
    // would start a closed cut anywhere), fitted to the work area (x and y scaled, z kept):
    // long pieces to look at.
    const changed = async (id, before) => {
      const end = Date.now() + 15000;
      while (Date.now() < end && Number(await page.getAttribute(`#${id}`, 'data-value')) === before)
        await new Promise(r => setTimeout(r, 50));
      return Number(await page.getAttribute(`#${id}`, 'data-value'));
    };
    const travel = Number(await page.getAttribute('#fig-travel', 'data-value'));
    await page.uncheck('#order');
    check(await changed('fig-travel', travel) !== travel, 'in the file\'s order: another travel');
    const asDrawn = Number(await page.getAttribute('#fig-drawn', 'data-value'));
    await page.selectOption('#fit', 'area');
    check(await changed('fig-drawn', asDrawn) > 2 * asDrawn, 'fitted to the work area: drawn longer');

    // The canvas against the preview's own numbers: the work volume's box fixes the view's
    // scale and offset; each vertex of the path, projected by the formula, is drawn there.
    const { p, area } = await page.evaluate(async () => ({
      p: await fetch('/api/preview').then(r => r.json()),
      area: document.getElementById('preview').dataset.area.split(',').map(Number),
    }));
    check(p.view && p.view.projection === 'isometric' && Array.isArray(p.path.z), 'the preview document has view and path.z');
    const b = p.view.box;
    let u0 = Infinity, u1 = -Infinity, v0 = Infinity, v1 = -Infinity;
    for (const x of [b.x_min, b.x_max]) for (const y of [b.y_min, b.y_max]) for (const z of [b.z_min, b.z_max]) {
      const [u, v] = iso(x, y, z);
      u0 = Math.min(u0, u); u1 = Math.max(u1, u); v0 = Math.min(v0, v); v1 = Math.max(v1, v);
    }
    const [left, top, right, bottom] = area;
    const sx = (right - left) / (u1 - u0), sy = (bottom - top) / (v1 - v0);
    check(Math.abs(sx / sy - 1) < 0.01, `equal scale: ${sx.toFixed(4)} and ${sy.toFixed(4)} px per mm across and up`);
    const css = (x, y, z) => { const [u, v] = iso(x, y, z); return [left + (u - u0) * sx, top + (v1 - v) * sx]; };
    // Along each piece (vertex i-1 to i), the middle 60 %: ink on every sample of a feed move,
    // on some but not all of a rapid (dashed).
    const samples = [];
    const { x, y, z, pen } = p.path;
    for (let i = 1; i < x.length; i++) {
      const a = css(x[i - 1], y[i - 1], z[i - 1]), e = css(x[i], y[i], z[i]);
      const length = Math.hypot(e[0] - a[0], e[1] - a[1]);
      if (length < 20) continue;
      const pts = [];
      for (let s = 0.2; s <= 0.8; s += 0.6 / 24) pts.push([a[0] + s * (e[0] - a[0]), a[1] + s * (e[1] - a[1])]);
      samples.push({ pen: pen[i], pts, length });
    }
    // A control: the feed moves' samples 12 px lower, off the path, are mostly background.
    const feedPieces = samples.filter(s => s.pen === 1);
    samples.push({ pen: -1, pts: feedPieces.flatMap(s => s.pts.map(([px, py]) => [px, py + 12])) });
    const colours = await page.evaluate(list => {
      const c = document.getElementById('preview');
      const k = c.width / c.clientWidth;
      const data = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      // The darkest pixel within half a pixel: a thin line between pixel centres still shows.
      return list.map(pts => pts.map(([px, py]) => {
        let best = 765;
        for (const dx of [-0.5, 0, 0.5]) for (const dy of [-0.5, 0, 0.5]) {
          const i = 4 * (Math.round((py + dy) * k) * c.width + Math.round((px + dx) * k));
          best = Math.min(best, data[i] + data[i + 1] + data[i + 2]);
        }
        return best;
      }));
    }, samples.map(s => s.pts));
    const background = 0xde + 0xe2 + 0xe6;
    const ink = v => v < background - 60;
    const feeds = samples.filter(s => s.pen === 1), rapids = samples.filter(s => s.pen === 0);
    check(feeds.length >= 4 && rapids.length >= 1, `long pieces to sample: ${feeds.length} feed moves, ${rapids.length} rapids`);
    const solid = feeds.every(s => colours[samples.indexOf(s)].every(ink));
    check(solid, 'every feed move is drawn solid where the formula puts it');
    const dashed = rapids.every(s => {
      const inked = colours[samples.indexOf(s)].filter(ink).length;
      return inked > 2 && inked < s.pts.length - 2;
    });
    const off = colours[samples.length - 1];
    check(off.filter(ink).length < 0.2 * off.length, `12 px off the feed moves the canvas is mostly empty (${off.filter(ink).length} of ${off.length} inked)`);
    const marker = (await page.getAttribute('#preview', 'data-marker') || '').split(',').map(Number);
    const origin = css(0, 0, 0);
    check(marker.length === 2 && Math.hypot(marker[0] - origin[0], marker[1] - origin[1]) < 1.5,
      `the device at (0, 0, 0) is marked where the view puts it: ${marker} (want ${origin.map(v => v.toFixed(1))})`);
    check(dashed, `every rapid is drawn dashed where the formula puts it (${rapids.map(s => colours[samples.indexOf(s)].filter(ink).length).join(', ')} of 25 samples inked)`);
    await page.screenshot({ path: path.join(outDir, 'serve-3d-preview.png'), fullPage: true });
  } finally {
    await browser.close();
  }
}

try {
  await main();
} catch (e) {
  console.log(`FAIL ${e.stack || e}`);
  failures++;
} finally {
  for (const c of children) c.kill('SIGTERM');
  await new Promise(r => setTimeout(r, 300));
  rmSync(work, { recursive: true, force: true });
}
console.log(failures === 0 ? 'serve 3-D browser test: all passed' : `serve 3-D browser test: ${failures} failed`);
process.exit(failures === 0 ? 0 : 1);
