// Instructor page: live sessions (pushed by the server over a WebSocket), the results CSV, the
// class archive, extra exam attempts, uploading an exercise, and a step-by-step replay of a log.
import { el, download } from "./dom.js";
import { drawField, scale } from "./eyepiece.js";
import { describe } from "./panels.js";

const token = new URLSearchParams(location.search).get("token") || "";
const auth = { Authorization: `Bearer ${token}` };
const $ = (id) => document.getElementById(id);
let frames = [], timer = null, retry = 500, replayId = null, view = null;
const patches = { left: null, right: null };
const MAG = 6; // the replay's eyepiece magnification

$("csv").addEventListener("click", (e) => { e.preventDefault(); download("/api/instructor/results.csv", auth, "results.csv"); });
$("zip").addEventListener("click", (e) => { e.preventDefault(); download("/api/instructor/archive.zip", auth, "class.zip"); });

function refused(text) {
  document.querySelector("main").replaceChildren(el("section", { class: "fail", text }));
}

function showRows(rows) {
  const body = $("sessions").tBodies[0];
  body.replaceChildren();
  for (const s of rows) {
    const replayButton = el("button", { text: "replay" });
    replayButton.addEventListener("click", () => replay(s.id));
    const result = s.passed === undefined ? "" : s.passed ? "passed" : "not passed";
    body.append(el("tr", { "data-id": s.id },
      el("td", { text: s.trainee }), el("td", { text: s.exercise }),
      el("td", {}, el("span", { class: `badge ${["exam", "practice", "demonstration"].includes(s.mode) ? s.mode : ""}`, text: s.mode })),
      el("td", { text: s.done ? "done" : s.stage ?? "" }), el("td", { class: "num", text: s.actions }),
      el("td", { text: s.started }), el("td", { class: "num", text: s.score ?? "—" }),
      el("td", { class: "num", text: s.percentile ?? "—" }),
      el("td", { class: s.passed ? "pass" : s.passed === false ? "fail" : "", text: result }),
      el("td", {}, replayButton, " ",
        el("a", { href: `/grade/${encodeURIComponent(s.id)}?token=${encodeURIComponent(token)}`, text: "grade" }))));
  }
  document.body.dataset.ready = "1";
}

function connect() {
  const ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws-instructor`);
  ws.onopen = () => ws.send(JSON.stringify({ auth: token }));
  ws.onmessage = (ev) => {
    const msg = JSON.parse(ev.data);
    if (msg.error) { refused(msg.error); ws.onclose = null; return; }
    retry = 500;
    $("status").textContent = "live";
    if (msg.sessions) showRows(msg.sessions);
  };
  ws.onclose = () => {
    $("status").textContent = "connection lost: reconnecting…";
    setTimeout(connect, retry); retry = Math.min(10000, retry * 2);
  };
}
connect();

// The replay's eyepieces: the photo patch around each mark (fetched with the token when the mark
// leaves the patch in hand), drawn as the trainee's page draws them.
function eyes(marks) {
  for (const side of ["left", "right"]) {
    const m = marks && marks[side], ctx = $(`replay-${side}`).getContext("2d");
    const p = patches[side], half = (view.patch_px * view.screen_pixel_mm) / MAG / 2;
    if (m && (!p || Math.abs(m.x_mm - p.x_mm) > half * 0.6 || Math.abs(m.y_mm - p.y_mm) > half * 0.6)) {
      const q = { x_mm: Number(m.x_mm.toFixed(3)), y_mm: Number(m.y_mm.toFixed(3)), mag: MAG, size: view.patch_px, img: new Image() };
      q.img.onload = () => { patches[side] = q; show(Number($("replay-pos").value)); };
      q.img.src = `/api/sessions/${encodeURIComponent(replayId)}/patch.png?side=${side}&x=${q.x_mm}&y=${q.y_mm}`
        + `&mag=${MAG}&size=${q.size}&token=${encodeURIComponent(token)}`;
      patches[side] = patches[side] || null;
    }
    drawField(ctx, m, MAG, { patch: patches[side] });
  }
}

function show(i) {
  const f = frames[i];
  if (view) eyes(f.state.marks);
  $("replay-n").textContent = `${i} / ${frames.length - 1}`;
  $("replay-action").textContent = f.action ? `${f.t} s: ${describe(f.action)}${f.refused ? " — refused: " + f.refused : ""}` : "start";
  $("replay-counters").replaceChildren(...Object.entries(f.state.counters).map(([k, c]) =>
    el("tr", {}, el("td", { text: k }), el("td", { class: "num", text: c.value === null ? "—" : c.value.toFixed(3) }), el("td", { text: c.unit }))));
}

async function replay(id) {
  $("replay-action").textContent = "replaying the log…";
  const r = await fetch(`/api/instructor/replay/${encodeURIComponent(id)}`, { headers: auth });
  const j = await r.json();
  if (!r.ok) { $("replay-action").textContent = j.error; return; }
  frames = j.frames; replayId = id; view = j.view; patches.left = patches.right = null;
  scale.pxPerMmAt1x = 1 / view.screen_pixel_mm; scale.formatMm = view.format_mm;
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
  }, 1000 / Number($("replay-speed").value));
};

$("grant").addEventListener("submit", async (e) => {
  e.preventDefault();
  const r = await fetch("/api/instructor/grant", {
    method: "POST", headers: { ...auth, "Content-Type": "application/json" },
    body: JSON.stringify({ trainee: $("grant-trainee").value, exercise: $("grant-exercise").value }),
  });
  const j = await r.json();
  $("grant-result").textContent = r.ok ? `${j.trainee}: ${j.extra_attempts} extra attempt(s) at ${j.exercise}` : j.error;
});

$("upload").addEventListener("submit", async (e) => {
  e.preventDefault();
  const file = $("upload-file").files[0];
  if (!file) return;
  const r = await fetch("/api/instructor/exercises", { method: "POST", headers: auth, body: await file.text() });
  const j = await r.json();
  $("upload-result").textContent = r.ok ? `added ${j.name}: ${j.title}` : j.error;
});

// The class's stereo acuities (recorded in the sessions by the trainees' acuity tests).
async function loadAcuities() {
  const r = await fetch("/api/instructor/acuity", { headers: auth });
  if (!r.ok) return;
  const rows = await r.json();
  const fmt = (v) => (v === undefined ? "—" : v.toFixed(1));
  $("acuities").tBodies[0].replaceChildren(...rows.map((a) => el("tr", { "data-id": a.id },
    el("td", { text: a.trainee }), el("td", { text: a.id }),
    el("td", { class: "num", text: fmt(a.x_arcsec) }), el("td", { class: "num", text: fmt(a.y_arcsec) }))));
  document.body.dataset.acuities = String(rows.length);
}
$("acuity-refresh").addEventListener("click", loadAcuities);
loadAcuities();
