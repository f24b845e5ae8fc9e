// Drawing: the disk from above or the board from the side, a side view of a few pendulums, r(t) scrolling and the
// phase wheel. Colours: a bob's hue is its phase, as on the playback page.
"use strict";

const View = (function () {
  function hue(phase) {
    return "hsl(" + (((phase + Math.PI) / (2 * Math.PI)) * 360).toFixed(0) + ",85%,50%)";
  }

  function clear(g) {
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.fillStyle = "#fff";
    g.fillRect(0, 0, g.canvas.width, g.canvas.height);
  }

  // Seen from above: pivots on the rim at 2πi/N + φ; each pendulum swings along the
  // tangent, so its bob is drawn displaced by sin θ along it.
  function disk(g, session, phases, held) {
    const w = g.canvas.width, h = g.canvas.height, n = session.state.n;
    const R = 0.38 * Math.min(w, h), phi = session.state.phi;
    const rod = Math.min(0.3 * R, Math.max(10, 2.2 * Math.PI * R / n));
    const bob = Math.max(2.5, Math.min(8, 1.1 * Math.PI * R / n));
    clear(g);
    g.translate(w / 2, h / 2);
    g.scale(1, -1);
    g.fillStyle = held ? "#e4e9f2" : "#eee";
    g.strokeStyle = held ? "#3b5b92" : "#888";
    g.lineWidth = held ? 4 : 1.5;
    g.beginPath(); g.arc(0, 0, R + 0.12 * R, 0, 2 * Math.PI); g.fill(); g.stroke();
    g.lineWidth = 1; g.strokeStyle = "#ccc";
    for (let j = 0; j < 3; j++) {
      const a = phi + j * Math.PI / 3;
      g.beginPath();
      g.moveTo(-1.1 * R * Math.cos(a), -1.1 * R * Math.sin(a));
      g.lineTo(1.1 * R * Math.cos(a), 1.1 * R * Math.sin(a));
      g.stroke();
    }
    for (let i = 0; i < n; i++) {
      const a = 2 * Math.PI * i / n + phi, px = R * Math.cos(a), py = R * Math.sin(a);
      const tx = -Math.sin(a), ty = Math.cos(a), s = rod * Math.sin(session.state.theta[i]);
      g.strokeStyle = "#444"; g.lineWidth = 1.5;
      g.beginPath(); g.moveTo(px, py); g.lineTo(px + s * tx, py + s * ty); g.stroke();
      g.fillStyle = hue(phases[i]); g.strokeStyle = "#333"; g.lineWidth = 1;
      g.beginPath(); g.arc(px + s * tx, py + s * ty, bob, 0, 2 * Math.PI); g.fill(); g.stroke();
    }
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.fillStyle = "#222";
    g.fillText(held ? "disk held" : "disk free", 8, 16);
  }

  // The board from the side, resting on two rollers (cans), every metronome standing
  // on it with its pendulum swinging along it. The board is drawn about its mean
  // position (session.boardCentre, which follows φ over a few seconds of simulated
  // time): without damping the start's momentum carries the board away at a steady
  // drift, which would take it out of view. The rollers, rolling without slipping,
  // move half as far and turn by x/(2a). World units are metres.
  function board(g, session, phases, held) {
    const w = g.canvas.width, h = g.canvas.height, st = session.state, n = st.n;
    const c = session.constants, l2 = session.system.l2;
    const top = 1.15 * Math.max(...Array.from(l2), c.l1) + 0.01;  // rod above the pivot
    const tall = 0.9 * (top + c.l1), cell = Math.max(0.6 * tall, 0.04);
    // A 12 fl. oz can lying on its side (radius 3.3 cm); the board at least long
    // enough to rest on two of them apart.
    const can = 0.033, thick = 0.012, length = Math.max((n + 0.5) * cell, 10 * can);
    const spacing = length / (n + 0.5);  // spread along the board
    const scale = Math.min(0.92 * w / (length * 1.35), 0.8 * h / (2 * can + thick + top + c.l1));
    const tau = 3.0;  // s of simulated time over which the drawing follows the drift
    const mean = session.boardCentre;
    if (mean === null || session.t < mean.t) {
      session.boardCentre = { x: st.phi, t: session.t };
    } else {
      mean.x += (st.phi - mean.x) * (1 - Math.exp(-(session.t - mean.t) / tau));
      mean.t = session.t;
    }
    // Kept within a quarter of the board of the middle, whatever the drift.
    const x = Math.min(0.25 * length, Math.max(-0.25 * length, st.phi - session.boardCentre.x));
    clear(g);
    g.translate(w / 2, h - 0.1 * h);  // the table's line, x = 0 in the middle
    g.scale(scale, scale);
    g.lineWidth = 1 / scale;
    g.strokeStyle = "#999";
    g.beginPath(); g.moveTo(-w / scale, 0); g.lineTo(w / scale, 0); g.stroke();
    for (const side of [-1, 1]) {
      const cx = side * 0.3 * length + x / 2, turn = x / (2 * can);
      g.fillStyle = "#d9dde3"; g.strokeStyle = "#777";
      g.beginPath(); g.arc(cx, -can, can, 0, 2 * Math.PI); g.fill(); g.stroke();
      g.strokeStyle = "#999";
      g.beginPath();
      g.moveTo(cx - can * Math.cos(turn), -can - can * Math.sin(turn));
      g.lineTo(cx + can * Math.cos(turn), -can + can * Math.sin(turn));
      g.stroke();
    }
    const deck = -2 * can - thick;
    g.fillStyle = held ? "#e4e9f2" : "#e8d9bf";
    g.strokeStyle = held ? "#3b5b92" : "#9a8a70";
    g.lineWidth = (held ? 3 : 1) / scale;
    g.fillRect(x - length / 2, deck, length, thick);
    g.strokeRect(x - length / 2, deck, length, thick);
    g.lineWidth = 1 / scale;
    for (let i = 0; i < n; i++) {
      const x0 = x + (i - (n - 1) / 2) * spacing, y0 = deck - c.l1;
      const th = st.theta[i], dx = Math.sin(th), dy = Math.cos(th);  // y grows downwards
      g.fillStyle = "#efe6d8"; g.strokeStyle = "#9a8a70";
      g.beginPath();
      g.moveTo(x0 - 0.4 * cell, deck); g.lineTo(x0 + 0.4 * cell, deck);
      g.lineTo(x0 + 0.12 * cell, deck - tall); g.lineTo(x0 - 0.12 * cell, deck - tall);
      g.closePath(); g.fill(); g.stroke();
      // θ > 0 carries the pendulum's centre of mass (below the pivot) along +x, the
      // way the board moves for φ > 0.
      g.strokeStyle = "#333"; g.lineWidth = 2 / scale;
      g.beginPath();
      g.moveTo(x0 + c.l1 * dx, y0 + c.l1 * dy);
      g.lineTo(x0 - top * dx, y0 - top * dy);
      g.stroke();
      g.lineWidth = 1 / scale;
      const size = Math.min(0.3 * cell, 0.012);
      g.fillStyle = hue(phases[i]); g.strokeStyle = "#222";
      g.fillRect(x0 - l2[i] * dx - size, y0 - l2[i] * dy - size / 2, 2 * size, size);
      g.strokeRect(x0 - l2[i] * dx - size, y0 - l2[i] * dy - size / 2, 2 * size, size);
      g.fillStyle = "#555";
      g.beginPath(); g.arc(x0 + c.l1 * dx, y0 + c.l1 * dy, 0.6 * size, 0, 2 * Math.PI); g.fill();
    }
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.fillStyle = "#222";
    g.fillText((held ? "board held" : "board free") + "   x − mean = "
      + (100 * (st.phi - session.boardCentre.x)).toFixed(2) + " cm", 8, 16);
  }

  // A few metronomes from the front: the rod turns about its pivot by θ, the fixed
  // weight w1 at L1 below it, the slider w2 at L2 above (its height sets the rate).
  function side(g, session, phases, count) {
    const w = g.canvas.width, h = g.canvas.height, n = session.state.n;
    const c = session.constants, k = Math.min(count, n), cell = w / k;
    const top = 1.15 * Math.max(...Array.from(session.system.l2), c.l1) + 0.01;
    const scale = 0.55 * h / (top + c.l1);
    clear(g);
    for (let j = 0; j < k; j++) {
      const i = Math.floor(j * n / k), th = session.state.theta[i];
      const x0 = (j + 0.5) * cell, y0 = h - 22 - c.l1 * scale;
      g.fillStyle = "#efe6d8"; g.strokeStyle = "#9a8a70";
      g.beginPath();
      g.moveTo(x0 - 0.42 * cell, h - 22); g.lineTo(x0 + 0.42 * cell, h - 22);
      g.lineTo(x0 + 0.12 * cell, h - 22 - 0.9 * (top + c.l1) * scale);
      g.lineTo(x0 - 0.12 * cell, h - 22 - 0.9 * (top + c.l1) * scale);
      g.closePath(); g.fill(); g.stroke();
      const dx = Math.sin(th), dy = -Math.cos(th);
      g.strokeStyle = "#333"; g.lineWidth = 2;
      g.beginPath();
      g.moveTo(x0 + c.l1 * scale * dx, y0 - c.l1 * scale * dy);
      g.lineTo(x0 - top * scale * dx, y0 + top * scale * dy);
      g.stroke();
      g.lineWidth = 1;
      const l2 = session.system.l2[i];
      g.fillStyle = hue(phases[i]); g.strokeStyle = "#222";
      g.fillRect(x0 - l2 * scale * dx - 9, y0 + l2 * scale * dy - 5, 18, 10);
      g.strokeRect(x0 - l2 * scale * dx - 9, y0 + l2 * scale * dy - 5, 18, 10);
      g.fillStyle = "#555";
      g.beginPath(); g.arc(x0 + c.l1 * scale * dx, y0 - c.l1 * scale * dy, 6, 0, 2 * Math.PI);
      g.fill();
      g.beginPath(); g.arc(x0, y0, 2.5, 0, 2 * Math.PI); g.fill();
      g.fillStyle = "#222";
      g.fillText("#" + (i + 1) + "  " + (60 * session.system.omega[i] / Math.PI).toFixed(1)
        + " BPM", x0 - 0.4 * cell, h - 7);
    }
  }

  // r(t) over the last `span` seconds of simulated time, settings changes marked.
  function order(g, session, span) {
    const w = g.canvas.width, h = g.canvas.height, pad = { l: 34, r: 8, t: 8, b: 22 };
    const end = Math.max(session.t, span), start = end - span;
    const x = (t) => pad.l + (t - start) / span * (w - pad.l - pad.r);
    const y = (r) => pad.t + (1 - r) * (h - pad.t - pad.b);
    clear(g);
    g.strokeStyle = "#999"; g.lineWidth = 1;
    g.strokeRect(pad.l, pad.t, w - pad.l - pad.r, h - pad.t - pad.b);
    g.fillStyle = "#444";
    for (const r of [0, 0.5, 1]) g.fillText(r.toFixed(1), 8, y(r) + 4);
    g.fillText(start.toFixed(0) + " s", pad.l, h - 6);
    g.fillText(end.toFixed(0) + " s", w - pad.r - 44, h - 6);
    g.fillText("r(t)", w / 2 - 10, h - 6);
    g.strokeStyle = "#bbb"; g.fillStyle = "#777";
    let previous = -Infinity, row = 0;
    for (const [t, label] of session.markers) {
      if (t < start) continue;
      row = x(t) - previous < 70 ? (row + 1) % 8 : 0;  // close labels step down
      previous = x(t);
      g.beginPath(); g.moveTo(x(t), pad.t); g.lineTo(x(t), h - pad.b); g.stroke();
      g.fillText(label, x(t) + 3, pad.t + 12 + 12 * row);
    }
    const hist = session.history;
    let first = hist.length;
    while (first > 0 && hist[first - 1][0] >= start) first--;
    const stride = Math.max(1, Math.floor((hist.length - first) / (w - pad.l - pad.r)));
    g.strokeStyle = "#1f77b4"; g.lineWidth = 1.5;
    g.beginPath();
    for (let k = first; k < hist.length; k += stride) {
      if (k === first) g.moveTo(x(hist[k][0]), y(hist[k][1]));
      else g.lineTo(x(hist[k][0]), y(hist[k][1]));
    }
    g.stroke();
  }

  // Each phase as a dot on the unit circle; the arrow is r e^{iψ}.
  function wheel(g, phases, n, r, psi) {
    const w = g.canvas.width, h = g.canvas.height, R = 0.4 * Math.min(w, h);
    clear(g);
    g.translate(w / 2, h / 2);
    g.strokeStyle = "#bbb";
    g.beginPath(); g.arc(0, 0, R, 0, 2 * Math.PI); g.stroke();
    const dot = n > 30 ? 3.5 : 6;
    for (let i = 0; i < n; i++) {
      g.fillStyle = hue(phases[i]); g.strokeStyle = "#333";
      g.beginPath();
      g.arc(R * Math.cos(phases[i]), -R * Math.sin(phases[i]), dot, 0, 2 * Math.PI);
      g.fill(); g.stroke();
    }
    g.strokeStyle = "#c0392b"; g.lineWidth = 3;
    g.beginPath(); g.moveTo(0, 0); g.lineTo(R * r * Math.cos(psi), -R * r * Math.sin(psi));
    g.stroke();
    g.lineWidth = 1;
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.fillStyle = "#222";
    g.fillText("r = " + r.toFixed(2), 8, 16);
  }

  return { hue, disk, board, side, order, wheel };
})();
