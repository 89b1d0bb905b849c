// The instrument page: WebSocket to the server (action → state), eyepieces, wheels, counters.
// The session's key (kept by this browser when it started the session) opens the socket; a
// dropped socket is reopened (with growing pauses) and the session resumes where its log ends.
import { drawField, anaglyph, covers, scale } from "./eyepiece.js";
import { Wheels, LABELS, decimals } from "./wheels.js";
import { el, sessionKey } from "./dom.js";
import { buildActions, describe, parseCommand, showResult, showChecklist, showAnnounced, showCoupled, showSheet } from "./panels.js";
import { Overview } from "./overview.js";
import { loadGlossary, glossaryBox, withTerms, termEl, names } from "./words.js";
import { AcuityTest, acuityPanel } from "./acuity.js";

const sid = location.pathname.split("/").pop();
const key = sessionKey.get(sid);
const $ = (id) => document.getElementById(id);
let state = null, hello = null, seq = 0, ws = null, retry = 250;
const waiting = new Map(); // seq → resolve(frame time)
const trail = [];
const wheels = new Wheels($("wheels"), send, {
  multiplier: () => $("step-mult").value, side: () => $("approach").value,
});
const sent = new Map(); // seq → [action, state before] (for its result and coupled motions)
let overview = null;

function link(text, lost) {
  $("link").textContent = text; $("link").className = lost ? "meta lost" : "meta";
}

