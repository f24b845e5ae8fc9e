// The page: controls wired to the live Session, the animation loop, the numbers, and
// window.metrosync (run, the frame counter, the session) for scripts and tests.
"use strict";

(function () {
  const config = JSON.parse(document.getElementById("config").textContent);
  const limits = config.limits;
  const $ = (id) => document.getElementById(id);
  const session = new Session(config);
  const clicks = new Clicks();
  const graphics = {};
  for (const id of ["disk", "wheel", "side", "order"]) graphics[id] = $(id).getContext("2d");

  let playing = false, last = null, clock = 0, frames = 0, fps = 0, fpsFrames = 0, fpsSince = null;
  let achieved = 0, achievedSim = 0, achievedWall = 0;

  // Sliders over several decades are logarithmic; position 0 may stand for zero.
  function logSlider(id, [low, high], allowZero) {
    const el = $(id), top = Number(el.max);
    return {
      get() {
        const u = Number(el.value);
        if (allowZero && u === 0) return 0;
        const frac = allowZero ? (u - 1) / (top - 1) : u / top;
        return low * Math.pow(high / low, frac);
      },
      set(value) {
        if (allowZero && value <= 0) { el.value = 0; return; }
        const frac = Math.log(Math.min(high, Math.max(low, value)) / low) / Math.log(high / low);
        el.value = Math.round(allowZero ? 1 + frac * (top - 1) : frac * top);
      },
    };
  }
  const drive = logSlider("drive", limits.drive, true);
  const cphi = logSlider("cphi", limits.c_phi, true);
  const inertia = logSlider("inertia", limits.inertia, false);
  const boardMass = logSlider("boardmass", limits.board_mass, false);
  const boardDamping = logSlider("boarddamping", limits.board_damping, true);
  const sci = (v) => (v === 0 ? "0" : v.toExponential(1));

  function setRange(id, [low, high], value) {
    const el = $(id);
    el.min = low; el.max = high; el.value = value;
  }

  // Put the session's settings into the controls (at load, and after a preset change).
  function showSettings() {
    const s = session.settings;
    $("preset").value = s.preset;
    setRange("speed", limits.speed, $("speed").value);
    setRange("n", limits.n, s.n);
    setRange("bpm", session.preset.bpm_range, s.bpm);
    setRange("sigma", limits.sigma_bpm, s.sigma);
    setRange("offset", limits.group_offset_bpm, s.offset);
    $("groups").checked = s.groups === 2;
    $("hold").checked = s.hold;
    $("jlaw").checked = s.jLaw;
    drive.set(s.drive); cphi.set(s.cPhi); inertia.set(s.j);
    boardMass.set(s.boardMass); boardDamping.set(s.boardDamping);
    showPlatform();
    // The steady-swing tuning's spline is the preset's drive's: M stays as tuned.
    const steady = session.constants.tuning === "steady-swing";
    $("drive").disabled = steady;
    $("drive").title = steady ? "the steady-swing tuning holds M at the preset's value" : "";
    showValues();
  }

  function showValues() {
    const s = session.settings;
    $("speed-out").textContent = $("speed").value + "×";
    $("n-out").textContent = s.n;
    $("bpm-out").textContent = s.bpm.toFixed(1);
    $("sigma-out").textContent = s.sigma.toFixed(2);
    $("offset-out").textContent = (s.offset >= 0 ? "+" : "") + s.offset.toFixed(1);
    $("drive-out").textContent = sci(s.drive);
    $("cphi-out").textContent = sci(s.cPhi);
    $("inertia-out").textContent = s.j.toPrecision(3);
    $("boardmass-out").textContent = s.boardMass.toPrecision(3);
    $("boarddamping-out").textContent = sci(s.boardDamping);
    if (s.jLaw) inertia.set(s.j);  // the law moves J with N
  }

  // The chosen platform's own controls show; the other's hide.
  function showPlatform() {
    const board = session.settings.platform === "board";
    $("platform").value = session.settings.platform;
    $("disk-controls").hidden = board;
    $("board-controls").hidden = !board;
    $("platform-name").textContent = board ? "a board on rollers" : "a rotating disk";
  }

  for (const name of Object.keys(config.presets)) {
    const option = document.createElement("option");
    option.value = name;
    option.textContent = name;
    option.title = config.presets[name].description;
    $("preset").appendChild(option);
  }

  // Every control changes a setting, then the run continues from where it is.
  function onChange(id, apply, label) {
    $(id).addEventListener("input", () => {
      apply($(id));
      session.rebuild(label());
      showValues();
    });
  }
  const s = session.settings;
  onChange("n", (el) => { s.n = Number(el.value); }, () => "N=" + s.n);
  onChange("bpm", (el) => { s.bpm = Number(el.value); }, () => s.bpm.toFixed(1) + " BPM");
  onChange("sigma", (el) => { s.sigma = Number(el.value); }, () => "σ=" + s.sigma.toFixed(2));
  onChange("groups", (el) => { s.groups = el.checked ? 2 : 1; },
    () => (s.groups === 2 ? "2 groups" : "1 group"));
  onChange("offset", (el) => { s.offset = Number(el.value); },
    () => "Δ=" + s.offset.toFixed(1));
  onChange("drive", () => { s.drive = drive.get(); }, () => "M=" + sci(s.drive));
  onChange("cphi", () => { s.cPhi = cphi.get(); }, () => "cφ=" + sci(s.cPhi));
  onChange("inertia", () => { s.j = inertia.get(); s.jLaw = false; $("jlaw").checked = false; },
    () => "J=" + s.j.toPrecision(2));
  onChange("jlaw", (el) => { s.jLaw = el.checked; }, () => (s.jLaw ? "J(N)" : "J fixed"));
  onChange("hold", (el) => { s.hold = el.checked; }, () => (s.hold ? "held" : "free"));
  onChange("boardmass", () => { s.boardMass = boardMass.get(); },
    () => "m_b=" + s.boardMass.toPrecision(2));
  onChange("boarddamping", () => { s.boardDamping = boardDamping.get(); },
    () => "c_b=" + sci(s.boardDamping));
  onChange("platform", (el) => { s.platform = el.value; showPlatform(); }, () => s.platform);
  $("preset").addEventListener("input", () => { session.usePreset($("preset").value); showSettings(); });
  $("speed").addEventListener("input", showValues);
  $("mute").addEventListener("input", () => { clicks.muted = $("mute").checked; });
  $("restart").addEventListener("click", () => {
    session.restart(Math.floor(Math.random() * 4294967296));
    last = null;
    clock = 0;
  });

  function setPlaying(on) {
    playing = on;
    last = null;
    clock = session.t;
    $("play").textContent = on ? "Pause" : "Play";
    if (on) clicks.start();
  }
  $("play").addEventListener("click", () => setPlaying(!playing));
  document.addEventListener("keydown", (e) => {
    // Buttons, boxes and menus answer the space bar themselves; sliders do not.
    const own = ["SELECT", "BUTTON"].includes(e.target.tagName) || e.target.type === "checkbox";
    if (e.code === "Space" && !own) {
      e.preventDefault();
      setPlaying(!playing);
    }
  });

  const phases = new Float64Array(limits.n[1]);
  function showNumbers(o) {
    const rates = session.tickRates(), n = session.state.n, st = session.state;
    $("numbers").innerHTML =
      "<span>r</span><b id='r-value'>" + o.r.toFixed(3) + "</b>"
      + "<span>time</span><span>" + session.t.toFixed(1) + " s</span>"
      + "<span>tick rate</span><span>" + (rates.count ? rates.mean.toFixed(2) + " /min" : "–")
      + "</span><span>spread of rates</span><span>"
      + (rates.count ? rates.spread.toFixed(3) + " /min" : "–") + "</span>"
      + "<span>natural spread</span><span>" + session.naturalSpread().toFixed(3) + " BPM</span>"
      + "<span>running at</span><span>" + (playing ? achieved.toFixed(1) + "×" : "paused")
      + "</span><span>frames/s</span><span id='fps'>" + fps.toFixed(0) + "</span>";
    const notes = [];
    if (st.status & Physics.STATUS_DIVERGED) notes.push("the run diverged: press Restart.");
    if (st.status & Physics.STATUS_OVERTURNED) notes.push("a pendulum swung past the horizontal.");
    const rate = session.system.dampingRate, limit = config.max_damping_per_step;
    if (rate * session.dt > limit) {
      // As playground_config refuses such a start: the step cannot follow the damping.
      const board = session.settings.platform === "board";
      const value = board ? session.settings.boardDamping : session.settings.cPhi;
      notes.push((board ? "The board's damping " : "The disk's friction c_φ ") + sci(value)
        + " damps it at " + rate.toPrecision(3) + " /s, too fast for the step " + session.dt
        + " s: lower it to at most " + sci(value * limit / (rate * session.dt)) + ".");
    }
    if (session.clipped) notes.push(session.clipped + " of " + n + " frequencies clipped to the "
      + "tunable range.");
    const terms = modelTerms(session.constants);
    if (terms.length) notes.push("Beyond the paper: " + terms.join(", ") + ".");
    $("status").textContent = notes.join(" ");
  }

  // The model's terms beyond the paper that the preset switches on, in words; on the
  // board only the board's own (it reads none of the disk's fields).
  function modelTerms(c) {
    const terms = [], board = c.platform === "board";
    if (board) terms.push("the board on rollers (Pantaleone 2002)");
    if (c.forcing_amplitude) {
      terms.push((board ? "forcing " + sci(c.forcing_amplitude) + " N"
        : "forcing " + sci(c.forcing_amplitude) + " N m") + " at " + c.forcing_bpm + " BPM");
    }
    if (c.escapement_offset) terms.push("escapement at δ = " + c.escapement_offset + " rad");
    if (!board && !c.escapement_reaction) terms.push("no escapement reaction on the disk");
    if (!board && c.disk_dry_friction) {
      terms.push("dry friction " + sci(c.disk_dry_friction) + " N m");
    }
    if (board && c.board_dry_friction) {
      terms.push("dry friction " + sci(c.board_dry_friction) + " N");
    }
    if (c.tuning === "steady-swing") terms.push("steady-swing tuning");
    return terms;
  }

  // A canvas draws at the size the layout gives it (one canvas pixel per CSS pixel),
  // so it stays sharp and in proportion when the window is resized.
  function fit(canvas) {
    const w = Math.max(1, Math.round(canvas.clientWidth));
    const h = Math.max(1, Math.round(canvas.clientHeight));
    if (canvas.width !== w || canvas.height !== h) {
      canvas.width = w;
      canvas.height = h;
    }
  }

  function frame(now) {
    frames++;
    fpsFrames++;
    if (fpsSince === null) fpsSince = now;
    if (now - fpsSince >= 1000) {
      fps = fpsFrames * 1000 / (now - fpsSince);
      fpsFrames = 0;
      fpsSince = now;
    }
    if (playing) {
      const speed = Number($("speed").value);
      // A long pause (a hidden tab) must not be caught up all at once.
      const wall = last === null ? 0 : Math.min(now - last, 100) / 1000;
      last = now;
      // `clock` is where simulated time should be; steps follow it whole, so that no
      // fraction of a step is lost or gained from frame to frame.
      const before = session.t;
      clock = Math.max(clock, before) + wall * speed;
      const budget = performance.now() + 12;
      const chunk = Math.max(1, Math.ceil(0.02 / session.dt));
      let ticks = [];
      while (session.t + session.dt <= clock + 1e-9) {
        if (performance.now() > budget) { clock = session.t; break; }  // behind: drop it
        const steps = Math.min(chunk, Math.floor((clock - session.t) / session.dt + 1e-9));
        session.advance(Math.max(1, steps));
        ticks = ticks.concat(session.ticks);
        if (session.state.status & Physics.STATUS_DIVERGED) break;
      }
      const onBoard = session.settings.platform === "board";
      clicks.play(ticks, before, speed, session.state.n, onBoard ? null : session.state.phi);
      achievedSim += session.t - before;
      achievedWall += wall;
      if (achievedWall >= 0.5) {
        achieved = achievedSim / achievedWall;
        achievedSim = 0; achievedWall = 0;
      }
    }
    for (const g of Object.values(graphics)) fit(g.canvas);
    const o = Physics.order(session.state, session.system, phases);
    const platformView = session.settings.platform === "board" ? View.board : View.disk;
    platformView(graphics.disk, session, phases, session.settings.hold);
    View.wheel(graphics.wheel, phases, session.state.n, o.r, o.psi);
    View.side(graphics.side, session, phases, 4);
    const speed = Number($("speed").value);
    View.order(graphics.order, session, speed <= 5 ? 60 : 12 * speed);
    showNumbers(o);
    requestAnimationFrame(frame);
  }

  showSettings();
  window.metrosync = {
    version: config.version,
    config,
    session,
    clicks,
    run: (params, steps) => runTrajectories(config, params, steps),
    get frames() { return frames; },
    get fps() { return fps; },
    get playing() { return playing; },
    get r() { return Physics.order(session.state, session.system).r; },
  };
  requestAnimationFrame(frame);
})();
