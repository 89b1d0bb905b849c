// The grade report page: the core's grade of this session, and downloads. The session's own
// key (kept by this browser when it started the session) or the instructor's token is needed.
import { el, sessionKey, download } from "./dom.js";
import { fmt, pointTables, findMaps, drawMap, drawPointMap, processParts, rowsTable, tableParts } from "./gradeparts.js";

const sid = location.pathname.split("/").pop();
const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get("token");
const auth = { Authorization: `Bearer ${token || sessionKey.get(sid) || ""}` };
const r = await fetch(`/api/sessions/${encodeURIComponent(sid)}/grade`, { headers: auth });
const body = await r.json();
if (!r.ok) {
  $("overall").append(el("p", { class: "fail", text: body.error }));
  document.body.dataset.ready = "1";
  throw new Error(body.error);
}
const grade = body.grade;
window.__grade = grade;
$("who").textContent = `${grade.trainee} · ${grade.exercise} · ${grade.mode}`;
const o = grade.overall;
$("overall").append(
  el("p", { class: "big" },
    el("span", { class: o.passed ? "pass" : "fail", text: o.passed ? "PASSED" : "NOT PASSED" }),
    " — score ", el("b", { text: o.score.toFixed(3) }),
    ` (simulated operator ${o.par_score.toFixed(3)}), percentile ${o.percentile.toFixed(1)} ± `
    + `${o.percentile_se.toFixed(1)} among simulated operators`),
  el("p", { class: "meta", text: grade.title }));
if (grade.population && grade.population.acuity) {
  $("overall").append(el("p", { class: "meta", id: "acuity-note", text: grade.population.acuity.text }));
}
$("md").addEventListener("click", (e) => {
  e.preventDefault(); download(`/api/sessions/${sid}/grade.md`, auth, `grade-${sid}.md`);
});
$("log").addEventListener("click", (e) => {
  e.preventDefault(); download(`/api/sessions/${sid}/log.jsonl`, auth, `session-${sid}.jsonl`);
});
const num = (v) => el("td", { class: "num", text: v });
if (o.points !== undefined) {
  $("overall").append(el("p", { class: "points", text: `points ${fmt(o.points)} of 100: outcome ${fmt(o.outcome_points)}`
    + ` − hints ${fmt(o.hint_cost)}; passing needs every measure within its tolerance and ${fmt(o.pass_points)} points` }));
}
if (grade.hints) {
  const h = grade.hints, rows = Object.entries(h).filter(([, v]) => Array.isArray(v) && v.length && typeof v[0] === "object");
  $("overall").append(el("p", { class: "meta", text: h.rule || "hint cost: the highest level asked in a stage costs a share of its points" }),
    ...rows.map(([, v]) => rowsTable(v)));
}
for (const [stage, s] of Object.entries(grade.stages)) {
  const table = el("table", {}, el("tr", {}, ...["measure", "yours", "tolerance", "operator",
    "percentile", ""].map((h) => el("th", { text: h }))));
  for (const m of s.measures) {
    table.append(el("tr", {}, el("td", { text: m.name }), num(fmt(m.value)),
      num(`${fmt(m.tolerance)} ${m.unit}`), num(fmt(m.par)),
      num(m.percentile == null ? "—" : m.percentile.toFixed(1)),
      el("td", { class: m.passed ? "pass" : "fail", text: m.passed ? "✓" : "✗" })));
  }
  $("stages").append(el("div", { class: "stage", "data-stage": stage },
    el("h3", { text: `Stage ${stage} ${s.claimed ? "" : "(not claimed)"}` }), table, ...pointTables(s)));
}
const tables = grade.tables || {};
if (Object.keys(tables).length) $("tables").append(...tableParts(tables));
$("tables").hidden = $("tables").childElementCount === 0;
const maps = tables.y_parallax_map ? [] : findMaps(grade);
$("maps").hidden = maps.length === 0 && !tables.y_parallax_map;
if (tables.y_parallax_map) {
  const canvas = el("canvas", { width: 460, height: 360, class: "pmap", id: "ymap" });
  const tol = tables.y_parallax ? tables.y_parallax.tolerance : null;
  $("maps").append(el("figure", {}, canvas, el("figcaption", {
    text: `true y-parallax over the working area (${tables.y_parallax_map.shape.join(" × ")} points), north up; blue −, red +, against ±${fmt(tol)} ${tables.y_parallax_map.unit}` })));
  const drawn = drawPointMap(canvas, tables.y_parallax_map, tol);
  canvas.dataset.cells = `${drawn.rows}x${drawn.cols}`;
}
for (const m of maps) {
  const canvas = el("canvas", { width: 420, height: 326, class: "pmap" });
  const title = m.map.title || m.path.concat(m.key).join(" · ").replaceAll("_", " ");
  $("maps").append(el("figure", {}, canvas, el("figcaption", { text: title })));
  const drawn = drawMap(canvas, m);
  canvas.dataset.cells = `${drawn.rows}x${drawn.cols}`;
}
$("process").append(...processParts(grade.process, grade.par_process));
if (grade.process_by_stage) {
  $("process").append(el("h3", { text: "per stage (time from the stage's first action)" }),
    rowsTable(Object.entries(grade.process_by_stage).map(([stage, p]) => ({ stage, ...p }))));
}
document.body.dataset.ready = "1";