function connect() {
  ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws/${encodeURIComponent(sid)}`);
  // patches: after the first frame's whole state the server sends what changed (applyPatch)
  ws.onopen = () => ws.send(JSON.stringify({ auth: key || "", patches: true }));
  ws.onmessage = onMessage;
  ws.onclose = (ev) => {
    if (ev.code === 4403) { link("", false); return; } // refused: the message says why
    link("connection lost: reconnecting…", true);
    setTimeout(connect, retry); retry = Math.min(8000, retry * 2);
  };
}

// Messages leave at most at the server's rate (told in hello: a rate and a burst), a little
// under it: a fast hand (or the robot trainee) is queued here, never refused there.
const queue = [];
let tokens = 0, lastFill = performance.now(), pumping = null;
function pump() {
  pumping = null;
  const [rate, burst] = hello && hello.rate ? hello.rate : [60, 120];
  const now = performance.now();
  tokens = Math.min(burst * 0.9, tokens + ((now - lastFill) / 1000) * rate * 0.9);
  lastFill = now;
  while (queue.length && tokens >= 1 && ws && ws.readyState === WebSocket.OPEN) {
    ws.send(queue.shift()); tokens -= 1;
  }
  window.__queued = queue.length;
  if (queue.length) pumping = setTimeout(pump, Math.max(4, 1000 / rate));
}

function send(action) {
  tourEvent(action.kind, action);
  seq += 1;
  if (!ws || ws.readyState !== WebSocket.OPEN) {
    message("not connected to the server: this action was not sent (reconnecting…)", "error");
    return seq;
  }
  sent.set(seq, [action, state]);
  queue.push(JSON.stringify({ action, seq }));
  if (!pumping) pump();
  return seq;
}

function sendDemo() {
  if (!ws || ws.readyState !== WebSocket.OPEN) return;
  queue.push(JSON.stringify({ demo: "step" }));
  if (!pumping) pump();
}

function message(text, cls = "") {
  const m = $("message"); m.textContent = text || ""; m.className = cls;
}

// --- eyepieces -----------------------------------------------------------------------------
const off = { left: document.createElement("canvas"), right: document.createElement("canvas") };
off.left.width = off.left.height = off.right.width = off.right.height = 320;
let flickerSide = "left";

// Photo patches (one per side): fetched when the mark nears a patch's edge or the magnification
// changes; a move only redraws from the patch in hand. Coarse first: with the sharp patch a
// small one at hello.coarse_mag (the pyramid's level rendered whole at start-up, answered at
// once) is fetched too and drawn, scaled, until the sharp one arrives.
const patches = { left: null, right: null }, loading = { left: false, right: false };
function patchUrl(side, mark, mag, size) {
  return `/api/sessions/${encodeURIComponent(sid)}/patch.png?side=${side}&x=${mark.x_mm.toFixed(3)}`
    + `&y=${mark.y_mm.toFixed(3)}&mag=${mag}&size=${size}&key=${encodeURIComponent(key || "")}`;
}
function needPatch(side, mark, mag) {
  const p = patches[side];
  if (loading[side] || !hello) return;
  const fieldMm = 320 / (scale.pxPerMmAt1x * mag);
  const halfMm = (hello.patch_px * hello.screen_pixel_mm) / mag / 2;
  if (p && !p.coarse && p.mag === mag && Math.abs(mark.x_mm - p.x_mm) < halfMm - fieldMm * 0.75
      && Math.abs(mark.y_mm - p.y_mm) < halfMm - fieldMm * 0.75) return;
  loading[side] = true;
  const at = { x_mm: Number(mark.x_mm.toFixed(3)), y_mm: Number(mark.y_mm.toFixed(3)) };
  const q = { side, ...at, mag, size: hello.patch_px, img: new Image() };
  q.img.onload = () => { patches[side] = q; loading[side] = false; window.__patches = (window.__patches || 0) + 1; drawEyes(); };
  q.img.onerror = () => { loading[side] = false; };
  q.img.src = patchUrl(side, mark, mag, hello.patch_px);
  const cm = hello.coarse_mag, cs = Math.max(16, Math.round((hello.patch_px * cm) / mag));
  const c = { side, ...at, mag: cm, size: cs, coarse: true, img: new Image() };
  c.img.onload = () => {
    const now = patches[side];
    if (!now || now.coarse || now.mag !== Number($("mag").value)) { patches[side] = c; drawEyes(); }
  };
  c.img.src = patchUrl(side, mark, cm, cs);
}

// A new photo patch is asked for once the mark has rested (PATCH_REST_MS without a new
// state): a fast run of moves shows the patch in hand (or the graticule) and the server renders
// one patch where the mark stops, not one per move.
const PATCH_REST_MS = 120;
let patchTimer = null;
function askPatches(marks, mag) {
  clearTimeout(patchTimer);
  patchTimer = setTimeout(() => {
    const m = state && state.marks;
    if (m) for (const side of ["left", "right"]) needPatch(side, m[side], Number($("mag").value) || mag);
  }, PATCH_REST_MS);
}

function drawEyes() {
  const marks = state ? state.marks : null;
  const mag = Number($("mag").value) || 6;
  const mode = $("view").value;
  if (marks) askPatches(marks, mag);
  $("eyepieces").hidden = mode !== "split";
  $("stereo").hidden = mode === "split";
  if (mode === "split") {
    for (const side of ["left", "right"]) {
      drawField($(`eye-${side}`).getContext("2d"), marks && marks[side], mag, { patch: patches[side] });
      // with the read-out off the server gives the marks to the counters' least count
      const places = state.assists && state.assists.parallax_readout === false ? 2 : 3;
      $(`cap-${side}`).textContent = marks
        ? `${side}: x ${marks[side].x_mm.toFixed(places)}  y ${marks[side].y_mm.toFixed(places)} mm` : `${side} photo`;
    }
  } else {
    for (const side of ["left", "right"]) drawField(off[side].getContext("2d"), marks && marks[side], mag, { markColour: "#ffffff", patch: patches[side] });
    const ctx = $("eye-stereo").getContext("2d");
    if (mode === "anaglyph") anaglyph(ctx, off.left, off.right, $("colours").value.split(","));
    else { ctx.drawImage(off[flickerSide], 0, 0); }
  }
  if (overview) overview.draw(marks, mag);
  zoomNote(marks, mag);
  window.__frames = (window.__frames || 0) + 1;
}
setInterval(() => {
  if ($("view").value === "flicker") { flickerSide = flickerSide === "left" ? "right" : "left"; drawEyes(); }
}, 125);
for (const id of ["view", "colours", "mag"]) $(id).addEventListener("change", () => { drawEyes(); tourEvent("mag", { value: Number($("mag").value) }); });

// --- coordinatograph -----------------------------------------------------------------------
const NS = "http://www.w3.org/2000/svg";
function svg(tag, attrs, text) {
  const e = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  if (text !== undefined) e.textContent = text;
  return e;
}

function drawTable() {
  const c = state.counters;
  if (!c.X || !c.Y) return;
  const x = c.X.value, y = c.Y.value;
  if (x === null || y === null) return;
  const last = trail[trail.length - 1];
  if (!last || last[0] !== x || last[1] !== y) trail.push([x, y]);
  if (trail.length > 400) trail.shift();
  const grid = svg("g", { stroke: "#d9d0bb", "stroke-width": 1 });
  for (let i = 0; i < 15; i++) {
    grid.append(svg("line", { x1: -50 + i * 50, y1: -150, x2: -50 + i * 50, y2: 550 }),
      svg("line", { x1: -50, y1: -150 + i * 50, x2: 650, y2: -150 + i * 50 }));
  }
  $("table-svg").replaceChildren(
    svg("rect", { x: -50, y: -150, width: 700, height: 700, fill: "#f4efe2", stroke: "#999" }), grid,
    svg("polyline", { points: trail.map(([a, b]) => `${a},${400 - b}`).join(" "), fill: "none", stroke: "#3060a0", "stroke-width": 2 }),
    svg("circle", { cx: x, cy: 400 - y, r: 7, fill: "none", stroke: "#c02020", "stroke-width": 3 }),
    svg("text", { x: -40, y: 540, "font-size": 22, fill: "#333" }, `X ${x.toFixed(2)}  Y ${y.toFixed(2)} mm`));
}

// --- counters and stage --------------------------------------------------------------------
function drawCounters() {
  const body = $("counters").tBodies[0];
  const names = Object.keys(state.counters).join(",");
  if (body.dataset.names !== names) {
    body.replaceChildren(); body.dataset.names = names;
    for (const name of Object.keys(state.counters)) {
      const zero = name.startsWith("dx") || name.startsWith("dy")
        ? "a decentration counter: at its place of zero (MO_dx, MO_dy) it reads 20.00 mm" : null;
      const tr = el("tr", { "data-counter": name, title: zero }, el("td", { text: LABELS[name] || name }),
        el("td", { class: "num" }), el("td"),
        el("td", {}, el("button", { class: "dir", title: "reverse the counter's direction", text: "±" })),
        el("td", {}, el("button", { class: "read", text: "read" })));
      body.append(tr);
      tr.querySelector(".dir").onclick = () =>
        send({ kind: "direction", counter: name, sign: -state.counters[name].direction });
      tr.querySelector(".read").onclick = () => send({ kind: "read", counter: name });
    }
  }
  for (const tr of body.rows) {
    const c = state.counters[tr.dataset.counter];
    tr.cells[1].textContent = c.value === null ? "—" : c.value.toFixed(decimals(c.least_count));
    tr.cells[2].textContent = c.unit; tr.cells[2].title = `least count ${c.least_count} ${c.unit}`;
    tr.querySelector(".dir").textContent = c.direction > 0 ? "+" : "−";
  }
}

function drawStage() {
  $("stage").textContent = state.done ? "all stages claimed" : `stage ${state.stage}`;
  $("mode").textContent = hello.demonstration ? "demonstration" : state.mode;
  $("mode").className = `badge ${hello.demonstration ? "demonstration" : state.mode}`;
  const ul = $("checks"); ul.replaceChildren();
  for (const ch of state.checks) {
    const lc = ch.unit === "mm" && state.counters.X ? state.counters.X.least_count : null;
    const fine = lc && ch.tolerance !== null && ch.tolerance > lc * 1.0001 && ch.tolerance < 2 * lc
      ? ` — under two least counts of the counters (${lc} mm): point carefully in the eyepieces, read twice` : "";
    ul.appendChild(termEl("li", {}, `${ch.name}: tolerance ${ch.tolerance === null ? "—" : ch.tolerance.toPrecision(3)} ${ch.unit}${fine}`));
  }
  const allowed = new Set(state.allowed);
  const demo = hello.demonstration;
  $("undo").hidden = !allowed.has("undo") && !allowed.has("redo") && state.mode === "exam";
  $("undo").disabled = demo || !allowed.has("undo");
  $("redo").disabled = demo || !allowed.has("redo");
  $("hints").hidden = !allowed.has("hint");
  $("claim").disabled = demo || !allowed.has("claim");
  $("check").hidden = state.mode !== "practice" || demo;
  $("check").disabled = !allowed.has("claim");
  $("demo").hidden = !demo;
  $("done").hidden = !state.done;
  $("grade-link").href = `/grade/${encodeURIComponent(sid)}`;
  const p = state.parallax;
  const um = (v) => (v === null || v === undefined ? "—" : v.toFixed(1));
  $("parallax").textContent = p ? `parallax at standard point ${p.point}: q = ${um(p.y_um)} µm, p = ${um(p.x_um)} µm`
    : state.marks ? "no q/p read-out in this exercise: judge the parallax in the eyepieces (or the anaglyph)" : "";
  tickChecklist(state.checklist_ticks);
  showAnnounced($("announced"), $("announced-list"), state.injected_errors_list || state.injected_errors);
}

// The controls with the metre height scale H once the height counter is geared (the core
// lists H among the counters; it is set and turned like a handwheel).
function withHeightScale(st) {
  const h = st.counters.H;
  if (!h || st.controls.H) return st.controls;
  return { ...st.controls, H: { value: h.value, unit: h.unit, step: h.least_count, min: null, max: null } };
}

let framePending = false;
function render() { // at most once an animation frame, however many states arrive
  if (framePending) return;
  framePending = true;
  requestAnimationFrame(() => {
    const t0 = performance.now();
    framePending = false;
    drawEyes(); drawCounters(); drawStage(); drawTable();
    wheels.update(withHeightScale(state), state.locked || []);
    window.__renderMs = (window.__renderMs || 0) + performance.now() - t0; // for the benchmarks
  });
}

// A new object: `old` with the server's patch applied ({set, del, sub}: keys replaced or
// added, keys removed, objects patched in turn); `old` is left as it was (a sent action keeps
// the state it was sent from). Keys are defined as own data properties, never assigned: a
// record named "__proto__" stays a record.
function applyPatch(old, patch) {
  const out = { ...old };
  const put = (k, v) => Object.defineProperty(out, k, { value: v, enumerable: true, writable: true, configurable: true });
  for (const k of patch.del || []) delete out[k];
  for (const [k, v] of Object.entries(patch.set || {})) put(k, v);
  for (const [k, inner] of Object.entries(patch.sub || {})) put(k, applyPatch(out[k], inner));
  return out;
}

function onMessage(ev) {
  const t0 = performance.now();
  try { handle(JSON.parse(ev.data)); } finally { window.__messageMs = (window.__messageMs || 0) + performance.now() - t0; }
}

function handle(msg) {
  if (msg.hello) {
    hello = msg.hello; retry = 250; link("", false);
    scale.pxPerMmAt1x = 1 / hello.screen_pixel_mm;
    scale.formatMm = hello.format_mm;
    $("who").textContent = `${hello.trainee} · ${hello.exercise}`;
    $("title").textContent = "Stereoplotter trainer";
    $("instructions").replaceChildren(...withTerms(hello.description));
    waiting.clear();
    buildActions($("actions"), hello.actions || [], Object.keys(msg.state.controls), send, message);
    loadOverview();
  }
  if (msg.patch && state) msg.state = applyPatch(state, msg.patch);
  if (msg.state) state = msg.state;
  window.__n = msg.n;
  if (state) render();
  const [action, before] = msg.seq !== undefined && sent.has(msg.seq) ? sent.get(msg.seq) : [msg.demo && msg.demo.action, null];
  if (msg.seq !== undefined) sent.delete(msg.seq);
  if (msg.error && action && !msg.demo && /^too many messages/.test(msg.error)) {
    // refused for the server's rate before it counted (messages bunch up on a busy line):
    // the action goes out again shortly, as the queue above promises a fast hand
    setTimeout(() => send(action), 250);
    return;
  }
  if (msg.error) message(msg.error, "error");
  else if (msg.demo) message(`operator: ${describe(msg.demo.action)}`);
  else if (!msg.hello) message("");
  if (!msg.hello && !msg.error) {
    showResult($("result"), action, msg.result);
    afterClaim(action, msg.result);
    if (action && action.kind === "record") message(`recorded: ${describe(action)} (kept in your session's record)`);
    showCoupled($("coupled"), action, before, msg.state, msg.state && msg.state.events);
  }
  if (msg.demo) $("demo-count").textContent = `${msg.demo.done} / ${msg.demo.of}`;
  if (msg.seq !== undefined && waiting.has(msg.seq)) { waiting.get(msg.seq)(performance.now()); waiting.delete(msg.seq); }
  document.body.dataset.ready = "1";
}
await loadGlossary();
Object.assign(LABELS, names.controls);
glossaryBox($("term-box"));
if (key) connect();
else {
  message("this browser holds no key for this session: start a session from the exercises page", "error");
  document.body.dataset.ready = "1";
}

