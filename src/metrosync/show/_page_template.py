"""HTML, CSS and JavaScript of the playback page (see `metrosync.show.page`).

``@TITLE@`` and ``@DATA@`` are replaced by the escaped title and the run's JSON; a
board run (``platform`` "board" in it) draws the board from the side instead of the disk.
Nothing here loads from the network. After drawing each frame the page sets
``window.metrosyncFrame`` (frames drawn so far) and ``window.metrosyncTime`` (the
simulated time shown, s), so that a test or a screen recorder can wait for frames
rather than for wall-clock time.
"""

TEMPLATE = r"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>metrosync: @TITLE@</title>
<style>
  body { font: 14px/1.4 system-ui, sans-serif; margin: 16px; color: #222; background: #fafafa; }
  h1 { font-size: 16px; font-weight: 600; margin: 0 0 8px; }
  .views { display: flex; flex-wrap: wrap; gap: 12px; align-items: flex-start; }
  canvas { background: #fff; border: 1px solid #ddd; border-radius: 4px; }
  .controls { display: flex; gap: 10px; align-items: center; margin: 10px 0; flex-wrap: wrap; }
  #seek { flex: 1; min-width: 240px; }
  button { min-width: 72px; padding: 4px 10px; }
  #readout { font-variant-numeric: tabular-nums; min-width: 260px; }
  .note { color: #666; font-size: 12px; }
</style>
</head>
<body>
<h1>@TITLE@</h1>
<div class="controls">
  <button id="play" type="button">Play</button>
  <input id="seek" type="range" min="0" max="1" step="any" value="0" aria-label="time">
  <label>speed
    <select id="speed">
      <option value="0.25">0.25×</option><option value="0.5">0.5×</option>
      <option value="1" selected>1×</option><option value="2">2×</option>
      <option value="5">5×</option><option value="10">10×</option><option value="30">30×</option>
    </select>
  </label>
  <span id="readout"></span>
</div>
<div class="views">
  <canvas id="disk" width="360" height="360" aria-label="disk seen from above"></canvas>
  <canvas id="wheel" width="220" height="220" aria-label="phase wheel"></canvas>
  <canvas id="order" width="600" height="220" aria-label="order parameter r(t)"></canvas>
</div>
<p class="note">Disk seen from above: each pendulum swings along the rim; its bob is coloured
by its phase (on a board run, the board from the side on two rollers, drawn about its mean
motion, each pendulum swinging along it). Phase wheel: each metronome's phase on the unit
circle, the arrow is r e<sup>iψ</sup>. Click r(t) to seek; space bar plays and pauses.</p>
<script type="application/json" id="run-data">@DATA@</script>
<script>
"use strict";
(function () {
  const D = JSON.parse(document.getElementById("run-data").textContent);
  const N = D.n, T0 = D.t0, DT = D.dt, COUNT = D.count;
  const disk = document.getElementById("disk").getContext("2d");
  const wheel = document.getElementById("wheel").getContext("2d");
  const orderCanvas = document.getElementById("order");
  const order = orderCanvas.getContext("2d");
  const playButton = document.getElementById("play");
  const seek = document.getElementById("seek");
  const speedSelect = document.getElementById("speed");
  const readout = document.getElementById("readout");
  let t = D.start, playing = false, last = null;
  if (D.platform === "board") disk.canvas.setAttribute("aria-label", "board seen from the side");
  seek.min = D.start; seek.max = D.end; seek.value = D.start;

  // Cubic Hermite interpolation between records, from values and derivatives.
  function locate(time) {
    let k = Math.floor((time - T0) / DT);
    k = Math.max(0, Math.min(COUNT - 2, k));
    return [k, (time - (T0 + k * DT)) / DT];
  }
  function hermite(y, yd, k, s) {
    const s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * y[k] + (s3 - 2 * s2 + s) * DT * yd[k]
      + (-2 * s3 + 3 * s2) * y[k + 1] + (s3 - s2) * DT * yd[k + 1];
  }
  function state(time) {
    const [k, s] = locate(time);
    const theta = [], phase = [];
    for (let i = 0; i < N; i++) {
      const th = hermite(D.theta[i], D.theta_dot[i], k, s);
      const thd = D.theta_dot[i][k] + s * (D.theta_dot[i][k + 1] - D.theta_dot[i][k]);
      theta.push(th);
      phase.push(Math.atan2(-thd / D.omega[i], th));
    }
    const phi = hermite(D.phi, D.phi_dot, k, s);
    let re = 0, im = 0;
    for (const p of phase) { re += Math.cos(p); im += Math.sin(p); }
    return { theta, phase, phi, r: Math.hypot(re, im) / N, psi: Math.atan2(im, re) };
  }
  function colour(p) {
    const hue = ((p + Math.PI) / (2 * Math.PI)) * 360;
    return "hsl(" + hue.toFixed(1) + ", 85%, 50%)";
  }

  function drawDisk(st) {
    const w = disk.canvas.width, h = disk.canvas.height;
    const scale = 0.36 * Math.min(w, h) / D.radius, R = D.radius * scale, rod = 0.35 * R;
    disk.clearRect(0, 0, w, h);
    disk.save();
    disk.translate(w / 2, h / 2);
    disk.scale(1, -1);
    disk.fillStyle = "#eee"; disk.strokeStyle = "#888"; disk.lineWidth = 1.5;
    disk.beginPath(); disk.arc(0, 0, R, 0, 2 * Math.PI); disk.fill(); disk.stroke();
    disk.strokeStyle = "#c4c4c4"; disk.lineWidth = 1;
    for (let j = 0; j < 4; j++) {
      const a = st.phi + j * Math.PI / 4;
      disk.beginPath();
      disk.moveTo(-R * Math.cos(a), -R * Math.sin(a));
      disk.lineTo(R * Math.cos(a), R * Math.sin(a));
      disk.stroke();
    }
    for (let i = 0; i < N; i++) {
      const a = 2 * Math.PI * i / N + st.phi;
      const px = R * Math.cos(a), py = R * Math.sin(a), tx = -Math.sin(a), ty = Math.cos(a);
      disk.strokeStyle = "#d0d0d0";
      disk.beginPath();
      disk.moveTo(px - rod * tx, py - rod * ty);
      disk.lineTo(px + rod * tx, py + rod * ty);
      disk.stroke();
      const bx = px + rod * Math.sin(st.theta[i]) * tx, by = py + rod * Math.sin(st.theta[i]) * ty;
      disk.strokeStyle = "#333"; disk.lineWidth = 2;
      disk.beginPath(); disk.moveTo(px, py); disk.lineTo(bx, by); disk.stroke();
      disk.lineWidth = 1;
      disk.fillStyle = "#777"; disk.fillRect(px - 6, py - 6, 12, 12);
      disk.fillStyle = colour(st.phase[i]); disk.strokeStyle = "#333";
      disk.beginPath(); disk.arc(bx, by, 7, 0, 2 * Math.PI); disk.fill(); disk.stroke();
    }
    disk.restore();
  }

  // The board from the side on two rolling cans, the metronomes in a row on it, each
  // rod (pivot to slider) swinging along it; in metres, as `animate`'s BoardView. It
  // is drawn about its mean motion a + b t: an undamped board drifts steadily with the
  // momentum of its start, which would take it out of view.
  function drawBoard(st, time) {
    const w = disk.canvas.width, h = disk.canvas.height, CAN = 0.033, THICK = 0.012;
    const ROD = 0.08, PIVOT = 0.02, length = Math.max(0.09 * (N + 0.5), 10 * CAN);
    const spacing = length / (N + 0.5), deck = 2 * CAN + THICK;
    const scale = Math.min(0.8 * w / length, 0.8 * h / (deck + PIVOT + 1.3 * ROD));
    const x = st.phi - (D.phi_trend[0] + D.phi_trend[1] * time), turn = x / (2 * CAN);
    disk.clearRect(0, 0, w, h);
    disk.save();
    disk.translate(w / 2, 0.85 * h);
    disk.scale(scale, -scale);  // y up, metres
    disk.lineWidth = 1 / scale;
    disk.strokeStyle = "#999";
    disk.beginPath(); disk.moveTo(-w / scale, 0); disk.lineTo(w / scale, 0); disk.stroke();
    for (const side of [-1, 1]) {
      const cx = side * 0.3 * length + x / 2;  // rolling: half the board's travel
      disk.fillStyle = "#d9dde3"; disk.strokeStyle = "#777";
      disk.beginPath(); disk.arc(cx, CAN, CAN, 0, 2 * Math.PI); disk.fill(); disk.stroke();
      disk.beginPath();
      disk.moveTo(cx - CAN * Math.cos(turn), CAN + CAN * Math.sin(turn));
      disk.lineTo(cx + CAN * Math.cos(turn), CAN - CAN * Math.sin(turn));
      disk.stroke();
    }
    disk.fillStyle = "#e8d9bf"; disk.strokeStyle = "#9a8a70";
    disk.fillRect(x - length / 2, 2 * CAN, length, THICK);
    disk.strokeRect(x - length / 2, 2 * CAN, length, THICK);
    for (let i = 0; i < N; i++) {
      const px = x + (i - (N - 1) / 2) * spacing, py = deck + PIVOT;
      // θ > 0 carries the centre of mass (below the pivot) along +x, the slider back.
      const bx = px - ROD * Math.sin(st.theta[i]), by = py + ROD * Math.cos(st.theta[i]);
      disk.fillStyle = "#777"; disk.fillRect(px - 0.006, deck, 0.012, PIVOT);
      disk.strokeStyle = "#333"; disk.lineWidth = 2 / scale;
      disk.beginPath(); disk.moveTo(px, py); disk.lineTo(bx, by); disk.stroke();
      disk.lineWidth = 1 / scale;
      disk.fillStyle = colour(st.phase[i]); disk.strokeStyle = "#333";
      disk.beginPath(); disk.arc(bx, by, 7 / scale, 0, 2 * Math.PI); disk.fill(); disk.stroke();
    }
    disk.restore();
  }

  function drawWheel(st) {
    const w = wheel.canvas.width, h = wheel.canvas.height, R = 0.4 * Math.min(w, h);
    wheel.clearRect(0, 0, w, h);
    wheel.save();
    wheel.translate(w / 2, h / 2);
    wheel.strokeStyle = "#bbb";
    wheel.beginPath(); wheel.arc(0, 0, R, 0, 2 * Math.PI); wheel.stroke();
    for (let i = 0; i < N; i++) {
      wheel.fillStyle = colour(st.phase[i]); wheel.strokeStyle = "#333";
      wheel.beginPath();
      wheel.arc(R * Math.cos(st.phase[i]), -R * Math.sin(st.phase[i]), 6, 0, 2 * Math.PI);
      wheel.fill(); wheel.stroke();
    }
    const x = R * st.r * Math.cos(st.psi), y = -R * st.r * Math.sin(st.psi);
    wheel.strokeStyle = "#c0392b"; wheel.lineWidth = 3;
    wheel.beginPath(); wheel.moveTo(0, 0); wheel.lineTo(x, y); wheel.stroke();
    wheel.restore();
    wheel.fillStyle = "#222";
    wheel.fillText("r = " + st.r.toFixed(2), 8, 16);
  }

  // r(t) is static: draw it once off screen, then add the cursor each frame.
  const PAD = { l: 40, r: 10, t: 10, b: 28 };
  const background = document.createElement("canvas");
  background.width = orderCanvas.width; background.height = orderCanvas.height;
  function xOf(time) {
    return PAD.l + (time - D.start) / (D.end - D.start) * (orderCanvas.width - PAD.l - PAD.r);
  }
  function yOf(r) { return PAD.t + (1 - r) * (orderCanvas.height - PAD.t - PAD.b); }
  (function drawOrderBackground() {
    const g = background.getContext("2d"), w = background.width, h = background.height;
    g.fillStyle = "#fff"; g.fillRect(0, 0, w, h);
    if (D.equilibrium_start !== null && D.equilibrium_start < D.end) {
      const x0 = xOf(Math.max(D.start, D.equilibrium_start));
      g.fillStyle = "#ececec"; g.fillRect(x0, PAD.t, xOf(D.end) - x0, h - PAD.t - PAD.b);
    }
    g.strokeStyle = "#999"; g.fillStyle = "#444"; g.lineWidth = 1;
    g.strokeRect(PAD.l, PAD.t, w - PAD.l - PAD.r, h - PAD.t - PAD.b);
    for (const r of [0, 0.5, 1]) g.fillText(r.toFixed(1), 12, yOf(r) + 4);
    g.fillText(D.start.toFixed(0) + " s", PAD.l, h - 8);
    g.fillText(D.end.toFixed(0) + " s", w - PAD.r - 40, h - 8);
    g.fillText("r(t)", w / 2, h - 8);
    g.strokeStyle = "#1f77b4"; g.beginPath();
    for (let k = 0; k < COUNT; k++) {
      const time = T0 + k * DT;
      if (time < D.start || time > D.end) continue;
      const x = xOf(time), y = yOf(D.r[k]);
      if (k === 0 || T0 + (k - 1) * DT < D.start) g.moveTo(x, y); else g.lineTo(x, y);
    }
    g.stroke();
  })();
  function drawOrder() {
    order.drawImage(background, 0, 0);
    const x = xOf(t);
    order.strokeStyle = "#d62728"; order.lineWidth = 2;
    order.beginPath(); order.moveTo(x, PAD.t); order.lineTo(x, orderCanvas.height - PAD.b);
    order.stroke(); order.lineWidth = 1;
  }

  function render() {
    const st = state(t);
    if (D.platform === "board") drawBoard(st, t); else drawDisk(st);
    drawWheel(st); drawOrder();
    seek.value = t;
    readout.textContent = "t = " + t.toFixed(2) + " s   r = " + st.r.toFixed(3) + (D.platform
      === "board" ? "   x = " + (100 * st.phi).toFixed(2) + " cm" : "   φ = " + st.phi.toFixed(3)
      + " rad");
    window.metrosyncTime = t;
    window.metrosyncFrame = (window.metrosyncFrame || 0) + 1;
  }
  function setPlaying(on) {
    playing = on; last = null;
    playButton.textContent = on ? "Pause" : "Play";
    if (on && t >= D.end) t = D.start;
  }
  function frame(now) {
    if (playing) {
      if (last !== null) t += (now - last) / 1000 * Number(speedSelect.value);
      last = now;
      if (t >= D.end) { t = D.end; setPlaying(false); }
    }
    render();
    requestAnimationFrame(frame);
  }
  playButton.addEventListener("click", () => setPlaying(!playing));
  seek.addEventListener("input", () => { t = Number(seek.value); last = null; });
  orderCanvas.addEventListener("click", (e) => {
    const box = orderCanvas.getBoundingClientRect();
    const frac = (e.clientX - box.left - PAD.l) / (box.width - PAD.l - PAD.r);
    t = Math.max(D.start, Math.min(D.end, D.start + frac * (D.end - D.start))); last = null;
  });
  document.addEventListener("keydown", (e) => {
    if (e.code === "Space" && e.target.tagName !== "SELECT") {
      e.preventDefault();
      setPlaying(!playing);
    }
  });
  requestAnimationFrame(frame);
})();
</script>
</body>
</html>
"""
