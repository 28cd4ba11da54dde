/* linkwork viewers, shared part: data decoding, canvas sizing, number formatting and a small line plot. */
"use strict";

const LW = {};

/** The page's data: the JSON in <script id="linkwork-data">. */
LW.data = function () {
  return JSON.parse(document.getElementById("linkwork-data").textContent);
};

/** A typed array from {dtype, shape, b64} (little-endian, as written by linkwork.viz.viewer). */
LW.decode = function (entry) {
  const bin = atob(entry.b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  const Type = { f4: Float32Array, f8: Float64Array, i4: Int32Array, u2: Uint16Array, u4: Uint32Array }[entry.dtype];
  return new Type(bytes.buffer);
};

/** Size a canvas's backing store to its CSS box times the device pixel ratio; return [w, h] in CSS pixels. */
LW.fit = function (canvas) {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(10, canvas.clientWidth), h = Math.max(10, canvas.clientHeight);
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
  }
  const ctx = canvas.getContext("2d");
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  return [w, h];
};

LW.fmt = function (v, digits) {
  if (!isFinite(v)) return "–";
  return v.toFixed(digits === undefined ? 3 : digits);
};

LW.sci = function (v) {
  if (!isFinite(v)) return "–";
  if (v === 0) return "0";
  const a = Math.abs(v);
  return a >= 1e-3 && a < 1e4 ? v.toPrecision(4) : v.toExponential(2);
};

/** Round tick positions covering [lo, hi], about `count` of them. */
LW.ticks = function (lo, hi, count) {
  if (!(hi > lo)) return [lo];
  const raw = (hi - lo) / Math.max(1, count);
  const mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((s) => s >= raw) || 10 * mag;
  const out = [];
  for (let t = Math.ceil(lo / step) * step; t <= hi + step * 1e-9; t += step) out.push(Math.abs(t) < step * 1e-9 ? 0 : t);
  return out;
};

LW.SUPERSCRIPT = { "-": "⁻", 0: "⁰", 1: "¹", 2: "²", 3: "³", 4: "⁴", 5: "⁵", 6: "⁶", 7: "⁷", 8: "⁸", 9: "⁹" };
LW.decade = function (k) {
  return "10" + String(k).split("").map((c) => LW.SUPERSCRIPT[c]).join("");
};

LW.DASHES = [[], [7, 4], [2, 3], [8, 3, 2, 3]];

/** A line plot on a canvas: series over a shared x, optional log y, vertical markers and a cursor.
 *  Clicking or dragging on it calls onPick(index of the nearest x). */
