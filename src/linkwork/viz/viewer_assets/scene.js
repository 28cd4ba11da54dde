/* linkwork trace viewer: a small 3-D renderer on a 2-D canvas.
 * Flat-shaded triangles sorted back to front (painter's algorithm), a perspective camera orbiting a target
 * (z up), a floor grid, joint labels and an axis triad. Each part is a mesh fixed to one body; a frame gives
 * every body's pose as 12 numbers (rotation rows, then translation). */
"use strict";

LW.Scene = class {
  constructor(canvas, data) {
    this.canvas = canvas;
    this.allBounds = data.bounds;
    this.bounds = data.bounds.centred;
    this.joints = data.joints;
    this.planar = data.planar;
    this.showLabels = true;
    this.onChange = null;
    this.overlays = data.overlays || []; // fixed polylines (e.g. target profiles), drawn in the fixed view
    this.mode = "centred";
    this.parts = data.parts.map((p) => {
      const c = parseInt(p.color.slice(1), 16);
      return {
        body: p.body,
        v: LW.decode(p.vertices),
        f: LW.decode(p.faces),
        rgb: [(c >> 16) & 255, (c >> 8) & 255, c & 255],
      };
    });
    let tris = 0, verts = 0;
    for (const p of this.parts) { tris += p.f.length / 3; verts = Math.max(verts, p.v.length); }
    this.cam = new Float64Array(verts);
    this.depth = new Float64Array(tris);
    this.shade = new Float32Array(tris);
    this.pts = new Float32Array(tris * 6);
    this.tpart = new Uint16Array(tris);
    this.order = new Uint32Array(tris);
    this.resetView("iso");
    this.interact();
  }

  /** "centred": the view follows the linkage's centre; "fixed": one body stays still. */
  setMode(mode) {
    this.mode = mode;
    this.bounds = this.allBounds[mode];
    this.resetView(this.lastView || "iso");
  }

  resetView(kind) {
    this.lastView = kind;
    const r = this.bounds.radius;
    this.target = this.bounds.center.slice();
    this.dist = 3.2 * r;
    if (kind === "top" || (kind === "iso" && this.planar)) { this.yaw = -Math.PI / 2; this.pitch = Math.PI / 2 - 1e-3; }
    else if (kind === "front") { this.yaw = -Math.PI / 2; this.pitch = 0; }
    else { this.yaw = -Math.PI / 3; this.pitch = 0.45; }
    this.changed();
  }

  changed() {
    if (this.onChange) this.onChange();
  }

  interact() {
    const c = this.canvas;
    let drag = null;
    c.addEventListener("contextmenu", (ev) => ev.preventDefault());
    c.addEventListener("pointerdown", (ev) => {
      drag = { x: ev.clientX, y: ev.clientY, pan: ev.shiftKey || ev.button !== 0 };
      c.setPointerCapture(ev.pointerId);
      c.classList.add("dragging");
    });
    c.addEventListener("pointermove", (ev) => {
      if (!drag) return;
      const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
      drag.x = ev.clientX; drag.y = ev.clientY;
      if (drag.pan) {
        const s = this.dist / Math.max(200, c.clientHeight) * 1.1;
        const [, right, up] = this.basis();
        for (let k = 0; k < 3; k++) this.target[k] += s * (-dx * right[k] + dy * up[k]);
      } else {
        this.yaw -= dx * 0.008;
        this.pitch = Math.max(-1.55, Math.min(1.5699, this.pitch + dy * 0.008));
      }
      this.changed();
    });
    const end = () => { drag = null; c.classList.remove("dragging"); };
    c.addEventListener("pointerup", end);
    c.addEventListener("pointercancel", end);
    c.addEventListener("wheel", (ev) => {
      ev.preventDefault();
      this.dist *= Math.exp(ev.deltaY * 0.0012);
      this.dist = Math.max(0.2 * this.bounds.radius, Math.min(30 * this.bounds.radius, this.dist));
      this.changed();
    }, { passive: false });
    c.addEventListener("dblclick", () => this.resetView("iso"));
  }

  /** Eye position and the camera's right and up unit vectors (world, z up). */
  basis() {
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch), cy = Math.cos(this.yaw), sy = Math.sin(this.yaw);
    const back = [cp * cy, cp * sy, sp];
    const eye = [0, 1, 2].map((k) => this.target[k] + this.dist * back[k]);
    const right = [-sy, cy, 0];
    const up = [back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2], back[0] * right[1] - back[1] * right[0]];
    return [eye, right, up, back];
  }

  /** Draw every part at the body poses `poses` (Float32Array, 12 per body), all moved by -shift. */
  render(poses, shift) {
    const s0 = shift ? shift[0] : 0, s1 = shift ? shift[1] : 0, s2 = shift ? shift[2] : 0;
    const [w, h] = LW.fit(this.canvas);
    const ctx = this.canvas.getContext("2d");
    ctx.fillStyle = "#ffffff";
    ctx.fillRect(0, 0, w, h);
    const [eye, right, up, back] = this.basis();
    const focal = 0.5 * Math.min(w, h) / Math.tan((30 * Math.PI) / 180 / 2) * 0.9;
    const cx = w / 2, cy = h / 2;
    const near = 1e-3 * this.bounds.radius;
    // world -> camera: x right, y up, z depth (distance in front of the eye)
    const toCam = (X, Y, Z, out, o) => {
      const dx = X - s0 - eye[0], dy = Y - s1 - eye[1], dz = Z - s2 - eye[2];
      out[o] = dx * right[0] + dy * right[1] + dz * right[2];
      out[o + 1] = dx * up[0] + dy * up[1] + dz * up[2];
      out[o + 2] = -(dx * back[0] + dy * back[1] + dz * back[2]);
    };
    const project = (c, o) => [cx + (focal * c[o]) / c[o + 2], cy - (focal * c[o + 1]) / c[o + 2]];

    this.drawFloor(ctx, toCam, project, near, eye, s0, s1, s2);

    // light from the upper left, slightly in front (camera coordinates)
    const L = [-0.45, 0.65, -0.61];
    const cam = this.cam;
    let n = 0;
    for (let pi = 0; pi < this.parts.length; pi++) {
      const part = this.parts[pi];
      const o = part.body * 12;
      const R = poses.subarray(o, o + 12);
      const v = part.v;
      for (let i = 0; i < v.length; i += 3) {
        const x = v[i], y = v[i + 1], z = v[i + 2];
        toCam(R[0] * x + R[1] * y + R[2] * z + R[9], R[3] * x + R[4] * y + R[5] * z + R[10],
          R[6] * x + R[7] * y + R[8] * z + R[11], cam, i);
      }
      const f = part.f;
      for (let t = 0; t < f.length; t += 3) {
        const a = 3 * f[t], b = 3 * f[t + 1], c = 3 * f[t + 2];
        const za = cam[a + 2], zb = cam[b + 2], zc = cam[c + 2];
        if (za < near || zb < near || zc < near) continue;
        const ux = cam[b] - cam[a], uy = cam[b + 1] - cam[a + 1], uz = zb - za;
        const vx = cam[c] - cam[a], vy = cam[c + 1] - cam[a + 1], vz = zc - za;
        let nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
        const len = Math.hypot(nx, ny, nz);
        if (len === 0) continue;
        nx /= len; ny /= len; nz /= len;
        this.shade[n] = 0.42 + 0.58 * Math.abs(nx * L[0] + ny * L[1] + nz * L[2]);
        this.depth[n] = (za + zb + zc) / 3;
        const q = 6 * n;
        this.pts[q] = cx + (focal * cam[a]) / za; this.pts[q + 1] = cy - (focal * cam[a + 1]) / za;
        this.pts[q + 2] = cx + (focal * cam[b]) / zb; this.pts[q + 3] = cy - (focal * cam[b + 1]) / zb;
        this.pts[q + 4] = cx + (focal * cam[c]) / zc; this.pts[q + 5] = cy - (focal * cam[c + 1]) / zc;
        this.tpart[n] = pi;
        this.order[n] = n;
        n++;
      }
    }
    const depth = this.depth;
    const order = this.order.subarray(0, n).sort((i, j) => depth[j] - depth[i]);
    ctx.lineJoin = "round";
    ctx.lineWidth = 0.6;
    for (let k = 0; k < n; k++) {
      const t = order[k], q = 6 * t;
      const rgb = this.parts[this.tpart[t]].rgb, s = this.shade[t];
      const col = `rgb(${(rgb[0] * s) | 0},${(rgb[1] * s) | 0},${(rgb[2] * s) | 0})`;
      ctx.fillStyle = col;
      ctx.strokeStyle = col;
      ctx.beginPath();
      ctx.moveTo(this.pts[q], this.pts[q + 1]);
      ctx.lineTo(this.pts[q + 2], this.pts[q + 3]);
      ctx.lineTo(this.pts[q + 4], this.pts[q + 5]);
      ctx.closePath();
      ctx.fill();
      ctx.stroke();
    }
    if (this.overlays.length && this.mode === "fixed") this.drawOverlays(ctx, toCam, project, near);
    if (this.showLabels) this.drawLabels(ctx, poses, toCam, project, near);
    this.drawTriad(ctx, right, up, back, w, h);
    this.triangles = n;
  }

  drawFloor(ctx, toCam, project, near, eye, s0, s1, s2) {
    const b = this.bounds;
    const z0 = this.planar ? b.min[2] - 1e-6 : b.min[2];
    if (!this.planar && eye[2] < z0) return;
    const r = b.radius * 1.3;
    const ticks = LW.ticks(-r, r, 8);
    const step = ticks.length > 1 ? ticks[1] - ticks[0] : r;
    const c = new Float64Array(6);
    ctx.lineWidth = 1;
    const line = (x0, y0, x1, y1, strong) => {
      toCam(x0 + s0, y0 + s1, z0 + s2, c, 0);
      toCam(x1 + s0, y1 + s1, z0 + s2, c, 3);
      if (c[2] < near || c[5] < near) return;
      const p = project(c, 0), q = project(c, 3);
      ctx.strokeStyle = strong ? "#c9d1da" : "#e8ecf0";
      ctx.beginPath(); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]); ctx.stroke();
    };
    const gx = Math.round(b.center[0] / step) * step, gy = Math.round(b.center[1] / step) * step;
    for (const t of ticks) {
      line(gx + t, gy - r, gx + t, gy + r, Math.abs(gx + t) < step * 1e-6);
      line(gx - r, gy + t, gx + r, gy + t, Math.abs(gy + t) < step * 1e-6);
    }
  }

  /** Dashed polylines fixed to the ground (the target profiles of a mechanized chain). */
  drawOverlays(ctx, toCam, project, near) {
    const c = new Float64Array(3);
    ctx.lineWidth = 1.5;
    ctx.setLineDash([6, 4]);
    for (const o of this.overlays) {
      ctx.strokeStyle = o.color;
      ctx.beginPath();
      let pen = false;
      for (const p of o.points) {
        toCam(p[0], p[1], p[2], c, 0);
        if (c[2] < near) { pen = false; continue; }
        const [x, y] = project(c, 0);
        if (pen) ctx.lineTo(x, y); else ctx.moveTo(x, y);
        pen = true;
      }
      ctx.stroke();
    }
    ctx.setLineDash([]);
  }

  drawLabels(ctx, poses, toCam, project, near) {
    const c = new Float64Array(3);
    ctx.font = "600 13px system-ui, sans-serif";
    ctx.textAlign = "center";
    ctx.textBaseline = "middle";
    for (const j of this.joints) {
      const o = j.body * 12, R = poses, p = j.point;
      toCam(R[o] * p[0] + R[o + 1] * p[1] + R[o + 2] * p[2] + R[o + 9],
        R[o + 3] * p[0] + R[o + 4] * p[1] + R[o + 5] * p[2] + R[o + 10],
        R[o + 6] * p[0] + R[o + 7] * p[1] + R[o + 8] * p[2] + R[o + 11], c, 0);
      if (c[2] < near) continue;
      const [x, y] = project(c, 0);
      ctx.fillStyle = j.color;
      ctx.beginPath(); ctx.arc(x, y, 3, 0, 2 * Math.PI); ctx.fill();
      ctx.lineWidth = 3.5;
      ctx.strokeStyle = "rgba(255,255,255,0.92)";
      ctx.strokeText(j.name, x + 10, y - 10);
      ctx.fillText(j.name, x + 10, y - 10);
    }
  }

  drawTriad(ctx, right, up, back, w, h) {
    const ox = 46, oy = h - 46, len = 26;
    const axes = [["x", [1, 0, 0], "#c0392b"], ["y", [0, 1, 0], "#27ae60"], ["z", [0, 0, 1], "#2e6fbf"]];
    axes.sort((a, b) => (a[1][0] * back[0] + a[1][1] * back[1] + a[1][2] * back[2]) - (b[1][0] * back[0] + b[1][1] * back[1] + b[1][2] * back[2]));
    ctx.font = "11px system-ui, sans-serif";
    ctx.textAlign = "center";
    ctx.textBaseline = "middle";
    for (const [name, d, col] of axes) {
      const x = d[0] * right[0] + d[1] * right[1] + d[2] * right[2];
      const y = d[0] * up[0] + d[1] * up[1] + d[2] * up[2];
      ctx.strokeStyle = col;
      ctx.fillStyle = col;
      ctx.lineWidth = 2;
      ctx.beginPath(); ctx.moveTo(ox, oy); ctx.lineTo(ox + len * x, oy - len * y); ctx.stroke();
      ctx.fillText(name, ox + (len + 9) * x, oy - (len + 9) * y);
    }
  }
};