$("claim").onclick = () => send({ kind: "claim", step: state.stage });
// In practice the stage may be checked before it is claimed: a failing check is named with its
// measured and allowed values and the likely wrong setting; fix it, then claim.
$("check").onclick = async () => {
  if (!state || hello.demonstration || state.mode !== "practice") return;
  if (state.assists && state.assists.parallax_readout === false) {
    message("the read-out is off in this exercise: the stage's checks come with its claim");
    return;
  }
  const fb = await feedbackOf("now");
  if (!fb) return;
  if (fb.passed) { showFeedback({ lines: ["Every check of the stage is within its tolerance: claim it."] }, `Stage ${fb.stage}:`, []); return; }
  showFeedback(fb, `Stage ${fb.stage} is not yet within its tolerance:`, [
    ["Fix it first", () => { $("feedback").hidden = true; }],
    ["Claim anyway", () => { $("feedback").hidden = true; send({ kind: "claim", step: state.stage }); }],
  ]);
};$("undo").onclick = () => send({ kind: "undo" });
$("redo").onclick = () => send({ kind: "redo" });
for (const b of $("hints").querySelectorAll("button[data-level]")) {
  b.onclick = () => {
    const level = Number(b.dataset.level);
    if (level < 3) { send({ kind: "hint", level }); return; }
    confirmBox(`Hint 3: the simulated operator does the whole of stage ${state.stage} on your instrument at once `
      + `(${words ? words.show_me_actions : "its"} actions), and it costs ${hintCost(3)}. `
      + "Your own settings of the stage are replaced by the operator's.", () => send({ kind: "hint", level: 3 }));
  };
}
$("command").addEventListener("keydown", (e) => {
  if (e.key !== "Enter" || !state) return;
  const names = [...Object.keys(withHeightScale(state)), ...Object.keys(state.counters)];
  const parsed = parseCommand($("command").value, [...new Set(names)]);
  if (parsed.error) { message(parsed.error, "error"); return; }
  send(parsed.action);
  $("command").value = "";
});

