// The fleet page in a real browser: Debian's Chromium, headless, driven by playwright-core,
// against `pathstream fleet serve` and a real broker (mosquitto on loopback) on which
// mosquitto_pub stands in for three machines that draw.
//
//   node fleet_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR
//
// Checks: the machines' table (online, state, job, progress) at 390x844 with no page wider than
// the window; a job's history shown on a click; a job submitted through the form, to the queue
// and to one machine, arriving on the broker as published by the server (id, file, drawing);
// a command button answered by a stand-in machine; the API's 4xx with a reason for a bad id,
// an unknown extension, an unknown machine, a drawing too large. Screenshots go to OUT_DIR
// (fleet-stand-ins.png, fleet-stand-ins-phone.png); docs/images/fleet.png comes from
// fleet_machines_test.mjs, where real machines draw.
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { harness } from './fleet_support.mjs';

const [bin, source, outDir] = process.argv.slice(2);
if (!bin || !source || !outDir) {
  console.error('usage: node fleet_test.mjs PATHSTREAM SOURCE_DIR OUT_DIR');
  process.exit(2);
}
const h = harness('fleet', outDir);
const { check, within, startBroker } = h;

// Resolves, once subscribed, with { messages }: a promise of the first `count` messages on
// `topic` (one per line). Wrapped in an object: a promise resolved with a promise would wait
// for it.
function subscribe(port, topic, count) {
  const child = h.spawn('mosquitto_sub', ['-p', String(port), '-t', topic, '-C', String(count), '-W', '20'],
    { stdio: ['ignore', 'pipe', 'pipe'] });
  let text = '';
  child.stdout.on('data', c => { text += c; });
  // 'close', not 'exit': the output is read to its end.
  const done = new Promise(resolve => child.on('close', () => resolve(text.split('\n').filter(Boolean))));
  // Subscribed once mosquitto_sub has had a moment to connect: give it one.
  return new Promise(r => setTimeout(() => r({ messages: done }), 500));
}

