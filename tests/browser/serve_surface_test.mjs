// `pathstream serve`'s View panel for a drawing with surfaces, in Debian's Chromium (headless,
// playwright-core) against `pathstream serve` and the simulated device on loopback:
//
//   node serve_surface_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR
//
// With examples/machines/a3_plotter.json, fitted to A4 with a 10 mm margin: loads
// examples/teapot.json and sees the panel show the file's view (azimuth -70, elevation 25,
// hidden lines removed); turns it to azimuth 20 (the number, then the slider by keyboard) and
// sees the preview's drawn length become `plan --json`'s for the file with that view and its
// shape change; draws the hidden lines and sees the drawn length grow, to plan's; switches to
// perspective and gets a default eye distance that plans; an eye 0.5 units away shows the
// reader's "not in front of the eye" as an upload error, with the panel still usable, and 12
// recovers. Never two uploads in flight. The panel fits the 390 px phone. examples/rose.json
// (a plain path) and examples/teapot.bpt (no view) show no panel. A screenshot goes to
// OUT_DIR/serve-surface.png.
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, mkdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { chromium } from 'playwright-core';

const [bin, source, outDir] = process.argv.slice(2);
if (!bin || !source || !outDir) {
  console.error('usage: node serve_surface_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR');
  process.exit(2);
}
const machine = path.join(source, 'examples/machines/a3_plotter.json');
const teapot = path.join(source, 'examples/teapot.json');
const work = mkdtempSync(path.join(tmpdir(), 'pathstream-browser-surface-'));
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

async function within(ms, what, condition) {
  const end = Date.now() + ms;
  let last;
  while (Date.now() < end) {
    last = await condition();
    if (last === true) {
      console.log(`ok   ${what}`);
      return true;
    }
    await new Promise(r => setTimeout(r, 100));
  }
  check(false, `${what} (within ${ms} ms; last: ${last})`);
  return false;
}

// `plan --json` of the teapot with its view changed by `view`, placed as the page places it.
function planWith(view) {
  const doc = JSON.parse(readFileSync(teapot, 'utf8'));
  doc.view = { ...doc.view, ...view };
  const file = path.join(work, 'teapot-view.json');
  writeFileSync(file, JSON.stringify(doc));
  return JSON.parse(execFileSync(bin, ['plan', file, '-m', machine, '--fit', 'a4', '--margin', '10', '--json'],
    { encoding: 'utf8' }));
}

const same = (a, b) => Math.abs(a - b) <= 1e-6 * Math.abs(b) + 1e-3;

// The box of the drawn (pen-down) pieces of a preview document, and its width : height.
function drawnBox(p) {
  const { x, y, pen } = p.path;
  let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
  for (let i = 1; i < x.length; i++) {
    if (pen[i] !== 1) continue;
    for (const k of [i - 1, i]) {
      x0 = Math.min(x0, x[k]); x1 = Math.max(x1, x[k]); y0 = Math.min(y0, y[k]); y1 = Math.max(y1, y[k]);
    }
  }
  return { x0, x1, y0, y1, aspect: (x1 - x0) / (y1 - y0) };
}

