// The paper's model and its fixed-step scheme, in JavaScript: a line-by-line twin of
// metrosync's NumPy reference integrator (integrators/reference.py), which the
// package's tests compare with this file to 1e-9 over 10 000 steps.
//
// Tuning (model/metronome.py): ω = π·BPM/60 and L2 from ω²(m h² + J_i) = m g h.
// Equations (equations.py): the solved form (eqm1)-(eqm2) with the sums A, B, C, D.
// Scheme (integrators/verlet.py), per step of length dt:
//   1. θ' = θ + θ̇ dt + a dt²/2
//   2. kick 𝕄_i = +M/dt if θ_i < 0 < θ_i', −M/dt if θ_i > 0 > θ_i', else 0
//   3. a' = f(θ', θ̇ + a dt, φ̇ + φ̈ dt, 𝕄)
//   4. θ̇' = θ̇ + (a + a') dt/2
//   5. p_φ' = p_φ + (F + F') dt/2, F = −c_φ φ̇* − Σ𝕄, and φ̇' recovered from
//      p_φ' = (J + R²Σm) φ̇' + R Σ m h cos θ' θ̇'.
// A held disk has J = ∞: φ̇ = 0 and p_φ is not used.
// Every number comes from the configuration the page embeds; none is written here.
"use strict";

