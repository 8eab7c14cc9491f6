// The page of `pathstream serve`: load a drawing, place it, preview it, stream or simulate it,
// and watch and steer the machine through the server's API (docs/serve.md).
import { PreviewView, drawSpeed, layerColours } from './preview.js';
import { ViewPanel, surfaceDocument } from './view_panel.js';

const $ = id => document.getElementById(id);
const view = new PreviewView($('preview'));
const page = {
  preview: null,       // the last preview document; null: none (Start is off)
  drawing: '',         // the drawing the server holds (it may have no preview)
  colours: [],         // per layer of the drawing
  allLayers: [],       // the drawing's layers as planned with all of them (their subpaths)
  jobPreview: null,    // the preview the running (or last) job was planned from
  jobKind: '',
  wholeTicks: null,    // the whole job's ticks: a resumed job counts as a part of it
  shown: 0,            // the fraction shown for the job (never goes back within a job)
  jobRunning: false,
  device: null,
  surface: null,       // a JSON drawing with surfaces: { name, doc }, its document parsed once
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
  let res;
  try {
    res = await fetch(path, init);
  } catch (e) {
    return { ok: false, error: `the server does not answer (${e.message})` };
  }
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
  if (value === null) delete $(id).dataset.value; else $(id).dataset.value = value;
}

function minutes(s) {
  const m = Math.floor(s / 60), r = Math.round(s - 60 * m);
  return `${m}:${String(r).padStart(2, '0')}`;
}

const percent = f => `${(100 * f).toFixed(1)} %`;
const seconds = s => (s === null || s === undefined ? '? s' : `${s.toFixed(1)} s`);

function options() {
  const o = {
    fit: $('fit').value,
    margin: $('fit').value ? Number($('margin').value) || 0 : 0,  // a margin is the fit's
    rotate: Number($('rotate').value),
    flip_y: $('flip').checked,
    origin: $('origin').value,
    keep_order: !$('order').checked,
    pause: $('pause').value,
  };
  const boxes = [...document.querySelectorAll('#layers input')];
  if (boxes.length && boxes.some(b => !b.checked)) o.layers = boxes.filter(b => b.checked).map(b => b.value);
  return o;
}

// The form as the options of a preview the server kept (a page opened later, or reloaded).
function setOptions(o) {
  if (!o) return;
  if (typeof o.fit === 'string') $('fit').value = o.fit;
  $('margin').disabled = !$('fit').value;
  if (typeof o.margin === 'number') $('margin').value = String(o.margin);
  if (typeof o.rotate === 'number') $('rotate').value = String(o.rotate);
  if (typeof o.flip_y === 'boolean') $('flip').checked = o.flip_y;
  if (typeof o.origin === 'string') setOrigin(o.origin);
  if (typeof o.keep_order === 'boolean') $('order').checked = !o.keep_order;
  if (typeof o.pause === 'string') $('pause').value = o.pause;
}

// The machine's origin decides which way y points in the preview and on the jog pad. It is
// the machine's, not the drawing's: the browser keeps it.
function setOrigin(origin) {
  const up = origin === 'bottom-left';
  $('origin').value = up ? 'bottom-left' : 'top-left';
  try { localStorage.setItem('pathstream.origin', $('origin').value); } catch { /* storage off */ }
  $('preview').dataset.y = up ? 'up' : 'down';
  document.querySelector('.pad').dataset.y = up ? 'up' : 'down';
  document.querySelector('.pad .y-plus').textContent = up ? '↑ Y+' : 'Y+ ↓';
  document.querySelector('.pad .y-minus').textContent = up ? 'Y− ↓' : '↑ Y−';
  view.setYUp(up);
  layout();
}

// The layer list under the preview is its legend too: each layer's colour, name and
// subpaths, and a box that plans it or leaves it out (`chosen`: the layers planned, by
// number from 1 or name; none: all).
function showLayers(layers, chosen, rapids) {
  if (!chosen || page.allLayers.length !== layers.length) page.allLayers = layers;
  page.colours = layerColours(layers);
  const entries = layers.length < 2 ? [] : page.allLayers.map((l, i) => {
    const label = document.createElement('label');
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.value = String(i + 1);
    box.checked = !chosen || chosen.includes(box.value) || chosen.includes(l.name);
    label.classList.toggle('off', !box.checked);
    box.addEventListener('change', () => {
      if (![...document.querySelectorAll('#layers input')].some(b => b.checked)) box.checked = true;
      label.classList.toggle('off', !box.checked);
      refreshPreview();
    });
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = page.colours[i];
    swatch.dataset.colour = page.colours[i];
    label.append(box, swatch, ` ${l.name} (${l.subpaths})`);
    return label;
  });
  const travel = document.createElement('span');
  travel.className = 'entry';
  const dash = document.createElement('span');
  dash.className = 'swatch travel';
  travel.append(dash, rapids ? ' rapids (pen-up travel)' : ' pen-up travel');
  $('layers').replaceChildren(...entries, travel);
}