let playing = null, showing = null;
// "Show me", animated: the operator's actions of the stage sent one by one at the chosen speed
// (the eyepieces, wheels and counters move as they go); the server charged it as hint 3 when it
// handed out the actions.
$("show-me").onclick = () => {
  if (showing) { clearInterval(showing); showing = null; $("show-me").textContent = "Show me"; return; }
  confirmBox(`Show me: the simulated operator does stage ${state.stage} on your instrument, one action at a time `
    + `(${words ? words.show_me_actions : "its"} actions at the speed chosen below; Stop ends it). It costs as hint 3: `
    + `${hintCost(3)}.`, showMe);
};
async function showMe() {
  const r = await fetch(`/api/sessions/${encodeURIComponent(sid)}/showme`, { headers: auth() });
  const body = await r.json();
  if (!r.ok) { message(body.error, "error"); return; }
  const actions = body.actions;
  let i = 0;
  $("show-me").textContent = "Stop";
  showing = setInterval(() => {
    if (i >= actions.length) {
      clearInterval(showing); showing = null; $("show-me").textContent = "Show me";
      return;
    }
    const a = actions[i++];
    $("show-me-count").textContent = `show me ${i} / ${actions.length}: ${describe(a)}`;
    send(a);
  }, 1000 / Number($("demo-speed").value));
}
$("demo-step").onclick = sendDemo;
function play() {
  if (playing) clearInterval(playing);
  playing = setInterval(sendDemo, 1000 / Number($("demo-speed").value));
  $("demo-play").textContent = "Pause";
}
$("demo-play").onclick = () => {
  if (playing) { clearInterval(playing); playing = null; $("demo-play").textContent = "Play"; return; }
  play();
};
$("demo-speed").onchange = () => { if (playing) play(); };

