// The preview canvas: the planned path to scale on the paper and in the work area, each layer
// in its own colour, pen-up travel dashed, the part already drawn in full colour over the
// rest (faded while a job runs), the drawing order cut at the scrubber, the live position
// marker. Vertices come from the server's preview (span end points of the plan).
// y points the way the machine's does: down from a top-left origin, or up from a bottom-left
// one (`yUp`), so the jog pad's arrows and the pen's marker move the same way on screen.
// A machine with x, y and z axes (a router: the preview has `view` and path.z) is shown in
// the isometric view instead, the one path.svg of `pathstream sim --plot` draws: x to the
// lower right, y to the upper right, z up; its work volume as a box.

const TRAVEL = '#9aa5b1';
const BACKGROUND = '#dee2e6', AREA_FILL = '#f8f9fa', AREA_EDGE = '#adb5bd';
const PAPER_FILL = '#ffffff', PAPER_EDGE = '#6c757d', MARGIN_EDGE = '#ced4da';
const MARKER = '#d62828', CUT = '#2a9d8f', LABEL = '#495057';

// Layer colours: a layer named by a colour ("#ff0000", as Inkscape's stroke-colour layers
// are) keeps it unless it is too pale to see on white paper; the others take the first
// colours of this list that no layer has yet. Chosen at least 70 apart in RGB from each
// other and from the travel's grey, the outlines, the paper and the marker's red.
const PALETTE = ['#1d3557', '#2a9d8f', '#f4a261', '#b5179e', '#0096c7', '#7f5539', '#f77f00', '#4cc9f0', '#9d0208',
  '#3a86ff', '#2b9348', '#8338ec'];

// The isometric view of a point, mm: [right, up] = [(x + y) cos 30°, z + (y - x) / 2]
// (host/include/pathstream/host/isometric.hpp; a mm along any axis is a mm on the view).
const COS30 = 0.8660254037844386;
export function isometric(x, y, z) {
  return [(x + y) * COS30, z + (y - x) * 0.5];
}

// The box's eight corners, corner k taking each axis's max where its bit (x 1, y 2, z 4) is set.
function boxCorners(b) {
  return [0, 1, 2, 3, 4, 5, 6, 7].map(k => [k & 1 ? b.x_max : b.x_min, k & 2 ? b.y_max : b.y_min, k & 4 ? b.z_max : b.z_min]);
}

function luminance(hex) {
  const n = parseInt(hex.slice(1), 16);
  return (0.2126 * ((n >> 16) & 255) + 0.7152 * ((n >> 8) & 255) + 0.0722 * (n & 255)) / 255;
}