const Physics = (function () {
  const STATUS_OVERTURNED = 1, STATUS_DIVERGED = 2;

  // Slider position for a nominal BPM (MetronomeDesign.l2_for_bpm, the larger root).
  function l2ForBpm(d, bpm) {
    const m = d.w1 + d.w2, a = d.w1 * d.l1, w2sq = d.w2 * d.w2;
    const omega = Math.PI * bpm / 60.0, omegaSq = omega * omega;
    const qa = omegaSq * (w2sq / m + d.w2);
    const qb = -2.0 * omegaSq * a * d.w2 / m + d.g * d.w2;
    const qc = omegaSq * (a * a / m + d.w1 * d.l1 * d.l1) - d.g * a;
    const disc = Math.sqrt(Math.max(qb * qb - 4.0 * qa * qc, 0.0));
    return (-qb + disc) / (2.0 * qa);
  }

  // Energy-balance amplitude 2M/(π c_θ), rad (model.metronome.steady_amplitude).
  function steadyAmplitude(drive, cTheta) {
    if (cTheta === 0) return drive > 0 ? Infinity : 0.0;
    return 2.0 * drive / (Math.PI * cTheta);
  }

  // Per-metronome and disk constants (ensemble.build_ensemble, one run).
  // c: the model's constants (metronome design and platform fields by name);
  // freqs: natural frequencies, BPM; hold: pin the disk (J = ∞).
  function buildSystem(c, freqs, hold) {
    const n = freqs.length;
    const sys = {
      n, l2: new Float64Array(n), mh: new Float64Array(n), mgh: new Float64Array(n),
      inertia: new Float64Array(n), cTheta: new Float64Array(n), drive: new Float64Array(n),
      omega: new Float64Array(n), radius: c.radius, cPhi: c.c_phi, totalInertia: 0.0,
      diskInertia: 0.0,
    };
    const mass = c.w1 + c.w2;
    let massSum = 0.0;
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
      massSum += mass;
    }
    sys.diskInertia = c.inertia === null ? c.j0 + n * c.j_per_metronome : c.inertia;
    sys.totalInertia = hold ? Infinity : sys.diskInertia + (c.radius * c.radius) * massSum;
    return sys;
  }

  // Solved equations of motion, eqs. (eqm1)-(eqm2); writes θ̈ into thdd, returns φ̈.
  // cos θ is left in cosOut for the momentum that follows; sinOut is scratch.
  function accelerations(sys, th, thd, phd, kick, thdd, cosOut, sinOut) {
    const n = sys.n, radius = sys.radius;
    let sum1 = 0.0, sumKick = 0.0, sumAbc = 0.0, sumD = 0.0;
    for (let i = 0; i < n; i++) {
      const s = Math.sin(th[i]), co = Math.cos(th[i]);
      cosOut[i] = co;
      sinOut[i] = s;
      const mhOverI = sys.mh[i] / sys.inertia[i];
      const a = radius * mhOverI * sys.mgh[i] * s * co;
      const b = radius * mhOverI * sys.cTheta[i] * thd[i] * co;
      const cc = radius * mhOverI * kick[i] * co;
      const rm = radius * sys.mh[i];
      sumD += rm * rm / sys.inertia[i] * (co * co);
      sum1 += sys.mh[i] * (thd[i] * thd[i]) * s;
      sumKick += kick[i];
      sumAbc += a + b - cc;
    }
    const phdd = (radius * sum1 - sys.cPhi * phd - sumKick + sumAbc) / (sys.totalInertia - sumD);
    for (let i = 0; i < n; i++) {
      thdd[i] = (kick[i] - radius * sys.mh[i] * phdd * cosOut[i] - sys.mgh[i] * sinOut[i]
        - sys.cTheta[i] * thd[i]) / sys.inertia[i];
    }
    return phdd;
  }

  // The disk's angular momentum (observables.mechanics.platform_momentum).
  function momentum(sys, th, thd, phd) {
    if (sys.totalInertia === Infinity) return 0.0;
    let coupling = 0.0;
    for (let i = 0; i < sys.n; i++) coupling += sys.mh[i] * Math.cos(th[i]) * thd[i];
    return sys.totalInertia * phd + sys.radius * coupling;
  }

  // A state from positions and velocities (StepState.start): the derived quantities
  // (accelerations, p_φ, the disk's torque) are evaluated for the system `sys`.
  function startState(sys, theta, thetaDot, phi, phiDot) {
    const n = sys.n;
    const st = {
      n, theta: Float64Array.from(theta), thetaDot: Float64Array.from(thetaDot),
      phi, phiDot: sys.totalInertia === Infinity ? 0.0 : phiDot,
      accTheta: new Float64Array(n), accPhi: 0.0, pPhi: 0.0, forcePhi: 0.0,
      status: 0, step: 0,
      // scratch
      thNew: new Float64Array(n), velPred: new Float64Array(n), kick: new Float64Array(n),
      thdd: new Float64Array(n), cos: new Float64Array(n), sin: new Float64Array(n),
    };
    st.accPhi = accelerations(sys, st.theta, st.thetaDot, st.phiDot, st.kick, st.accTheta, st.cos,
      st.sin);
    st.pPhi = momentum(sys, st.theta, st.thetaDot, st.phiDot);
    st.forcePhi = -sys.cPhi * st.phiDot;
    if (!Number.isFinite(st.accPhi)) st.status |= STATUS_DIVERGED;
    return st;
  }

  // Advance `st` by one step of length dt. onTick(i, t, up), if given, hears of every
  // zero crossing (a tick of the escapement) at its linearly interpolated time.
  function step(st, sys, dt, overturnAngle, onTick) {
    if (st.status & STATUS_DIVERGED) return false;
    const n = st.n, th = st.theta, thd = st.thetaDot, acc = st.accTheta;
    const thNew = st.thNew, vel = st.velPred, kick = st.kick;
    const tOld = st.step * dt;
    const phdPred = st.phiDot + st.accPhi * dt;
    let overturned = false;
    for (let i = 0; i < n; i++) {
      thNew[i] = th[i] + thd[i] * dt + 0.5 * acc[i] * dt * dt;
      vel[i] = thd[i] + acc[i] * dt;
      const up = th[i] < 0 && thNew[i] > 0, down = th[i] > 0 && thNew[i] < 0;
      kick[i] = up ? sys.drive[i] / dt : down ? -sys.drive[i] / dt : 0.0;
      if ((up || down) && onTick) onTick(i, tOld + dt * th[i] / (th[i] - thNew[i]), up);
      if (Math.abs(thNew[i]) > overturnAngle) overturned = true;
    }
    if (overturned) st.status |= STATUS_OVERTURNED;
    const phdd = accelerations(sys, thNew, vel, phdPred, kick, st.thdd, st.cos, st.sin);
    if (!Number.isFinite(phdd)) {
      st.status |= STATUS_DIVERGED;
      return false;
    }
    let sumKick = 0.0, coupling = 0.0;
    for (let i = 0; i < n; i++) {
      sumKick += kick[i];
      const newThd = thd[i] + 0.5 * (acc[i] + st.thdd[i]) * dt;
      coupling += sys.mh[i] * st.cos[i] * newThd;
      th[i] = thNew[i];
      thd[i] = newThd;
      acc[i] = st.thdd[i];
    }
    const force = -sys.cPhi * phdPred - sumKick;
    const rigid = sys.totalInertia === Infinity;
    const newP = st.pPhi + 0.5 * (st.forcePhi + force) * dt;
    st.phi += st.phiDot * dt + 0.5 * st.accPhi * dt * dt;
    if (!rigid) st.pPhi = newP;
    st.phiDot = rigid ? 0.0 : (newP - sys.radius * coupling) / sys.totalInertia;
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
    STATUS_OVERTURNED, STATUS_DIVERGED, l2ForBpm, steadyAmplitude, buildSystem,
    accelerations, momentum, startState, step, order,
  };
})();
