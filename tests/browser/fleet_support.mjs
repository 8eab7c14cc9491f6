// What the fleet page's browser tests share: a work directory, checks that count failures, a
// poll for a condition, a real broker (mosquitto on loopback, own config, free port), pathstream
// processes whose output is read for a line, headless Chromium, and the clean-up of every child
// (fleet_test.mjs: stand-in machines; fleet_machines_test.mjs: real ones).
import { spawn } from 'node:child_process';
import { mkdtempSync, writeFileSync, rmSync, mkdirSync, readdirSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import net from 'node:net';
import path from 'node:path';
import { chromium } from 'playwright-core';

// Every process below pid, from Linux's /proc/PID/task/TID/children: `pathstream serve` runs its
// jobs (`stream`) in process groups of their own, which a kill of serve's group does not reach.
function descendants(pid) {
  const out = [];
  let tasks = [];
  try { tasks = readdirSync(`/proc/${pid}/task`); } catch { return out; }
  for (const tid of tasks) {
    let text = '';
    try { text = readFileSync(`/proc/${pid}/task/${tid}/children`, 'utf8'); } catch { continue; }
    for (const c of text.split(' ').filter(Boolean).map(Number)) out.push(c, ...descendants(c));
  }
  return out;
}

export function harness(name, outDir) {
  const work = mkdtempSync(path.join(tmpdir(), `pathstream-${name}-`));
  mkdirSync(outDir, { recursive: true });
  const children = [];
  // cleaning: set once clean-up begins, so that a child's exit then is no failure.
  const h = { work, children, failures: 0, cleaning: false };

  h.check = (ok, what) => {
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
    if (!ok) h.failures++;
    return ok;
  };

  // Polls the condition until it holds; `ms` only bounds a hang, it is not what is tested.
  h.within = async (ms, what, condition) => {
    const end = Date.now() + ms;
    while (Date.now() < end) {
      if (await condition()) {
        console.log(`ok   ${what}`);
        return true;
      }
      await new Promise(r => setTimeout(r, 50));
    }
    h.check(false, `${what} (within ${ms} ms)`);
    return false;
  };

  h.freePort = () => new Promise(resolve => {
    const s = net.createServer();
    s.listen(0, '127.0.0.1', () => { const p = s.address().port; s.close(() => resolve(p)); });
  });

  // Each child leads its own process group (detached), so that clean-up reaches whatever it
  // started too.
  h.spawn = (cmd, args, opts = {}) => {
    const child = spawn(cmd, args, { detached: true, ...opts });
    children.push(child);
    return child;
  };

  h.startBroker = async () => {
    const port = await h.freePort();
    const conf = path.join(work, 'mosquitto.conf');
    writeFileSync(conf, `listener ${port} 127.0.0.1\npersistence false\nallow_anonymous true\n`);
    h.spawn('/usr/sbin/mosquitto', ['-c', conf], { stdio: 'ignore' });
    await h.within(5000, 'mosquitto listens', () => new Promise(resolve => {
      const c = net.connect(port, '127.0.0.1', () => { c.end(); resolve(true); });
      c.on('error', () => resolve(false));
    }));
    return port;
  };

  // Starts `cmd args` and resolves with { child, match, output } once its standard output or
  // error matches `pattern`; rejects if it exits first. output() is all it has written so far.
  h.startAndRead = (cmd, args, pattern, what) => {
    const child = h.spawn(cmd, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    let text = '';
    const output = () => text;
    return new Promise((resolve, reject) => {
      const timer = setTimeout(() => reject(new Error(`${what}: no ${pattern} in 10 s: ${text}`)), 10000);
      const look = chunk => {
        text += chunk;
        const m = text.match(pattern);
        if (m) { clearTimeout(timer); resolve({ child, match: m, output }); }
      };
      child.stdout.on('data', look);
      child.stderr.on('data', look);
      child.on('exit', code => reject(new Error(`${what} exited ${code}: ${text}`)));
    });
  };

  h.launchBrowser = () => chromium.launchPersistentContext(path.join(work, 'chromium'), {
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    viewport: { width: 390, height: 844 },
  });

  h.noOverflow = async (page, what) => {
    const width = await page.evaluate(() => ({ scroll: document.documentElement.scrollWidth, w: window.innerWidth }));
    h.check(width.scroll <= width.w, `no horizontal overflow at ${width.w} px ${what}: the page is ${width.scroll} px wide`);
  };

  // Runs main, then kills every child, its descendants and their process groups and removes the work directory whatever
  // happened, and exits 0 only if nothing failed.
  h.run = async (main, title) => {
    try {
      await main();
    } catch (e) {
      console.log(`FAIL ${e.stack || e}`);
      h.failures++;
    } finally {
      h.cleaning = true;
      // Stopped first, so that none starts another process while the rest are killed.
      // Only children still running: an exited one's pid may be another process's now.
      const all = children.filter(c => c.exitCode === null && c.signalCode === null)
        .flatMap(c => [c.pid, ...descendants(c.pid)]);
      for (const pid of all) { try { process.kill(pid, 'SIGSTOP'); } catch { /* gone */ } }
      for (const pid of all) { try { process.kill(-pid, 'SIGKILL'); } catch { /* not a group leader */ } }
      for (const pid of all) { try { process.kill(pid, 'SIGKILL'); } catch { /* gone */ } }
      await new Promise(r => setTimeout(r, 300));
      rmSync(work, { recursive: true, force: true });
    }
    console.log(h.failures === 0 ? `${title}: all passed` : `${title}: ${h.failures} failed`);
    process.exit(h.failures === 0 ? 0 : 1);
  };
  return h;
}
