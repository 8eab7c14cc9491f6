// The fleet page with real machines drawing: a real broker (mosquitto on loopback), three
// simulated pen plotters (`pathstream device`), each with its `pathstream serve --mqtt`, and
// `pathstream fleet serve`, in headless Chromium driven by playwright-core. The README's
// picture of the fleet page comes from here, so it shows what a fleet really looks like.
//
//   node fleet_machines_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR
//
// Checks: three machines online, of kind pen_plotter; five jobs submitted through the page's
// form to the queue of kind pen_plotter (fit A4) each answered `queued`; the page showing all
// three machines `running` a job with a progress bar above 0 %, the jobs list showing three
// jobs running on three different machines; no horizontal overflow at 390 px while they draw;
// a click on a running job shows its history, queued then running on its machine; the stop
// button answered ok by each machine. Screenshots go to OUT_DIR (fleet.png at 1366 px, full
// page, and fleet-phone.png at 390 px); with PATHSTREAM_UPDATE_IMAGES=1 fleet.png is also
// copied to docs/images/.
import { copyFileSync } from 'node:fs';
import path from 'node:path';
import { harness } from './fleet_support.mjs';

const [bin, source, outDir] = process.argv.slice(2);
if (!bin || !source || !outDir) {
  console.error('usage: node fleet_machines_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR');
  process.exit(2);
}
const h = harness('fleet-machines', outDir);
const { check, within } = h;
const machine = path.join(source, 'examples/machines/pen_plotter.json');
const names = ['plotter-1', 'plotter-2', 'plotter-3'];
// The three long drawings first, so that each machine takes one and all three draw at once;
// the short two wait in the queue (a queued job in the picture, too).
const drawings = ['leaf.ngc', 'rose.json', 'landscape.svg', 'star.csv', 'wave.json'];

const machineRows = page => page.evaluate(() => [...document.querySelectorAll('#machines tbody tr')].map(r => ({
  name: r.dataset.machine, online: r.dataset.online, state: r.dataset.state, job: r.dataset.job,
  progress: Number(r.querySelector('progress')?.value ?? 0),
})));
const jobRows = page => page.evaluate(() => [...document.querySelectorAll('#jobs tbody tr')].map(r => ({
  id: r.dataset.job, state: r.dataset.state, machine: r.cells[2].textContent,
})));
// All three machines running a job with some of it drawn.
const allDrawing = rows => rows.length === 3 &&
  rows.every(r => r.online === 'true' && r.state === 'running' && r.job !== '' && r.progress > 0);

