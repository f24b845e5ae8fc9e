// A live run: the controls' settings, the metronomes, and the state that Physics
// advances. A change of setting keeps the current positions and velocities and
// re-evaluates what depends on the constants (accelerations, the disk's momentum),
// exactly as a new run started from the current state would.
"use strict";

// A small seeded generator (mulberry32), so that a seed shown on the page repeats a start.
function seededRandom(seed) {
  let a = seed >>> 0;
  return function () {
    a = (a + 0x6D2B79F5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

function normalFrom(random) {
  const u = 1.0 - random(), v = random();
  return Math.sqrt(-2.0 * Math.log(u)) * Math.cos(2.0 * Math.PI * v);
}

class Session {
  // config: the JSON the page embeds (presets, the start's settings, dt, limits).
  constructor(config) {
    this.config = config;
    this.dt = config.dt;
    this.overturnAngle = config.overturn_angle;
    const s = config.start;
    this.settings = {
      preset: s.preset, n: s.n, bpm: s.bpm, sigma: s.sigma_bpm, groups: 1, offset: 0.0,
      hold: Boolean(s.hold), jLaw: true, j: null, cPhi: null, drive: null,
      platform: "disk", boardMass: null, boardDamping: null,
    };
    this.seed = s.seed;
    this.z = [];           // each metronome's standard-normal draw: f_i = bpm + σ z_i
    this.clipped = 0;      // how many frequencies the tunable range cut
    this.t = 0.0;
    this.history = [];     // [t, r] every recordInterval of simulated time
    this.recordInterval = 0.1;
    this.markers = [];     // [t, label]: when a setting changed
    this.lastUp = [];      // per metronome: its last few upward crossing times
    this.ratePeriods = 4;  // tick rates average over this many periods
    this.ticks = [];       // crossings of the last advance: [i, t]
    this.tickCount = 0;    // crossings since the page opened
    this.boardCentre = null;  // {x, t}: the board's mean position, for View.board
    this.usePreset(s.preset, false);
    this.restart(this.seed);
  }

  get constants() {
    const base = this.config.presets[this.settings.preset].constants;
    const c = Object.assign({}, base);
    if (this.settings.drive !== null) c.drive = this.settings.drive;
    c.platform = this.settings.platform;
    if (c.platform === "board") {
      // The disk's fields stay the preset's: the board reads none of them.
      c.board_mass = this.settings.boardMass;
      c.board_damping = this.settings.boardDamping;
      return c;
    }
    if (this.settings.cPhi !== null) c.c_phi = this.settings.cPhi;
    if (!this.settings.jLaw) c.inertia = this.settings.j;
    return c;
  }

  get preset() { return this.config.presets[this.settings.preset]; }

  usePreset(name, rebuild = true) {
    this.settings.preset = name;
    const c = this.preset.constants;
    this.settings.drive = c.drive;
    this.settings.cPhi = c.c_phi;
    this.settings.platform = c.platform;
    this.settings.boardMass = c.board_mass;
    this.settings.boardDamping = c.board_damping;
    this.settings.jLaw = c.inertia === null;
    if (this.preset.held) this.settings.hold = true;
    this.settings.j = c.inertia === null ? c.j0 + this.settings.n * c.j_per_metronome : c.inertia;
    if (rebuild) this.rebuild("preset " + name);
  }

  // Natural frequencies: group 2 (every other metronome) sits `offset` BPM higher;
  // draws outside the tunable range are clipped to it (and counted).
  frequencies() {
    const [low, high] = this.preset.bpm_range, f = [];
    this.clipped = 0;
    for (let i = 0; i < this.settings.n; i++) {
      const base = this.settings.bpm + (this.settings.groups === 2 && i % 2 ? this.settings.offset : 0);
      let v = base + this.settings.sigma * this.z[i];
      if (v < low || v > high) { v = Math.min(high, Math.max(low, v)); this.clipped++; }
      f.push(v);
    }
    return f;
  }

  startAmplitude() {
    const c = this.constants, a = Physics.steadyAmplitude(c.drive, c.c_theta);
    // Without drive the steady swing is 0 (or, without friction, unbounded): start
    // from the preset's own swing instead, so that there is something to watch.
    return a > 0 && Number.isFinite(a)
      ? a : Physics.steadyAmplitude(this.preset.constants.drive, this.preset.constants.c_theta);
  }

  // New random phases at the steady swing; the metronomes (their draws z_i) are kept.
  restart(seed) {
    this.seed = seed >>> 0;
    const random = seededRandom(this.seed);
    while (this.z.length < this.settings.n) this.z.push(normalFrom(random));
    this.system = Physics.buildSystem(this.constants, this.frequencies(), this.settings.hold);
    const amp = this.startAmplitude(), n = this.settings.n;
    const theta = [], thetaDot = [];
    for (let i = 0; i < n; i++) {
      const p = 2 * Math.PI * random();
      theta.push(amp * Math.cos(p));
      thetaDot.push(-amp * this.system.omega[i] * Math.sin(p));
    }
    this.state = Physics.startState(this.system, theta, thetaDot, 0.0, 0.0);
    this.builtPlatform = this.settings.platform;
    this.boardCentre = null;
    this.t = 0.0;
    this.history = [];
    this.markers = [];
    this.lastUp = Array.from({ length: n }, () => []);
    this.record();
  }

  // Apply the current settings and continue from the present positions and velocities.
  // New metronomes (N raised) join at random phases; removed ones leave from the end.
  rebuild(label) {
    const old = this.state, n = this.settings.n, random = seededRandom(this.seed + old.step);
    while (this.z.length < n) this.z.push(normalFrom(random));
    if (this.settings.jLaw) {
      const c = this.preset.constants;
      this.settings.j = c.j0 + n * c.j_per_metronome;
    }
    this.system = Physics.buildSystem(this.constants, this.frequencies(), this.settings.hold);
    const theta = [], thetaDot = [], amp = this.startAmplitude();
    for (let i = 0; i < n; i++) {
      if (i < old.n) {
        theta.push(old.theta[i]);
        thetaDot.push(old.thetaDot[i]);
      } else {
        const p = 2 * Math.PI * random();
        theta.push(amp * Math.cos(p));
        thetaDot.push(-amp * this.system.omega[i] * Math.sin(p));
      }
    }
    while (this.lastUp.length < n) this.lastUp.push([]);
    this.lastUp.length = n;
    // Another platform starts at rest: φ (rad on the disk, m on the board) and its
    // velocity mean nothing on the other.
    const same = this.builtPlatform === this.settings.platform;
    this.builtPlatform = this.settings.platform;
    if (!same) this.boardCentre = null;
    const st = Physics.startState(this.system, theta, thetaDot, same ? old.phi : 0.0,
      same ? old.phiDot : 0.0, old.step * this.dt);
    st.step = old.step;
    st.status = old.status & Physics.STATUS_OVERTURNED;
    this.state = st;
    if (label) this.markers.push([this.t, label]);
  }

  // Advance by `steps` steps; the crossings met are left in this.ticks.
  advance(steps) {
    this.ticks.length = 0;
    const onTick = (i, t, up) => {
      this.ticks.push([i, t]);
      this.tickCount++;
      if (up) {
        const times = this.lastUp[i];
        times.push(t);
        if (times.length > this.ratePeriods + 1) times.shift();
      }
    };
    for (let k = 0; k < steps; k++) {
      if (!Physics.step(this.state, this.system, this.dt, this.overturnAngle, onTick)) break;
      this.t = this.state.step * this.dt;
      const last = this.history.length ? this.history[this.history.length - 1][0] : -Infinity;
      if (this.t - last >= this.recordInterval - 1e-9) this.record();
    }
  }

  record() {
    this.history.push([this.t, Physics.order(this.state, this.system).r]);
    // Ten minutes of history at 10 per second is plenty for the scrolling plot.
    if (this.history.length > 6000) this.history.splice(0, this.history.length - 6000);
  }

  // Tick rates (ticks per minute, two per period) over the last few full periods of
  // each metronome that has one; their mean and standard deviation.
  tickRates() {
    const rates = [];
    for (const times of this.lastUp) {
      const k = times.length - 1;
      if (k >= 1) rates.push(120.0 * k / (times[k] - times[0]));
    }
    if (!rates.length) return { count: 0, mean: NaN, spread: NaN };
    const mean = rates.reduce((s, v) => s + v, 0) / rates.length;
    const variance = rates.reduce((s, v) => s + (v - mean) * (v - mean), 0) / rates.length;
    return { count: rates.length, mean, spread: Math.sqrt(variance) };
  }

  naturalSpread() {
    const f = Array.from(this.system.omega, (w) => 60.0 * w / Math.PI);
    const mean = f.reduce((s, v) => s + v, 0) / f.length;
    return Math.sqrt(f.reduce((s, v) => s + (v - mean) * (v - mean), 0) / f.length);
  }
}

// The physics as a pure function, for tests and for anyone who wants numbers:
// run(params, steps) -> trajectories, recorded every `record_every` steps (default 1).
// params: preset (name, default the page's), changes ({drive, c_phi, inertia, platform,
// board_mass, ...} by the package's names), hold (pin the platform), frequencies_bpm, theta0, theta_dot0
// (default 0), phi_dot0 (default 0), dt (default the page's).
function runTrajectories(config, params, steps) {
  const preset = config.presets[params.preset || config.start.preset];
  if (!preset) throw new Error("unknown preset " + JSON.stringify(params.preset));
  const c = Object.assign({}, preset.constants, params.changes || {});
  const freqs = params.frequencies_bpm, n = freqs.length, every = params.record_every || 1;
  const dt = params.dt || config.dt;
  const sys = Physics.buildSystem(c, freqs, Boolean(params.hold));
  const st = Physics.startState(sys, params.theta0, params.theta_dot0 || new Array(n).fill(0),
    0.0, params.phi_dot0 || 0.0);
  const out = { time: [], theta: [], theta_dot: [], phi: [], phi_dot: [], r: [], status: 0 };
  const keep = () => {
    out.time.push(st.step * dt);
    out.theta.push(Array.from(st.theta));
    out.theta_dot.push(Array.from(st.thetaDot));
    out.phi.push(st.phi);
    out.phi_dot.push(st.phiDot);
    out.r.push(Physics.order(st, sys).r);
  };
  keep();
  for (let k = 0; k < steps; k++) {
    if (!Physics.step(st, sys, dt, config.overturn_angle, null)) break;
    if ((k + 1) % every === 0) keep();
  }
  out.status = st.status;
  out.l2 = Array.from(sys.l2);
  return out;
}
