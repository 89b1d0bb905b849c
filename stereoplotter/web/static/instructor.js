// Instructor page: live sessions (polled), the results CSV and a step-by-step replay of a log.
const token = new URLSearchParams(location.search).get("token") || "";
const $ = (id) => document.getElementById(id);
$("csv").href = `/api/instructor/results.csv?token=${encodeURIComponent(token)}`;
let frames = [], timer = null;

async function refresh() {
  const r = await fetch(`/api/instructor/sessions?token=${encodeURIComponent(token)}`);
  if (!r.ok) { document.querySelector("main").innerHTML = `<section class="fail">${(await r.json()).error}</section>`; return; }
  const rows = await r.json();
  const body = $("sessions").tBodies[0];
  body.innerHTML = "";
  for (const s of rows) {
    const tr = body.insertRow();
    tr.innerHTML = `<td>${s.trainee}</td><td>${s.exercise}</td><td><span class="badge ${s.mode}">${s.mode}</span></td>
      <td>${s.done ? "done" : s.stage}</td><td class="num">${s.actions}</td><td>${s.started}</td>
      <td class="num">${s.score ?? "—"}</td><td class="num">${s.percentile ?? "—"}</td>
      <td class="${s.passed ? "pass" : s.passed === false ? "fail" : ""}">${s.passed === undefined ? "" : s.passed ? "passed" : "not passed"}</td>
      <td><button>replay</button> <a href="/grade/${s.id}">grade</a></td>`;
    tr.querySelector("button").onclick = () => replay(s.id);
  }
  document.body.dataset.ready = "1";
}

function show(i) {
  const f = frames[i];
  $("replay-n").textContent = `${i} / ${frames.length - 1}`;
  $("replay-action").textContent = f.action ? `${f.t} s: ${JSON.stringify(f.action)}${f.refused ? " — refused: " + f.refused : ""}` : "start";
  $("replay-counters").innerHTML = Object.entries(f.state.counters).map(([k, c]) => `<tr><td>${k}</td><td class="num">${c.value === null ? "—" : c.value.toFixed(3)}</td><td>${c.unit}</td></tr>`).join("");
}

async function replay(id) {
  const r = await fetch(`/api/instructor/replay/${id}?token=${encodeURIComponent(token)}`);
  const j = await r.json();
  frames = j.frames;
  $("replay").hidden = false;
  $("replay-who").textContent = `${j.trainee} · ${j.exercise}`;
  $("replay-pos").max = frames.length - 1;
  $("replay-pos").value = frames.length - 1;
  show(frames.length - 1);
}
$("replay-pos").oninput = () => show(Number($("replay-pos").value));
$("replay-play").onclick = () => {
  if (timer) { clearInterval(timer); timer = null; return; }
  $("replay-pos").value = 0;
  timer = setInterval(() => {
    const i = Number($("replay-pos").value) + 1;
    if (i >= frames.length) { clearInterval(timer); timer = null; return; }
    $("replay-pos").value = i; show(i);
  }, 200);
};
await refresh();
setInterval(refresh, 3000);
