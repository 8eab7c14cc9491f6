// The page of `pathstream serve`: load a drawing, place it, preview it, stream or simulate it,
// and watch and steer the machine through the server's API (docs/serve.md).
import { PreviewView, drawSpeed } from './preview.js';

const $ = id => document.getElementById(id);
const view = new PreviewView($('preview'));
const page = {
  preview: null,       // the last preview document
  allLayers: [],       // the drawing's layers before any was deselected
  leadTicks: 0,        // the running job's ticks before the preview's first (its lead-in)
  planTicks: 0,
  jobRunning: false,
  device: null,
};

// The token came once in the address (?token=); the server keeps it as a cookie, so it is
// taken out of the address bar and the history.
if (new URLSearchParams(location.search).has('token')) history.replaceState(null, '', location.pathname);

async function api(path, body, raw) {
  const init = body === undefined ? {} : {
    method: 'POST',
    headers: raw ? {} : { 'Content-Type': 'application/json' },
    body: raw ? body : JSON.stringify(body),
  };
  const res = await fetch(path, init);
  let json;
  try { json = await res.json(); } catch { json = { ok: false, error: `HTTP ${res.status}` }; }
  if (res.status === 413) json = { ok: false, error: 'the file is larger than the server accepts' };
  return json;
}

function showError(message) {
  $('error').hidden = !message;
  $('error').textContent = message || '';
}

function setFigure(id, value, text) {
  $(id).textContent = text;
  $(id).dataset.value = value;
}

function minutes(s) {
  const m = Math.floor(s / 60), r = Math.round(s - 60 * m);
  return `${m}:${String(r).padStart(2, '0')}`;
}

function options() {
  const o = {
    fit: $('fit').value,
    margin: Number($('margin').value) || 0,
    rotate: Number($('rotate').value),
    flip_y: $('flip').checked,
    keep_order: !$('order').checked,
    pause: $('pause').value,
  };
  const boxes = [...document.querySelectorAll('#layers input')];
  if (boxes.length && boxes.some(b => !b.checked)) o.layers = boxes.filter(b => b.checked).map(b => b.value);
  return o;
}

function showPreview(p) {
  page.preview = p;
  const s = p.summary;
  setFigure('fig-time', s.duration_s, `${s.duration_s.toFixed(3)} s (${minutes(s.duration_s)})`);
  setFigure('fig-drawn', s.drawn_length_mm, `${s.drawn_length_mm.toFixed(1)} mm`);
  setFigure('fig-travel', s.travel_length_mm, `${s.travel_length_mm.toFixed(1)} mm`);
  setFigure('fig-subpaths', s.subpaths, String(s.subpaths));
  setFigure('fig-spans', s.spans, `${s.spans} (${s.vertices} vertices)`);
  setFigure('fig-pens', s.pen_changes, `${s.pen_changes}, ${s.pauses}`);
  $('drawing-name').textContent = p.drawing;
  if (!options().layers) {
    page.allLayers = s.layers;
    $('layers').replaceChildren(...s.layers.map((l, i) => {
      const label = document.createElement('label');
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = true;
      box.value = String(i + 1);
      box.addEventListener('change', () => {
        if (![...document.querySelectorAll('#layers input')].some(b => b.checked)) box.checked = true;
        refreshPreview();
      });
      label.append(box, ` ${l.name} (${l.subpaths})`);
      return label;
    }));
    if (s.layers.length < 2) $('layers').replaceChildren();
  }
  view.setPreview(p);
  $('scrub').max = String(s.ticks);
  $('scrub').value = String(s.ticks);
  redraw();
  $('start').disabled = page.jobRunning;
  $('simulate').disabled = false;
}

// At most one redraw per animation frame, however fast the updates come.
let drawPending = false;
function scheduleDraw() {
  if (drawPending) return;
  drawPending = true;
  requestAnimationFrame(() => { drawPending = false; redraw(); });
}

