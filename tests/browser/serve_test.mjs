// `pathstream serve` in a real browser: Debian's Chromium, headless, driven by playwright-core
// (no browser download), against `pathstream serve` and the simulated device on loopback.
//
//   node serve_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR [--bench]
//
// Loads examples/landscape.svg and checks the preview's subpaths, time and travel against
// `pathstream check --json` and `pathstream plan --json`; streams it, holds and resumes it mid
// job, sees the progress reach 100 % and the device end idle; a malformed SVG shows its
// file:line:col; a server beyond loopback refuses a request without its token. Screenshots
// of the preview and of the running page go to OUT_DIR. Prints the server's CPU use while
// streaming. --bench: also the preview's draw time for a 10^5-segment drawing against
// landscape.svg's, measured in the same run.
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
const machine = path.join(source, 'examples/machines/pen_plotter.json');
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

async function main() {
  const reference = JSON.parse(execFileSync(bin, ['plan', landscape, '-m', machine, '--json'], { encoding: 'utf8' }));
  const checked = JSON.parse(execFileSync(bin, ['check', landscape, '--json'], { encoding: 'utf8' }));

  // The simulated plotter at three times real time (the 36 s drawing runs in 12 s).
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
    viewport: { width: 1320, height: 900 },
  });
  try {
    const page = await browser.newPage();
    page.on('pageerror', e => check(false, `no script error on the page: ${e.message}`));
    page.on('console', m => { if (m.type() === 'error' && !/favicon|404/.test(m.text())) console.log(`page console: ${m.text()}`); });
    await page.goto(url);
    await page.waitForSelector('body[data-ready="true"]');
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
    await page.screenshot({ path: path.join(outDir, 'serve-preview.png'), fullPage: true });

    // Simulate: `pathstream sim`'s report on the page.
    await page.click('#simulate');
    await within(20000, 'the simulation report is shown', async () =>
      (await page.textContent('#sim-report')).includes('pathstream run on the simulated device'));

    // Fit to A4 with a margin: the drawn length of `plan --fit a4 --margin 10` (the order's
    // start point changes the travel, not what is drawn).
    const fitted = JSON.parse(execFileSync(bin, ['plan', landscape, '-m', machine, '--fit', 'a4', '--margin', '10', '--json'],
      { encoding: 'utf8' }));
    await page.selectOption('#fit', 'a4');
    await page.fill('#margin', '10');
    await page.dispatchEvent('#margin', 'change');
    await within(10000, `fit A4, margin 10: drawn ${fitted.drawn_length_mm.toFixed(3)} mm as plan's`, async () =>
      Math.abs(await figure(page, 'fig-drawn') - fitted.drawn_length_mm) < 1e-6);
    await page.selectOption('#fit', '');
    await page.fill('#margin', '0');
    await page.dispatchEvent('#margin', 'change');
    await within(10000, 'as drawn again: the plan\'s time', async () => Math.abs(await figure(page, 'fig-time') - reference.duration_s) < 1e-9);

    // Stream it; hold and resume mid-job; run to the end.
    await page.click('#start');
    // The server's CPU from the job's first progress to its end: the live updates (device
    // status and job progress, each at 10 Hz, to one page), without the planning of the run.
    await within(15000, 'the job reports progress', async () => /^\d+\.\d %  ETA/.test(await page.textContent('#progress-text')));
    const cpu0 = cpuSeconds(server.child.pid), wall0 = Date.now();
    await within(15000, 'progress passes 30 %', async () =>
      /^\d+\.\d %  ETA/.test(await page.textContent('#progress-text')) &&
      Number(await page.getAttribute('#progress', 'value')) > 0.3);
    await page.screenshot({ path: path.join(outDir, 'serve-running.png'), fullPage: true });
    await page.click('#hold');
    const held = await within(5000, 'the device holds', async () =>
      (await page.getAttribute('#device-state', 'data-state')) === 'holding');
    if (held) {
      await new Promise(r => setTimeout(r, 600));
      const a = Number(await page.getAttribute('#progress', 'value'));
      await new Promise(r => setTimeout(r, 800));
      const b = Number(await page.getAttribute('#progress', 'value'));
      check(a === b && a < 1, `no progress while held (${a} then ${b})`);
    }
    await page.click('#resume');
    await within(5000, 'the device runs again', async () =>
      (await page.getAttribute('#device-state', 'data-state')) === 'running');
    await within(30000, 'progress reaches 100 %', async () =>
      (await page.textContent('#progress-text')).startsWith('100 %'));
    check(Number(await page.getAttribute('#progress', 'value')) === 1, 'the progress bar is full');
    await within(5000, 'the device ends idle', async () =>
      (await page.getAttribute('#device-state', 'data-state')) === 'idle');
    const cpu1 = cpuSeconds(server.child.pid), wall1 = Date.now();
    const cpuShare = (cpu1 - cpu0) / ((wall1 - wall0) / 1000);
    console.log(`figure: server CPU while streaming ${(100 * cpuShare).toFixed(2)} % of one core ` +
      `(${(cpu1 - cpu0).toFixed(2)} s CPU in ${((wall1 - wall0) / 1000).toFixed(1)} s; the device's status ` +
      `at 10 Hz and the job's progress at 10 Hz to one page, a hold included)`);

    // At rest: the pen down and up, a jog of 10 mm.
    await page.click('#pen-down');
    await within(5000, 'the pen goes down', async () => (await page.getAttribute('#pen-state', 'data-down')) === 'true');
    await page.click('#pen-up');
    await within(5000, 'the pen goes up', async () => (await page.getAttribute('#pen-state', 'data-down')) === 'false');
    const xOf = async () => Number((await page.textContent('#position')).match(/x (-?[\d.]+)/)[1]);
    const x0 = await xOf();
    await page.selectOption('#step', '10');
    await page.click('[data-jog="x"][data-sign="1"]');
    const jogged = await within(8000, 'a jog of x +10 mm', async () => Math.abs(await xOf() - (x0 + 10)) < 1e-6);
    if (!jogged) console.log(`  the page says: ${await page.textContent('#command-text')}`);

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
    for (let i = 0; i < layers.length; i++) {
      if (i !== house) await page.check(`#layers label:nth-child(${i + 1}) input`);
    }
    await within(10000, 'every layer again: 42 subpaths', async () => (await figure(page, 'fig-subpaths')) === 42);
    await page.click('#start');
    await within(15000, 'the second job passes 20 %', async () =>
      /^\d+\.\d %  ETA/.test(await page.textContent('#progress-text')) &&
      Number(await page.getAttribute('#progress', 'value')) > 0.2);
    await page.click('#stop');
    const stopped = await within(10000, 'the job ends stopped', async () => (await page.textContent('#progress-text')).startsWith('stopped'));
    if (!stopped) {
      console.log(`  progress: ${await page.textContent('#progress-text')}; job: ${await page.textContent('#job-text')}; ` +
        `command: ${await page.textContent('#command-text')}; device: ${await page.textContent('#device-state')}`);
    }
    await within(5000, 'the device is idle after the stop', async () =>
      (await page.getAttribute('#device-state', 'data-state')) === 'idle');
    await within(5000, 'Resume job is offered', async () => !(await page.isDisabled('#resume-job')));
    await page.click('#resume-job');
    await within(30000, 'the resumed job reaches 100 %', async () =>
      (await page.textContent('#progress-text')).startsWith('100 %'));

    // A malformed SVG: its place in the file, as the command line prints it.
    const bad = path.join(work, 'broken.svg');
    writeFileSync(bad, '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">\n' +
      '  <path d="M 10 10 L 20 20"/>\n  <path d="M 10 10 L 20 q"/>\n</svg>\n');
    await page.setInputFiles('#file', bad);
    await page.waitForSelector('#error:not([hidden])');
    const message = await page.textContent('#error');
    check(/^broken\.svg:3:\d+: /.test(message), `the error names broken.svg:3:COL: "${message}"`);

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
