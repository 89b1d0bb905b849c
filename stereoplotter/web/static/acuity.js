// The trainee's own stereo acuity, measured in the page: an adaptive staircase (the rule of
// stereoplotter.trainer.acuity, tested there on a simulated observer: after a right answer the
// disparity is divided by STEP, after a wrong one multiplied by STEP³; it settles at 75 % right,
// σ = s₇₅/Φ⁻¹(0.75), the geometric mean of the reversals after the first DISCARD) on
// x-parallax (which of two squares is nearer, red/cyan glasses) and on visible y-parallax
// (is the right bar higher or lower). A disparity is an angle at the eye: CSS px × pixel pitch /
// viewing distance (the pitch typed, or calibrated against a bank card's 85.60 mm width).
// The result goes into the session's record (two record actions), where the grade finds it.
import { el } from "./dom.js";

export const STEP = 1.25, REVERSALS = 12, DISCARD = 3, MAX_TRIALS = 100, Z75 = 0.6744897501960817;
const ARCSEC = Math.PI / (180 * 3600), CARD_MM = 85.6;
export const RECORDS = { x: "stereo acuity x (arcsec)", y: "stereo acuity y (arcsec)" };

export class Staircase {
  constructor(start, floor = 0.5, ceiling = 3600) {
    Object.assign(this, { level: start, floor, ceiling, trials: 0, reversals: [], last: 0 });
  }
  get done() { return this.reversals.length >= REVERSALS || this.trials >= MAX_TRIALS; }
  answer(right) {
    this.trials += 1;
    const move = right ? -1 : 1;
    if (this.last && move !== this.last) this.reversals.push(this.level);
    this.last = move;
    this.level *= right ? 1 / STEP : STEP ** 3;
    this.level = Math.min(Math.max(this.level, this.floor), this.ceiling);
  }
  estimate() { // [σ ″, relative standard error]
    const used = this.reversals.slice(DISCARD).map(Math.log);
    if (used.length < 2) return [NaN, NaN];
    const mean = used.reduce((a, b) => a + b, 0) / used.length;
    const sd = Math.sqrt(used.reduce((a, b) => a + (b - mean) ** 2, 0) / (used.length - 1));
    return [Math.exp(mean) / Z75, sd / Math.sqrt(used.length / 4)];
  }
}

// (eye 1): an angle at the eye as µm of photo through a binocular of magnification V referred
// to 250 mm; and on this screen, where the page shows the photo at screenPixelMm/V mm a pixel.
function throughInstrument(arcsec, v) { return arcsec * ARCSEC * 250 / v * 1000; }
function onScreen(arcsec, v, pitchMm, distMm, screenPixelMm) {
  return arcsec * ARCSEC * distMm / pitchMm * (screenPixelMm / v) * 1000;
}

export class AcuityTest {
  // root: the section; send(action): logs an action; screenPixelMm(): photo mm of a page pixel at ×1
  constructor(root, send, screenPixelMm) {
    this.root = root; this.send = send; this.screenPixelMm = screenPixelMm; this.run = null;
    const $ = (id) => root.querySelector(`#${id}`);
    this.$ = $;
    $("acuity-card-size").oninput = () => { $("acuity-card").style.width = `${$("acuity-card-size").value}px`; };
    $("acuity-card-use").onclick = () => { $("acuity-pitch").value = (CARD_MM / Number($("acuity-card-size").value)).toFixed(4); };
    $("acuity-start-x").onclick = () => this.start("x");
    $("acuity-start-y").onclick = () => this.start("y");
    $("acuity-a").onclick = () => this.answer(0);
    $("acuity-b").onclick = () => this.answer(1);
  }

  pxPerArcsec() {
    const pitch = Number(this.$("acuity-pitch").value), dist = Number(this.$("acuity-distance").value) * 10;
    return ARCSEC * dist / pitch;
  }

  start(kind) {
    this.kind = kind;
    this.run = new Staircase(kind === "x" ? 120 : 60);
    this.$("acuity-a").textContent = kind === "x" ? "left is nearer" : "right bar is higher";
    this.$("acuity-b").textContent = kind === "x" ? "right is nearer" : "right bar is lower";
    this.$("acuity-ask").hidden = false;
    this.$("acuity-result-" + kind).textContent = "";
    this.show();
  }

