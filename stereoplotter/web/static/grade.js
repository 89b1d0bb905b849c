// The grade report page: the core's grade of this session, and downloads. The session's own
// key (kept by this browser when it started the session) or the instructor's token is needed.
import { el, sessionKey, download } from "./dom.js";
import { fmt, pointTables, findMaps, drawMap, processParts } from "./gradeparts.js";

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
$("md").addEventListener("click", (e) => {
  e.preventDefault(); download(`/api/sessions/${sid}/grade.md`, auth, `grade-${sid}.md`);
});
$("log").addEventListener("click", (e) => {
  e.preventDefault(); download(`/api/sessions/${sid}/log.jsonl`, auth, `session-${sid}.jsonl`);
});
const num = (v) => el("td", { class: "num", text: v });
if (o.hint_cost || grade.hints) {
  const h = grade.hints || {};
  $("overall").append(el("p", { class: "meta", text: `hints: ${(h.used || []).length ? h.used.join(", ") : "none"}`
    + (o.hint_cost !== undefined ? ` — cost ${fmt(o.hint_cost)} added to the score` : "")
    + (o.score_before_hints !== undefined ? ` (score without them ${fmt(o.score_before_hints)})` : "")
    + (h.rule ? `; rule: ${h.rule}` : "") }));
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
const maps = findMaps(grade);
$("maps").hidden = maps.length === 0;
for (const m of maps) {
  const canvas = el("canvas", { width: 420, height: 326, class: "pmap" });
  const title = m.map.title || m.path.concat(m.key).join(" · ").replaceAll("_", " ");
  $("maps").append(el("figure", {}, canvas, el("figcaption", { text: title })));
  const drawn = drawMap(canvas, m);
  canvas.dataset.cells = `${drawn.rows}x${drawn.cols}`;
}
$("process").append(...processParts(grade.process, grade.par_process));
document.body.dataset.ready = "1";
