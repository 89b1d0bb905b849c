// The grade page's teaching parts: per-point tables, the y-parallax map (a canvas drawn from the
// grade's JSON grid), process measures per stage, the checks skipped by name, hint costs.
// Built from elements and text nodes only.
import { el } from "./dom.js";

export const fmt = (v) => (typeof v !== "number" ? String(v ?? "—")
  : Number.isInteger(v) ? String(v) : Math.abs(v) >= 1e-3 || v === 0 ? v.toFixed(4) : v.toExponential(2));

const words = (k) => String(k).replaceAll("_", " ");
const isRows = (v) => Array.isArray(v) && v.length > 0 && v.every((r) => r && typeof r === "object" && !Array.isArray(r));

// A list of mappings as a table: one column per key (a pass/fail column shown as ✓ / ✗).
export function rowsTable(rows, cls = "") {
  const cols = [...new Set(rows.flatMap((r) => Object.keys(r)))].filter((c) => !isRows(rows[0][c]));
  return el("table", { class: `points ${cls}` },
    el("tr", {}, ...cols.map((c) => el("th", { text: words(c) }))),
    ...rows.map((r) => el("tr", {}, ...cols.map((c) => {
      const v = r[c];
      if (typeof v === "boolean") return el("td", { class: v ? "pass" : "fail", text: v ? "✓" : "✗" });
      if (Array.isArray(v)) return el("td", { text: v.length ? v.map(fmt).join(", ") : "none" });
      if (v && typeof v === "object") return el("td", { text: Object.entries(v).map(([a, b]) => `${words(a)} ${fmt(b)}`).join(", ") });
      return el("td", { class: typeof v === "number" ? "num" : "", text: fmt(v) });
    }))));
}

// Every per-point table of a stage's body (any list of rows but the measures), titled.
export function pointTables(body) {
  const out = [];
  for (const [k, v] of Object.entries(body)) {
    if (k === "measures") continue;
    if (isRows(v)) out.push(el("h4", { text: words(k) }), rowsTable(v));
    else if (v && typeof v === "object" && !Array.isArray(v)) {
      for (const [k2, v2] of Object.entries(v)) if (isRows(v2)) out.push(el("h4", { text: `${words(k)}: ${words(k2)}` }), rowsTable(v2));
    }
  }
  return out;
}

// A 2-D grid of numbers anywhere in the grade: {x…, y…, values…} with a 2-D array.
export function findMaps(value, path = [], found = []) {
  if (!value || typeof value !== "object") return found;
  if (!Array.isArray(value)) {
    const grid = Object.entries(value).find(([, v]) => Array.isArray(v) && v.length > 1 && v.every((r) => Array.isArray(r) && r.length > 1 && r.every((x) => typeof x === "number" || x === null)));
    if (grid && /parallax|map|grid/i.test(path.join(" ") + " " + grid[0])) found.push({ path, key: grid[0], grid: grid[1], map: value });
    for (const [k, v] of Object.entries(value)) if (v && typeof v === "object" && v !== (grid && grid[1])) findMaps(v, [...path, k], found);
  }
  return found;
}

// Diverging colour: −1 blue, 0 white, +1 red.
function colour(t) {
  const c = Math.max(-1, Math.min(1, t));
  const a = Math.round(255 * (1 - Math.abs(c)));
  return c >= 0 ? `rgb(255,${a},${a})` : `rgb(${a},${a},255)`;
}