  show() {
    const c = this.$("acuity-canvas"), ctx = c.getContext("2d");
    const d = this.run.level * this.pxPerArcsec(); // CSS px of disparity
    this.truth = Math.random() < 0.5 ? 0 : 1;
    c.dataset.truth = String(this.truth); // the client is not trusted: a test reads it
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = "#000"; ctx.fillRect(0, 0, c.width, c.height);
    if (this.kind === "x") { // two squares; the nearer one with crossed disparity (red left eye)
      ctx.globalCompositeOperation = "lighter";
      for (const [i, cx] of [[0, 100], [1, 220]]) {
        const shift = i === this.truth ? d / 2 : 0;
        ctx.fillStyle = "#ff0000"; ctx.fillRect(cx - 20 + shift, 80, 40, 40);
        ctx.fillStyle = "#00ffff"; ctx.fillRect(cx - 20 - shift, 80, 40, 40);
      }
      ctx.globalCompositeOperation = "source-over";
    } else { // two bars side by side; the right one offset by d (up: truth 0)
      ctx.fillStyle = "#e8e4d8";
      ctx.fillRect(70, 99, 80, 2);
      ctx.fillRect(170, 99 + (this.truth === 0 ? -d : d), 80, 2);
    }
    this.$("acuity-progress").textContent = `trial ${this.run.trials + 1} · ${this.run.level.toFixed(1)}″ · reversals ${this.run.reversals.length}/${REVERSALS}`;
  }

  answer(which) {
    if (!this.run) return;
    this.run.answer(which === this.truth);
    if (!this.run.done) { this.show(); return; }
    const [sigma, se] = this.run.estimate();
    if (!Number.isFinite(sigma)) { // no reversals: right at the smallest disparity shown
      this.$("acuity-result-" + this.kind).textContent = `finer than ${this.run.floor}″, the smallest disparity this test shows: not recorded`;
      this.$("acuity-ask").hidden = true; this.run = null; return;
    }
    const pitch = Number(this.$("acuity-pitch").value), dist = Number(this.$("acuity-distance").value) * 10;
    const mags = [2, 6, 20];
    const text = `${this.kind === "x" ? "depth (x-parallax)" : "across the base (y-parallax)"}: ${sigma.toFixed(1)}″ ± ${(100 * se).toFixed(0)} % `
      + `(${this.run.trials} trials) = µm of photo through the instrument at ${mags.map((v) => `×${v} ${throughInstrument(sigma, v).toFixed(2)}`).join(", ")}; `
      + `on this screen at ${mags.map((v) => `×${v} ${onScreen(sigma, v, pitch, dist, this.screenPixelMm()).toFixed(2)}`).join(", ")}`;
    this.$("acuity-result-" + this.kind).textContent = text;
    this.$("acuity-ask").hidden = true;
    this.send({ kind: "record", name: RECORDS[this.kind], value: Number(sigma.toFixed(2)) });
    this.root.dataset[`done${this.kind.toUpperCase()}`] = sigma.toFixed(2);
    this.run = null;
  }
}

export function acuityPanel() {
  return el("div", { id: "acuity-body", hidden: true },
    el("div", { class: "meta small", text: "The grade compares you with simulated operators of your own measured acuity. Depth needs red/cyan glasses (red on the left eye). Answer as you see it; guess when unsure." }),
    el("div", { class: "row" },
      el("label", {}, "pixel pitch [mm] ", el("input", { id: "acuity-pitch", type: "number", step: "0.0001", value: "0.2646", class: "w80" })),
      el("label", {}, "viewing distance [cm] ", el("input", { id: "acuity-distance", type: "number", step: "1", value: "50", class: "w50" }))),
    el("div", { class: "row" }, el("span", { class: "meta small", text: "or hold a bank card to the screen and size this bar to its width:" }),
      el("input", { id: "acuity-card-size", type: "range", min: "150", max: "600", value: "323" }),
      el("button", { id: "acuity-card-use", text: "use it" })),
    el("div", { id: "acuity-card", class: "acuity-card" }),
    el("div", { class: "row" }, el("button", { id: "acuity-start-x", text: "Test depth (x-parallax)" }), el("button", { id: "acuity-start-y", text: "Test across (y-parallax)" })),
    el("canvas", { id: "acuity-canvas", width: "320", height: "200" }),
    el("div", { id: "acuity-ask", class: "row", hidden: true }, el("button", { id: "acuity-a" }), el("button", { id: "acuity-b" }), el("span", { id: "acuity-progress", class: "meta small" })),
    el("div", { id: "acuity-result-x", class: "meta" }), el("div", { id: "acuity-result-y", class: "meta" }));
}
