/* linkwork synthesis viewer: the target profiles and the joined chain posed on each, with a slider across them. */
"use strict";

(function () {
  const data = LW.data();
  const $ = (id) => document.getElementById(id);
  const p = data.targets.length, q = data.segments.length;
  const SEG_COLORS = ["#1f5f9e", "#d9782d", "#2e8b57", "#b03a48", "#7553a8", "#8c6d31", "#c2519b", "#4a7d8c"];
  const segColor = (e) => SEG_COLORS[e % SEG_COLORS.length];
  const JOINT_COLORS = data.joint_colors;  // the one palette (linkwork.viz.palette.TAB10)
  const jointColor = (i) => JOINT_COLORS[i % JOINT_COLORS.length];
  const state = { profile: 0, playing: false, renders: 0 };
  const canvas = $("scene");
  const ctx = canvas.getContext("2d");

  $("subtitle").textContent = [
    `${data.profile_kind} profiles`,
    `${p} target profiles`,
    `design ${data.design} (${q} segments, ${q - 1} joints)`,
    `piece length ${LW.sci(data.piece_length)}`,
    "angles in degrees",
  ].join(" · ");
  if (!data.compound) $("compound-box").style.display = "none";

  // ------------------------------------------------------------------ view: fit, pan, zoom (y up, equal axes)
  let lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
  const grow = (pts) => { for (const [x, y] of pts) { lo = [Math.min(lo[0], x), Math.min(lo[1], y)]; hi = [Math.max(hi[0], x), Math.max(hi[1], y)]; } };
  data.targets.forEach((t) => grow(t.points));
  data.joined.forEach((c) => grow(c.points));
  const view = { cx: 0, cy: 0, scale: 1 };
  function fit() {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    view.cx = (lo[0] + hi[0]) / 2;
    view.cy = (lo[1] + hi[1]) / 2;
    view.scale = 0.86 * Math.min((w - 60) / Math.max(hi[0] - lo[0], 1e-9), (h - 70) / Math.max(hi[1] - lo[1], 1e-9));
    draw();
  }
  let drag = null;
  canvas.addEventListener("pointerdown", (ev) => { drag = [ev.clientX, ev.clientY]; canvas.setPointerCapture(ev.pointerId); canvas.classList.add("dragging"); });
  canvas.addEventListener("pointermove", (ev) => {
    if (!drag) return;
    view.cx -= (ev.clientX - drag[0]) / view.scale;
    view.cy += (ev.clientY - drag[1]) / view.scale;
    drag = [ev.clientX, ev.clientY];
    draw();
  });
  const end = () => { drag = null; canvas.classList.remove("dragging"); };
  canvas.addEventListener("pointerup", end);
  canvas.addEventListener("pointercancel", end);
  canvas.addEventListener("wheel", (ev) => {
    ev.preventDefault();
    const r = canvas.getBoundingClientRect();
    const mx = ev.clientX - r.left, my = ev.clientY - r.top;
    const w = canvas.clientWidth, h = canvas.clientHeight;
    const wx = view.cx + (mx - w / 2) / view.scale, wy = view.cy - (my - h / 2) / view.scale;
    view.scale *= Math.exp(-ev.deltaY * 0.0015);
    view.cx = wx - (mx - w / 2) / view.scale;
    view.cy = wy + (my - h / 2) / view.scale;
    draw();
  }, { passive: false });
  canvas.addEventListener("dblclick", fit);

  // ------------------------------------------------------------------ drawing
  function chain() {
    return $("compound").checked && data.compound ? data.compound.profiles : data.joined;
  }

  function draw() {
    const [w, h] = LW.fit(canvas);
    const X = (x) => w / 2 + (x - view.cx) * view.scale;
    const Y = (y) => h / 2 - (y - view.cy) * view.scale;
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, w, h);
    // grid with coordinates
    const x0 = view.cx - w / 2 / view.scale, x1 = view.cx + w / 2 / view.scale;
    const y0 = view.cy - h / 2 / view.scale, y1 = view.cy + h / 2 / view.scale;
    ctx.font = "10.5px system-ui, sans-serif";
    ctx.lineWidth = 1;
    ctx.fillStyle = "#8a96a3";
    ctx.textBaseline = "bottom";
    ctx.textAlign = "left";
    for (const t of LW.ticks(x0, x1, Math.floor(w / 110))) {
      ctx.strokeStyle = Math.abs(t) < 1e-12 ? "#c9d1da" : "#eef1f4";
      ctx.beginPath(); ctx.moveTo(X(t), 0); ctx.lineTo(X(t), h); ctx.stroke();
      ctx.fillText(String(+t.toFixed(6)), X(t) + 3, h - 22);
    }
    for (const t of LW.ticks(y0, y1, Math.floor(h / 80))) {
      ctx.strokeStyle = Math.abs(t) < 1e-12 ? "#c9d1da" : "#eef1f4";
      ctx.beginPath(); ctx.moveTo(0, Y(t)); ctx.lineTo(w, Y(t)); ctx.stroke();
      ctx.fillText(String(+t.toFixed(6)), 4, Y(t) - 2);
    }
    const line = (pts, color, width, dash) => {
      ctx.strokeStyle = color;
      ctx.lineWidth = width;
      ctx.setLineDash(dash || []);
      ctx.beginPath();
      pts.forEach(([x, y], i) => (i ? ctx.lineTo(X(x), Y(y)) : ctx.moveTo(X(x), Y(y))));
      ctx.stroke();
      ctx.setLineDash([]);
    };
    const j = state.profile;
    // the other target profiles, faint
    if ($("show-all").checked) data.targets.forEach((t, k) => { if (k !== j) line(t.points, "#c3cad2", 1.2, [5, 4]); });
    // the target profile shown: its points
    const target = data.targets[j];
    line(target.points, "#7b8794", 1);
    ctx.fillStyle = "#1d2733";
    for (const [x, y] of target.points) { ctx.beginPath(); ctx.arc(X(x), Y(y), 1.7, 0, 2 * Math.PI); ctx.fill(); }
    // the chain: one colour per segment
    const c = chain()[j];
    ctx.lineCap = "round";
    ctx.lineJoin = "round";
    data.segments.forEach((seg, e) => {
      const a = seg.starts[j], b = a + seg.pieces[j];
      line(c.points.slice(a, b + 1), segColor(e), seg.kind === "M" ? 5 : 3.5);
    });
    ctx.lineCap = "butt";
    // segment labels, offset from the chain's middle point of each segment
    ctx.font = "600 12px system-ui, sans-serif";
    ctx.textAlign = "center";
    ctx.textBaseline = "middle";
    data.segments.forEach((seg, e) => {
      const a = seg.starts[j], b = a + seg.pieces[j];
      const m = Math.floor((a + b) / 2);
      const p0 = c.points[Math.max(a, m - 1)], p1 = c.points[Math.min(b, m + 1)];
      let nx = -(p1[1] - p0[1]), ny = p1[0] - p0[0];
      const len = Math.hypot(nx, ny) || 1;
      nx /= len; ny /= len;
      const px = X(c.points[m][0]) + 18 * nx, py = Y(c.points[m][1]) - 18 * ny;
      ctx.lineWidth = 3.5;
      ctx.strokeStyle = "rgba(255,255,255,0.9)";
      ctx.strokeText(`${e + 1} ${seg.kind}`, px, py);
      ctx.fillStyle = segColor(e);
      ctx.fillText(`${e + 1} ${seg.kind}`, px, py);
    });
    // joints: revolute joints as rings, merged (locked) joints as grey diamonds, chain ends as squares
    const merged = $("compound").checked && data.compound ? data.compound.merged : [];
    c.joints.forEach(([x, y], i) => {
      const px = X(x), py = Y(y);
      ctx.lineWidth = 2;
      ctx.strokeStyle = "#1d2733";
      if (i === 0 || i === c.joints.length - 1) {
        ctx.fillStyle = "#1d2733";
        ctx.fillRect(px - 4, py - 4, 8, 8);
      } else if (merged.includes(i - 1)) {
        ctx.fillStyle = "#9aa5b1";
        ctx.beginPath(); ctx.moveTo(px, py - 6); ctx.lineTo(px + 6, py); ctx.lineTo(px, py + 6); ctx.lineTo(px - 6, py); ctx.closePath(); ctx.fill(); ctx.stroke();
      } else {
        ctx.fillStyle = "#fff";
        ctx.beginPath(); ctx.arc(px, py, 5, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
      }
    });
    state.renders++;
  }

  // ------------------------------------------------------------------ panels and plots
  const segBody = $("segments").querySelector("tbody");
  const segCells = data.segments.map((seg, e) => {
    const label = `${e + 1} ${seg.kind}${seg.kind === "C" && seg.radius !== null ? ` (r ${LW.sci(seg.radius)})` : ""}`;
    const row = LW.row(segBody, [label, "", "", ""], { color: segColor(e), dash: 0 });
    return [row[1], row[2], row[3]];
  });
  $("segment-note").textContent = "M: rigid segment (a link). C: constant-curvature segment, its length changes between profiles. Error: largest distance to the target points (Eq. 21).";
  const errRows = [["E_max after segmentation", data.e_max], ["E_mean after segmentation", data.e_mean], ["E_max of the joined chain", data.joined_e_max]];
  if (data.compound) errRows.push(["E_max with compound segments", data.compound.e_max]);
  const errBody = $("errors").querySelector("tbody");
  errBody.textContent = "";
  errRows.forEach(([k, v]) => LW.row(errBody, [k, LW.sci(v)]));
  if (data.compound) {
    const m = data.compound.merged.map((i) => i + 1);
    $("compound-note").textContent = (m.length ? `Compound segments: joint${m.length > 1 ? "s" : ""} ${m.join(", ")} merged (range of motion below ${LW.fmt(data.compound.merge_below, 1)}°). ` : `No joint moves less than ${LW.fmt(data.compound.merge_below, 1)}°: nothing merged. `) + data.compound.notes.join(" ");
  }

  const xs = Float64Array.from({ length: p }, (_, k) => k + 1);
  const xticks = data.targets.map((t, k) => ({ x: k + 1, label: `${k + 1}: ${t.name}` }));
  const jointPlot = new LW.Plot($("plot-joints"), { xlabel: "target profile", ylabel: "joint angle (deg)", xticks });
  const errPlot = new LW.Plot($("plot-errors"), { xlabel: "target profile", ylabel: "segment error", xticks });
  function updatePlots() {
    const c = chain();
    const turns = Array.from({ length: q - 1 }, (_, i) => ({ y: Float64Array.from(c, (prof) => prof.turns[i]), color: jointColor(i), dash: 0 }));
    jointPlot.set(xs, turns, []);
    const errs = data.segments.map((_, e) => ({ y: Float64Array.from(c, (prof) => prof.errors[e]), color: segColor(e), dash: 0 }));
    errPlot.set(xs, errs, []);
    jointPlot.setCursor(state.profile);
    errPlot.setCursor(state.profile);
  }
  LW.legend($("legend-joints"), Array.from({ length: q - 1 }, (_, i) => ({ label: `joint ${i + 1} (segments ${i + 1}–${i + 2})`, color: jointColor(i) })));
  LW.legend($("legend-errors"), data.segments.map((s, e) => ({ label: `${e + 1} ${s.kind}`, color: segColor(e) })));
  $("joints-caption").textContent = "Relative angle at each revolute joint of the chain (the turn from the piece arriving to the piece leaving), profile by profile; its range is the joint's motion (Eq. 34). Click a plot to choose a profile.";

  function setProfile(k) {
    k = Math.max(0, Math.min(p - 1, Math.round(k)));
    state.profile = k;
    $("slider").value = String(k);
    const t = data.targets[k];
    const c = chain()[k];
    LW.lead($("profile-info"), t.name, ` (${k + 1} of ${p}): arc length ${LW.sci(t.arc_length)}, ${t.pieces} pieces.`);
    data.segments.forEach((seg, e) => {
      segCells[e][0].textContent = String(seg.pieces[k]);
      segCells[e][1].textContent = LW.sci(seg.lengths[k]);
      segCells[e][2].textContent = LW.sci(c.errors[e]);
    });
    $("position").textContent = `profile ${k + 1} of ${p}: ${t.name}`;
    $("stage-caption").textContent = `${t.name}: chain on target profile ${k + 1} · largest error ${LW.sci(Math.max(...c.errors))}`;
    jointPlot.setCursor(k);
    errPlot.setCursor(k);
    draw();
  }

  $("slider").max = String(p - 1);
  $("slider").addEventListener("input", (ev) => setProfile(+ev.target.value));
  $("view-fit").addEventListener("click", fit);
  $("show-all").addEventListener("change", draw);
  $("compound").addEventListener("change", () => { updatePlots(); setProfile(state.profile); });
  jointPlot.onPick = setProfile;
  errPlot.onPick = setProfile;
  let timer = null;
  function play(on) {
    state.playing = on;
    $("play").textContent = on ? "❚❚ Pause" : "▶ Play";
    clearInterval(timer);
    if (on) timer = setInterval(() => setProfile((state.profile + 1) % p), 900);
  }
  $("play").addEventListener("click", () => play(!state.playing));
  document.addEventListener("keydown", (ev) => {
    const tag = ev.target.tagName;
    if (tag === "SELECT" || (tag === "INPUT" && ev.target.type !== "range")) return;
    if (ev.key === " ") { ev.preventDefault(); play(!state.playing); }
  });
  window.addEventListener("resize", () => { updatePlots(); fit(); });

  const hash = new URLSearchParams(location.hash.slice(1));
  updatePlots();
  fit();
  setProfile(hash.has("profile") ? +hash.get("profile") - 1 : 0);

  /** For scripts and tests: the viewer's state and its controls. */
  window.linkworkViewer = { setProfile, play, state: () => ({ profile: state.profile, profiles: p, playing: state.playing, renders: state.renders }) };
})();
