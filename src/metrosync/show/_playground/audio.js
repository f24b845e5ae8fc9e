// A click for every tick through the Web Audio API, panned by where the metronome
// sits on the disk (left to right as seen from the front). Browsers only start audio
// after a user gesture, so the context is made on the first press of Play.
"use strict";

class Clicks {
  constructor() {
    this.context = null;
    this.muted = false;
    this.scheduled = 0;   // clicks handed to the audio graph so far
    this.lead = 0.06;     // s: scheduling margin ahead of the audio clock
    this.maxPerFrame = 120;
  }

  // Called from a user gesture. Returns false where the browser has no Web Audio.
  start() {
    if (this.context) {
      if (this.context.state === "suspended") this.context.resume();
      return true;
    }
    const Context = window.AudioContext || window.webkitAudioContext;
    if (!Context) return false;
    const ctx = new Context();
    // A short decaying noise burst: what a metronome's escapement sounds like, roughly.
    const length = Math.round(0.012 * ctx.sampleRate);
    this.buffer = ctx.createBuffer(1, length, ctx.sampleRate);
    const data = this.buffer.getChannelData(0);
    let seed = 1;
    for (let k = 0; k < length; k++) {
      seed = (seed * 16807) % 2147483647;
      data[k] = (2 * seed / 2147483647 - 1) * Math.exp(-k / (0.0025 * ctx.sampleRate));
    }
    // Ticks that come together add up: a compressor keeps a synchronized crowd bearable.
    this.output = ctx.createDynamicsCompressor();
    this.output.connect(ctx.destination);
    this.context = ctx;
    return true;
  }

  // ticks: [i, t] with t in simulated seconds between tFrom and the present; they are
  // played spread over the next frame, at the speed the simulation ran.
  play(ticks, tFrom, speed, n, phi) {
    // A context still starting ("suspended") queues the clicks and plays them once it runs.
    if (!this.context || this.muted || this.context.state === "closed" || !ticks.length) return;
    const ctx = this.context, now = ctx.currentTime + this.lead;
    // At high speed and large N there are thousands of ticks a second; play a sample
    // of them, louder, rather than flood the audio thread.
    const stride = Math.ceil(ticks.length / this.maxPerFrame);
    const gain = Math.min(1, 0.9 / Math.sqrt(n)) * Math.sqrt(stride);
    for (let k = 0; k < ticks.length; k += stride) {
      const [i, t] = ticks[k];
      const source = ctx.createBufferSource();
      source.buffer = this.buffer;
      const level = ctx.createGain();
      level.gain.value = gain;
      source.connect(level);
      let node = level;
      if (ctx.createStereoPanner) {
        const pan = ctx.createStereoPanner();
        // Where the metronome stands: round the disk, or (phi null) left to right
        // along the board.
        pan.pan.value = phi === null ? (n > 1 ? 2 * i / (n - 1) - 1 : 0)
          : Math.cos(2 * Math.PI * i / n + phi);
        level.connect(pan);
        node = pan;
      }
      node.connect(this.output);
      source.start(now + Math.max(0, (t - tFrom) / speed));
      this.scheduled++;
    }
  }
}
