// The paper's model and its fixed-step scheme, in JavaScript: line by line as
// metrosync's NumPy twin of the integrator (integrators/twin.py), which the
// package's tests compare with this file to 1e-9 over 10 000 steps, with every model
// term the capability table (metrosync/capabilities.py) says the playground runs.
//
// Tuning (model/metronome.py): ω = π·BPM/60 and L2 from ω²(m h² + J_i) = m g h; under
// the steady-swing tuning (theory/tuning.py) the same inversion of BPM/ρ(L2), iterated,
// with the per-design spline ρ(L2) that the package sends.
// Equations (equations.py): the solved form (eqm1)-(eqm2) with the sums A, B, C, D,
// the platform's force −c_φ φ̇ − r Σ𝕄 + A sin(Ω t) (r = 1 with the escapement's
// reaction on the disk, 0 without and always on the board) and its dry friction F_d
// (at most T). The disk and the board (Pantaleone 2002) are one coordinate φ with the
// same equations, written with the lever ℓ (R, or 1 m) and J_p (platformTerms): the
// R below is ℓ, J is J_p.
// Scheme (integrators/verlet.py), per step of length dt:
//   1. θ' = θ + θ̇ dt + a dt²/2
//   2. kick 𝕄_i = +M/dt if θ_i < δ < θ_i', −M/dt if θ_i > δ > θ_i', else 0
//      (δ the escapement's offset)
//   3. a' = f(θ', θ̇ + a dt, φ̇ + φ̈ dt, 𝕄, t'), with the dry friction held, slipping
//      (−T sign φ̇) or breaking free (±T) as the step starts
//   4. θ̇' = θ̇ + (a + a') dt/2
//   5. p_φ' = p_φ + (F + F') dt/2, F = −c_φ φ̇* − r Σ𝕄 + A sin(Ω t') + F_d, and φ̇'
//      recovered from p_φ' = (J + R²Σm) φ̇' + R Σ m h cos θ' θ̇'; a disk whose velocity
//      would pass 0 within the step stops (or reverses) with the friction's end value
//      solved for, as verlet.py's docstring says.
// A held disk has J = ∞: φ̇ = 0 and p_φ is not used.
// Every number comes from the configuration the page embeds; none is written here.
"use strict";