function clearPreview() {
  page.preview = null;
  view.setPreview(null, []);
  for (const id of ['fig-time', 'fig-drawn', 'fig-travel', 'fig-subpaths', 'fig-spans', 'fig-pens', 'fig-draw-ms']) setFigure(id, null, '–');
  $('preview').hidden = true;
  $('no-preview').hidden = false;
  $('no-preview').textContent = page.drawing ? `No preview: ${page.drawing} cannot be planned with these options.` : 'No preview: load a drawing.';
  $('layers').replaceChildren();
  $('scrub').disabled = true;
  $('scrub-text').textContent = '';
  $('speed').hidden = true;
  $('start').disabled = true;
  $('simulate').disabled = true;
}

function showPreview(p) {
  page.preview = p;
  page.drawing = p.drawing;
  const s = p.summary;
  setFigure('fig-time', s.duration_s, `${s.duration_s.toFixed(3)} s (${minutes(s.duration_s)})`);
  setFigure('fig-drawn', s.drawn_length_mm, `${s.drawn_length_mm.toFixed(1)} mm`);
  setFigure('fig-travel', s.travel_length_mm, `${s.travel_length_mm.toFixed(1)} mm`);
  setFigure('fig-subpaths', s.subpaths, String(s.subpaths));
  setFigure('fig-spans', s.spans, `${s.spans} (${s.vertices} vertices)`);
  setFigure('fig-pens', s.pen_changes, `${s.pen_changes}, ${s.pauses}`);
  $('drawing-name').textContent = p.drawing;
  // summary.layers lists every layer of the drawing, planned or not: the colours stay.
  showLayers(s.layers, p.options && p.options.layers, Boolean(p.view));
  $('preview').hidden = false;
  $('speed').hidden = false;
  $('no-preview').hidden = true;
  view.setPreview(p, page.colours);
  $('scrub').disabled = false;
  $('scrub').max = String(s.ticks);
  $('scrub').value = String(s.ticks);
  $('scrub-text').textContent = '';
  layout();
  $('start').disabled = page.jobRunning;
  $('simulate').disabled = false;
}