LW.Plot = class {
  constructor(canvas, opts) {
    this.canvas = canvas;
    this.opts = Object.assign({ logy: false, xlabel: "", ylabel: "", floor: 1e-16 }, opts);
    this.x = new Float64Array(0);
    this.series = [];
    this.markers = [];
    this.cursor = -1;
    this.onPick = null;
    this.base = document.createElement("canvas");
    const pick = (ev) => {
      if (!this.onPick || this.x.length === 0 || !this.frame) return;
      const r = canvas.getBoundingClientRect();
      const px = ev.clientX - r.left;
      const xv = this.frame.ix(px);
      let best = 0, bestd = Infinity;
      for (let i = 0; i < this.x.length; i++) {
        const d = Math.abs(this.x[i] - xv);
        if (d < bestd) { bestd = d; best = i; }
      }
      this.onPick(best);
    };
    let down = false;
    canvas.addEventListener("pointerdown", (ev) => { down = true; canvas.setPointerCapture(ev.pointerId); pick(ev); });
    canvas.addEventListener("pointermove", (ev) => { if (down) pick(ev); });
    canvas.addEventListener("pointerup", () => { down = false; });
  }

  /** x: array; series: [{y: array, color, dash: index into LW.DASHES, width}]; markers: [{x, label}]. */
  set(x, series, markers) {
    this.x = x;
    this.series = series;
    this.markers = markers || [];
    this.drawBase();
    this.draw();
  }

  drawBase() {
    const [w, h] = LW.fit(this.canvas);
    const dpr = window.devicePixelRatio || 1;
    this.base.width = this.canvas.width;
    this.base.height = this.canvas.height;
    const ctx = this.base.getContext("2d");
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, w, h);
    const o = this.opts;
    const m = { l: 58, r: 12, t: 10, b: 38 };
    const x = this.x;
    let x0 = Infinity, x1 = -Infinity;
    for (let i = 0; i < x.length; i++) { x0 = Math.min(x0, x[i]); x1 = Math.max(x1, x[i]); }
    if (!isFinite(x0)) { x0 = 0; x1 = 1; }
    if (x1 === x0) { x0 -= 0.5; x1 += 0.5; }
    const ty = (v) => (o.logy ? Math.log10(Math.max(v, o.floor)) : v);
    let y0 = Infinity, y1 = -Infinity;
    for (const s of this.series) for (let i = 0; i < s.y.length; i++) {
      const v = ty(s.y[i]);
      if (isFinite(v)) { y0 = Math.min(y0, v); y1 = Math.max(y1, v); }
    }
    if (!isFinite(y0)) { y0 = 0; y1 = 1; }
    if (o.logy) { y0 = Math.floor(y0); y1 = Math.ceil(y1); if (y1 === y0) y1 += 1; }
    else { const pad = (y1 - y0) * 0.05 || 1; y0 -= pad; y1 += pad; }
    const pw = w - m.l - m.r, ph = h - m.t - m.b;
    const fx = (v) => m.l + ((v - x0) / (x1 - x0)) * pw;
    const fy = (v) => m.t + (1 - (ty(v) - y0) / (y1 - y0)) * ph;
    this.frame = { fx, fy, ix: (px) => x0 + ((px - m.l) / pw) * (x1 - x0), m, w, h };

    ctx.font = "11px system-ui, sans-serif";
    ctx.lineWidth = 1;
    // grid and ticks
    ctx.strokeStyle = "#e7ebef";
    ctx.fillStyle = "#5b6673";
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    const xt = o.xticks || LW.ticks(x0, x1, Math.max(2, Math.floor(pw / 80))).map((t) => ({ x: t, label: Math.abs(t) >= 1e4 ? t.toExponential(1) : String(+t.toFixed(6)) }));
    for (const t of xt) {
      const px = fx(t.x);
      ctx.beginPath(); ctx.moveTo(px, m.t); ctx.lineTo(px, m.t + ph); ctx.stroke();
      ctx.fillText(t.label, px, m.t + ph + 4);
    }
    ctx.textAlign = "right";
    ctx.textBaseline = "middle";
    if (o.logy) {
      const every = Math.max(1, Math.ceil((y1 - y0) / Math.max(2, Math.floor(ph / 28))));
      for (let k = y0; k <= y1; k++) {
        const py = m.t + (1 - (k - y0) / (y1 - y0)) * ph;
        ctx.strokeStyle = k % every === 0 ? "#e7ebef" : "#f3f5f7";
        ctx.beginPath(); ctx.moveTo(m.l, py); ctx.lineTo(m.l + pw, py); ctx.stroke();
        if (k % every === 0) ctx.fillText(LW.decade(k), m.l - 5, py);
      }
    } else {
      for (const t of LW.ticks(y0, y1, Math.max(2, Math.floor(ph / 36)))) {
        const py = fy(t);
        ctx.beginPath(); ctx.moveTo(m.l, py); ctx.lineTo(m.l + pw, py); ctx.stroke();
        ctx.fillText(String(+t.toFixed(6)), m.l - 5, py);
      }
    }
    ctx.strokeStyle = "#9aa5b1";
    ctx.strokeRect(m.l + 0.5, m.t + 0.5, pw, ph);
    // axis labels
    ctx.fillStyle = "#1d2733";
    ctx.font = "12px system-ui, sans-serif";
    ctx.textAlign = "center";
    ctx.textBaseline = "bottom";
    ctx.fillText(o.xlabel, m.l + pw / 2, h - 2);
    ctx.save();
    ctx.translate(13, m.t + ph / 2);
    ctx.rotate(-Math.PI / 2);
    ctx.textBaseline = "middle";
    ctx.fillText(o.ylabel, 0, 0);
    ctx.restore();
    // markers (bifurcation points)
    ctx.save();
    ctx.beginPath(); ctx.rect(m.l, m.t, pw, ph); ctx.clip();
    for (const mk of this.markers) {
      const px = fx(mk.x);
      ctx.strokeStyle = "#e08a00";
      ctx.setLineDash([4, 3]);
      ctx.lineWidth = 1.2;
      ctx.beginPath(); ctx.moveTo(px, m.t); ctx.lineTo(px, m.t + ph); ctx.stroke();
      ctx.setLineDash([]);
      ctx.fillStyle = "#e08a00";
      ctx.beginPath(); ctx.moveTo(px - 5, m.t); ctx.lineTo(px + 5, m.t); ctx.lineTo(px, m.t + 7); ctx.fill();
      ctx.fillStyle = "#9a5c00";
      ctx.font = "10.5px system-ui, sans-serif";
      ctx.textAlign = px > m.l + pw - 50 ? "right" : "left";
      ctx.textBaseline = "top";
      ctx.fillText(mk.label, px + (ctx.textAlign === "left" ? 4 : -4), m.t + 8);
    }
    // series
    for (const s of this.series) {
      ctx.strokeStyle = s.color;
      ctx.lineWidth = s.width || 1.6;
      ctx.setLineDash(LW.DASHES[(s.dash || 0) % LW.DASHES.length]);
      ctx.beginPath();
      let pen = false;
      for (let i = 0; i < x.length; i++) {
        const v = s.y[i];
        if (!isFinite(v) || (o.logy && !(v > 0) && o.floor <= 0)) { pen = false; continue; }
        const px = fx(x[i]), py = fy(v);
        if (pen) ctx.lineTo(px, py); else ctx.moveTo(px, py);
        pen = true;
      }
      ctx.stroke();
    }
    ctx.setLineDash([]);
    ctx.restore();
  }

  setCursor(i) {
    this.cursor = i;
    this.draw();
  }

  draw() {
    const ctx = this.canvas.getContext("2d");
    const dpr = window.devicePixelRatio || 1;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, this.canvas.width, this.canvas.height);
    ctx.drawImage(this.base, 0, 0);
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    const i = this.cursor;
    if (!this.frame || i < 0 || i >= this.x.length) return;
    const { fx, fy, m, h } = this.frame;
    const px = fx(this.x[i]);
    ctx.strokeStyle = "#c0392b";
    ctx.lineWidth = 1.5;
    ctx.beginPath(); ctx.moveTo(px, m.t); ctx.lineTo(px, h - m.b); ctx.stroke();
    for (const s of this.series) {
      const v = s.y[i];
      if (!isFinite(v)) continue;
      ctx.fillStyle = s.color;
      ctx.strokeStyle = "#fff";
      ctx.lineWidth = 1.5;
      ctx.beginPath(); ctx.arc(px, fy(v), 3.5, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
    }
  }
};