const Physics = (function () {
  const STATUS_OVERTURNED = 1, STATUS_DIVERGED = 2;

  // Slider position whose small-amplitude frequency is `bpm`
  // (MetronomeDesign.small_amplitude_l2, the larger root).
  function smallAmplitudeL2(d, bpm) {
    const m = d.w1 + d.w2, a = d.w1 * d.l1, w2sq = d.w2 * d.w2;
    const omega = Math.PI * bpm / 60.0, omegaSq = omega * omega;
    const qa = omegaSq * (w2sq / m + d.w2);
    const qb = -2.0 * omegaSq * a * d.w2 / m + d.g * d.w2;
    const qc = omegaSq * (a * a / m + d.w1 * d.l1 * d.l1) - d.g * a;
    const disc = Math.sqrt(Math.max(qb * qb - 4.0 * qa * qc, 0.0));
    return (-qb + disc) / (2.0 * qa);
  }

  // The spline ρ(L2) of a steady-swing table (scipy's CubicSpline: on [x_k, x_k+1],
  // Σ_j c[k][j] (L2 − x_k)^(3−j), the end pieces extended beyond the knots).
  function spline(table, x) {
    const knots = table.knots;
    let k = 0;
    while (k < knots.length - 2 && x >= knots[k + 1]) k++;
    const dx = x - knots[k], c = table.coefficients[k];
    let value = 0.0, power = 1.0;  // summed from the constant term up, as scipy does
    for (let j = c.length - 1; j >= 0; j--) {
      value += c[j] * power;
      power *= dx;
    }
    return value;
  }

  // Slider position for a nominal BPM under the design's tuning (l2_for_bpm): the
  // small-amplitude inversion, or for "steady-swing" the iteration of
  // theory/tuning.py's steady_swing_l2 with the table `d.steady_swing` it sends.
  function l2ForBpm(d, bpm) {
    if (d.tuning !== "steady-swing") return smallAmplitudeL2(d, bpm);
    const table = d.steady_swing;
    if (!table) throw new Error("the steady-swing tuning needs its spline from the package");
    if (d.drive !== table.drive || d.c_theta !== table.c_theta) {
      throw new Error("the steady-swing spline was made for another drive or friction");
    }
    const [lo, hi] = d.l2_bounds, [natLo, natHi] = table.natural_range;
    let x = (lo + hi) / 2;
    for (let round = 0; round < table.max_rounds; round++) {
      const target = Math.min(natHi, Math.max(natLo, bpm / spline(table, x)));
      const next = smallAmplitudeL2(d, target);
      const done = Math.abs(next - x) < 1e-14;
      x = next;
      if (done) break;
    }
    return x;
  }

  // Energy-balance amplitude 2M/(π c_θ), rad (model.metronome.balance_amplitude).
  function steadyAmplitude(drive, cTheta) {
    if (cTheta === 0) return drive > 0 ? Infinity : 0.0;
    return 2.0 * drive / (Math.PI * cTheta);
  }

  // The platform's constants (model/platform.py, Platform.terms): the lever ℓ (the
  // disk's R, or 1 m for the board), its own inertia J_p (the disk's J(N) law or fixed
  // J, kg m²; the board's mass with the rollers' and the N cases', kg), its damping and
  // dry friction, and whether the escapement's reaction acts on it (never on the
  // board). Everything after this reads only these, so the board runs the disk's step.
  function platformTerms(c, n) {
    if (c.platform === "board") {
      return {
        lever: 1.0, own: c.board_mass + c.roller_mass + n * c.box_mass,
        damping: c.board_damping, dryFriction: c.board_dry_friction, reaction: 0.0,
      };
    }
    return {
      lever: c.radius, own: c.inertia === null ? c.j0 + n * c.j_per_metronome : c.inertia,
      damping: c.c_phi, dryFriction: c.disk_dry_friction,
      reaction: c.escapement_reaction ? 1.0 : 0.0,
    };
  }

  // Per-metronome and platform constants (model/system.py's system_arrays, one run).
  // c: the model's constants (metronome design and platform fields by name);
  // freqs: natural frequencies, BPM; hold: pin the platform (J_p = ∞).
  function buildSystem(c, freqs, hold) {
    const n = freqs.length, terms = platformTerms(c, n);
    const sys = {
      n, l2: new Float64Array(n), mh: new Float64Array(n), mgh: new Float64Array(n),
      inertia: new Float64Array(n), cTheta: new Float64Array(n), drive: new Float64Array(n),
      omega: new Float64Array(n), offset: new Float64Array(n), lever: terms.lever,
      cPhi: terms.damping, totalInertia: 0.0, ownInertia: terms.own,
      forcingAmplitude: c.forcing_amplitude, forcingOmega: Math.PI * c.forcing_bpm / 60.0,
      reaction: terms.reaction, dryFriction: terms.dryFriction,
    };
    const mass = c.w1 + c.w2;
    let massSum = 0.0, hanging = 0.0;
    for (let i = 0; i < n; i++) {
      const l2 = l2ForBpm(c, freqs[i]);
      const h = (c.w1 * c.l1 - c.w2 * l2) / mass;
      const ji = c.w1 * (c.l1 * c.l1) + c.w2 * (l2 * l2);
      sys.l2[i] = l2;
      sys.inertia[i] = mass * (h * h) + ji;
      sys.omega[i] = Math.sqrt(mass * c.g * h / sys.inertia[i]);
      sys.mh[i] = mass * h;
      sys.mgh[i] = mass * c.g * h;
      sys.cTheta[i] = c.c_theta;
      sys.drive[i] = c.drive;
      sys.offset[i] = c.escapement_offset;
      massSum += mass;
      hanging += sys.mh[i] * sys.mh[i] / sys.inertia[i];
    }
    sys.totalInertia = hold ? Infinity : sys.ownInertia + (terms.lever * terms.lever) * massSum;
    // The damping rate c/D₀ (D₀: eq. (eqm1)'s denominator, pendulums hanging), which the
    // step must resolve (playground.damping_rate); 0 for a held platform.
    sys.dampingRate = hold ? 0.0
      : sys.cPhi / (sys.totalInertia - (terms.lever * terms.lever) * hanging);
    return sys;
  }

  // The disk's torque from outside the pendulums' swing at time t (equations.disk_torque):
  // bearing friction, the escapement's reaction and the applied torque A sin(Ω t).
  function diskTorque(sys, phd, sumKick, t) {
    return -sys.cPhi * phd - sys.reaction * sumKick
      + sys.forcingAmplitude * Math.sin(sys.forcingOmega * t);
  }

  // The Coulomb law (equations.dry_friction): −T sign φ̇ on a moving disk; at rest the
  // holding torque clipped to ±T.
  function dryFriction(sys, phd, holding) {
    const limit = sys.dryFriction;
    return phd !== 0 ? -limit * Math.sign(phd) : Math.min(limit, Math.max(-limit, holding));
  }

  // Numerator without dry friction and denominator D of eq. (eqm1) (equations.
  // _disk_equation); cos θ and sin θ are left in cosOut and sinOut.
  function diskEquation(sys, th, thd, phd, kick, t, cosOut, sinOut) {
    const n = sys.n, lever = sys.lever;
    let sum1 = 0.0, sumKick = 0.0, sumAbc = 0.0, sumD = 0.0;
    for (let i = 0; i < n; i++) {
      const s = Math.sin(th[i]), co = Math.cos(th[i]);
      cosOut[i] = co;
      sinOut[i] = s;
      const mhOverI = sys.mh[i] / sys.inertia[i];
      const a = lever * mhOverI * sys.mgh[i] * s * co;
      const b = lever * mhOverI * sys.cTheta[i] * thd[i] * co;
      const cc = lever * mhOverI * kick[i] * co;
      const rm = lever * sys.mh[i];
      sumD += rm * rm / sys.inertia[i] * (co * co);
      sum1 += sys.mh[i] * (thd[i] * thd[i]) * s;
      sumKick += kick[i];
      sumAbc += a + b - cc;
    }
    const numerator = lever * sum1 + diskTorque(sys, phd, sumKick, t) + sumAbc;
    return { numerator, denominator: sys.totalInertia - sumD, sumKick };
  }

  // Solved equations of motion, eqs. (eqm1)-(eqm2), from the disk's equation `eq` and
  // its dry-friction torque; writes θ̈ into thdd, returns φ̈.
  function solve(sys, eq, friction, thd, kick, thdd, cos, sin) {
    const phdd = (eq.numerator + friction) / eq.denominator;
    for (let i = 0; i < sys.n; i++) {
      thdd[i] = (kick[i] - sys.lever * sys.mh[i] * phdd * cos[i] - sys.mgh[i] * sin[i]
        - sys.cTheta[i] * thd[i]) / sys.inertia[i];
    }
    return phdd;
  }

  // equations.accelerations: the dry friction by its law at φ̇; returns φ̈.
  function accelerations(sys, th, thd, phd, kick, t, thdd, cosOut, sinOut) {
    const eq = diskEquation(sys, th, thd, phd, kick, t, cosOut, sinOut);
    const friction = dryFriction(sys, phd, -eq.numerator);
    return solve(sys, eq, friction, thd, kick, thdd, cosOut, sinOut);
  }

  // The disk's angular momentum (observables.mechanics.platform_momentum).
  function momentum(sys, th, thd, phd) {
    if (sys.totalInertia === Infinity) return 0.0;
    let coupling = 0.0;
    for (let i = 0; i < sys.n; i++) coupling += sys.mh[i] * Math.cos(th[i]) * thd[i];
    return sys.totalInertia * phd + sys.lever * coupling;
  }

  // A state from positions and velocities (StepState.start): the derived quantities
  // (accelerations, p_φ, the disk's torque) are evaluated for the system `sys` at time
  // step·dt (0 for a new run).
  function startState(sys, theta, thetaDot, phi, phiDot, t = 0.0) {
    const n = sys.n;
    const st = {
      n, theta: Float64Array.from(theta), thetaDot: Float64Array.from(thetaDot),
      phi, phiDot: sys.totalInertia === Infinity ? 0.0 : phiDot,
      accTheta: new Float64Array(n), accPhi: 0.0, pPhi: 0.0, forcePhi: 0.0,
      status: 0, step: 0,
      // scratch
      thNew: new Float64Array(n), velPred: new Float64Array(n), kick: new Float64Array(n),
      thdd: new Float64Array(n), thdNew: new Float64Array(n), cos: new Float64Array(n),
      sin: new Float64Array(n),
    };
    const eq = diskEquation(sys, st.theta, st.thetaDot, st.phiDot, st.kick, t, st.cos, st.sin);
    const friction = dryFriction(sys, st.phiDot, -eq.numerator);
    st.accPhi = solve(sys, eq, friction, st.thetaDot, st.kick, st.accTheta, st.cos, st.sin);
    st.pPhi = momentum(sys, st.theta, st.thetaDot, st.phiDot);
    st.forcePhi = diskTorque(sys, st.phiDot, 0.0, t)
      + (sys.totalInertia === Infinity ? 0.0 : friction);
    if (!Number.isFinite(st.accPhi)) st.status |= STATUS_DIVERGED;
    return st;
  }

  // θ̇' = θ̇ + (a + a') dt/2 into out; returns R Σ m h cos θ' θ̇'.
  function newVelocities(sys, st, thdd, dt, out) {
    let coupling = 0.0;
    for (let i = 0; i < sys.n; i++) {
      out[i] = st.thetaDot[i] + 0.5 * (st.accTheta[i] + thdd[i]) * dt;
      coupling += sys.mh[i] * st.cos[i] * out[i];
    }
    return sys.lever * coupling;
  }

  // Advance `st` by one step of length dt. onTick(i, t, up), if given, hears of every
  // zero crossing (a tick of the escapement) at its linearly interpolated time.
  function step(st, sys, dt, overturnAngle, onTick) {
    if (st.status & STATUS_DIVERGED) return false;
    const n = st.n, th = st.theta, thd = st.thetaDot, acc = st.accTheta;
    const thNew = st.thNew, vel = st.velPred, kick = st.kick, thdd = st.thdd;
    const thdNew = st.thdNew;
    const tOld = st.step * dt, tNew = (st.step + 1) * dt;
    const phdPred = st.phiDot + st.accPhi * dt;
    const rigid = sys.totalInertia === Infinity, limit = sys.dryFriction;
    const dry = limit > 0 && !rigid;
    let overturned = false;
    for (let i = 0; i < n; i++) {
      thNew[i] = th[i] + thd[i] * dt + 0.5 * acc[i] * dt * dt;
      vel[i] = thd[i] + acc[i] * dt;
      const at = sys.offset[i];
      const up = th[i] < at && thNew[i] > at, down = th[i] > at && thNew[i] < at;
      kick[i] = up ? sys.drive[i] / dt : down ? -(sys.drive[i] / dt) : 0.0;
      if (onTick && ((th[i] < 0 && thNew[i] > 0) || (th[i] > 0 && thNew[i] < 0))) {
        onTick(i, tOld + dt * th[i] / (th[i] - thNew[i]), th[i] < 0);
      }
      if (Math.abs(thNew[i]) > overturnAngle) overturned = true;
    }
    if (overturned) st.status |= STATUS_OVERTURNED;
    const eq = diskEquation(sys, thNew, vel, phdPred, kick, tNew, st.cos, st.sin);
    const others = diskTorque(sys, phdPred, eq.sumKick, tNew);
    // The dry friction as the step starts (twin._Step._dry_friction): held at rest when
    // the holding torque is within ±T.
    const holding = -eq.numerator;
    let friction = dry ? dryFriction(sys, st.phiDot, holding) : 0.0;
    let held = dry && st.phiDot === 0 && Math.abs(holding) <= limit;
    let phdd = solve(sys, eq, friction, vel, kick, thdd, st.cos, st.sin);
    if (!Number.isFinite(phdd)) {
      st.status |= STATUS_DIVERGED;
      return false;
    }
    let force = others + friction;
    let coupling = newVelocities(sys, st, thdd, dt, thdNew);
    let newP = st.pPhi + 0.5 * (st.forcePhi + force) * dt;
    if (dry && !held && friction * ((newP - coupling) / sys.totalInertia) >= 0) {
      // The disk's velocity reached 0 within the step (twin._friction_at_stop):
      // the friction's end value that stops it, if within ±T, else the reversed one.
      const velocity = (newP - coupling) / sys.totalInertia;
      const stop = friction - 2.0 * eq.denominator * velocity / dt;
      const stops = Math.abs(stop) <= limit;
      const end = stops ? stop : -friction;
      solve(sys, eq, end, vel, kick, thdd, st.cos, st.sin);
      coupling = newVelocities(sys, st, thdd, dt, thdNew);
      newP = st.pPhi + 0.5 * (st.forcePhi + others + end) * dt;
      friction = stops ? dryFriction(sys, 0.0, holding) : end;
      phdd = solve(sys, eq, friction, vel, kick, thdd, st.cos, st.sin);
      force = others + friction;
      held = held || stops;
    }
    if (held) newP = coupling;  // a disk at rest: p_φ = R Σ m h cos θ θ̇
    for (let i = 0; i < n; i++) {
      th[i] = thNew[i];
      thd[i] = thdNew[i];
      acc[i] = thdd[i];
    }
    st.phi += st.phiDot * dt + 0.5 * st.accPhi * dt * dt;
    if (!rigid) st.pPhi = newP;
    st.phiDot = rigid ? 0.0 : (newP - coupling) / sys.totalInertia;
    st.forcePhi = force;
    st.accPhi = phdd;
    st.step += 1;
    return true;
  }

  // Each metronome's analytic phase atan2(−θ̇/ω, θ) and the order parameter r e^{iψ}
  // built from it (the package's recorded `r`).
  function order(st, sys, phases) {
    let re = 0.0, im = 0.0;
    for (let i = 0; i < st.n; i++) {
      const x = st.theta[i], y = -st.thetaDot[i] / sys.omega[i];
      const rho = Math.hypot(x, y);
      if (rho > 0) { re += x / rho; im += y / rho; }
      if (phases) phases[i] = Math.atan2(y, x);
    }
    return { r: Math.hypot(re, im) / st.n, psi: Math.atan2(im, re) };
  }

  return {
    STATUS_OVERTURNED, STATUS_DIVERGED, smallAmplitudeL2, l2ForBpm, steadyAmplitude,
    platformTerms, buildSystem, accelerations, momentum, startState, step, order,
  };
})();
