// `pathstream serve` in a real browser: Debian's Chromium, headless, driven by playwright-core
// (no browser download), against `pathstream serve` and the simulated device on loopback.
//
//   node serve_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR [--bench]
//
// With examples/machines/a3_plotter.json (a 430 x 297 mm work area): loads
// examples/landscape.svg and checks the preview's subpaths, time and travel against
// `pathstream check --json` and `pathstream plan --json`, each layer in its own colour on the
// canvas, the work area and an A4 paper outlined; streams it and, while it runs, sees the
// state, progress, Hold and Stop inside the window at 390x844, 1366x768 and 1920x1080 (at the
// top of the page and scrolled to its end, no page wider than the window), holds it from the
// phone and resumes it from the desktop, sees 100 % and the device idle; jogs Y+ and sees y
// grow and the marker move the way the pad shows; stops a job and resumes it from its journal,
// counted as the whole job, with no server path on the page; an upload that cannot be placed
// takes the preview and Start away and its message wraps on the phone; a malformed SVG shows
// its file:line:col; a server beyond loopback refuses a request without its token.
// Screenshots of the preview and of the running page go to OUT_DIR. Prints the server's CPU
// use while streaming. --bench: also the preview's draw time for a 10^5-segment drawing
// against landscape.svg's, measured in the same run.
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, writeFileSync, readFileSync, rmSync, mkdirSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { chromium } from 'playwright-core';

const [bin, source, outDir] = process.argv.slice(2);
const bench = process.argv.includes('--bench');
if (!bin || !source || !outDir) {
  console.error('usage: node serve_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR [--bench]');
  process.exit(2);
}
const machine = path.join(source, 'examples/machines/a3_plotter.json');
const landscape = path.join(source, 'examples/landscape.svg');
const work = mkdtempSync(path.join(tmpdir(), 'pathstream-browser-'));
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

// CPU seconds (user + system) of a process so far.
function cpuSeconds(pid) {
  const fields = readFileSync(`/proc/${pid}/stat`, 'utf8').split(') ')[1].split(' ');
  return (Number(fields[11]) + Number(fields[12])) / 100;  // utime, stime in USER_HZ (100)
}

async function within(ms, what, condition) {
  const end = Date.now() + ms;
  while (Date.now() < end) {
    if (await condition()) {
      console.log(`ok   ${what}`);
      return true;
    }
    await new Promise(r => setTimeout(r, 50));
  }
  check(false, `${what} (within ${ms} ms)`);
  return false;
}

const figure = async (page, id) => Number(await page.getAttribute(`#${id}`, 'data-value'));

// The three windows the page is checked in: a phone, a laptop, a desktop.
const PHONE = { width: 390, height: 844 }, LAPTOP = { width: 1366, height: 768 }, DESKTOP = { width: 1920, height: 1080 };
const sizeName = v => `${v.width}x${v.height}`;

// Every selector's box lies inside the window (scrolled as it is), and the page is no wider
// than the window.
async function inWindow(page, selectors, what) {
  const r = await page.evaluate(sel => {
    const boxes = sel.map(s => {
      const e = document.querySelector(s);
      const b = e ? e.getBoundingClientRect() : null;
      return { s, box: b && [b.left, b.top, b.right, b.bottom].map(Math.round), shown: Boolean(b && b.width > 0 && b.height > 0) };
    });
    return { boxes, w: window.innerWidth, h: window.innerHeight, scrollW: document.documentElement.scrollWidth, y: window.scrollY };
  }, selectors);
  const outside = r.boxes.filter(b => !b.shown || b.box[0] < 0 || b.box[1] < 0 || b.box[2] > r.w || b.box[3] > r.h);
  check(outside.length === 0 && r.scrollW <= r.w,
    `${what}: ${selectors.join(' ')} inside the ${r.w}x${r.h} window (scrolled to ${r.y}), page ${r.scrollW} px wide` +
    (outside.length ? `; outside: ${outside.map(b => `${b.s} at ${b.box}`).join(', ')}` : ''));
  return r;
}