// --- the stage's checklist: its steps fetched once a stage, ticked from every state ------------
let checklist = null, checklistFor = null;
async function tickChecklist(ticks) {
  if (!ticks) { showChecklist($("checklist"), []); return; }
  if (checklistFor !== ticks.stage) {
    checklistFor = ticks.stage;
    const r = await fetch(`/api/sessions/${encodeURIComponent(sid)}/checklist`, { headers: auth() });
    checklist = r.ok ? await r.json() : null;
    loadWords();
  }
  if (!checklist || checklist.stage !== ticks.stage) return;
  checklist.steps.forEach((s, i) => { s.done = !!ticks.done[i]; s.shown = ticks.shown ? !!ticks.shown[i] : true; });
  checklist.done = checklist.steps.filter((s) => s.shown && s.done).length;
  checklist.total = checklist.steps.filter((s) => s.shown).length;
  showChecklist($("checklist"), checklist, sheetData);
  $("checklist-count").textContent = `${checklist.done} / ${checklist.total}`;
}

// --- photo overview and the setup sheet ----------------------------------------------------
const auth = () => ({ Authorization: `Bearer ${key || ""}` });
async function loadOverview() {
  const r = await fetch(`/api/sessions/${encodeURIComponent(sid)}/overview`, { headers: auth() });
  const data = await r.json();
  if (!r.ok) { $("overview-note").textContent = data.error; return; }
  overview = new Overview($("overview-svg"), (xy) => {
    if ($("click-mode").value === "drive") { goTo({ x: xy[0], y: xy[1] }); return; }
    const n = $("substitute-for").value;
    if (!n) { $("overview-note").textContent = "no standard point of this exercise needs a substitute"; return; }
    send({ kind: "record", name: `substitute ${n}`, value: xy });
  });
  overview.set(data);
  const unusable = data.photos
    ? data.photos.left.standard_points.filter((p) => p.usable === false).map((p) => p.id) : data.unusable || [];
  $("substitute-for").replaceChildren(...unusable.map((n) => el("option", { value: String(n), text: String(n) })));
  $("overview-note").textContent = unusable.length ? `unusable: ${unusable.join(", ")} (on water or outside the overlap)` : "";
  if (unusable.length) $("click-mode").value = "substitute";
  overviewData = data;
  document.body.dataset.overview = "1";
  drawEyes();
}

