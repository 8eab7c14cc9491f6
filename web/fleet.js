// The fleet page: polls the fleet server's view of the broker (GET /api/fleet) once a second,
// submits jobs (POST /api/submit) and sends one machine a command (POST /api/command). Every
// text from the broker goes into the page as text, never as HTML: anyone may publish there.
const $ = id => document.getElementById(id);
let selectedJob = null;
let lastView = null;

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k.startsWith('data-')) e.setAttribute(k, v);
    else e[k] = v;
  }
  for (const c of children) e.append(c);
  return e;
}

const percent = f => (f === null || f === undefined ? '' : `${Math.floor(f * 100)} %`);
const time = at => (at ? new Date(at * 1000).toLocaleTimeString() : '');

function machineRow(m) {
  const state = m.error ? 'fault' : (m.online ? (m.state || 'unknown') : 'offline');
  const tr = el('tr', { 'data-machine': m.name, 'data-online': String(m.online), 'data-state': state,
    'data-job': m.job || '' });
  const name = el('td', {}, el('div', { className: 'mono', textContent: m.name }),
    el('span', { className: 'badge', textContent: m.online ? 'online' : 'offline',
      'data-state': m.online ? 'idle' : 'offline' }));
  const st = el('td', {}, el('span', { className: 'badge', textContent: state, 'data-state': state }));
  if (m.error) st.append(el('div', { className: 'wrap muted', textContent: m.error }));
  const job = el('td', { className: 'mono' });
  if (m.job) {
    job.append(el('div', { className: 'wrap', textContent: `${m.job} ${percent(m.fraction)}` }));
    const bar = el('progress', { max: 1, value: m.fraction ?? 0 });
    job.append(bar);
  } else {
    job.append(el('span', { className: 'muted', textContent: '-' }));
  }
  tr.append(name, st, job);
  return tr;
}

function jobRow(j) {
  const tr = el('tr', { 'data-job': j.id, 'data-state': j.state });
  if (j.id === selectedJob) tr.classList.add('selected');
  tr.append(el('td', { className: 'mono wrap', textContent: j.id }),
    el('td', {}, el('span', { className: 'badge', textContent: j.state, 'data-state': j.state })),
    el('td', { className: 'mono wrap', textContent: j.machine || '-' }));
  tr.addEventListener('click', () => { selectedJob = j.id; render(lastView); });
  return tr;
}

function showHistory(jobs) {
  const box = $('history');
  const j = jobs.find(x => x.id === selectedJob);
  box.hidden = !j;
  if (!j) return;
  box.replaceChildren(el('div', { textContent: `${j.id}: ${j.file}${j.error ? ` (${j.error})` : ''}` }));
  const list = el('ol', { id: 'history-list' });
  for (const h of j.history) {
    list.append(el('li', { textContent: `${h.state}${h.machine ? ` on ${h.machine}` : ''} at ${time(h.at)}` }));
  }
  box.append(list);
}

// The select keeps what the user chose while its options are renewed.
function fillSelect(select, options) {
  const chosen = select.value;
  const same = select.options.length === options.length &&
    options.every(([v, t], i) => select.options[i].value === v && select.options[i].text === t);
  if (same) return;
  select.replaceChildren(...options.map(([v, t]) => el('option', { value: v, textContent: t })));
  if (options.some(([v]) => v === chosen)) select.value = chosen;
}

function render(view) {
  if (!view) return;
  lastView = view;
  $('machines').tBodies[0].replaceChildren(...view.machines.map(machineRow));
  $('no-machines').hidden = view.machines.length > 0;
  $('jobs').tBodies[0].replaceChildren(...view.jobs.map(jobRow));
  $('no-jobs').hidden = view.jobs.length > 0;
  showHistory(view.jobs);
  const online = view.machines.filter(m => m.online).length;
  $('counts').textContent = `${online} of ${view.machines.length} online, ${view.jobs_total ?? view.jobs.length} jobs` +
    (view.ignored ? `, ${view.ignored} malformed messages ignored` : '');
  const kinds = [...new Set(view.machines.map(m => m.kind).filter(Boolean))].sort();
  fillSelect($('target'), [['kind:any', 'any idle machine'],
    ...kinds.map(k => [`kind:${k}`, `any idle ${k}`]),
    ...view.machines.map(m => [`machine:${m.name}`, `${m.name}${m.online ? '' : ' (offline)'}`])]);
  fillSelect($('command-machine'), view.machines.map(m => [m.name, m.name]));
}

async function poll() {
  try {
    const res = await fetch('/api/fleet');
    if (!res.ok) throw new Error(`${res.status}`);
    const view = await res.json();
    $('broker').textContent = `broker ${view.broker}`;
    $('broker').dataset.state = 'idle';
    render(view);
  } catch (e) {
    $('broker').textContent = 'fleet server unreachable';
    $('broker').dataset.state = 'offline';
  }
  setTimeout(poll, 1000);
}

async function post(path, body) {
  const res = await fetch(path, { method: 'POST', headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify(body) });
  let answer = {};
  try { answer = await res.json(); } catch (e) { answer = { error: `HTTP ${res.status}` }; }
  return { status: res.status, answer };
}

$('submit-form').addEventListener('submit', async event => {
  event.preventDefault();
  const out = $('submit-result');
  const file = $('file').files[0];
  if (!file) return;
  out.className = 'wrap';
  out.textContent = `sending ${file.name} ...`;
  const [how, where] = $('target').value.split(/:(.*)/s);
  const body = { file: file.name, drawing: await file.text(), [how]: where };
  if ($('fit').value) {
    body.fit = $('fit').value;
    body.margin = Number($('margin').value || 0);
  }
  if ($('job-id').value) body.id = $('job-id').value;
  const { status, answer } = await post('/api/submit', body);
  if (status === 200) {
    out.textContent = `job ${answer.id} queued on ${answer.topic}`;
    out.dataset.id = answer.id;
    selectedJob = answer.id;
  } else {
    out.className = 'error';
    out.textContent = `${status}: ${answer.error}`;
  }
});

for (const b of document.querySelectorAll('.machine-controls button')) {
  b.addEventListener('click', async () => {
    const machine = $('command-machine').value;
    if (!machine) return;
    const out = $('command-result');
    out.textContent = `${b.dataset.verb} to ${machine} ...`;
    const { status, answer } = await post('/api/command', { machine, verb: b.dataset.verb });
    out.textContent = status === 200 ? `${machine}: ${b.dataset.verb} ok` : `${machine}: ${status} ${answer.error || ''}`;
  });
}

poll();
