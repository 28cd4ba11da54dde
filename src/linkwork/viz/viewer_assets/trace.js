/* linkwork trace viewer: the slider, play button, branch selector, readouts and linked plots. */
"use strict";

(function () {
  const data = LW.data();
  const nb = data.bodies.length, nj = data.joints.length;
  const poses = LW.decode(data.poses);
  const angles = LW.decode(data.angles);
  const sigma = LW.decode(data.sigma);
  const rank = LW.decode(data.rank);
  const step = LW.decode(data.step);
  const arclength = LW.decode(data.arclength);
  const steady = LW.decode(data.steady);
  const steadied = new Float32Array(nb * 12);
  const k = data.sigma.shape[1];
  const $ = (id) => document.getElementById(id);
  const unit = (j) => (data.joints[j].type === "R" ? "°" : "");
  const drive = data.joints[data.drive];

  const scene = new LW.Scene($("scene"), data);
  if (data.view === "fixed") { $("centred").checked = false; scene.setMode("fixed"); } // mechanism viewer
  const anglePlot = new LW.Plot($("plot-angles"), { ylabel: "hinge angle (deg)" });
  const sigmaPlot = new LW.Plot($("plot-sigma"), { ylabel: "singular value σᵢ", logy: true, floor: 1e-10 });
  const SIGMA_COLORS = ["#08306b", "#2171b5", "#4292c6", "#6baed6", "#41ab5d", "#fd8d3c", "#e6550d", "#a63603", "#756bb1", "#636363"];
  const state = { branch: 0, point: 0, playing: false, renders: 0 };

  // ------------------------------------------------------------------ header and static panels
  const nbr = data.branches.length, nbif = data.bifurcations.length;
  $("subtitle").textContent = [
    `${nj} joints, ${nb} bodies`,
    `${data.points_traced} traced points` + (data.points < data.points_traced ? ` (${data.points} shown)` : ""),
    nbr === 1 ? "one branch" : `${nbr} branches`,
    nbif === 0 ? "no bifurcation point" : nbif === 1 ? "1 bifurcation point" : `${nbif} bifurcation points`,
    `drive ${drive.name}`,
    "angles in degrees",
  ].join(" · ");

  const sel = $("branch");
  data.branches.forEach((b, i) => {
    const opt = document.createElement("option");
    opt.value = String(i);
    const from = b.parent === null ? "from the start" : `from bif. ${b.bifurcation} on branch ${b.parent} (${b.direction > 0 ? "+" : "−"})`;
    opt.textContent = `branch ${b.id}: ${from}, ${b.steps} steps`;
    sel.appendChild(opt);
  });
  if (nbr === 1) $("branch-box").style.display = "none";
  if (nbif === 0) $("bif-box").style.display = "none";

  const bifBody = $("bif-table").querySelector("tbody");
  data.bifurcations.forEach((b) => {
    const row = LW.row(bifBody, [b.id, b.branch, b.step, b.rank, ""]);
    const go = document.createElement("button");
    go.className = "jump";
    go.textContent = "go";
    go.title = `Show bifurcation point ${b.id}`;
    const first = b.visits.find((v) => data.branches[v[0]].id === b.branch) || b.visits[0];
    if (first) go.addEventListener("click", () => setBranch(first[0], first[1]));
    else go.disabled = true;
    row[4].appendChild(go);
  });

  const readBody = $("readout").querySelector("tbody");
  const cells = data.joints.map((j) => {
    const row = LW.row(readBody, [j.name, "", ""], { color: j.color, dash: j.dash });
    return [row[1], row[2]];
  });

  LW.legend($("legend-angles"), data.joints.map((j) => ({ label: j.name + (j.type === "R" ? "" : " (length)"), color: j.color, dash: j.dash })));
  LW.legend($("legend-sigma"), Array.from({ length: k }, (_, i) => ({ label: `σ${i + 1}`, color: SIGMA_COLORS[i % SIGMA_COLORS.length] })));

  // ------------------------------------------------------------------ branch and point
  function rows() {
    const b = data.branches[state.branch];
    return [b.start, b.count];
  }

  function xValues() {
    const [start, count] = rows();
    const x = new Float64Array(count);
    const kind = $("xaxis").value;
    for (let i = 0; i < count; i++) {
      const r = start + i;
      x[i] = kind === "s" ? arclength[r] : kind === "drive" ? angles[r * nj + data.drive] : step[r];
    }
    return x;
  }

  function updatePlots() {
    const [start, count] = rows();
    const x = xValues();
    const series = data.joints.map((j, jj) => {
      const y = new Float64Array(count);
      for (let i = 0; i < count; i++) y[i] = angles[(start + i) * nj + jj];
      return { y, color: j.color, dash: j.dash };
    });
    const sig = [];
    for (let s = 0; s < k; s++) {
      const y = new Float64Array(count);
      for (let i = 0; i < count; i++) y[i] = sigma[(start + i) * k + s];
      sig.push({ y, color: SIGMA_COLORS[s % SIGMA_COLORS.length], dash: 0, width: 1.4 });
    }
    const markers = [];
    data.bifurcations.forEach((b) => {
      for (const [bi, row] of b.visits) if (bi === state.branch) markers.push({ x: x[row], label: `bif. ${b.id}` });
    });
    const kind = $("xaxis").value;
    const xlabel = kind === "s" ? "arclength along the branch (deg)" : kind === "drive" ? `drive angle ${drive.name} (deg)` : `step along branch ${data.branches[state.branch].id}`;
    anglePlot.opts.xlabel = xlabel;
    sigmaPlot.opts.xlabel = xlabel;
    anglePlot.set(x, series, markers);
    sigmaPlot.set(x, sig, markers);
    // joint ranges on this branch
    data.joints.forEach((j, jj) => {
      let lo = Infinity, hi = -Infinity;
      for (let i = 0; i < count; i++) { const v = angles[(start + i) * nj + jj]; lo = Math.min(lo, v); hi = Math.max(hi, v); }
      cells[jj][1].textContent = `${LW.fmt(lo, 2)} … ${LW.fmt(hi, 2)}`;
    });
  }

  function setBranch(bi, point) {
    bi = Math.max(0, Math.min(nbr - 1, bi | 0));
    state.branch = bi;
    sel.value = String(bi);
    const b = data.branches[bi];
    $("slider").max = String(Math.max(0, b.count - 1));
    const from = b.parent === null ? "Starts at the start configuration" : `Leaves bifurcation point ${b.bifurcation} (on branch ${b.parent}) in the ${b.direction > 0 ? "+" : "−"} direction of its tangent`;
    $("branch-info").textContent = `${from}; ${b.steps} steps; ends: ${b.end}.`;
    updatePlots();
    setPoint(point === undefined ? 0 : point);
  }

  function renderScene() {
    const r = data.branches[state.branch].start + state.point;
    const P = poses.subarray(r * nb * 12, (r + 1) * nb * 12);
    if (!$("centred").checked) { scene.render(P, null); state.renders++; return; }
    // Steady: the whole mechanism moved by this point's rigid motion S (rotation rows, translation).
    const S = steady.subarray(12 * r, 12 * r + 12);
    for (let b = 0; b < nb; b++) {
      const o = 12 * b;
      for (let i = 0; i < 3; i++) {
        for (let j = 0; j < 3; j++) {
          steadied[o + 3 * i + j] = S[3 * i] * P[o + j] + S[3 * i + 1] * P[o + 3 + j] + S[3 * i + 2] * P[o + 6 + j];
        }
        steadied[o + 9 + i] = S[3 * i] * P[o + 9] + S[3 * i + 1] * P[o + 10] + S[3 * i + 2] * P[o + 11] + S[9 + i];
      }
    }
    scene.render(steadied, null);
    state.renders++;
  }

  function setPoint(i) {
    const [start, count] = rows();
    i = Math.max(0, Math.min(count - 1, Math.round(i)));
    state.point = i;
    $("slider").value = String(i);
    const r = start + i;
    renderScene();
    anglePlot.setCursor(i);
    sigmaPlot.setCursor(i);
    data.joints.forEach((j, jj) => { cells[jj][0].textContent = LW.fmt(angles[r * nj + jj], 3) + unit(jj); });
    const sv = Array.from(sigma.subarray(r * k, (r + 1) * k));
    const rk = rank[r];
    const cond = rk > 0 && sv[rk - 1] > 0 ? sv[0] / sv[rk - 1] : NaN;
    $("sigma-readout").textContent = `rank ${rk}, mobility ${data.unknowns - rk}; σ = ${sv.map(LW.sci).join(", ")}; condition σ₁/σ${rk} = ${LW.sci(cond)}`;
    $("position").textContent = `branch ${data.branches[state.branch].id} · point ${i + 1} of ${count} · step ${step[r]} · s = ${LW.fmt(arclength[r], 2)}°`;
    $("stage-caption").textContent = `${drive.name} = ${LW.fmt(angles[r * nj + data.drive], 2)}${unit(data.drive)} · branch ${data.branches[state.branch].id}, step ${step[r]}`;
    showHere();
  }

  /** At a bifurcation point: offer every other branch through it. */
  function showHere() {
    const here = $("here");
    here.textContent = "";
    for (const b of data.bifurcations) {
      const mine = b.visits.some(([bi, row]) => bi === state.branch && row === state.point);
      if (!mine) continue;
      const box = document.createElement("div");
      box.className = "here";
      const p = document.createElement("p");
      LW.lead(p, `Bifurcation point ${b.id}`, `: rank ${b.rank}, ${b.tangents} branch tangents. Continue on:`);
      box.appendChild(p);
      for (const [bi, row] of b.visits) {
        if (bi === state.branch && row === state.point) continue;
        const br = data.branches[bi];
        const btn = document.createElement("button");
        btn.className = "jump";
        btn.textContent = `branch ${br.id}` + (row === 0 ? " (leaves)" : row === br.count - 1 ? " (arrives)" : ` (step ${step[br.start + row]})`);
        btn.addEventListener("click", () => setBranch(bi, row));
        box.appendChild(btn);
      }
      here.appendChild(box);
    }
  }

  // ------------------------------------------------------------------ controls
  let redrawQueued = false;
  scene.onChange = () => {
    if (redrawQueued) return;
    redrawQueued = true;
    requestAnimationFrame(() => { redrawQueued = false; renderScene(); });
  };
  $("slider").addEventListener("input", (ev) => setPoint(+ev.target.value));
  sel.addEventListener("change", () => setBranch(+sel.value));
  $("xaxis").addEventListener("change", () => { updatePlots(); setPoint(state.point); });
  anglePlot.onPick = setPoint;
  sigmaPlot.onPick = setPoint;
  $("view-iso").addEventListener("click", () => scene.resetView("iso"));
  $("view-top").addEventListener("click", () => scene.resetView("top"));
  $("view-front").addEventListener("click", () => scene.resetView("front"));
  $("centred").addEventListener("change", (ev) => scene.setMode(ev.target.checked ? "centred" : "fixed"));
  $("centred").parentElement.title = `Hold the linkage steady as a whole (each point fitted onto the previous one, the flattest shape level); untick to hold ${data.fixed_body} still`;
  $("show-labels").addEventListener("change", (ev) => { scene.showLabels = ev.target.checked; renderScene(); });

  let last = 0, carry = 0;
  function tick(t) {
    if (!state.playing) return;
    const dt = last ? Math.min(0.1, (t - last) / 1000) : 0;
    last = t;
    carry += dt * 40 * +$("speed").value;
    const n = Math.floor(carry);
    if (n > 0) {
      carry -= n;
      const count = rows()[1];
      if (state.point + n >= count - 1) { setPoint(count - 1); play(false); return; }
      setPoint(state.point + n);
    }
    requestAnimationFrame(tick);
  }
  function play(on) {
    state.playing = on;
    $("play").textContent = on ? "❚❚ Pause" : "▶ Play";
    if (on) {
      if (state.point >= rows()[1] - 1) setPoint(0);
      last = 0; carry = 0;
      requestAnimationFrame(tick);
    }
  }
  $("play").addEventListener("click", () => play(!state.playing));
  document.addEventListener("keydown", (ev) => {
    const tag = ev.target.tagName;
    if (tag === "SELECT" || (tag === "INPUT" && ev.target.type !== "range")) return;
    if (ev.key === " ") { ev.preventDefault(); play(!state.playing); }
    else if (tag !== "INPUT" && (ev.key === "ArrowRight" || ev.key === "ArrowLeft")) {
      ev.preventDefault();
      setPoint(state.point + (ev.key === "ArrowRight" ? 1 : -1) * (ev.shiftKey ? 10 : 1));
    }
  });
  window.addEventListener("resize", () => { anglePlot.drawBase(); sigmaPlot.drawBase(); setPoint(state.point); });

  // ------------------------------------------------------------------ start: #branch=B&point=P in the address
  const hash = new URLSearchParams(location.hash.slice(1));
  const startBranch = hash.has("branch") ? data.branches.findIndex((b) => String(b.id) === hash.get("branch")) : 0;
  setBranch(Math.max(0, startBranch), hash.has("point") ? +hash.get("point") : 0);

  /** For scripts and tests: the viewer's state and its controls. */
  window.linkworkViewer = {
    setBranch: (id, point) => setBranch(data.branches.findIndex((b) => b.id === id), point),
    setPoint,
    play,
    state: () => ({ branch: data.branches[state.branch].id, point: state.point, points: rows()[1], playing: state.playing, renders: state.renders, triangles: scene.triangles }),
  };
})();