async function main() {
  const port = await h.startBroker();
  const mqtt = `mqtt://127.0.0.1:${port}`;
  for (const [k, name] of names.entries()) {
    // --time-scale 2: the drawings take tens of seconds, not a minute or more; --exit-after
    // bounds a device this test failed to kill.
    const device = await h.startAndRead(bin, ['device', '-m', machine, '--no-gpio', '--tcp', '127.0.0.1:0',
      '--time-scale', '2', '--exit-after', '300'], /serving (modbus-tcp:\/\/\S+)/, `device ${k + 1}`);
    const serve = h.spawn(bin, ['serve', '-m', machine, '-t', device.match[1], '--listen', '127.0.0.1:0',
      '--state-dir', path.join(h.work, `state${k + 1}`), '--mqtt', mqtt, '--name', name],
    { stdio: ['ignore', 'pipe', 'pipe'] });
    let text = '';
    serve.stdout.on('data', c => { text += c; });
    serve.stderr.on('data', c => { text += c; });
    serve.on('exit', code => h.cleaning || check(false, `serve ${name} exited ${code} while in use: ${text}`));
  }
  const fleet = await h.startAndRead(bin, ['fleet', '--mqtt', mqtt, 'serve', '--listen', '127.0.0.1:0'],
    /(http:\/\/127\.0\.0\.1:\d+\/)/, 'fleet serve');
  const url = fleet.match[1];

  const browser = await h.launchBrowser();
  try {
    const page = await browser.newPage();
    page.on('pageerror', e => check(false, `no script error on the page: ${e.message}`));
    await page.setViewportSize({ width: 1366, height: 768 });
    await page.goto(url);
    await within(20000, 'three machines online, idle', async () => {
      const rows = await machineRows(page);
      return rows.length === 3 && rows.every(r => r.online === 'true' && r.state === 'idle');
    });
    // The form offers the machines' kind once they have reported it.
    await within(5000, 'the form offers the queue of kind pen_plotter', async () =>
      (await page.locator('#target option[value="kind:pen_plotter"]').count()) === 1);

    for (const [i, file] of drawings.entries()) {
      const id = `print-${String(i + 1).padStart(2, '0')}`;
      await page.setInputFiles('#file', path.join(source, 'examples', file));
      await page.selectOption('#target', 'kind:pen_plotter');
      await page.selectOption('#fit', 'a4');
      await page.fill('#job-id', id);
      await page.click('#submit');
      await within(5000, `${id} (${file}) queued on pathstream/queue/pen_plotter`, async () =>
        (await page.textContent('#submit-result')) === `job ${id} queued on pathstream/queue/pen_plotter`);
    }

    await within(60000, 'three machines running, each with a progress bar above 0 %', async () =>
      allDrawing(await machineRows(page)));
    const rows = await machineRows(page);
    check(allDrawing(rows) && new Set(rows.map(r => r.job)).size === 3,
      `the machines: ${JSON.stringify(rows.map(r => [r.name, r.state, r.job, r.progress]))}`);
    const running = (await jobRows(page)).filter(j => j.state === 'running');
    check(running.length === 3 && new Set(running.map(j => j.machine)).size === 3 &&
      running.every(j => names.includes(j.machine) && rows.find(r => r.name === j.machine)?.job === j.id),
    `the jobs list: three running on three machines: ${JSON.stringify(running.map(j => [j.id, j.machine]))}`);

    // A phone while they draw: one column, nothing wider than the window.
    await page.setViewportSize({ width: 390, height: 844 });
    await within(3000, 'the page laid out at 390 px', () => page.evaluate(() => window.innerWidth === 390));
    await h.noOverflow(page, 'with three machines drawing');
    await page.screenshot({ path: path.join(outDir, 'fleet-phone.png'), fullPage: true });

    // The picture for the docs: a running job's history shown, on a laptop.
    await page.setViewportSize({ width: 1366, height: 768 });
    const shown = running[0];
    await page.click(`#jobs tr[data-job="${shown.id}"]`);
    await within(3000, `the history of ${shown.id}: queued, then running on ${shown.machine}`, async () =>
      (await page.locator('#history-list li').allTextContents()).map(t => t.split(' at ')[0]).join('|') ===
        `queued|running on ${shown.machine}`);
    await page.evaluate(() => window.scrollTo(0, 0));
    // Still all three drawing in the picture (a machine may have finished meanwhile: then the
    // next queued job runs there and the poll sees it again).
    await within(30000, 'still three machines drawing for the picture', async () =>
      allDrawing(await machineRows(page)));
    await page.screenshot({ path: path.join(outDir, 'fleet.png'), fullPage: true });
    if (process.env.PATHSTREAM_UPDATE_IMAGES === '1') {
      copyFileSync(path.join(outDir, 'fleet.png'), path.join(source, 'docs/images/fleet.png'));
      console.log('copied fleet.png to docs/images/');
    }

    // Stop every machine from the page; each answers.
    for (const name of names) {
      await page.selectOption('#command-machine', name);
      await page.click('.machine-controls button[data-verb="stop"]');
      await within(15000, `${name} answers stop`, async () =>
        (await page.textContent('#command-result')) === `${name}: stop ok`);
    }
  } finally {
    await browser.close();
  }
}

await h.run(main, 'fleet machines browser test');