let sheetLoaded = false;
async function openSheet() {
  $("sheet").hidden = false;
  if (sheetLoaded) return;
  const r = await fetch(`/api/sessions/${encodeURIComponent(sid)}/sheet`, { headers: auth() });
  const data = await r.json();
  if (!r.ok) { $("sheet-body").textContent = data.error; return; }
  sheetLoaded = true;
  $("sheet-title").textContent = [data.exercise, data.method && `${data.method} method`, data.instrument].filter(Boolean).join(" · ");
  showSheet($("sheet-body"), data);
  $("sheet-body").className = "";
  document.body.dataset.sheet = "1";
}
$("sheet-btn").onclick = () => ($("sheet").hidden ? openSheet() : ($("sheet").hidden = true));
$("sheet-close").onclick = () => { $("sheet").hidden = true; };
$("sheet-print").onclick = () => { document.body.classList.add("print-sheet"); window.print(); };
window.addEventListener("afterprint", () => document.body.classList.remove("print-sheet"));

// For tests and the latency benchmark: send an action, resolve with ms until its frame is drawn.
window.trainer = {
  state: () => state,
  // the magnifications of the sharp patches in hand (left, right)
  patchMags: () => [patches.left, patches.right].map((p) => (p && !p.coarse ? p.mag : null)),
  // every action sent has left the page's queue and been answered
  idle: () => queue.length === 0 && sent.size === 0,
  // drop the socket as a network would (the page must reconnect and resume)
  drop: () => ws && ws.close(),
  // both eyepieces drawn from a photo patch that covers the current marks
  photosReady: () => !!(state && state.marks && patches.left && patches.right && !loading.left && !loading.right
    && !patches.left.coarse && !patches.right.coarse
    && covers(patches.left, state.marks.left) && covers(patches.right, state.marks.right)),
  actAndFrame(action) {
    const t0 = performance.now();
    const s = send(action);
    return new Promise((res) => waiting.set(s, (t) => requestAnimationFrame(() => res(t - t0))));
  },
};