function redraw() {
  const ms = view.draw();
  if (ms > 0) setFigure('fig-draw-ms', ms, `${ms.toFixed(1)} ms`);
  const p = page.preview;
  if (p) {
    const at = view.doneTick >= 0 ? view.doneTick : (view.limitTick === Infinity ? null : view.limitTick);
    drawSpeed($('speed'), p.speed, at === null ? null : at / p.summary.tick_hz);
  }
}

async function load(file) {
  showError('');
  $('drawing-name').textContent = `${file.name}: planning…`;
  const r = await api(`/api/drawing?name=${encodeURIComponent(file.name)}`, file, true);
  if (!r.ok) {
    $('drawing-name').textContent = file.name;
    showError(r.error);
    return;
  }
  $('layers').replaceChildren();
  showPreview(r);
}

let previewSerial = 0;
async function refreshPreview() {
  if (!page.preview) return;
  const serial = ++previewSerial;
  const r = await api('/api/preview', { options: options() });
  if (serial !== previewSerial) return;  // a newer request is on its way
  if (!r.ok) { showError(r.error); return; }
  showError('');
  showPreview(r);
}

async function command(body) {
  $('command-text').textContent = `${body.verb}…`;
  const r = await api('/api/control', body);
  $('command-text').textContent = r.ok ? `${body.verb}: done` : `${body.verb}: ${r.error}`;
  return r;
}

function wire() {
  $('file').addEventListener('change', e => { if (e.target.files[0]) load(e.target.files[0]); });
  const drop = $('drop');
  drop.addEventListener('dragover', e => { e.preventDefault(); drop.classList.add('over'); });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', e => {
    e.preventDefault();
    drop.classList.remove('over');
    if (e.dataTransfer.files[0]) load(e.dataTransfer.files[0]);
  });
  for (const id of ['fit', 'margin', 'rotate', 'flip', 'order', 'pause']) $(id).addEventListener('change', refreshPreview);
  $('scrub').addEventListener('input', () => {
    const t = Number($('scrub').value);
    view.limitTick = t >= Number($('scrub').max) ? Infinity : t;
    $('scrub-text').textContent = page.preview ? `${(t / page.preview.summary.tick_hz).toFixed(2)} s` : '';
    scheduleDraw();
  });
  $('start').addEventListener('click', async () => {
    showError('');
    $('sim-report').hidden = true;
    const r = await api('/api/run', { options: options() });
    if (!r.ok) { showError(r.error); return; }
    showPreview(r);
  });
  $('simulate').addEventListener('click', async () => {
    $('sim-report').hidden = false;
    $('sim-report').textContent = 'simulating…';
    const r = await api('/api/simulate', { options: options() });
    $('sim-report').textContent = r.ok ? r.report : `${r.error || ''}\n${r.report || ''}`;
  });
  $('resume-job').addEventListener('click', async () => {
    const r = await api('/api/resume', {});
    if (!r.ok) showError(r.error);
  });
  for (const verb of ['hold', 'resume', 'stop', 'reset']) $(verb).addEventListener('click', () => command({ verb }));
  $('home').addEventListener('click', () => command({ verb: 'home' }));
  $('pen-up').addEventListener('click', () => command({ verb: 'pen', down: false }));
  $('pen-down').addEventListener('click', () => command({ verb: 'pen', down: true }));
  for (const b of document.querySelectorAll('[data-jog]')) {
    b.addEventListener('click', () => command({
      verb: 'jog', axis: b.dataset.jog,
      distance_mm: Number(b.dataset.sign) * Number($('step').value),
      feed: Number($('feed').value) || undefined,
    }));
  }
}

