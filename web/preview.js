// The preview canvas: the planned path to scale in the work area, pen-up travel dashed, the
// part already drawn in another colour, the drawing order cut at the scrubber, the live
// position marker. Vertices come from the server's preview (span end points of the plan).

const INK = '#1d3557', DONE = '#e76f51', TRAVEL = '#9aa5b1', AREA = '#ced4da';

export class PreviewView {
  constructor(canvas) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.base = document.createElement('canvas');
    this.base.width = canvas.width;
    this.base.height = canvas.height;
    this.baseCtx = this.base.getContext('2d');
    this.built = null;           // what the path layer shows: { last, done } vertex indexes
    this.preview = null;
    this.limitTick = Infinity;   // the scrubber: draw only up to this tick
    this.doneTick = -1;          // the job's progress on this plan
    this.marker = null;          // [x, y] mm
    this.rest = null;            // where the pen is before the job (the lead-in starts there)
  }

  // Keeps the arrays in typed form: a 10^5-vertex path redraws without allocation.
  setPreview(p) {
    const n = p.path.x.length;
    this.preview = {
      n,
      x: Float64Array.from(p.path.x),
      y: Float64Array.from(p.path.y),
      tick: Float64Array.from(p.path.tick),
      pen: Uint8Array.from(p.path.pen),
      area: p.work_area,
      ticks: p.summary.ticks,
    };
    this.rest = p.rest_mm && p.rest_mm.length >= 2 ? p.rest_mm : null;
    this.limitTick = Infinity;
    this.doneTick = -1;
    this.built = null;
    this.fitView();
  }

  fitView() {
    const p = this.preview;
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    const grow = (x, y) => { x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); };
    if (p.area) { grow(p.area.x_min, p.area.y_min); grow(p.area.x_max, p.area.y_max); }
    for (let i = 0; i < p.n; i++) grow(p.x[i], p.y[i]);
    if (!isFinite(x0)) { x0 = 0; y0 = 0; x1 = 1; y1 = 1; }
    const w = this.canvas.width, h = this.canvas.height, pad = 12;
    const scale = Math.min((w - 2 * pad) / Math.max(x1 - x0, 1e-6), (h - 2 * pad) / Math.max(y1 - y0, 1e-6));
    // Machine y grows downward from the top-left origin, as in the SVG the drawing came from.
    this.view = { scale, ox: pad - x0 * scale + ((w - 2 * pad) - (x1 - x0) * scale) / 2, oy: pad - y0 * scale };
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
  // accepts, as few subpaths as the runs allow.
  strokeWhere(ctx, first, last, wanted, style, width, dash) {
    const p = this.preview, { scale, ox, oy } = this.view;
    ctx.beginPath();
    let open = false;
    for (let i = Math.max(first, 1); i <= last; i++) {
      if (!wanted(i)) { open = false; continue; }
      if (!open) ctx.moveTo(ox + p.x[i - 1] * scale, oy + p.y[i - 1] * scale);
      ctx.lineTo(ox + p.x[i] * scale, oy + p.y[i] * scale);
      open = true;
    }
    ctx.setLineDash(dash);
    ctx.strokeStyle = style;
    ctx.lineWidth = width;
    ctx.stroke();
    ctx.setLineDash([]);
  }

  // The path layer, drawn whole: the work area, the lead-in, travel, strokes, the done part.
  // Kept on a canvas of its own so that a moving marker or a few more done segments cost
  // nothing like a full redraw. Returns the milliseconds it took, rasterizing included.
  rebuild(last, done) {
    const t0 = performance.now();
    const ctx = this.baseCtx, p = this.preview, { scale, ox, oy } = this.view;
    ctx.clearRect(0, 0, this.base.width, this.base.height);
    if (p.area) {
      ctx.strokeStyle = AREA;
      ctx.lineWidth = 1;
      ctx.strokeRect(ox + p.area.x_min * scale, oy + p.area.y_min * scale,
                     (p.area.x_max - p.area.x_min) * scale, (p.area.y_max - p.area.y_min) * scale);
    }
    if (this.rest && p.n > 0) {
      ctx.beginPath();
      ctx.moveTo(ox + this.rest[0] * scale, oy + this.rest[1] * scale);
      ctx.lineTo(ox + p.x[0] * scale, oy + p.y[0] * scale);
      ctx.setLineDash([2, 4]);
      ctx.strokeStyle = TRAVEL;
      ctx.lineWidth = 0.8;
      ctx.stroke();
      ctx.setLineDash([]);
    }
    const pen = p.pen;
    this.strokeWhere(ctx, 1, last, i => pen[i] === 0, TRAVEL, 0.8, [4, 3]);
    this.strokeWhere(ctx, 1, last, i => pen[i] === 1 && i > done, INK, 1.2, []);
    this.strokeWhere(ctx, 1, Math.min(last, done), i => pen[i] === 1, DONE, 1.6, []);
    // Reading a pixel back makes the canvas finish rasterizing now, so the time measured is
    // the whole draw, not only the queuing of the path commands.
    ctx.getImageData(0, 0, 1, 1);
    this.built = { last, done };
    return performance.now() - t0;
  }

  // Shows the current state; returns the milliseconds of a full redraw of the path, or 0 when
  // the path layer could be kept (only the done part grew, or only the marker moved).
  draw() {
    const { ctx, canvas } = this;
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    const p = this.preview;
    if (!p) return 0;
    const last = this.limitTick === Infinity ? p.n - 1 : this.vertexAt(this.limitTick);
    const done = Math.min(this.vertexAt(this.doneTick), p.n - 1);
    let ms = 0;
    if (!this.built || this.built.last !== last || done < this.built.done) {
      ms = this.rebuild(last, done);
    } else if (done > this.built.done) {
      this.strokeWhere(this.baseCtx, this.built.done + 1, Math.min(last, done), i => p.pen[i] === 1, DONE, 1.6, []);
      this.built.done = done;
    }
    ctx.drawImage(this.base, 0, 0);
    if (last >= 0 && last < p.n - 1) this.dot(p.x[last], p.y[last], '#2a9d8f', 4);
    if (this.marker) this.dot(this.marker[0], this.marker[1], '#d62828', 5);
    return ms;
  }

  dot(x, y, colour, r) {
    const { ctx } = this, { scale, ox, oy } = this.view;
    ctx.beginPath();
    ctx.arc(ox + x * scale, oy + y * scale, r, 0, 2 * Math.PI);
    ctx.fillStyle = colour;
    ctx.fill();
  }
}

