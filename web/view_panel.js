// The View panel: the view of a JSON drawing with surfaces (docs/formats-surfaces.md) as
// controls. The panel only edits the view; app.js puts it in the document and uploads it.

// The reader's defaults for a view, or for a missing key of one.
const DEFAULTS = { projection: 'orthographic', azimuth: -30, elevation: 25, roll: 0, hidden_lines: 'draw' };
const ANGLES = ['azimuth', 'elevation', 'roll'];

// The drawing's document when it is a JSON file with surfaces or a view; otherwise null (the
// server reads every other file, and reports its errors, as before).
export function surfaceDocument(name, text) {
  if (!/\.json$/i.test(name)) return null;
  let doc;
  try { doc = JSON.parse(text); } catch { return null; }
  const object = doc !== null && typeof doc === 'object' && !Array.isArray(doc);
  return object && ('surfaces' in doc || 'view' in doc) ? doc : null;
}

// The largest distance from the origin of any point of the model (arrays of 2 or 3 numbers:
// vertices, control points, profile points, axes; a profile's [radius, height] counts as a
// point). Cheap, and enough to put a perspective eye safely outside the model.
export function modelExtent(doc) {
  let extent = 0;
  const walk = value => {
    if (!value || typeof value !== 'object') return;
    if (Array.isArray(value) && (value.length === 2 || value.length === 3) && value.every(Number.isFinite)) {
      extent = Math.max(extent, Math.hypot(...value));
      return;
    }
    for (const v of Object.values(value)) walk(v);
  };
  walk([doc.surfaces, doc.points, doc.subpaths]);
  return extent;
}

// A distance rounded up to two significant digits: a default a person can read and retype.
function roundUp(x) {
  const unit = 10 ** (Math.floor(Math.log10(x)) - 1);
  return Math.ceil(x / unit) * unit;
}

// Angles the reader takes (−360..360) shown in the sliders' range: the same view.
function wrapDegrees(a) {
  return a > 180 ? a - 360 : (a < -180 ? a + 360 : a);
}

export class ViewPanel {
  // `root` holds the controls (index.html's #surface-view); `onChange` is called on every edit.
  constructor(root, onChange) {
    this.root = root;
    this.onChange = onChange;
    this.extent = 0;
    const $ = id => root.querySelector(`#${id}`);
    this.el = {
      projection: $('projection'), eye: $('eye-distance'), eyeRow: $('eye-row'),
      hidden: $('hidden-lines'), note: $('view-text'),
    };
    for (const a of ANGLES) {
      const range = $(a), number = $(`${a}-deg`);
      this.el[a] = number;
      // The slider and its number show one value; the number is the one read (it keeps decimals).
      range.addEventListener('input', () => { number.value = range.value; this.onChange(); });
      number.addEventListener('input', () => {
        if (!Number.isFinite(number.valueAsNumber)) return;  // half typed ("-"): wait
        range.value = String(number.valueAsNumber);
        this.onChange();
      });
    }
    this.el.projection.addEventListener('change', () => { this.showEye(); this.onChange(); });
    this.el.eye.addEventListener('input', () => {
      this.el.note.textContent = '';  // the default's note no longer describes the value
      if (Number.isFinite(this.el.eye.valueAsNumber)) this.onChange();
    });
    this.el.hidden.addEventListener('change', () => this.onChange());
  }

  // Shows the panel with the document's view (the reader's defaults where it has none).
  show(doc) {
    const v = { ...DEFAULTS, ...(doc.view && typeof doc.view === 'object' ? doc.view : {}) };
    this.extent = modelExtent(doc);
    for (const a of ANGLES) this.setAngle(a, Number(v[a]));
    this.el.projection.value = v.projection === 'perspective' ? 'perspective' : 'orthographic';
    this.el.eye.value = Number.isFinite(v.eye_distance) ? String(v.eye_distance) : '';
    this.el.hidden.checked = v.hidden_lines === 'remove';
    this.el.note.textContent = '';
    this.showEye();
    this.root.hidden = false;
  }

  hide() {
    this.root.hidden = true;
  }

  setAngle(name, degrees) {
    const a = Number.isFinite(degrees) ? degrees : DEFAULTS[name];
    const shown = name === 'elevation' ? a : wrapDegrees(a);
    this.el[name].value = String(shown);
    this.root.querySelector(`#${name}`).value = String(shown);
  }

  // The eye distance matters under perspective only. A perspective view needs one: without
  // one in the file, 3 x the model's extent (the eye well outside the model); without an
  // extent, the field asks for it (the server's message says the same if it stays empty).
  showEye() {
    const perspective = this.el.projection.value === 'perspective';
    this.el.eyeRow.hidden = !perspective;
    this.el.note.textContent = '';
    if (!perspective || this.el.eye.value !== '') return;
    if (this.extent > 0) {
      this.el.eye.value = String(roundUp(3 * this.extent));
      this.el.note.textContent = `eye distance: 3 × the model's extent (${roundUp(this.extent)} units)`;
    } else {
      this.el.note.textContent = 'perspective: type the eye\'s distance from the origin, in model units';
      this.el.eye.focus();
    }
  }

  // The document's view as the controls say, keeping its other keys (scale).
  view(old) {
    const v = { ...(old && typeof old === 'object' ? old : {}) };
    v.projection = this.el.projection.value;
    for (const a of ANGLES) {
      const n = this.el[a].valueAsNumber;
      v[a] = Number.isFinite(n) ? n : Number(this.root.querySelector(`#${a}`).value);  // a cleared field: the slider's
    }
    v.hidden_lines = this.el.hidden.checked ? 'remove' : 'draw';
    delete v.eye_distance;
    if (v.projection === 'perspective' && Number.isFinite(this.el.eye.valueAsNumber)) v.eye_distance = this.el.eye.valueAsNumber;
    return v;
  }
}