// The map on a canvas: cells coloured by value against ±scale (the tolerance when given),
// points of the map (standard points) as circles, a legend of the scale.
export function drawMap(canvas, found) {
  const { grid, map } = found;
  const rows = grid.length, cols = grid[0].length;
  const ctx = canvas.getContext("2d");
  const w = canvas.width, h = canvas.height - 26;
  const vals = grid.flat().filter((v) => typeof v === "number");
  const tol = map.tolerance ?? map.tolerance_um ?? map.tolerance_mm ?? Math.max(...vals.map(Math.abs));
  ctx.fillStyle = "#15181a"; ctx.fillRect(0, 0, canvas.width, canvas.height);
  const cw = w / cols, ch = h / rows;
  for (let i = 0; i < rows; i++) {
    for (let j = 0; j < cols; j++) {
      const v = grid[i][j];
      ctx.fillStyle = typeof v === "number" ? colour(v / tol) : "#444";
      ctx.fillRect(j * cw, (rows - 1 - i) * ch, Math.ceil(cw), Math.ceil(ch)); // first row at the bottom (y up)
    }
  }
  const pts = map.points || map.standard_points || [];
  const xs = map.x || map.x_m || map.x_mm, ys = map.y || map.y_m || map.y_mm;
  if (Array.isArray(pts) && xs && ys) {
    const [x0, x1, y0, y1] = [xs[0], xs[xs.length - 1], ys[0], ys[ys.length - 1]];
    ctx.strokeStyle = "#111"; ctx.fillStyle = "#111"; ctx.font = "11px sans-serif";
    for (const p of pts) {
      const px = p.x ?? p.x_m ?? p.x_mm, py = p.y ?? p.y_m ?? p.y_mm;
      if (typeof px !== "number" || typeof py !== "number") continue;
      const cx = ((px - x0) / (x1 - x0)) * w, cy = h - ((py - y0) / (y1 - y0)) * h;
      ctx.beginPath(); ctx.arc(cx, cy, 5, 0, 2 * Math.PI); ctx.stroke();
      if (p.id !== undefined) ctx.fillText(String(p.id), cx + 7, cy - 5);
    }
  }
  const unit = map.unit || (found.key.endsWith("_um") ? "µm" : found.key.endsWith("_mm") ? "mm" : "");
  for (let k = 0; k <= 100; k++) { ctx.fillStyle = colour(k / 50 - 1); ctx.fillRect((k / 101) * w, h + 6, w / 100 + 1, 8); }
  ctx.fillStyle = "#e8e4d8"; ctx.font = "11px sans-serif";
  ctx.fillText(`−${fmt(tol)} ${unit}`, 2, h + 25); ctx.fillText("0", w / 2 - 3, h + 25);
  ctx.fillText(`+${fmt(tol)} ${unit}`, w - 70, h + 25);
  return { rows, cols, tol };
}

// Process measures: scalars as one table (yours | operator), per-stage mappings as a table of
// stages, lists of names (the checks skipped) spelled out.
export function processParts(p, par) {
  const out = [];
  const scalars = Object.keys(p).filter((k) => p[k] === null || typeof p[k] !== "object");
  out.push(el("table", {}, el("tr", {}, el("th"), el("th", { text: "yours" }), el("th", { text: "operator" })),
    ...scalars.map((k) => el("tr", {}, el("td", { text: words(k) }), el("td", { class: "num", text: fmt(p[k]) }),
      el("td", { class: "num", text: fmt((par || {})[k]) })))));
  for (const [k, v] of Object.entries(p)) {
    if (Array.isArray(v) && !isRows(v)) {
      out.push(el("p", {}, el("b", { text: `${words(k)}: ` }), v.length ? v.map((x) => (typeof x === "object" ? Object.values(x).join(" ") : String(x))).join("; ") : "none"));
    } else if (isRows(v)) {
      out.push(el("h4", { text: words(k) }), rowsTable(v));
    } else if (v && typeof v === "object") {
      const entries = Object.entries(v);
      if (entries.every(([, x]) => x && typeof x === "object" && !Array.isArray(x))) {
        out.push(el("h4", { text: words(k) }), rowsTable(entries.map(([name, x]) => ({ [k.includes("stage") ? "stage" : "name"]: name, ...flat(x) }))));
      } else {
        out.push(el("p", {}, el("b", { text: `${words(k)}: ` }), entries.map(([a, b]) => `${words(a)} ${Array.isArray(b) ? b.join(", ") : fmt(b)}`).join("; ")));
      }
    }
  }
  return out;
}