// The speed plot: the fastest planned speed per time bin, and a line at time `at` (s).
export function drawSpeed(canvas, speed, at) {
  const ctx = canvas.getContext('2d');
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  if (!speed || speed.t.length === 0) return;
  const w = canvas.width, h = canvas.height, pad = 24;
  const tMax = speed.t[speed.t.length - 1] || 1;
  const vMax = Math.max(...speed.v, 1e-9);
  ctx.strokeStyle = INK;
  ctx.lineWidth = 1;
  ctx.beginPath();
  speed.t.forEach((t, i) => {
    const x = pad + (t / tMax) * (w - 2 * pad), y = h - pad - (speed.v[i] / vMax) * (h - 2 * pad);
    if (i === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y);
  });
  ctx.stroke();
  ctx.fillStyle = '#555';
  ctx.font = '11px sans-serif';
  ctx.fillText(`${vMax.toFixed(0)} mm/s`, 2, pad - 8);
  ctx.fillText(`${tMax.toFixed(1)} s`, w - pad - 30, h - 6);
  if (at !== null && at !== undefined) {
    const x = pad + Math.min(at / tMax, 1) * (w - 2 * pad);
    ctx.strokeStyle = DONE;
    ctx.beginPath();
    ctx.moveTo(x, pad);
    ctx.lineTo(x, h - pad);
    ctx.stroke();
  }
}