// One colour per layer, in the order of summary.layers (every layer of the drawing).
export function layerColours(layers) {
  const own = layers.map(l => (/^#[0-9a-f]{6}$/i.test(l.name) && luminance(l.name) < 0.8 ? l.name.toLowerCase() : null));
  const used = new Set(own.filter(Boolean));
  const free = PALETTE.filter(c => !used.has(c));
  let next = 0;
  return own.map(c => c || free[next++ % free.length]);
}

export class PreviewView {
  constructor(canvas) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.base = document.createElement('canvas');
    this.baseCtx = this.base.getContext('2d');
    this.dpr = 1;
    this.built = null;           // what the path layer shows: { last, done } vertex indexes
    this.preview = null;
    this.colours = [];           // per layer index
    this.yUp = false;
    this.limitTick = Infinity;   // the scrubber: draw only up to this tick
    this.doneTick = -1;          // the job's progress on this plan; -1: no job on it
    this.marker = null;          // [x, y] mm
    this.rest = null;            // where the pen is before the job (the lead-in starts there)
    this.iso = null;             // the preview's `view` when it is the 3-D (isometric) one
  }

  // Keeps the arrays in typed form: a 10^5-vertex path redraws without allocation. null: no
  // preview (the canvas is cleared).
  setPreview(p, colours) {
    this.built = null;
    this.limitTick = Infinity;
    this.doneTick = -1;
    if (!p) {
      this.preview = null;
      this.iso = null;
      return;
    }
    const n = p.path.x.length;
    // In 3-D the view's x and y are the isometric view's right and up, mm: all that draws
    // below works on them as on a plotter's x and y.
    const iso = p.view && p.view.projection === 'isometric' && Array.isArray(p.path.z) ? p.view : null;
    const x = Float64Array.from(p.path.x), y = Float64Array.from(p.path.y);
    if (iso) {
      for (let i = 0; i < n; i++) [x[i], y[i]] = isometric(p.path.x[i], p.path.y[i], p.path.z[i]);
    }
    this.iso = iso;
    this.preview = {
      n,
      x,
      y,
      tick: Float64Array.from(p.path.tick),
      pen: Uint8Array.from(p.path.pen),
      layer: Uint16Array.from(p.path.layer || new Array(n).fill(0)),
      layers: Math.max(1, p.summary.layers.length),
      area: p.work_area,
      paper: p.paper,
      ticks: p.summary.ticks,
    };
    this.colours = colours.length ? colours : [PALETTE[0]];
    this.rest = p.rest_mm && p.rest_mm.length >= 2 ? p.rest_mm : null;
    if (this.rest && iso) {
      const [ax, ay, az] = iso.axes;
      this.rest = p.rest_mm.length > Math.max(ax, ay, az) ? isometric(p.rest_mm[ax], p.rest_mm[ay], p.rest_mm[az]) : null;
    }
    this.canvas.dataset.view = iso ? 'isometric' : 'plan';
    this.fitView();
  }

  // The 3-D view's marker for a device position by axis name ({x: .., y: .., z: ..}): its
  // projection; null without all three (a plotter's marker is its first two axes).
  projectPosition(position) {
    if (!this.iso || !position || ![position.x, position.y, position.z].every(Number.isFinite)) return null;
    return isometric(position.x, position.y, position.z);
  }

  setYUp(up) {
    this.yUp = up;
    this.built = null;
    if (this.preview) this.fitView();
  }

  // What the view must show, mm: the work area, the paper, the path.
  bounds() {
    const p = this.preview;
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    const grow = (x, y) => { x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); };
    if (p && this.iso) {
      if (this.iso.box) for (const c of boxCorners(this.iso.box)) grow(...isometric(...c));
      for (let i = 0; i < p.n; i++) grow(p.x[i], p.y[i]);
    } else if (p) {
      if (p.area) { grow(p.area.x_min, p.area.y_min); grow(p.area.x_max, p.area.y_max); }
      if (p.paper) { grow(p.paper.x_min, p.paper.y_min); grow(p.paper.x_max, p.paper.y_max); }
      for (let i = 0; i < p.n; i++) grow(p.x[i], p.y[i]);
    }
    if (!isFinite(x0)) { x0 = 0; y0 = 0; x1 = 1; y1 = 1; }
    return { x0, y0, x1, y1 };
  }

  // Height over width of what is shown (the page sizes the canvas by it).
  aspect() {
    const b = this.bounds();
    return Math.max(b.y1 - b.y0, 1e-6) / Math.max(b.x1 - b.x0, 1e-6);
  }

  // The canvas's size on the page, CSS pixels; its pixels follow the device's pixel ratio.
  resize(width, height, dpr) {
    const w = Math.max(1, Math.round(width * dpr)), h = Math.max(1, Math.round(height * dpr));
    this.canvas.style.width = `${width}px`;
    this.canvas.style.height = `${height}px`;
    if (this.canvas.width === w && this.canvas.height === h && this.dpr === dpr) return;
    this.dpr = dpr;
    this.canvas.width = this.base.width = w;
    this.canvas.height = this.base.height = h;
    this.built = null;
    if (this.preview) this.fitView();
  }

  // Screen (device pixel) = o + mm * s per axis; y's scale is negative when y points up.
  fitView() {
    const { x0, y0, x1, y1 } = this.bounds();
    const w = this.canvas.width, h = this.canvas.height, pad = 18 * this.dpr;
    const scale = Math.min((w - 2 * pad) / Math.max(x1 - x0, 1e-6), (h - 2 * pad) / Math.max(y1 - y0, 1e-6));
    const left = (w - (x1 - x0) * scale) / 2, top = (h - (y1 - y0) * scale) / 2;
    // The isometric view's up is up, whichever corner a plotter's origin would be in.
    this.view = this.yUp || this.iso
      ? { sx: scale, sy: -scale, ox: left - x0 * scale, oy: top + y1 * scale }
      : { sx: scale, sy: scale, ox: left - x0 * scale, oy: top - y0 * scale };
  }

  // A point in mm on the canvas, CSS pixels from its top-left corner.
  toCss(x, y) {
    const { sx, sy, ox, oy } = this.view;
    return [(ox + x * sx) / this.dpr, (oy + y * sy) / this.dpr];
  }

  // The last vertex whose tick is <= t (binary search), -1 before the first.
  vertexAt(t) {
    const tick = this.preview.tick;
    let lo = 0, hi = this.preview.n - 1;
    if (hi < 0 || t < tick[0]) return -1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (tick[mid] <= t) lo = mid; else hi = mid - 1;
    }
    return lo;
  }

  // One stroke of every segment i (vertex i-1 to i, first <= i <= last) that `wanted(i)`
  // accepts, as few subpaths as the runs allow. Widths in CSS pixels.
  strokeWhere(ctx, first, last, wanted, style, width, dash, alpha = 1) {
    const p = this.preview, { sx, sy, ox, oy } = this.view;
    ctx.beginPath();
    let open = false;
    for (let i = Math.max(first, 1); i <= last; i++) {
      if (!wanted(i)) { open = false; continue; }
      if (!open) ctx.moveTo(ox + p.x[i - 1] * sx, oy + p.y[i - 1] * sy);
      ctx.lineTo(ox + p.x[i] * sx, oy + p.y[i] * sy);
      open = true;
    }
    ctx.setLineDash(dash.map(d => d * this.dpr));
    ctx.strokeStyle = style;
    ctx.lineWidth = width * this.dpr;
    ctx.lineJoin = 'round';
    ctx.globalAlpha = alpha;
    ctx.stroke();
    ctx.globalAlpha = 1;
    ctx.setLineDash([]);
  }

  // A box in mm, its edges on whole device pixels so that a 1 px outline is crisp.
  rect(b) {
    const { sx, sy, ox, oy } = this.view;
    const xa = Math.round(ox + b.x_min * sx), xb = Math.round(ox + b.x_max * sx);
    const ya = Math.round(oy + b.y_min * sy), yb = Math.round(oy + b.y_max * sy);
    return { left: Math.min(xa, xb), top: Math.min(ya, yb), right: Math.max(xa, xb), bottom: Math.max(ya, yb) };
  }

  outline(ctx, r, fill, edge, width, dash) {
    if (fill) {
      ctx.fillStyle = fill;
      ctx.fillRect(r.left, r.top, r.right - r.left, r.bottom - r.top);
    }
    const half = (width * this.dpr) / 2;
    ctx.setLineDash(dash.map(d => d * this.dpr));
    ctx.strokeStyle = edge;
    ctx.lineWidth = width * this.dpr;
    ctx.strokeRect(r.left + half, r.top + half, r.right - r.left - 2 * half, r.bottom - r.top - 2 * half);
    ctx.setLineDash([]);
  }

  label(ctx, text, x, y) {
    ctx.fillStyle = LABEL;
    ctx.font = `${11 * this.dpr}px system-ui, sans-serif`;
    ctx.textBaseline = 'bottom';
    ctx.fillText(text, x, y);
  }

  // The path layer, drawn whole: the work area, the paper, the lead-in, travel, strokes, the
  // done part. Kept on a canvas of its own so that a moving marker or a few more done
  // segments cost nothing like a full redraw. Returns the milliseconds it took, rasterizing
  // included.
  rebuild(last, done) {
    const t0 = performance.now();
    const ctx = this.baseCtx, p = this.preview, { sx, sy, ox, oy } = this.view;
    const size = (b) => `${+(b.x_max - b.x_min).toFixed(1)} × ${+(b.y_max - b.y_min).toFixed(1)} mm`;
    ctx.fillStyle = BACKGROUND;
    ctx.fillRect(0, 0, this.base.width, this.base.height);
    const marks = {};
    if (this.iso) {
      marks.area = this.volume(ctx);
    } else if (p.area) {
      const r = this.rect(p.area);
      this.outline(ctx, r, AREA_FILL, AREA_EDGE, 1, []);
      this.label(ctx, `work area ${size(p.area)}`, r.left + 3 * this.dpr, r.top - 2 * this.dpr);
      marks.area = r;
    }
    if (p.paper && !this.iso) {
      const r = this.rect(p.paper);
      this.outline(ctx, r, PAPER_FILL, PAPER_EDGE, 1, []);
      const m = p.paper.margin_mm || 0;
      if (m > 0) {
        const inner = { x_min: p.paper.x_min + m, y_min: p.paper.y_min + m, x_max: p.paper.x_max - m, y_max: p.paper.y_max - m };
        if (inner.x_max > inner.x_min && inner.y_max > inner.y_min) this.outline(ctx, this.rect(inner), null, MARGIN_EDGE, 1, [3, 3]);
      }
      this.label(ctx, `${p.paper.name.toUpperCase().replace('-LANDSCAPE', ' landscape')} ${size(p.paper)}`,
        r.left + 3 * this.dpr, r.bottom + 13 * this.dpr);
      marks.paper = r;
    }
    // Where the outlines are, CSS pixels (left, top, right, bottom): for the page's tests. In
    // 3-D `area` is the box around the work volume's view.
    const css = r => r ? [r.left, r.top, r.right, r.bottom].map(v => +(v / this.dpr).toFixed(1)).join(',') : '';
    this.canvas.dataset.area = css(marks.area);
    this.canvas.dataset.paper = css(marks.paper);
    if (this.rest && p.n > 0) {
      ctx.beginPath();
      ctx.moveTo(ox + this.rest[0] * sx, oy + this.rest[1] * sy);
      ctx.lineTo(ox + p.x[0] * sx, oy + p.y[0] * sy);
      ctx.setLineDash([2 * this.dpr, 4 * this.dpr]);
      ctx.strokeStyle = TRAVEL;
      ctx.lineWidth = 0.8 * this.dpr;
      ctx.stroke();
      ctx.setLineDash([]);
    }
    const pen = p.pen, layer = p.layer, running = this.doneTick >= 0;
    this.strokeWhere(ctx, 1, last, i => pen[i] === 0, TRAVEL, 0.8, [4, 3]);
    for (let l = 0; l < p.layers; l++) {
      const colour = this.colours[l % this.colours.length];
      this.strokeWhere(ctx, 1, last, i => pen[i] === 1 && layer[i] === l && i > done, colour, 1.4, [], running ? 0.3 : 1);
      this.strokeWhere(ctx, 1, Math.min(last, done), i => pen[i] === 1 && layer[i] === l, colour, 1.8, []);
    }
    // Reading a pixel back makes the canvas finish rasterizing now, so the time measured is
    // the whole draw, not only the queuing of the path commands.
    ctx.getImageData(0, 0, 1, 1);
    this.built = { last, done, running };
    return performance.now() - t0;
  }

  // The 3-D view's frame: the work volume's edges (when every axis has a travel) and, in the
  // lower left corner, arrows along +x, +y, +z (their directions on the view, 36 px long).
  // Returns the volume's bounding box on the canvas (device px), or undefined without one.
  volume(ctx) {
    const { sx, sy, ox, oy } = this.view, dpr = this.dpr, b = this.iso.box;
    ctx.lineWidth = dpr;
    let box;
    if (b) {
      const corners = boxCorners(b).map(c => isometric(...c)).map(([u, v]) => [ox + u * sx, oy + v * sy]);
      ctx.beginPath();
      for (let k = 0; k < 8; k++) {
        for (const bit of [1, 2, 4]) {
          if (k & bit) continue;
          ctx.moveTo(...corners[k]);
          ctx.lineTo(...corners[k | bit]);
        }
      }
      ctx.strokeStyle = AREA_EDGE;
      ctx.stroke();
      const xs = corners.map(c => c[0]), ys = corners.map(c => c[1]);
      box = { left: Math.min(...xs), top: Math.min(...ys), right: Math.max(...xs), bottom: Math.max(...ys) };
      const top = corners.reduce((a, c) => (c[1] < a[1] ? c : a));
      this.label(ctx, `work volume ${+(b.x_max - b.x_min).toFixed(1)} × ${+(b.y_max - b.y_min).toFixed(1)} × ${+(b.z_max - b.z_min).toFixed(1)} mm`,
        top[0] - 60 * dpr, top[1] - 3 * dpr);
    }
    const o = [14 * dpr, this.base.height - 30 * dpr];
    ctx.font = `${11 * dpr}px system-ui, sans-serif`;
    ctx.textBaseline = 'middle';
    [['x', 1, 0, 0], ['y', 0, 1, 0], ['z', 0, 0, 1]].forEach(([name, ...e]) => {
      const [u, v] = isometric(...e);
      const tip = [o[0] + 36 * dpr * u, o[1] - 36 * dpr * v];
      ctx.beginPath();
      ctx.moveTo(...o);
      ctx.lineTo(...tip);
      ctx.strokeStyle = LABEL;
      ctx.stroke();
      ctx.fillStyle = LABEL;
      ctx.fillText(name, tip[0] + 6 * dpr * u - 3 * dpr, tip[1] - 8 * dpr * v);
    });
    return box;
  }

  // Shows the current state; returns the milliseconds of a full redraw of the path, or 0 when
  // the path layer could be kept (only the done part grew, or only the marker moved).
  draw() {
    const { ctx, canvas } = this;
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    const p = this.preview;
    if (!p) {
      delete canvas.dataset.marker;
      canvas.dataset.paper = '';
      canvas.dataset.area = '';
      return 0;
    }
    const last = this.limitTick === Infinity ? p.n - 1 : this.vertexAt(this.limitTick);
    const done = Math.min(this.vertexAt(this.doneTick), p.n - 1);
    const running = this.doneTick >= 0;
    let ms = 0;
    if (!this.built || this.built.last !== last || done < this.built.done || this.built.running !== running) {
      ms = this.rebuild(last, done);
    } else if (done > this.built.done) {
      for (let l = 0; l < p.layers; l++) {
        this.strokeWhere(this.baseCtx, this.built.done + 1, Math.min(last, done), i => p.pen[i] === 1 && p.layer[i] === l,
          this.colours[l % this.colours.length], 1.8, []);
      }
      this.built.done = done;
    }
    ctx.drawImage(this.base, 0, 0);
    if (last >= 0 && last < p.n - 1) this.dot(p.x[last], p.y[last], CUT, 4, null);
    if (this.marker) {
      this.dot(this.marker[0], this.marker[1], MARKER, 5, '#ffffff');
      const [mx, my] = this.toCss(this.marker[0], this.marker[1]);
      canvas.dataset.marker = `${mx.toFixed(1)},${my.toFixed(1)}`;
    } else {
      delete canvas.dataset.marker;
    }
    return ms;
  }

  dot(x, y, colour, r, ring) {
    const { ctx } = this, { sx, sy, ox, oy } = this.view;
    ctx.beginPath();
    ctx.arc(ox + x * sx, oy + y * sy, r * this.dpr, 0, 2 * Math.PI);
    ctx.fillStyle = colour;
    ctx.fill();
    if (ring) {
      ctx.strokeStyle = ring;
      ctx.lineWidth = 1.5 * this.dpr;
      ctx.stroke();
    }
  }
}