// The preview's size: the column's width, as tall as the drawing's shape wants, never taller
// than the window below the bar (the order slider stays in view under it).
function layout() {
  const bar = $('bar').getBoundingClientRect().height;
  document.documentElement.style.setProperty('--bar-h', `${Math.ceil(bar)}px`);
  const canvas = $('preview');
  if (canvas.hidden) return;
  const width = Math.floor($('view').clientWidth) - 2;  // the canvas's border
  const narrow = matchMedia('(max-width: 820px)').matches;
  const room = window.innerHeight - bar - (narrow ? 70 : 110);
  const height = Math.round(Math.max(220, Math.min(room, width * (page.preview ? view.aspect() : 0.7) + 36)));
  view.resize(width, height, window.devicePixelRatio || 1);
  redraw();
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

// A drawing that cannot be read or placed leaves no preview behind: what the page shows is
// what Start would run.
function failed(message) {
  showError(message);
  clearPreview();
}

let previewSerial = 0;  // the latest upload or preview asked for: older answers are dropped

// Stores the drawing (a file, or a surface drawing's text with another view) on the server
// and plans it with the page's placement.
async function upload(name, body, o) {
  const serial = ++previewSerial;
  const r = await api(`/api/drawing?name=${encodeURIComponent(name)}&options=${encodeURIComponent(JSON.stringify(o))}`, body, true);
  if (serial !== previewSerial) return;
  if (!r.ok) {
    $('drawing-name').textContent = r.drawing || '';
    page.drawing = r.drawing || '';  // stored but not planned: other options may place it
    failed(r.error);
    return;
  }
  showError('');
  showPreview(r);
}

async function load(file) {
  showError('');
  $('drawing-name').textContent = `${file.name}: planning…`;
  // A JSON drawing with surfaces gets the View panel; the file itself goes up unchanged, so
  // the reader's messages name its own lines.
  clearTimeout(viewUpload.timer);
  viewUpload.again = false;
  const doc = surfaceDocument(file.name, await file.text().catch(() => ''));
  page.surface = doc ? { name: file.name, doc } : null;
  if (doc) viewPanel.show(doc); else viewPanel.hide();
  const o = options();
  delete o.layers;  // another drawing: its own layers
  $('layers').replaceChildren();
  viewUpload.loading = upload(file.name, file, o);
  await viewUpload.loading;
}

// A view changed in the panel: 250 ms after the last change the document goes up again with
// its new view, under the same name and with the same placement. One upload at a time (a
// newer one would only stop the older's plan); a change while one is on its way goes up
// when it answers, as the latest view.
const viewUpload = { timer: 0, busy: false, again: false, loading: Promise.resolve() };
const viewPanel = new ViewPanel($('surface-view'), () => {
  clearTimeout(viewUpload.timer);
  viewUpload.timer = setTimeout(uploadView, 250);
});

async function uploadView() {
  if (viewUpload.busy) { viewUpload.again = true; return; }
  viewUpload.busy = true;
  await viewUpload.loading;  // the file's own upload answers first
  do {
    viewUpload.again = false;
    const s = page.surface;
    if (!s) break;
    s.doc.view = viewPanel.view(s.doc.view);
    $('drawing-name').textContent = `${s.name}: planning the new view…`;
    await upload(s.name, JSON.stringify(s.doc), options());
  } while (viewUpload.again);
  viewUpload.busy = false;
}

async function refreshPreview() {
  if (!page.drawing) return;
  const serial = ++previewSerial;
  const r = await api('/api/preview', { options: options() });
  if (serial !== previewSerial) return;  // a newer request is on its way
  if (!r.ok) { $('drawing-name').textContent = page.drawing; failed(r.error); return; }
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
  $('fit').addEventListener('change', () => { $('margin').disabled = !$('fit').value; });
  $('origin').addEventListener('change', () => { setOrigin($('origin').value); refreshPreview(); });
  $('scrub').addEventListener('input', () => {
    const t = Number($('scrub').value);
    view.limitTick = t >= Number($('scrub').max) ? Infinity : t;
    $('scrub-text').textContent = page.preview ? `${(t / page.preview.summary.tick_hz).toFixed(2)} s` : '';
    scheduleDraw();
  });
  $('start').addEventListener('click', async () => {
    showError('');
    $('sim-report').hidden = true;
    $('start').disabled = true;
    // The run names the drawing this page previewed: another page's upload in between is refused.
    const r = await api('/api/run', { options: options(), drawing_hash: page.preview ? page.preview.drawing_hash : '' });
    if (!r.ok) {
      if (page.jobRunning) { showError(r.error); return; }
      failed(r.error);
      return;
    }
    showPreview(r);
    page.jobPreview = page.preview;
    $('start').disabled = true;
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
  window.addEventListener('resize', layout);
  new ResizeObserver(layout).observe($('bar'));
  new ResizeObserver(layout).observe($('view'));
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
    view.marker = view.iso ? view.projectPosition(d.position_mm) : (axes.length >= 2 ? axes.slice(0, 2) : null);
    if (page.preview) scheduleDraw();
  }
}

// The fraction of the whole job done when `remaining` of this job's ticks are left. A
// resumed job is the rest of the job its journal began (plus the move back onto the
// drawing), so it counts from where that one stopped, not from zero.
function wholeFraction(remaining, planTicks) {
  const whole = page.wholeTicks || planTicks;
  if (!whole) return page.shown;
  return Math.min(1, Math.max(0, 1 - remaining / whole));
}

function showProgress(fraction) {
  page.shown = Math.max(page.shown, fraction);
  $('progress').value = page.shown;
  return page.shown;
}

function onEvent(e) {
  switch (e.event) {
    case 'device': showDevice(e); break;
    case 'process':
      page.jobRunning = e.running;
      $('start').disabled = e.running || !page.preview;
      $('resume-job').disabled = e.running;
      if (e.running) {
        // The rest of the job this page saw stop goes on from where the bar stands.
        const same = e.kind === 'resume' && e.whole_plan_ticks && e.whole_plan_ticks === page.wholeTicks;
        if (!same) page.shown = 0;
        page.jobKind = e.kind;
        page.wholeTicks = e.whole_plan_ticks ?? null;
        $('job-text').textContent = `${e.kind}: started`;
        if (e.kind !== 'resume') $('progress').value = 0;
        $('progress-text').textContent = 'starting';
        view.doneTick = -1;
      } else if (e.exit === 7) {
        // Held or stopped: its journal keeps the rest.
        $('job-text').textContent = `${e.kind}: interrupted; Resume job continues it`;
        $('resume-job').disabled = false;
      } else {
        $('job-text').textContent = e.exit === 0 ? `${e.kind}: ended` : `${e.kind}: ${e.error || `exit ${e.exit}`}`;
        $('resume-job').disabled = false;
      }
      break;
    case 'job_start':
      if (page.jobKind !== 'resume') page.shown = 0;
      if (!page.wholeTicks || page.jobKind !== 'resume') page.wholeTicks = e.plan_ticks;
      showProgress(e.plan_ticks ? wholeFraction(e.plan_ticks, e.plan_ticks) : 0);
      $('progress-text').textContent = page.jobKind === 'resume'
        ? `resumed at ${percent(page.shown)}: ${seconds(e.duration_s)} of motion left`
        : `job ${e.job ?? ''}: ${seconds(e.duration_s)} of motion`;
      break;
    case 'progress': {
      const f = e.plan_ticks === null ? page.shown : showProgress(wholeFraction(e.plan_ticks - e.ticks, e.plan_ticks));
      const pen = page.device ? (page.device.pen_down ? 'pen down' : 'pen up') : '';
      $('progress-text').textContent =
        `${percent(f)}  ETA ${e.eta_s === null ? '?' : minutes(e.eta_s)}  queue ${e.queue_s.toFixed(2)} s (${e.queue_spans} spans) ${pen}`;
      const axes = Object.values(e.position_mm);
      view.marker = view.iso ? view.projectPosition(e.position_mm) : axes.slice(0, 2);
      // The preview's tick: the job's end is the preview's end (a lead-in or a move back
      // onto the drawing comes before the drawing's ticks).
      if (page.preview && page.preview === page.jobPreview && e.plan_ticks !== null) {
        view.doneTick = Math.max(0, page.preview.summary.ticks - (e.plan_ticks - e.ticks));
      }
      scheduleDraw();
      break;
    }
    case 'planning':
      // A long preview's progress (the server plans in a child it stops after --plan-timeout).
      $('drawing-name').textContent = `${e.file}: planning ${percent(e.fraction)}, about ${minutes(e.estimated_s)} of motion`;
      break;
    case 'pause':
      $('job-text').textContent = `paused for a pen change (${e.pause} of ${e.pauses}), next ${e.next}: press Resume`;
      break;
    case 'hold': case 'stop':
      $('job-text').textContent = `${e.event} requested`;
      break;
    case 'job_end':
      if (e.outcome === 'finished') {
        showProgress(1);
        $('progress-text').textContent = `100 %  finished: ${e.ticks} ticks in ${e.wall_s.toFixed(1)} s`;
        if (page.preview && page.preview === page.jobPreview) view.doneTick = Infinity;
      } else {
        const f = e.plan_ticks ? showProgress(wholeFraction(e.plan_ticks - e.ticks, e.plan_ticks)) : page.shown;
        $('progress-text').textContent = `${e.outcome}${e.error ? `: ${e.error}` : ''} at ${percent(f)}`;
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
  let origin = 'top-left';
  try { origin = localStorage.getItem('pathstream.origin') || origin; } catch { /* storage off */ }
  setOrigin(origin);
  $('margin').disabled = !$('fit').value;
  clearPreview();
  const s = await api('/api/state');
  if (s.ok) {
    $('machine-name').textContent = `${s.machine.file} → ${s.target}`;
    $('resume-job').disabled = !s.journal || s.job_running;
    page.jobRunning = s.job_running;
    page.drawing = s.drawing;
    // A page opened later (or reloaded) shows the drawing the server holds, as last planned:
    // the running job's, when one runs.
    if (s.drawing) {
      const p = await fetch('/api/preview').then(r => r.json()).catch(() => null);
      if (p && p.ok) {
        setOptions(p.options);
        showPreview(p);
        page.jobPreview = page.preview;
      } else {
        $('drawing-name').textContent = s.drawing;
        clearPreview();
      }
    }
  }
  const events = new EventSource('/api/events');
  events.onmessage = m => onEvent(JSON.parse(m.data));
  events.onerror = () => { $('device-state').dataset.state = 'offline'; $('device-state').textContent = 'server: reconnecting'; };
  document.body.dataset.ready = 'true';
}

start();