/** A table row of cells; each cell is text (set as textContent, never parsed as HTML) or a DOM node. The first
 * cell may start with a colour swatch {color, dash}. Returns the row's cells. */
LW.row = function (tbody, texts, swatch) {
  const tr = document.createElement("tr");
  texts.forEach((t, i) => {
    const td = document.createElement("td");
    if (i === 0 && swatch) {
      const sw = document.createElement("i");
      sw.className = "swatch" + (["", " dash", " dot", " dash"][(swatch.dash || 0) % 4]);
      sw.style.borderTopColor = swatch.color;
      td.appendChild(sw);
    }
    if (t instanceof Node) td.appendChild(t);
    else td.appendChild(document.createTextNode(String(t)));
    tr.appendChild(td);
  });
  tbody.appendChild(tr);
  return Array.from(tr.children);
};

/** Replace an element's content by a bold lead and plain text after it (both as text, never HTML). */
LW.lead = function (el, bold, rest) {
  el.textContent = "";
  const b = document.createElement("b");
  b.textContent = bold;
  el.appendChild(b);
  el.appendChild(document.createTextNode(rest));
};

/** Fill a legend element with [{label, color, dash}] items. */
LW.legend = function (el, items) {
  el.textContent = "";
  for (const it of items) {
    const span = document.createElement("span");
    const sw = document.createElement("i");
    sw.className = "swatch" + (["", " dash", " dot", " dash"][(it.dash || 0) % 4]);
    sw.style.borderTopColor = it.color;
    span.appendChild(sw);
    span.appendChild(document.createTextNode(it.label));
    el.appendChild(span);
  }
};