async function main() {
  const device = await startAndRead(['device', '--tcp', '127.0.0.1:0'], /serving (modbus-tcp:\/\/\S+)/, 'device');
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
    // Uploads in flight at once, at most.
    let inFlight = 0, mostInFlight = 0, uploads = 0;
    const isUpload = r => r.url().includes('/api/drawing');
    page.on('request', r => { if (isUpload(r)) { uploads++; mostInFlight = Math.max(mostInFlight, ++inFlight); } });
    const done = r => { if (isUpload(r)) inFlight--; };
    page.on('requestfinished', done);
    page.on('requestfailed', done);

    await page.goto(server.match[1]);
    await page.waitForSelector('body[data-ready="true"]');
    await page.selectOption('#fit', 'a4');
    await page.fill('#margin', '10');
    await page.dispatchEvent('#margin', 'change');
    await page.setInputFiles('#file', teapot);
    await page.waitForSelector('#fig-drawn[data-value]', { timeout: 30000 }).catch(async () => {
      throw new Error(`no preview: ${await page.textContent('#error')} ${await page.textContent('#drawing-name')}`);
    });
    const drawn = async () => Number(await page.getAttribute('#fig-drawn', 'data-value'));
    const preview = () => page.evaluate(() => fetch('/api/preview').then(r => r.json()));

    // The file's own view.
    check(await page.isVisible('#surface-view'), 'a drawing with surfaces shows the View panel');
    const shown = await page.evaluate(() => Object.fromEntries(
      ['azimuth', 'azimuth-deg', 'elevation', 'elevation-deg', 'roll-deg', 'projection'].map(id => [id, document.getElementById(id).value])));
    check(shown.azimuth === '-70' && shown['azimuth-deg'] === '-70', `azimuth -70, slider and number: ${shown.azimuth}, ${shown['azimuth-deg']}`);
    check(shown.elevation === '25' && shown['elevation-deg'] === '25', `elevation 25: ${shown.elevation}, ${shown['elevation-deg']}`);
    check(shown['roll-deg'] === '0' && shown.projection === 'orthographic', `roll 0 (default), orthographic: ${shown['roll-deg']}, ${shown.projection}`);
    check(await page.isChecked('#hidden-lines'), 'hidden lines removed, as the file says');
    check(!(await page.isVisible('#eye-distance')), 'no eye distance under orthographic');
    const asFile = planWith({});
    check(same(await drawn(), asFile.drawn_length_mm), `the file's view: drawn ${await drawn()} mm, plan's ${asFile.drawn_length_mm}`);
    const box0 = drawnBox(await preview());

    // Azimuth 20: typed as 19, then one step of the slider by keyboard.
    await page.fill('#azimuth-deg', '19');
    check(await page.inputValue('#azimuth') === '19', 'the slider follows the number');
    await page.focus('#azimuth');
    await page.keyboard.press('ArrowRight');
    check(await page.inputValue('#azimuth-deg') === '20', 'the number follows the slider');
    const turned = planWith({ azimuth: 20 });
    check(!same(turned.drawn_length_mm, asFile.drawn_length_mm), `another view, another drawn length: ${turned.drawn_length_mm} against ${asFile.drawn_length_mm}`);
    await within(30000, `azimuth 20: the preview is plan's for that view (${turned.drawn_length_mm} mm)`,
      async () => same(await drawn(), turned.drawn_length_mm) || await drawn());
    const box1 = drawnBox(await preview());
    check(Math.abs(box1.aspect / box0.aspect - 1) > 0.05,
      `the drawing's shape changed: width/height ${box0.aspect.toFixed(3)} then ${box1.aspect.toFixed(3)}`);

    // Hidden lines drawn: more ink.
    await page.uncheck('#hidden-lines');
    const all = planWith({ azimuth: 20, hidden_lines: 'draw' });
    await within(30000, `hidden lines drawn: the preview is plan's (${all.drawn_length_mm} mm)`,
      async () => same((await preview()).summary?.drawn_length_mm, all.drawn_length_mm) || await drawn());
    check(all.drawn_length_mm > 1.2 * turned.drawn_length_mm, `the drawn length grows: ${turned.drawn_length_mm} to ${all.drawn_length_mm} mm`);

    // Perspective: a default eye distance that plans.
    await page.selectOption('#projection', 'perspective');
    check(await page.isVisible('#eye-distance'), 'perspective shows the eye distance');
    const eye = Number(await page.inputValue('#eye-distance'));
    check(eye > 0, `a default eye distance: ${eye}`);
    const near = planWith({ azimuth: 20, hidden_lines: 'draw', projection: 'perspective', eye_distance: eye });
    await within(60000, `perspective, eye ${eye}: the preview is plan's (${near.drawn_length_mm} mm)`,
      async () => same(await drawn(), near.drawn_length_mm) || await drawn());

    // Too near: the reader's message, as an upload error; the panel stays.
    await page.fill('#eye-distance', '0.5');
    await within(30000, 'eye 0.5: the error says a point is not in front of the eye',
      async () => /^teapot\.json:\d+:\d+: .*not in front of the eye/.test(await page.textContent('#error')) || await page.textContent('#error'));
    check(await page.isDisabled('#start') && await page.isDisabled('#simulate'), 'no preview: Start and Simulate off');
    check(await page.isVisible('#surface-view') && await page.isEnabled('#eye-distance'), 'the panel stays, usable');
    await page.fill('#eye-distance', '12');
    const twelve = planWith({ azimuth: 20, hidden_lines: 'draw', projection: 'perspective', eye_distance: 12 });
    await within(60000, `eye 12: the preview is back, plan's (${twelve.drawn_length_mm} mm)`,
      async () => (await page.isHidden('#error') && same(await drawn(), twelve.drawn_length_mm)) || await drawn());
    check(!(await page.isDisabled('#start')), 'Start is on again');
    check(mostInFlight === 1, `never two uploads in flight (${uploads} uploads, at most ${mostInFlight} at once)`);
    await page.screenshot({ path: path.join(outDir, 'serve-surface.png'), fullPage: true });

    // The phone: the panel inside the window's width, the page no wider.
    await page.setViewportSize({ width: 390, height: 844 });
    await page.evaluate(() => document.getElementById('surface-view').scrollIntoView());
    const fit = await page.evaluate(() => {
      const r = document.getElementById('surface-view').getBoundingClientRect();
      const slider = document.getElementById('azimuth').getBoundingClientRect();
      return { left: r.left, right: r.right, slider: slider.width, width: innerWidth, scroll: document.documentElement.scrollWidth };
    });
    check(fit.left >= 0 && fit.right <= fit.width && fit.scroll <= fit.width && fit.slider >= 100,
      `at 390x844 the panel fits: ${fit.left.toFixed(0)}..${fit.right.toFixed(0)} of ${fit.width} (page ${fit.scroll}), slider ${fit.slider.toFixed(0)} px`);
    await page.setViewportSize({ width: 1366, height: 768 });

    // A plain path and a .bpt file: no panel.
    for (const [file, what] of [['examples/rose.json', 'a plain JSON path'], ['examples/teapot.bpt', 'a .bpt file (no view)']]) {
      const before = await drawn();
      await page.setInputFiles('#file', path.join(source, file));
      await within(30000, `${what} is previewed`, async () => (await drawn()) !== before && !(await page.textContent('#drawing-name')).includes('planning'));
      check(await page.isHidden('#surface-view'), `${what}: no View panel`);
    }
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
console.log(failures === 0 ? 'serve surface browser test: all passed' : `serve surface browser test: ${failures} failed`);
process.exit(failures === 0 ? 0 : 1);