// The speed plot: the fastest planned speed per time bin, and a line at time `at` (s). Sized
// to its box on the page (CSS pixels times the device's pixel ratio).
export function drawSpeed(canvas, speed, at) {
  const dpr = window.devicePixelRatio || 1;
  const cssW = canvas.clientWidth || 300, cssH = canvas.clientHeight || 100;
  if (canvas.width !== Math.round(cssW * dpr) || canvas.height !== Math.round(cssH * dpr)) {
    canvas.width = Math.round(cssW * dpr);
    canvas.height = Math.round(cssH * dpr);
  }
  const ctx = canvas.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, cssW, cssH);
  if (!speed || speed.t.length === 0) return;
  const w = cssW, h = cssH, pad = 22;
  const tMax = speed.t[speed.t.length - 1] || 1;
  const vMax = Math.max(...speed.v, 1e-9);
  ctx.strokeStyle = PALETTE[0];
  ctx.lineWidth = 1;
  ctx.beginPath();
  speed.t.forEach((t, i) => {
    const x = pad + (t / tMax) * (w - 2 * pad), y = h - pad - (speed.v[i] / vMax) * (h - 2 * pad);
    if (i === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y);
  });
  ctx.stroke();
  ctx.fillStyle = '#555';
  ctx.font = '11px sans-serif';
  ctx.textBaseline = 'alphabetic';
  ctx.fillText(`${vMax.toFixed(0)} mm/s`, 2, pad - 8);
  ctx.fillText(`${tMax.toFixed(1)} s`, w - pad - 30, h - 6);
  if (at !== null && at !== undefined) {
    const x = pad + Math.min(at / tMax, 1) * (w - 2 * pad);
    ctx.strokeStyle = MARKER;
    ctx.beginPath();
    ctx.moveTo(x, pad);
    ctx.lineTo(x, h - pad);
    ctx.stroke();
  }
}