// --- words, feedback, navigation ------------------------------------------------------------
let words = null, sheetData = null, overviewData = null;
async function loadWords() {
  const r = await fetch(`/api/sessions/${encodeURIComponent(sid)}/words`, { headers: auth() });
  if (r.ok) words = await r.json();
  if (words && words.tour && words.tour.length && tourAt === null) { $("tour-btn").hidden = false; showTour(0); }
  for (const b of $("hints").querySelectorAll("button[data-level]")) {
    b.title = `hint ${b.dataset.level}: costs ${hintCost(Number(b.dataset.level))} (the highest level asked in a stage counts)`;
  }
  if (!sheetData) {
    const s = await fetch(`/api/sessions/${encodeURIComponent(sid)}/sheet`, { headers: auth() });
    if (s.ok) { sheetData = await s.json(); if (checklist) showChecklist($("checklist"), checklist, sheetData); }
  }
}
function hintCost(level) {
  const p = words && words.hint_points ? words.hint_points[String(level)] : null;
  return p === null || p === undefined ? "a part of the points" : `${p} of the exercise's 100 points`;
}

function confirmBox(text, yes) {
  const box = $("confirm");
  box.replaceChildren(termEl("p", {}, text), el("div", { class: "row" },
    el("button", { class: "primary", id: "confirm-yes", text: "Yes, do it", onclick: () => { box.hidden = true; yes(); } }),
    el("button", { id: "confirm-no", text: "Cancel", onclick: () => { box.hidden = true; } })));
  box.hidden = false;
}

async function feedbackOf(which) {
  const r = await fetch(`/api/sessions/${encodeURIComponent(sid)}/feedback?stage=${which}`, { headers: auth() });
  return r.ok ? r.json() : null;
}
function showFeedback(fb, title, buttons) {
  const box = $("feedback");
  box.replaceChildren(el("b", { text: title }), ...fb.lines.map((line) => termEl("p", {}, line)));
  if (buttons.length) box.append(el("div", { class: "row" }, ...buttons.map(([t, f]) => el("button", { text: t, onclick: f }))));
  box.hidden = false;
}
// After a claim whose checks failed (practice): the likely wrong setting, and the way back.
async function afterClaim(action, result) {
  if (!action || action.kind !== "claim" || !result || !result.measures) return;
  if (result.measures.every((m) => m.passed)) { $("feedback").hidden = true; return; }
  const fb = await feedbackOf("last");
  if (!fb) return;
  const back = state && !state.done && (state.allowed || []).includes("undo");
  showFeedback(fb, `Stage ${fb.stage} claimed, not within its tolerance.`, back
    ? [["Undo the claim, fix it and claim again (an undo costs no points; the grade takes your last claim)", () => { $("feedback").hidden = true; send({ kind: "undo" }); }]]
    : []);
}

// "Go to": the X, Y settings that put the left mark on the point, sent as the trainee's own.
async function goTo(where) {
  const q = where.point ? `point=${encodeURIComponent(where.point)}` : `x=${where.x}&y=${where.y}`;
  const r = await fetch(`/api/sessions/${encodeURIComponent(sid)}/goto?${q}`, { headers: auth() });
  const body = await r.json();
  if (!r.ok) { message(body.error, "error"); return; }
  for (const a of body.actions) send(a);
  tourEvent("goto", where);
  message(`${body.actions.map(describe).join(", ")}${where.point ? ` (standard point ${where.point})` : ""}`);
}
for (const b of $("goto").querySelectorAll("button[data-point]")) b.onclick = () => goTo({ point: b.dataset.point });