// The preview canvas as drawn: its size, the outlines and the marker it reports (CSS px),
// and the pixels (per colour: how many, and their bounding box) and the colours at points.
async function canvasFacts(page, colours = [], points = []) {
  return page.evaluate(([cols, pts]) => {
    const c = document.getElementById('preview');
    const k = c.width / c.clientWidth;
    const data = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    const parse = h => [1, 3, 5].map(i => parseInt(h.slice(i, i + 2), 16));
    const near = (i, rgb, tol) => Math.hypot(data[i] - rgb[0], data[i + 1] - rgb[1], data[i + 2] - rgb[2]) <= tol;
    const found = cols.map(h => {
      const rgb = parse(h);
      let n = 0, x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
      for (let y = 0; y < c.height; y++) {
        for (let x = 0; x < c.width; x++) {
          if (!near(4 * (y * c.width + x), rgb, 40)) continue;
          n++; x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
        }
      }
      return { colour: h, n, box: [x0 / k, y0 / k, x1 / k, y1 / k] };
    });
    const at = pts.map(([x, y]) => {
      const i = 4 * (Math.round(y * k) * c.width + Math.round(x * k));
      return `#${[data[i], data[i + 1], data[i + 2]].map(v => v.toString(16).padStart(2, '0')).join('')}`;
    });
    const box = s => (s ? s.split(',').map(Number) : null);
    return {
      hidden: c.hidden, width: c.clientWidth, height: c.clientHeight,
      paper: box(c.dataset.paper), area: box(c.dataset.area), marker: box(c.dataset.marker), found, at,
    };
  }, [colours, points]);
}

const rgbDistance = (a, b) => Math.hypot(...[1, 3, 5].map(i => parseInt(a.slice(i, i + 2), 16) - parseInt(b.slice(i, i + 2), 16)));

// Three points along each edge of a box (left, top, right, bottom), a quarter in from the corners.
const edgePoints = ([l, t, r, b]) => [0.25, 0.5, 0.75].flatMap(f =>
  [[l, t + f * (b - t)], [r, t + f * (b - t)], [l + f * (r - l), t], [l + f * (r - l), b]]);

const progressValue = async page => Number(await page.getAttribute('#progress', 'value'));
const positionOf = async (page, axis) =>
  Number((await page.textContent('#position')).match(new RegExp(`${axis} (-?[\\d.]+)`))[1]);

async function openPage(browser, url, viewport) {
  const page = await browser.newPage();
  await page.setViewportSize(viewport);
  page.on('pageerror', e => check(false, `no script error on the page (${sizeName(viewport)}): ${e.message}`));
  page.on('console', m => { if (m.type() === 'error' && !/favicon|Failed to load resource/.test(m.text())) console.log(`page console: ${m.text()}`); });
  page.on('response', r => {
    if (r.status() >= 400) console.log(`  (the server answered ${r.status()} to ${r.request().method()} ${new URL(r.url()).pathname})`);
  });
  await page.goto(url);
  await page.waitForSelector('body[data-ready="true"]');
  return page;
}

// The bar while a job runs: the state, the progress, Hold and Stop in the window at the top of
// the page and scrolled to its end; the preview as wide as the window allows.
async function runningLayout(page, viewport) {
  const what = `${sizeName(viewport)} while a job runs`;
  const bar = ['#device-state', '#progress', '#progress-text', '#hold', '#stop'];
  await page.evaluate(() => window.scrollTo(0, 0));
  await inWindow(page, bar, `${what}, top`);
  await page.evaluate(() => window.scrollTo(0, document.documentElement.scrollHeight));
  await page.waitForFunction(() => window.scrollY > 0 || document.documentElement.scrollHeight <= window.innerHeight);
  await inWindow(page, bar, `${what}, scrolled to the end`);
  await page.evaluate(() => window.scrollTo(0, 0));
  const c = await canvasFacts(page);
  const room = viewport.width < 820 ? viewport.width - 20 : viewport.width - 380;  // one column; beside the controls
  check(!c.hidden && c.width >= 0.95 * room && c.height >= 200,
    `${what}: the preview is ${c.width}x${c.height} px (at least ${Math.round(0.95 * room)} wide and 200 high)`);
}

