// SVG handwheels: one per control of the state; they send turn/set actions.
const NS = "http://www.w3.org/2000/svg";

export const LABELS = {
  X: "X", Y: "Y", Z: "Z (foot)", H: "H", bx: "b_x", by: "b_y", bz: "b_z", f_instrument: "f_пр",
  kappa_left: "κ left", kappa_right: "κ right", k_alpha_left: "k_α left", k_omega_left: "k_ω left",
  k_alpha_right: "k_α right", k_omega_right: "k_ω right", dx_left: "dx left", dy_left: "dy left",
  dx_right: "dx right", dy_right: "dy right",
};

export function decimals(step) {
  return Math.max(0, Math.min(6, Math.ceil(-Math.log10(step) - 1e-9)));
}

function svgWheel() {
  const svg = document.createElementNS(NS, "svg");
  svg.setAttribute("viewBox", "-40 -40 80 80");
  const g = document.createElementNS(NS, "g");
  const rim = document.createElementNS(NS, "circle");
  rim.setAttribute("r", "34"); rim.setAttribute("fill", "none");
  rim.setAttribute("stroke", "#c9a44c"); rim.setAttribute("stroke-width", "6");
  g.appendChild(rim);
  for (let i = 0; i < 6; i++) {
    const s = document.createElementNS(NS, "line");
    const a = (i * Math.PI) / 3;
    s.setAttribute("x1", "0"); s.setAttribute("y1", "0");
    s.setAttribute("x2", String(32 * Math.cos(a))); s.setAttribute("y2", String(32 * Math.sin(a)));
    s.setAttribute("stroke", "#8a8f94"); s.setAttribute("stroke-width", "3");
    g.appendChild(s);
  }
  const knob = document.createElementNS(NS, "circle");
  knob.setAttribute("cx", "28"); knob.setAttribute("r", "5"); knob.setAttribute("fill", "#e8e4d8");
  g.appendChild(knob);
  const hub = document.createElementNS(NS, "circle");
  hub.setAttribute("r", "7"); hub.setAttribute("fill", "#555");
  g.appendChild(hub);
  svg.appendChild(g);
  return [svg, g];
}

export class Wheels {
  // opts.multiplier(): the step multiplier chosen on the page; opts.side(): the approach side
  // a typed value finishes from ("" either); opts.onLock(name): lock the control.
  constructor(root, send, opts = {}) {
    this.root = root; this.send = send; this.items = {};
    this.opts = { multiplier: () => 1, side: () => "", onLock: null, ...opts };
  }

  build(controls) {
    for (const [name, c] of Object.entries(controls)) {
      if (this.items[name]) continue;
      const div = document.createElement("div");
      div.className = "wheel"; div.tabIndex = 0; div.dataset.control = name;
      const [svg, g] = svgWheel();
      const label = document.createElement("div");
      label.className = "label"; label.textContent = LABELS[name] || name;
      div.appendChild(label);
      div.appendChild(svg);
      const val = document.createElement("div"); val.className = "value"; div.appendChild(val);
      const inp = document.createElement("input"); inp.type = "number"; inp.step = "any";
      inp.title = `set ${name} (${c.unit})`;
      div.appendChild(inp);
      const lock = document.createElement("button");
      lock.className = "lock"; lock.textContent = "lock"; lock.title = `lock ${LABELS[name] || name}: later turns are refused`;
      lock.addEventListener("click", () => this.send({ kind: "lock", control: name }));
      div.appendChild(lock);
      this.root.appendChild(div);
      const item = { div, g, val, inp, step: c.step || 0.01, unit: c.unit };
      this.items[name] = item;
      const turn = (n) => this.send({ kind: "turn", control: name, delta: +(n * item.step).toPrecision(12) });
      const factor = (e) => (e.altKey ? 100 : e.shiftKey ? 10 : 1) * Number(this.opts.multiplier() || 1);
      svg.addEventListener("wheel", (e) => { e.preventDefault(); turn((e.deltaY < 0 ? 1 : -1) * factor(e)); }, { passive: false });
      div.addEventListener("keydown", (e) => {
        if (e.target === inp) {
          if (e.key === "Enter" && inp.value !== "") {
            const side = e.shiftKey ? "below" : e.altKey ? "above" : this.opts.side();
            const action = { kind: "set", control: name, value: Number(inp.value) };
            if (side) action.side = side;
            this.send(action);
          }
          return;
        }
        const k = { ArrowUp: 1, ArrowRight: 1, ArrowDown: -1, ArrowLeft: -1, PageUp: 100, PageDown: -100 }[e.key];
        if (k) { e.preventDefault(); turn(k * factor(e)); }
      });
      let last = null;
      svg.addEventListener("pointerdown", (e) => { last = Math.atan2(e.offsetY - 37, e.offsetX - 37); svg.setPointerCapture(e.pointerId); });
      svg.addEventListener("pointerup", () => { last = null; });
      svg.addEventListener("pointermove", (e) => {
        if (last === null) return;
        const a = Math.atan2(e.offsetY - 37, e.offsetX - 37);
        let d = a - last; if (d > Math.PI) d -= 2 * Math.PI; if (d < -Math.PI) d += 2 * Math.PI;
        const clicks = Math.trunc(d / (Math.PI / 18)); // 10° of the wheel = one step
        if (clicks !== 0) { last = a; turn(clicks * factor(e)); }
      });
    }
  }

  update(controls, locked) {
    this.build(controls);
    for (const [name, c] of Object.entries(controls)) {
      const it = this.items[name];
      const v = c.value;
      it.val.textContent = v === null ? "— " + c.unit : `${v.toFixed(decimals(it.step))} ${c.unit}`;
      const turns = v === null ? 0 : (v / it.step) * (Math.PI / 18);
      it.g.setAttribute("transform", `rotate(${((turns * 180) / Math.PI) % 360})`);
      it.div.classList.toggle("locked", locked.includes(name));
      it.div.querySelector(".lock").disabled = locked.includes(name);
    }
  }
}