function showDevice(d) {
  page.device = d;
  const badge = $('device-state');
  if (d.error) {
    badge.dataset.state = 'offline';
    badge.textContent = `device: ${d.error}`;
    return;
  }
  badge.dataset.state = d.state;
  badge.textContent = `device: ${d.state}${d.paused ? ' (paused)' : ''}${d.homing ? ' (homing)' : ''}`;
  $('pen-state').textContent = `pen ${d.pen_down ? 'down' : 'up'}`;
  $('pen-state').dataset.down = String(d.pen_down);
  $('position').textContent = Object.entries(d.position_mm).map(([a, v]) => `${a} ${v.toFixed(3)}`).join('  ');
  const alarm = d.state === 'e-stop' ? 'E-STOP: release it, then Reset'
    : d.state === 'fault' ? `FAULT: ${d.fault}; Reset to go on` : '';
  $('alarm').hidden = !alarm;
  $('alarm').textContent = alarm;
  if (!page.jobRunning) {
    const axes = Object.values(d.position_mm);
    view.marker = axes.length >= 2 ? axes.slice(0, 2) : null;
    if (page.preview) scheduleDraw();
  }
}

function onEvent(e) {
  switch (e.event) {
    case 'device': showDevice(e); break;
    case 'process':
      page.jobRunning = e.running;
      $('start').disabled = e.running || !page.preview;
      $('resume-job').disabled = e.running;
      if (e.running) {
        $('job-text').textContent = `${e.kind}: started`;
        $('progress').value = 0;
        $('progress-text').textContent = 'starting';
        view.doneTick = -1;
      } else {
        $('job-text').textContent = e.exit === 0 ? `${e.kind}: ended` : `${e.kind}: ${e.error || `exit ${e.exit}`}`;
        $('resume-job').disabled = false;
      }
      break;
    case 'job_start':
      page.planTicks = e.plan_ticks;
      page.leadTicks = page.preview ? Math.max(0, e.plan_ticks - page.preview.summary.ticks) : 0;
      $('progress').value = 0;
      $('progress-text').textContent = `job ${e.job ?? ''}: ${e.duration_s.toFixed(1)} s of motion`;
      break;
    case 'progress': {
      $('progress').value = e.fraction;
      const pen = page.device ? (page.device.pen_down ? 'pen down' : 'pen up') : '';
      $('progress-text').textContent =
        `${(100 * e.fraction).toFixed(1)} %  ETA ${minutes(e.eta_s)}  queue ${e.queue_s.toFixed(2)} s (${e.queue_spans} spans) ${pen}`;
      const axes = Object.values(e.position_mm);
      view.marker = axes.slice(0, 2);
      view.doneTick = e.ticks - page.leadTicks;
      scheduleDraw();
      break;
    }
    case 'pause':
      $('job-text').textContent = `paused for a pen change (${e.pause} of ${e.pauses}), next ${e.next}: press Resume`;
      break;
    case 'hold': case 'stop':
      $('job-text').textContent = `${e.event} requested`;
      break;
    case 'job_end':
      if (e.outcome === 'finished') {
        $('progress').value = 1;
        $('progress-text').textContent = `100 %  finished: ${e.ticks} ticks in ${e.wall_s.toFixed(1)} s`;
        view.doneTick = Infinity;
      } else {
        $('progress-text').textContent = `${e.outcome}${e.error ? `: ${e.error}` : ''} at ${(100 * e.ticks / e.plan_ticks).toFixed(1)} %`;
      }
      scheduleDraw();
      break;
    case 'command':
      if (!e.ok) $('command-text').textContent = `${e.verb}: ${e.error}`;
      // A job held on the way to a stop: the server's stop dropped the rest of its queue.
      if (e.ok && e.verb === 'stop' && $('progress-text').textContent.startsWith('held')) {
        $('progress-text').textContent = $('progress-text').textContent.replace(/^held/, 'stopped');
      }
      break;
    default: break;
  }
}

async function start() {
  wire();
  const s = await api('/api/state');
  if (s.ok) {
    $('machine-name').textContent = `${s.machine.file} → ${s.target}`;
    $('resume-job').disabled = !s.journal || s.job_running;
    page.jobRunning = s.job_running;
  }
  const events = new EventSource('/api/events');
  events.onmessage = m => onEvent(JSON.parse(m.data));
  events.onerror = () => { $('device-state').dataset.state = 'offline'; $('device-state').textContent = 'server: reconnecting'; };
  document.body.dataset.ready = 'true';
}

start();