async function main() {
  const reference = JSON.parse(execFileSync(bin, ['plan', landscape, '-m', machine, '--json'], { encoding: 'utf8' }));
  const checked = JSON.parse(execFileSync(bin, ['check', landscape, '--json'], { encoding: 'utf8' }));

  // The simulated plotter at three times real time (the 33 s drawing runs in 11 s).
  const device = await startAndRead(['device', '--tcp', '127.0.0.1:0', '--time-scale', '3'],
    /serving (modbus-tcp:\/\/\S+)/, 'device');
  const target = device.match[1];
  const server = await startAndRead(['serve', '-m', machine, '-t', target, '--listen', '127.0.0.1:0',
    '--state-dir', path.join(work, 'state')], /(http:\/\/127\.0\.0\.1:\d+\/)/, 'serve');
  const url = server.match[1];

  // A fresh profile directory each run; nothing but loopback is reached.
  const browser = await chromium.launchPersistentContext(path.join(work, 'chromium'), {
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    viewport: LAPTOP,
  });
  try {
    const page = await openPage(browser, url, LAPTOP);
    await within(5000, 'the device shows idle', async () =>
      (await page.getAttribute('#device-state', 'data-state')) === 'idle');

    // Load and preview.
    await page.setInputFiles('#file', landscape);
    await page.waitForSelector('#fig-subpaths[data-value]');
    const subpaths = await figure(page, 'fig-subpaths');
    const time = await figure(page, 'fig-time');
    const travel = await figure(page, 'fig-travel');
    const drawn = await figure(page, 'fig-drawn');
    check(subpaths === checked.subpaths.length, `preview subpaths ${subpaths} = check's ${checked.subpaths.length}`);
    check(Math.abs(time - reference.duration_s) < 1e-9, `preview time ${time} s = plan's ${reference.duration_s} s`);
    check(Math.abs(travel - reference.travel_length_mm) < 1e-6,
      `preview travel ${travel} mm = plan's ${reference.travel_length_mm} mm`);
    check(Math.abs(drawn - reference.drawn_length_mm) < 1e-6, `preview drawn ${drawn} mm = plan's ${reference.drawn_length_mm} mm`);
    const landscapeDrawMs = await figure(page, 'fig-draw-ms');

    // Each layer in its own colour, named in the legend and drawn in that colour.
    const legend = await page.$$eval('#layers .swatch[data-colour]', ss => ss.map(s => s.dataset.colour));
    const closest = Math.min(...legend.flatMap((a, i) => legend.slice(i + 1).map(b => rgbDistance(a, b))));
    check(legend.length === reference.layers.length && closest > 60,
      `the legend has the ${reference.layers.length} layers in distinct colours (${legend.join(' ')}; closest pair ${closest.toFixed(0)} apart in RGB)`);
    const drawnIn = await canvasFacts(page, legend);
    check(drawnIn.found.every(f => f.n >= 20), `every layer's colour is on the preview (pixels: ${drawnIn.found.map(f => f.n).join(', ')})`);
    // The machine's work area outlined: its right edge (the paper's left, top and bottom edges
    // lie on the area's in this machine) in the area's edge colour.
    check(drawnIn.area !== null, `the work area is outlined at ${drawnIn.area}`);
    if (drawnIn.area) {
      const [l, t, r, b] = drawnIn.area;
      const edge = (await canvasFacts(page, [], [0.25, 0.5, 0.75].map(f => [r - 1, t + f * (b - t)]))).at;
      check(edge.every(c => rgbDistance(c, '#adb5bd') < 30), `the work area's right edge is drawn: ${edge.join(' ')}`);
      check(Math.abs((r - l) / (b - t) - 430 / 297) < 0.01, `the work area is 430 x 297 mm in shape: ${((r - l) / (b - t)).toFixed(3)}`);
    }
    await page.screenshot({ path: path.join(outDir, 'serve-preview.png'), fullPage: true });

    // Simulate: `pathstream sim`'s report on the page.
    await page.click('#simulate');
    await within(20000, 'the simulation report is shown', async () =>
      (await page.textContent('#sim-report')).includes('pathstream run on the simulated device'));

    // Fit to A4 with a margin: the drawn length of `plan --fit a4 --margin 10` (the order's
    // start point changes the travel, not what is drawn), the paper outlined and the drawing
    // on it.
    const fitted = JSON.parse(execFileSync(bin, ['plan', landscape, '-m', machine, '--fit', 'a4', '--margin', '10', '--json'],
      { encoding: 'utf8' }));
    await page.selectOption('#fit', 'a4');
    await page.fill('#margin', '10');
    await page.dispatchEvent('#margin', 'change');
    await within(10000, `fit A4, margin 10: drawn ${fitted.drawn_length_mm.toFixed(3)} mm as plan's`, async () =>
      Math.abs(await figure(page, 'fig-drawn') - fitted.drawn_length_mm) < 1e-6);
    const onPaper = await canvasFacts(page, legend);
    check(onPaper.paper !== null, `the A4 paper is outlined at ${onPaper.paper}`);
    if (onPaper.paper) {
      const [l, t, r, b] = onPaper.paper;
      check(Math.abs((r - l) / (b - t) - 210 / 297) < 0.01, `the paper is A4 in shape: ${((r - l) / (b - t)).toFixed(3)} (210/297 = 0.707)`);
      const edge = (await canvasFacts(page, [], edgePoints([l, t, r - 1, b - 1]))).at;
      check(edge.every(c => rgbDistance(c, '#6c757d') < 30), `the paper's four edges are drawn: ${edge.join(' ')}`);
      const off = onPaper.found.filter(f => f.n > 0 && (f.box[0] < l || f.box[1] < t || f.box[2] > r || f.box[3] > b));
      check(off.length === 0, `every layer is drawn on the paper${off.length ? `; off it: ${off.map(f => `${f.colour} ${f.box}`).join(', ')}` : ''}`);
    }
    await page.fill('#margin', '0');
    await page.selectOption('#fit', '');
    await within(10000, 'as drawn again: the plan\'s time', async () => Math.abs(await figure(page, 'fig-time') - reference.duration_s) < 1e-9);
    check((await canvasFacts(page)).paper === null, 'as drawn: no paper outlined');

    // Stream it; while it runs, the page at the three sizes (two more pages join the running
    // job); hold it from the phone, resume it from the desktop; run to the end.
    await page.click('#start');
    // The server's CPU from the job's first progress to its end: the live updates (device
    // status and job progress, each at 10 Hz, to the pages), without the planning of the run.
    await within(15000, 'the job reports progress', async () => /^\d+\.\d %  ETA/.test(await page.textContent('#progress-text')));
    const cpu0 = cpuSeconds(server.child.pid), wall0 = Date.now();
    await runningLayout(page, LAPTOP);
    const phone = await openPage(browser, url, PHONE);
    const desktop = await openPage(browser, url, DESKTOP);
    for (const [p, v] of [[phone, PHONE], [desktop, DESKTOP]]) {
      await within(5000, `the ${sizeName(v)} page joins the running job`, async () =>
        /^\d+\.\d %  ETA/.test(await p.textContent('#progress-text')));
      await runningLayout(p, v);
    }
    await within(15000, 'progress passes 30 %', async () =>
      /^\d+\.\d %  ETA/.test(await page.textContent('#progress-text')) && await progressValue(page) > 0.3);
    await page.screenshot({ path: path.join(outDir, 'serve-running.png'), fullPage: true });
    await phone.screenshot({ path: path.join(outDir, 'serve-phone.png') });
    await phone.evaluate(() => window.scrollTo(0, document.documentElement.scrollHeight));
    await phone.click('#hold');
    const held = await within(5000, 'the device holds (Hold pressed on the phone, scrolled to the end)', async () =>
      (await page.getAttribute('#device-state', 'data-state')) === 'holding');
    if (held) {
      await new Promise(r => setTimeout(r, 600));
      const a = await progressValue(page);
      await new Promise(r => setTimeout(r, 800));
      const b = await progressValue(page);
      check(a === b && a < 1, `no progress while held (${a} then ${b})`);
    }
    await desktop.click('#resume');
    await within(5000, 'the device runs again (Resume pressed on the desktop)', async () =>
      (await page.getAttribute('#device-state', 'data-state')) === 'running');
    await phone.close();
    await desktop.close();
    await within(30000, 'progress reaches 100 %', async () =>
      (await page.textContent('#progress-text')).startsWith('100 %'));
    check(await progressValue(page) === 1, 'the progress bar is full');
    await within(5000, 'the device ends idle', async () =>
      (await page.getAttribute('#device-state', 'data-state')) === 'idle');
    const cpu1 = cpuSeconds(server.child.pid), wall1 = Date.now();
    const cpuShare = (cpu1 - cpu0) / ((wall1 - wall0) / 1000);
    console.log(`figure: server CPU while streaming ${(100 * cpuShare).toFixed(2)} % of one core ` +
      `(${(cpu1 - cpu0).toFixed(2)} s CPU in ${((wall1 - wall0) / 1000).toFixed(1)} s; the device's status ` +
      `at 10 Hz and the job's progress at 10 Hz to three pages for a while, a hold included)`);

    // At rest: the pen down and up, a jog of 10 mm.
    await page.click('#pen-down');
    await within(5000, 'the pen goes down', async () => (await page.getAttribute('#pen-state', 'data-down')) === 'true');
    await page.click('#pen-up');
    await within(5000, 'the pen goes up', async () => (await page.getAttribute('#pen-state', 'data-down')) === 'false');
    const x0 = await positionOf(page, 'x');
    await page.selectOption('#step', '10');
    await page.click('[data-jog="x"][data-sign="1"]');
    const jogged = await within(8000, 'a jog of x +10 mm', async () => Math.abs(await positionOf(page, 'x') - (x0 + 10)) < 1e-6);
    if (!jogged) console.log(`  the page says: ${await page.textContent('#command-text')}`);

    // Y+ on the pad: the device's y grows by the step, and the pen's marker on the preview
    // moves the way the pad's button sits from Home: down with the origin top-left (y down, as
    // the SVG), up with it bottom-left.
    for (const origin of ['top-left', 'bottom-left']) {
      if ((await page.inputValue('#origin')) !== origin) {
        await page.selectOption('#origin', origin);
        await within(10000, `origin ${origin}: the preview shows y ${origin === 'top-left' ? 'down' : 'up'}`, async () =>
          (await page.getAttribute('#preview', 'data-y')) === (origin === 'top-left' ? 'down' : 'up'));
      }
      const yPlus = await page.locator('.pad .y-plus').boundingBox(), home = await page.locator('#home').boundingBox();
      const padUp = yPlus.y + yPlus.height <= home.y;
      check(padUp === (origin === 'bottom-left') && (padUp || yPlus.y >= home.y + home.height),
        `origin ${origin}: Y+ is ${padUp ? 'above' : 'below'} Home on the pad ("${await page.textContent('.pad .y-plus')}")`);
      const y0 = await positionOf(page, 'y');
      const m0 = (await canvasFacts(page)).marker;
      await page.click('.pad .y-plus');
      await within(8000, `origin ${origin}: a jog of Y+ 10 mm (from ${y0} mm)`, async () =>
        Math.abs(await positionOf(page, 'y') - (y0 + 10)) < 1e-6);
      let m1 = m0;
      await within(3000, `origin ${origin}: the marker moves ${padUp ? 'up' : 'down'} on the preview, as Y+ sits on the pad`,
        async () => {
          m1 = (await canvasFacts(page)).marker;
          return m0 && m1 && Math.abs(m1[0] - m0[0]) < 0.5 && (padUp ? m1[1] < m0[1] - 3 : m1[1] > m0[1] + 3);
        });
      console.log(`  marker from ${m0} to ${m1} (CSS px)`);
    }
    await page.selectOption('#origin', 'top-left');
    await within(10000, 'origin top-left again', async () => (await page.getAttribute('#preview', 'data-y')) === 'down');

    // One layer: the preview plans it alone. Then the whole drawing again: streamed, stopped,
    // resumed from its journal.
    const layers = await page.$$eval('#layers label', ls => ls.map(l => l.textContent.trim()));
    const house = layers.findIndex(l => l.startsWith('House'));
    check(house >= 0, `the layers are listed: ${layers.join(', ')}`);
    const houseSubpaths = Number(layers[house].match(/\((\d+)\)$/)[1]);
    for (let i = 0; i < layers.length; i++) {
      if (i !== house) await page.uncheck(`#layers label:nth-child(${i + 1}) input`);
    }
    await within(10000, `the preview of layer House alone has its ${houseSubpaths} subpaths`,
      async () => (await figure(page, 'fig-subpaths')) === houseSubpaths);
    const houseColour = legend[house];
    const alone = await canvasFacts(page, legend);
    check(alone.found.every(f => (f.colour === houseColour) === (f.n >= 20)),
      `only House's colour ${houseColour} is drawn (pixels: ${alone.found.map(f => f.n).join(', ')})`);
    for (let i = 0; i < layers.length; i++) {
      if (i !== house) await page.check(`#layers label:nth-child(${i + 1}) input`);
    }
    await within(10000, 'every layer again: 42 subpaths', async () => (await figure(page, 'fig-subpaths')) === 42);
    await page.click('#start');
    await within(15000, 'the second job passes 20 %', async () =>
      /^\d+\.\d %  ETA/.test(await page.textContent('#progress-text')) && await progressValue(page) > 0.2);
    await page.click('#stop');
    const stopped = await within(10000, 'the job ends stopped', async () => (await page.textContent('#progress-text')).startsWith('stopped'));
    if (!stopped) {
      console.log(`  progress: ${await page.textContent('#progress-text')}; job: ${await page.textContent('#job-text')}; ` +
        `command: ${await page.textContent('#command-text')}; device: ${await page.textContent('#device-state')}`);
    }
    await within(5000, 'the device is idle after the stop', async () =>
      (await page.getAttribute('#device-state', 'data-state')) === 'idle');
    await within(5000, 'Resume job is offered', async () => !(await page.isDisabled('#resume-job')));
    const stoppedAt = await progressValue(page);
    // The server's directory (here the test's, by default a temporary one) is never named.
    const shown = await page.evaluate(() => document.body.innerText);
    check(!shown.includes(work) && !shown.includes(tmpdir()), `the stop names no server path: "${await page.textContent('#job-text')}"`);
    // Resume job: the rest of the same job, counted from where it stopped.
    const seen = [];
    const watch = setInterval(async () => { try { seen.push(await progressValue(page)); } catch { /* page busy */ } }, 100);
    await page.click('#resume-job');
    const resumed = await within(30000, 'the resumed job reaches 100 %', async () =>
      (await page.textContent('#progress-text')).startsWith('100 %'));
    clearInterval(watch);
    const lowest = Math.min(...seen);
    check(resumed && lowest >= stoppedAt - 0.02,
      `the resumed job counts the whole job: from ${(100 * stoppedAt).toFixed(1)} % (lowest shown ${(100 * lowest).toFixed(1)} %) to 100 %`);

    // A drawing that cannot be placed (600 mm wide, the machine's x travels 430 mm), on the
    // phone: the old preview goes, Start is off, the whole message is readable.
    await page.setViewportSize(PHONE);
    const big = path.join(work, 'too-wide.svg');
    writeFileSync(big, '<svg xmlns="http://www.w3.org/2000/svg" width="600mm" height="200mm" viewBox="0 0 600 200">\n' +
      '  <path d="M 10 10 L 590 190"/>\n</svg>\n');
    await page.setInputFiles('#file', big);
    await page.waitForSelector('#error:not([hidden])');
    const placement = await page.textContent('#error');
    check(/^too-wide\.svg:2:\d+: .*leaves the work area/.test(placement), `the error names the place and the work area: "${placement}"`);
    const after = {
      preview: await page.isHidden('#preview') ? 'gone' : 'shown',
      start: await page.isDisabled('#start') ? 'off' : 'on',
      simulate: await page.isDisabled('#simulate') ? 'off' : 'on',
      time: await page.textContent('#fig-time'),
      layers: (await page.$$('#layers label')).length,
    };
    check(after.preview === 'gone' && after.start === 'off' && after.simulate === 'off' && after.time === '–' && after.layers === 0,
      `a failed upload removes the preview, its figures and layers, and disables Start and Simulate: ${JSON.stringify(after)}`);
    const kept = await page.evaluate(() => fetch('/api/preview').then(r => r.status));
    check(kept === 404, `the server keeps no preview either (GET /api/preview: ${kept})`);
    await page.evaluate(() => document.getElementById('error').scrollIntoView());
    const readable = await page.evaluate(() => {
      const e = document.getElementById('error'), b = e.getBoundingClientRect();
      return { scrollW: e.scrollWidth, clientW: e.clientWidth, right: b.right, w: window.innerWidth, page: document.documentElement.scrollWidth };
    });
    check(readable.scrollW <= readable.clientW && readable.right <= readable.w && readable.page <= readable.w,
      `the error wraps inside the ${readable.w} px window (${readable.clientW} px wide, its text ${readable.scrollW} px)`);
    await inWindow(page, ['#error'], `${sizeName(PHONE)}, the error`);
    await page.setViewportSize(LAPTOP);

    // A malformed SVG: its place in the file, as the command line prints it.
    const bad = path.join(work, 'broken.svg');
    writeFileSync(bad, '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">\n' +
      '  <path d="M 10 10 L 20 20"/>\n  <path d="M 10 10 L 20 q"/>\n</svg>\n');
    await page.setInputFiles('#file', bad);
    await page.waitForSelector('#error:not([hidden])');
    await within(5000, 'the error names broken.svg:3:COL', async () => /^broken\.svg:3:\d+: /.test(await page.textContent('#error')));
    check(await page.isDisabled('#start'), 'Start stays off');

    if (bench) {
      // 10^5 segments: a polyline spiral of 100,001 points.
      const points = [];
      for (let i = 0; i <= 100000; i++) {
        const a = i * 0.02, r = 5 + 0.00055 * i;
        points.push(`${(100 + r * Math.cos(a)).toFixed(3)},${(100 + r * Math.sin(a)).toFixed(3)}`);
      }
      const big = path.join(work, 'spiral100k.svg');
      writeFileSync(big, `<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="200mm" viewBox="0 0 200 200">` +
        `<polyline fill="none" stroke="black" points="${points.join(' ')}"/></svg>\n`);
      await page.reload();
      await page.waitForSelector('body[data-ready="true"]');
      page.on('response', r => { if (r.url().includes('/api/drawing')) console.log(`upload answered ${r.status()}`); });
      page.on('requestfailed', r => console.log(`request failed: ${r.url()} ${r.failure()?.errorText}`));
      const t0 = Date.now();
      await page.setInputFiles('#file', big);
      await page.waitForSelector('#fig-spans[data-value], #error:not([hidden])', { timeout: 300000 });
      const uploadError = await page.textContent('#error');
      if (uploadError) throw new Error(`the 10^5-segment drawing: ${uploadError}`);
      const planned = (Date.now() - t0) / 1000;
      const first = await figure(page, 'fig-draw-ms');
      // Redraws as the scrubber moves: the median of five.
      const redraws = await page.evaluate(async () => {
        const scrub = document.getElementById('scrub');
        const frame = () => new Promise(r => requestAnimationFrame(() => r()));
        const times = [];
        for (let k = 0; k < 5; k++) {
          scrub.value = String(Math.round(Number(scrub.max) * (k + 1) / 6));
          scrub.dispatchEvent(new Event('input'));
          await frame();
          await frame();
          times.push(Number(document.getElementById('fig-draw-ms').dataset.value));
        }
        return times.sort((a, b) => a - b);
      });
      const spans = await figure(page, 'fig-spans');
      const vertices = Number((await page.textContent('#fig-spans')).match(/\((\d+) vertices\)/)[1]);
      console.log(`figure: preview of 100,000 segments (${spans} spans, ${vertices} vertices): first draw ` +
        `${first.toFixed(1)} ms, redraw median ${redraws[2].toFixed(1)} ms; landscape.svg ${landscapeDrawMs.toFixed(1)} ms ` +
        `(ratio ${(first / landscapeDrawMs).toFixed(1)}x); upload + plan + preview ${planned.toFixed(1)} s`);
      await page.screenshot({ path: path.join(outDir, 'serve-100k.png') });
    }
  } finally {
    await browser.close();
  }

  // Beyond loopback without a token: refused at the command line.
  try {
    execFileSync(bin, ['serve', '-m', machine, '-t', target, '--listen', '0.0.0.0:0'], { stdio: 'pipe', timeout: 10000 });
    check(false, 'serve --listen 0.0.0.0:0 without a token is refused');
  } catch (e) {
    check(e.status === 2 && /give --token/.test(String(e.stderr)),
      `serve --listen 0.0.0.0:0 without a token exits 2: ${String(e.stderr).trim()}`);
  }
  // Beyond loopback: no token, no answer; the token, an answer (over loopback all the same).
  const open = await startAndRead(['serve', '-m', machine, '-t', target, '--listen', '0.0.0.0:0', '--token', 't0k3n-for-test',
    '--state-dir', path.join(work, 'state2')], /http:\/\/0\.0\.0\.0:(\d+)\//, 'serve 0.0.0.0');
  const base = `http://127.0.0.1:${open.match[1]}`;
  const refused = await fetch(`${base}/api/state`);
  check(refused.status === 403, `no token: ${refused.status} (want 403)`);
  const wrong = await fetch(`${base}/`, { headers: { Authorization: 'Bearer wrong' } });
  check(wrong.status === 403, `a wrong token: ${wrong.status} (want 403)`);
  const allowed = await fetch(`${base}/api/state?token=t0k3n-for-test`);
  check(allowed.status === 200, `the token: ${allowed.status} (want 200)`);
  const crossSite = await fetch(`${base}/api/control`, {
    method: 'POST', body: '{"verb":"stop"}',
    headers: { Authorization: 'Bearer t0k3n-for-test', Origin: 'http://evil.example' },
  });
  check(crossSite.status === 403, `the token from another origin: ${crossSite.status} (want 403)`);
}

let status = 0;
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
status = failures === 0 ? 0 : 1;
console.log(failures === 0 ? 'serve browser test: all passed' : `serve browser test: ${failures} failed`);
process.exit(status);
