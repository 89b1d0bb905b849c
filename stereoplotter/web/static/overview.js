// The photo overview: both photos side by side in an SVG built by DOM calls — fiducials,
// standard points, control and check points, and the mark's footprint (the eyepiece field at
// the current magnification). A click on the left photo records a substitute standard point.
import { scale } from "./eyepiece.js";

const NS = "http://www.w3.org/2000/svg";
const SIDE = 260, GAP = 40, TOP = 24; // px of one photo, between them, for the captions

function svg(tag, attrs, text) {
  const e = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  if (text !== undefined) e.textContent = text;
  return e;
}

// Photo mm (x right, y up) → SVG px of photo `i` (0 left, 1 right).
function place(data, i, [x, y]) {
  const k = SIDE / data.format_mm;
  return [i * (SIDE + GAP) + SIDE / 2 + x * k, TOP + SIDE / 2 - y * k];
}

// The points of one kind on one side: [{id, xy}] from the overview's lists (the core sends a
// list of {id, left: [x, y], right: [x, y]} per kind, or {left: [[x, y]...], right: ...}).
function pointsOf(data, key, side) {
  if (data.photos) { // the core's overview: photos.left|right.<key> = [{id, x_mm, y_mm, usable}]
    const photo = data.photos[side] || {};
    const name = { standard: "standard_points", control: "control_points", check: "check_points", fiducials: "fiducials" }[key];
    return (photo[name] || []).map((p) => ({ id: String(p.id), xy: [p.x_mm, p.y_mm], usable: p.usable !== false }));
  }
  const list = data[key];
  if (!list) return [];
  if (Array.isArray(list)) {
    return list.filter((p) => p && p[side]).map((p, i) => ({ id: String(p.id ?? i + 1), xy: p[side], usable: p.usable !== false }));
  }
  return (list[side] || []).map((xy, i) => ({ id: String(i + 1), xy, usable: true }));
}

export class Overview {
  constructor(root, onPick) {
    this.root = root; this.onPick = onPick; this.data = null;
    root.addEventListener("click", (e) => this.click(e));
  }

  set(data) { this.data = data; }

  // The left photo's mm under a click (null outside it).
  click(e) {
    if (!this.data) return;
    const pt = this.root.createSVGPoint();
    pt.x = e.clientX; pt.y = e.clientY;
    const p = pt.matrixTransform(this.root.getScreenCTM().inverse());
    const k = SIDE / this.data.format_mm;
    let x = (p.x - SIDE / 2) / k, y = (TOP + SIDE / 2 - p.y) / k;
    const half = this.data.format_mm / 2;
    if (Math.abs(x) > half || Math.abs(y) > half) return;
    const hit = e.target.closest ? e.target.closest("[data-left-xy]") : null;
    if (hit) [x, y] = hit.dataset.leftXy.split(",").map(Number); // a marked point: its own place
    this.onPick([Math.round(x * 1000) / 1000, Math.round(y * 1000) / 1000]);
  }

  draw(marks, magnification) {
    const d = this.data;
    if (!d) return;
    const out = [];
    ["left photo", "right photo"].forEach((name, i) => {
      const [x0, y0] = place(d, i, [-d.format_mm / 2, d.format_mm / 2]);
      out.push(svg("rect", { x: x0, y: y0, width: SIDE, height: SIDE, class: "ov-photo" }),
        svg("text", { x: x0, y: TOP - 8, class: "ov-caption" }, name));
    });
    ["left", "right"].forEach((side, i) => {
      for (const f of pointsOf(d, "fiducials", side)) {
        const [x, y] = place(d, i, f.xy);
        out.push(svg("path", { d: `M${x - 5},${y}h10M${x},${y - 5}v10`, class: "ov-fiducial" }));
      }
      for (const p of pointsOf(d, "standard", side)) {
        const [x, y] = place(d, i, p.xy);
        const bad = (d.unusable || []).includes(Number(p.id)) || !p.usable;
        const g = svg("g", { class: bad ? "ov-standard unusable" : "ov-standard", "data-point": p.id });
        if (side === "left") g.setAttribute("data-left-xy", `${p.xy[0]},${p.xy[1]}`);
        g.append(svg("circle", { cx: x, cy: y, r: 6 }), svg("text", { x: x + 8, y: y - 6 }, p.id));
        out.push(g);
      }
      for (const p of pointsOf(d, "control", side)) {
        const [x, y] = place(d, i, p.xy);
        out.push(svg("path", { d: `M${x},${y - 5}l5,9h-10z`, class: "ov-control" }), svg("text", { x: x + 6, y: y + 10, class: "ov-id" }, p.id));
      }
      for (const p of pointsOf(d, "check", side)) {
        const [x, y] = place(d, i, p.xy);
        out.push(svg("rect", { x: x - 4, y: y - 4, width: 8, height: 8, class: "ov-check" }), svg("text", { x: x + 6, y: y + 10, class: "ov-id" }, p.id));
      }
      const m = marks && marks[side];
      if (m) {
        const field = 320 / (scale.pxPerMmAt1x * magnification); // mm of photo in the eyepiece
        const [x, y] = place(d, i, [m.x_mm, m.y_mm]);
        const r = Math.max(2, (field / 2) * (SIDE / d.format_mm));
        out.push(svg("circle", { cx: x, cy: y, r, class: "ov-footprint", "data-mark": side }));
      }
    });
    this.root.replaceChildren(...out);
  }
}