// A mapping with its lists joined (a table cell each).
function flat(x) {
  return Object.fromEntries(Object.entries(x).map(([k, v]) => [k, Array.isArray(v) ? (v.length ? v.join(", ") : "none") : v && typeof v === "object" ? Object.entries(v).map(([a, b]) => `${words(a)} ${fmt(b)}`).join(", ") : v]));
}

const TABLE_TITLES = {
  y_parallax: "Y-parallax at the six standard points",
  heights: "Height errors at the control points (built − true)",
  plan: "Plan errors at the control points (built − true)",
};

// The grade's per-point tables (grade.tables): each titled with its unit and tolerance.
export function tableParts(tables) {
  const out = [];
  for (const [key, title] of Object.entries(TABLE_TITLES)) {
    const t = tables[key];
    if (!t || !isRows(t.rows)) continue;
    const tol = t.tolerance !== undefined ? `, tolerance ${fmt(t.tolerance)} ${t.unit}` : "";
    const map = t.map_tolerance !== undefined ? ` (${fmt(t.map_tolerance)} ${t.map_unit} on the map)` : "";
    const stage = t.stage ? ` — as built at stage ${t.stage}` : "";
    out.push(el("h3", { text: `${title} [${t.unit}]${tol}${map}${stage}` }), rowsTable(t.rows, key));
  }
  return out;
}

// The y-parallax map of the built model (grade.tables.y_parallax_map: points on a grid of the
// working area with their value): one cell per point, coloured against ±tolerance (blue −,
// red +), its value written in it; north up.
export function drawPointMap(canvas, map, tolerance) {
  const pts = map.points.filter((p) => typeof p.value === "number");
  const xs = [...new Set(map.points.map((p) => p.x_m))].sort((a, b) => a - b);
  const ys = [...new Set(map.points.map((p) => p.y_m))].sort((a, b) => a - b);
  const near = (list, v) => list.reduce((best, x, i) => (Math.abs(x - v) < Math.abs(list[best] - v) ? i : best), 0);
  const [cols, rows] = map.shape ? [map.shape[1], map.shape[0]] : [xs.length, ys.length];
  const gx = cols === xs.length ? xs : null, gy = rows === ys.length ? ys : null;
  const ctx = canvas.getContext("2d");
  const w = canvas.width, h = canvas.height - 30;
  const tol = tolerance || Math.max(...pts.map((p) => Math.abs(p.value)));
  ctx.fillStyle = "#15181a"; ctx.fillRect(0, 0, canvas.width, canvas.height);
  const cw = w / cols, ch = h / rows;
  ctx.font = "10px sans-serif"; ctx.textAlign = "center";
  map.points.forEach((p, k) => {
    const i = gx ? near(gx, p.x_m) : k % cols, j = gy ? near(gy, p.y_m) : Math.floor(k / cols);
    ctx.fillStyle = typeof p.value === "number" ? colour(p.value / tol) : "#444";
    ctx.fillRect(i * cw, h - (j + 1) * ch, Math.ceil(cw), Math.ceil(ch));
    ctx.fillStyle = typeof p.value === "number" && Math.abs(p.value / tol) > 0.6 ? "#fff" : "#111";
    if (typeof p.value === "number") ctx.fillText(p.value.toFixed(1), i * cw + cw / 2, h - j * ch - ch / 2 + 3);
  });
  ctx.textAlign = "left";
  for (let k = 0; k <= 100; k++) { ctx.fillStyle = colour(k / 50 - 1); ctx.fillRect((k / 101) * w, h + 6, w / 100 + 1, 8); }
  ctx.fillStyle = "#e8e4d8";
  ctx.fillText(`−${fmt(tol)} ${map.unit || ""}`, 2, h + 27); ctx.fillText("0", w / 2 - 3, h + 27);
  ctx.fillText(`+${fmt(tol)} ${map.unit || ""}`, w - 80, h + 27);
  return { rows, cols, tol };
}
