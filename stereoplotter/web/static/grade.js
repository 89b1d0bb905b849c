// The grade report page: the core's grade of this session, and downloads.
const sid = location.pathname.split("/").pop();
const $ = (id) => document.getElementById(id);
const r = await fetch(`/api/sessions/${sid}/grade`);
const { grade } = await r.json();
window.__grade = grade;
$("who").textContent = `${grade.trainee} · ${grade.exercise} · ${grade.mode}`;
const o = grade.overall;
$("overall").innerHTML = `<p style="font-size:18px"><span class="${o.passed ? "pass" : "fail"}">${o.passed ? "PASSED" : "NOT PASSED"}</span>
  — score <b>${o.score.toFixed(3)}</b> (simulated operator ${o.par_score.toFixed(3)}),
  percentile ${o.percentile.toFixed(1)} ± ${o.percentile_se.toFixed(1)} among simulated operators</p>
  <p class="meta">${grade.title}</p>`;
$("md").href = `/api/sessions/${sid}/grade.md`;
$("log").href = `/api/sessions/${sid}/log.jsonl`;
const fmt = (v) => (typeof v !== "number" ? String(v ?? "—")
  : Number.isInteger(v) ? String(v) : Math.abs(v) >= 1e-3 ? v.toFixed(4) : v.toExponential(2));
for (const [stage, body] of Object.entries(grade.stages)) {
  const div = document.createElement("div");
  div.innerHTML = `<h3>Stage ${stage} ${body.claimed ? "" : "(not claimed)"}</h3>
   <table><tr><th>measure</th><th>yours</th><th>tolerance</th><th>operator</th><th>percentile</th><th></th></tr>
   ${body.measures.map((m) => `<tr><td>${m.name}</td><td class="num">${fmt(m.value)}</td><td class="num">${fmt(m.tolerance)} ${m.unit}</td>
     <td class="num">${fmt(m.par)}</td><td class="num">${m.percentile == null ? "—" : m.percentile.toFixed(1)}</td>
     <td class="${m.passed ? "pass" : "fail"}">${m.passed ? "✓" : "✗"}</td></tr>`).join("")}</table>`;
  $("stages").appendChild(div);
}
const p = grade.process, q = grade.par_process || {};
$("process").innerHTML = `<tr><th></th><th>yours</th><th>operator</th></tr>` +
  Object.keys(p).filter((k) => typeof p[k] !== "object").map((k) => `<tr><td>${k.replaceAll("_", " ")}</td><td class="num">${fmt(p[k])}</td><td class="num">${fmt(q[k])}</td></tr>`).join("");
document.body.dataset.ready = "1";