async function main() {
  const port = await startBroker();
  const pub = (topic, payload) =>
    execFileSync('mosquitto_pub', ['-p', String(port), '-q', '1', '-r', '-t', topic, '-m', JSON.stringify(payload)]);
  // Three machines drawing, each its own job, at its own progress; one job done before.
  const now = Date.now() / 1000;
  const names = ['plotter-1', 'plotter-2', 'plotter-3'];
  names.forEach((name, i) => {
    const job = `print-000${i + 1}`;
    pub(`pathstream/${name}/online`, { name, machine: 'pen_plotter.json', axes: ['x', 'y'], target: 't', online: true });
    pub(`pathstream/${name}/status`, { event: 'device', state: 'running', pen_down: true, position_mm: { x: 20 * i, y: 10 } });
    pub(`pathstream/${name}/progress`, { event: 'progress', fraction: 0.25 * (i + 1), eta_s: 30 - 10 * i });
    pub(`pathstream/jobs/${job}/state`, {
      id: job, state: 'running', machine: name, file: 'rose.json', at: now - 10 + i, error: '',
      history: [{ state: 'queued', machine: null, at: now - 20 }, { state: 'running', machine: name, at: now - 10 + i }],
    });
  });
  pub('pathstream/jobs/print-0000/state', {
    id: 'print-0000', state: 'done', machine: 'plotter-1', file: 'wave.json', at: now - 30, error: '',
    history: [{ state: 'queued', machine: null, at: now - 60 }, { state: 'running', machine: 'plotter-1', at: now - 50 },
      { state: 'done', machine: 'plotter-1', at: now - 30 }],
  });

  const server = await h.startAndRead(bin, ['fleet', '--mqtt', `mqtt://127.0.0.1:${port}`, 'serve', '--listen', '127.0.0.1:0',
    '--max-upload-mb', '0.005'], /(http:\/\/127\.0\.0\.1:\d+\/)/, 'fleet serve');
  const url = server.match[1];

  const browser = await h.launchBrowser();
  try {
    const page = await browser.newPage();
    page.on('pageerror', e => check(false, `no script error on the page: ${e.message}`));
    await page.setViewportSize({ width: 390, height: 844 });
    await page.goto(url);
    await within(5000, 'three machines in the table', async () =>
      (await page.locator('#machines tbody tr').count()) === 3);
    const rows = await page.evaluate(() => [...document.querySelectorAll('#machines tbody tr')].map(r => ({
      name: r.dataset.machine, online: r.dataset.online, state: r.dataset.state, job: r.dataset.job,
      progress: Number(r.querySelector('progress')?.value), text: r.textContent,
    })));
    check(rows.map(r => `${r.name} ${r.online} ${r.state} ${r.job}`).join(', ') ===
      'plotter-1 true running print-0001, plotter-2 true running print-0002, plotter-3 true running print-0003',
    `the machines: ${JSON.stringify(rows.map(r => [r.name, r.online, r.state, r.job]))}`);
    check(rows.map(r => r.progress).join(' ') === '0.25 0.5 0.75' && rows[1].text.includes('50 %'),
      `the progress bars: ${rows.map(r => r.progress)}`);
    await h.noOverflow(page, 'with three stand-ins drawing');

    // A click on a job shows its history.
    await page.click('#jobs tr[data-job="print-0000"]');
    await within(3000, 'the history of print-0000', async () =>
      (await page.locator('#history-list li').allTextContents()).map(t => t.split(' at ')[0]).join('|') ===
        'queued|running on plotter-1|done on plotter-1');

    // The form: to the queue of any machine, then to plotter-2 only.
    const rose = path.join(source, 'examples/rose.json');
    let got = await subscribe(port, 'pathstream/queue/any', 1);
    await page.setInputFiles('#file', rose);
    await page.selectOption('#target', 'kind:any');
    await page.selectOption('#fit', 'a4');
    await page.fill('#job-id', 'from-page-1');
    await page.click('#submit');
    await within(5000, 'the page says the job is queued', async () =>
      (await page.textContent('#submit-result')).includes('job from-page-1 queued on pathstream/queue/any'));
    let messages = (await got.messages).map(l => JSON.parse(l));
    check(messages.length === 1 && messages[0].id === 'from-page-1' && messages[0].file === 'rose.json' &&
      messages[0].drawing === readFileSync(rose, 'utf8') && messages[0].options.fit === 'a4' && messages[0].kind === 'any',
    `the job message on pathstream/queue/any: ${JSON.stringify(messages.map(m => [m.id, m.file, m.kind, m.options]))}`);
    await within(5000, 'the submitted job in the jobs list, queued', async () =>
      (await page.getAttribute('#jobs tr[data-job="from-page-1"]', 'data-state').catch(() => null)) === 'queued');

    got = await subscribe(port, 'pathstream/plotter-2/jobs', 1);
    await page.selectOption('#target', 'machine:plotter-2');
    await page.fill('#job-id', '');
    await page.click('#submit');
    messages = (await got.messages).map(l => JSON.parse(l));
    check(messages.length === 1 && /^job-\d{8}-\d{6}-[0-9a-f]{4}$/.test(messages[0].id) && messages[0].machine === 'plotter-2',
      `the job message on pathstream/plotter-2/jobs: ${JSON.stringify(messages.map(m => [m.id, m.machine]))}`);

    // A command button, answered by a stand-in plotter-1.
    const commands = await subscribe(port, 'pathstream/plotter-1/command', 1);
    await page.selectOption('#command-machine', 'plotter-1');
    await page.click('.machine-controls button[data-verb="hold"]');
    const command = JSON.parse((await commands.messages)[0] || '{}');
    check(command.verb === 'hold' && typeof command.id === 'string', `the command published: ${JSON.stringify(command)}`);
    execFileSync('mosquitto_pub', ['-p', String(port), '-t', 'pathstream/plotter-1/reply', '-m',
      JSON.stringify({ id: command.id, ok: true, status: 200 })]);
    await within(5000, 'the page shows the reply', async () =>
      (await page.textContent('#command-result')) === 'plotter-1: hold ok');

    // The API refuses what cannot be a job, with the reason. A machine that went offline first.
    pub('pathstream/plotter-9/online', { name: 'plotter-9', machine: 'pen_plotter.json', axes: ['x', 'y'], online: false });
    await within(5000, 'the offline plotter-9 in the table', async () =>
      (await page.getAttribute('#machines tr[data-machine="plotter-9"]', 'data-state').catch(() => null)) === 'offline');
    const api = await page.evaluate(async () => {
      const post = async body => {
        const r = await fetch('/api/submit', { method: 'POST', body: JSON.stringify(body) });
        return [r.status, (await r.json()).error];
      };
      return {
        id: await post({ file: 'a.json', drawing: '{}', id: 'a/b' }),
        ext: await post({ file: 'a.docx', drawing: 'x' }),
        machine: await post({ file: 'a.json', drawing: '{}', machine: 'nobody' }),
        offline: await post({ file: 'a.json', drawing: '{}', machine: 'plotter-9' }),
        large: await post({ file: 'a.json', drawing: 'x'.repeat(6000) }),
        json: await post('not an object'),
        verb: await (await fetch('/api/command', { method: 'POST', body: '{"machine":"plotter-1","verb":"explode"}' })).status,
        view: await (await fetch('/api/fleet')).json(),
      };
    });
    check(api.id[0] === 400 && api.id[1].includes('1 to 64 of A-Z a-z 0-9 _ -'), `a bad id: ${api.id}`);
    check(api.ext[0] === 400 && api.ext[1].includes('no reader knows its extension'), `an unknown extension: ${api.ext}`);
    check(api.machine[0] === 404 && api.machine[1] === 'no machine named nobody on the broker', `an unknown machine: ${api.machine}`);
    check(api.offline[0] === 409 && api.offline[1] === 'machine plotter-9 is offline: a job sent to it now would not be drawn',
      `an offline machine: ${api.offline}`);
    check(api.large[0] === 413 && api.large[1].includes('more than 5242'), `too large: ${api.large}`);
    check(api.json[0] === 400, `not an object: ${api.json}`);
    check(api.verb === 400, `an unknown verb: ${api.verb}`);
    check(api.view.jobs_total === 6 && api.view.jobs.length === 6 && api.view.ignored === 0,
      `GET /api/fleet: ${api.view.jobs.length} of ${api.view.jobs_total} jobs, ${api.view.ignored} ignored`);
    await page.screenshot({ path: path.join(outDir, 'fleet-stand-ins-phone.png'), fullPage: true });

    // Three stand-ins drawing, on a laptop (plotter-9 forgotten). Not the docs' picture:
    // fleet_machines_test.mjs takes that one with real machines drawing.
    execFileSync('mosquitto_pub', ['-p', String(port), '-q', '1', '-r', '-t', 'pathstream/plotter-9/online', '-n']);
    await within(5000, 'plotter-9 forgotten', async () => (await page.locator('#machines tbody tr').count()) === 3);
    await page.setViewportSize({ width: 1366, height: 768 });
    await page.click('#jobs tr[data-job="print-0002"]');
    await page.evaluate(() => window.scrollTo(0, 0));
    await within(3000, 'the history of print-0002 shown', async () =>
      (await page.textContent('#history')).startsWith('print-0002'));
    await page.screenshot({ path: path.join(outDir, 'fleet-stand-ins.png'), fullPage: true });
  } finally {
    await browser.close();
  }
}

await h.run(main, 'fleet browser test');