// Where the detail matching the left mark lies outside the right eyepiece's field: say so.
function zoomNote(marks, mag) {
  const box = $("zoom-note");
  if (!marks || !overviewData || !overviewData.photos) { box.hidden = true; return; }
  const L = overviewData.photos.left.standard_points, R = overviewData.photos.right.standard_points;
  let best = null;
  L.forEach((p, i) => {
    const d = Math.hypot(p.x_mm - marks.left.x_mm, p.y_mm - marks.left.y_mm);
    if (!best || d < best.d) best = { d, i };
  });
  const field = 256 / (scale.pxPerMmAt1x * mag); // mm of photo across an eyepiece
  if (!best || best.d > field) { box.hidden = true; return; }
  const p = L[best.i], r = R[best.i];
  const want = { x: r.x_mm + (marks.left.x_mm - p.x_mm), y: r.y_mm + (marks.left.y_mm - p.y_mm) };
  const dx = want.x - marks.right.x_mm, dy = want.y - marks.right.y_mm;
  const off = Math.hypot(dx, dy);
  if (off <= field / 2) { box.hidden = true; return; }
  const fits = [2, 6, 20].filter((m) => off <= 256 / (scale.pxPerMmAt1x * m) / 2);
  const why = Math.abs(dx) >= Math.abs(dy)
    ? "mostly along the base (x-parallax): turn Z, the foot wheel, to bring it in"
    : "mostly across the base (y-parallax): clear it roughly at standard points 1 and 2 first";
  box.textContent = `At standard point ${p.id} the detail under the left mark is ${off.toFixed(2)} mm from the right mark, `
    + `${why}; it is outside the right eyepiece's field at ×${mag} (${(field / 2).toFixed(2)} mm). `
    + (fits.length ? `Zoom out to ×${Math.max(...fits)} to find it, then clear the parallax and zoom in again.`
      : "Even ×2 does not reach it.");
  box.hidden = false;
}

// --- the newcomer's tour: one card at a time, each on one part of the page ----------------------
let tourAt = null;
function showTour(i) {
  document.querySelectorAll(".tour-target").forEach((e) => e.classList.remove("tour-target"));
  const cards = (words && words.tour) || [];
  const box = $("tour");
  if (i === null || i >= cards.length) { tourAt = cards.length; box.hidden = true; return; }
  tourAt = i;
  const c = cards[i];
  const target = $(c.target);
  if (target) { target.classList.add("tour-target"); target.scrollIntoView({ block: "nearest" }); }
  box.replaceChildren(el("h3", { text: c.title }), termEl("p", {}, c.text), el("p", { class: "meta", text: `Try: ${c.try}` }),
    el("div", { class: "row" },
      el("button", { id: "tour-next", class: "primary", text: i + 1 < cards.length ? "Next" : "Close", onclick: () => showTour(i + 1) }),
      el("button", { text: "Close the cards", onclick: () => showTour(null) }),
      el("span", { class: "meta", text: `${i + 1} / ${cards.length}` })));
  box.hidden = false;
  box.dataset.card = String(i);
}
function tourEvent(kind, detail) {
  const cards = (words && words.tour) || [];
  if (tourAt === null || tourAt >= cards.length) return;
  const want = cards[tourAt].done;
  const met = (want.kind === "mag" && kind === "mag" && detail.value === want.value)
    || (want.kind === "set" && (kind === "set" || kind === "turn") && detail.control === want.control)
    || (want.kind === "read" && kind === "read") || (want.kind === "goto" && kind === "goto");
  if (met) setTimeout(() => showTour(tourAt + 1), 400);
}
$("tour-btn").onclick = () => showTour(0);

// --- the trainee's stereo acuity ----------------------------------------------------------------
$("acuity").append(acuityPanel());
const acuityTest = new AcuityTest($("acuity"), send, () => (hello ? hello.screen_pixel_mm : 0.1));
$("acuity-open").onclick = () => { $("acuity-body").hidden = !$("acuity-body").hidden; };
window.acuityTest = acuityTest;
