// The instrument page's panels built from the core's data: the action controls (one per action
// kind of the core's catalogue), readable results, the stage checklist, announced errors,
// coupled motions and the setup sheet. DOM from elements and text nodes only.
import { el } from "./dom.js";
import { LABELS } from "./wheels.js";
import { withTerms, termEl, names, sheetValue } from "./words.js";

// Kinds with their own widgets elsewhere on the page: wheels (turn, set), the counters table
// (direction, read), the stage panel (claim, undo, redo, hint).
export const ELSEWHERE = new Set(["turn", "set", "direction", "read", "claim", "undo", "redo", "hint"]);

const SIDES = [["", "either side"], ["below", "below"], ["above", "above"]];

// A catalogue field as {name, type, unit, optional, choices, text} (the core may send a name only).
export function fieldOf(f) {
  return typeof f === "string" ? { name: f } : f;
}

// A typed record value: a number, a list of numbers ("12.5, -3"), else the text itself.
export function parseValue(text) {
  const t = text.trim();
  if (t !== "" && t.split(/[,;\s]+/).every((p) => p !== "" && Number.isFinite(Number(p)))) {
    const parts = t.split(/[,;\s]+/).map(Number);
    return parts.length === 1 ? parts[0] : parts;
  }
  return t;
}

function input(kind, f, controls) {
  const id = `act-${kind}-${f.name}`;
  if (f.type === "choice" || f.name === "control" || f.name === "side" || f.choices) {
    const choices = f.name === "control" ? controls : f.choices || [];
    const opts = choices.map((c) => el("option", { value: String(c), text: LABELS[c] || String(c) }));
    if (f.optional) opts.unshift(el("option", { value: "", text: f.name === "side" ? "either side" : "—" }));
    return el("select", { id, name: f.name }, ...opts);
  }
  if (f.type === "point" || f.type === "number-or-point" || f.type === "text") {
    const hint = f.type === "text" ? (f.examples || []).join(", ") : f.type === "point" ? "x, y" : "number or x, y";
    return el("input", { id, name: f.name, placeholder: hint + (f.optional ? " (optional)" : ""), maxlength: 64, class: "w120" });
  }
  return el("input", { id, name: f.name, type: "number", step: f.type === "integer" ? "1" : "any", class: "w80" });
}

// The action's fields read from its form; null (with a message) when one is missing.
function collect(kind, form, fields) {
  const action = { kind };
  for (const f of fields) {
    const box = form.elements.namedItem(f.name);
    const raw = box.value.trim();
    if (raw === "") {
      if (f.optional) continue;
      return null;
    }
    if (f.type === "point" || f.type === "number-or-point") action[f.name] = parseValue(raw);
    else if (f.type === "choice" && (f.choices || []).every((c) => typeof c === "number")) action[f.name] = Number(raw);
    else if (f.type === "choice" || f.type === "text" || box.tagName === "SELECT") action[f.name] = raw;
    else action[f.name] = Number(raw);
  }
  return action;
}

// One form per action kind of the catalogue not handled elsewhere: its fields, a button.
export function buildActions(root, catalogue, controls, send, say) {
  root.replaceChildren();
  for (const entry of catalogue) {
    if (ELSEWHERE.has(entry.kind)) continue;
    const all = (entry.fields || []).map(fieldOf);
    const fields = all.filter((f) => !f.optional);
    const button = el("button", { type: "submit", id: `act-${entry.kind}`, text: entry.kind });
    const unit = (f) => (f.unit && f.unit !== "control" && f.unit !== "—" ? ` [${f.unit}]` : "");
    const form = el("form", { class: "row action", "data-kind": entry.kind, title: entry.label || "" },
      button, ...all.map((f) => el("label", {}, `${f.name.replaceAll("_", " ")}${unit(f)} `, input(entry.kind, f, controls))));
    if (entry.label) form.append(el("span", { class: "meta small", text: entry.label }));
    form.addEventListener("submit", (e) => {
      e.preventDefault();
      const action = collect(entry.kind, form, all);
      if (action === null) { say(`${entry.kind}: fill in ${fields.map((f) => f.name).join(", ")}`, "error"); return; }
      send(action);
    });
    root.append(form);
  }
}

const fmt = (v) => (typeof v !== "number" ? String(v)
  : Number.isInteger(v) ? String(v) : Math.abs(v) >= 1e-3 ? String(Number(v.toFixed(6))) : v.toExponential(2));

// What an action answered, as readable text and tables (never a JSON dump).
export function showResult(root, action, result) {
  root.replaceChildren();
  if (result === null || result === undefined) return;
  if (typeof result === "number") {
    const what = action && action.counter ? `${LABELS[action.counter] || action.counter} reads` : "reading:";
    root.append(el("p", { text: `${what} ${fmt(result)}` }));
    return;
  }
  if (typeof result === "string") { root.append(el("p", { text: result })); return; }
  if (Array.isArray(result)) {
    const what = action && action.kind === "needle" ? "the needle pricked at" : "result:";
    root.append(el("p", { text: `${what} ${result.map(fmt).join(", ")}` }));
    return;
  }
  if (result.claimed && !result.text) root.append(el("p", { class: "big", text: `Stage ${result.claimed} claimed.` }));
  if (result.level) root.append(el("h3", { text: `Hint ${result.level}` }));
  if (Array.isArray(result.text)) for (const line of result.text) root.append(termEl("p", {}, String(line)));
  else if (result.lines && result.lines.length) for (const line of result.lines) root.append(termEl("p", {}, typeof line === "string" ? line : line.text || ""));
  else if (result.text) for (const para of String(result.text).split(/\n\s*\n/)) root.append(termEl("p", {}, para));
  if (result.cost !== undefined && result.cost !== null) root.append(el("p", { class: "meta", text: `this hint costs ${fmt(result.cost)} of the score` }));
  if (result.steps && result.steps.length && !(result.lines && result.lines.length)) {
    root.append(el("p", { class: "meta", text: "the simulated operator's steps in this stage:" }),
      el("ol", {}, ...result.steps.map((s) => termEl("li", {}, typeof s === "string" ? s : s.text || s.name || ""))));
  }
  if (result.controls && result.controls.length) {
    root.append(el("p", { text: `controls the operator uses here: ${result.controls.map((c) => LABELS[c] || c).join(", ")}` }));
  }
  if (result.applied) root.append(el("p", { text: `the operator's ${result.applied} actions of the stage were carried out on your instrument` }));
  if (result.measures && result.measures.length) {
    root.append(el("table", {}, el("tr", {}, ...["measure", "value", "tolerance", ""].map((h) => el("th", { text: h }))),
      ...result.measures.map((m) => el("tr", {}, termEl("td", {}, m.name), el("td", { class: "num", text: `${fmt(m.value)} ${m.unit}` }),
        el("td", { class: "num", text: `${fmt(m.tolerance)} ${m.unit}` }),
        el("td", { class: m.passed ? "pass" : "fail", text: m.passed ? "within" : "outside" })))));
  }
}

// The stage's steps as a checklist (the core's, ticked when their targets are met): each step
// with the controls it uses, the sheet rows its values come from (with the values, where the
// exercise's sheet gives them), a note where its number differs from the sheet's; a step taken
// only when a check fails is shown only while it fails, marked with its condition.
export function showChecklist(root, list, sheet) {
  const items = Array.isArray(list) ? list : list ? list.steps : [];
  root.dataset.done = list && list.done !== undefined ? `${list.done}/${list.total}` : "";
  root.replaceChildren(...(items || []).filter((it) => it.shown !== false).map((it) => {
    const done = !!(it.done || it.ticked);
    const li = el("li", { class: done ? "done" : it.conditional ? "conditional" : "", "data-done": done ? "1" : "0", "data-n": String(it.n ?? "") },
      el("span", { class: "tick", text: done ? "☑ " : "☐ " }), ...withTerms(it.text || it.step || it.name || ""));
    if (it.condition) li.append(termEl("div", { class: "step-condition" }, `if needed: ${it.condition}`));
    const uses = it.control_names && it.control_names.length ? it.control_names : null;
    if (uses) li.append(termEl("div", { class: "step-uses" }, `controls: ${uses.join(", ")}`));
    for (const row of it.sheet_rows || []) {
      const v = sheetValue(sheet, row.part, row.key);
      const where = `${SHEET_PARTS[row.part] || row.part} → ${names.sheet[row.key.split(".")[0]] || row.key}${row.key.includes(".") ? ` (${row.key.split(".").slice(1).join(" ")})` : ""}`;
      const value = v === undefined ? "" : ` = ${fmt(v)}`;
      li.append(termEl("div", { class: "step-sheet", "data-key": row.key }, `sheet: ${where}${value} — ${row.control}: ${row.use}`));
    }
    if (it.note) li.append(termEl("div", { class: "step-note" }, it.note));
    return li;
  }));
}

// Announced injected errors: name and size (the core's text when it sends one).
export function showAnnounced(box, list, errors) {
  const rows = Array.isArray(errors) ? errors
    : Object.entries(errors || {}).map(([name, value]) => ({ name, value }));
  box.hidden = rows.length === 0;
  list.replaceChildren(...rows.map((r) => el("li", {
    text: r.text || `${r.name}: ${fmt(r.value)}${r.unit ? ` ${r.unit}` : ""}`,
  })));
}

// Counters that moved though the action did not name them: said, with the core's reason.
export function showCoupled(root, action, before, after, explanations) {
  root.replaceChildren();
  if (!action || !before || !after || !["turn", "set"].includes(action.kind)) return;
  const moved = [];
  for (const [name, c] of Object.entries(after.counters)) {
    const b = before.counters[name];
    if (!b || name === action.control || b.value === null || c.value === null) continue;
    if (Math.abs(c.value - b.value) >= c.least_count) moved.push([name, b.value, c.value, c.unit]);
  }
  const events = (explanations || []).filter((x) => x && (typeof x === "string" || x.kind === "coupled" || x.text));
  if (events.some((x) => x.moved)) { // the core's own account: what moved and why
    moved.length = 0;
    for (const x of events) for (const [n, [b, a]] of Object.entries(x.moved || {})) moved.push([n, b, a, after.counters[n] ? after.counters[n].unit : ""]);
  }
  const texts = events.map((x) => (typeof x === "string" ? x : x.text)).filter(Boolean);
  if (!moved.length && !texts.length) return;
  root.append(el("p", { class: "meta", text: `${LABELS[action.control] || action.control} moved other counters too:` }),
    el("ul", {}, ...moved.map(([n, b, a, u]) => el("li", { text: `${LABELS[n] || n}: ${fmt(b)} → ${fmt(a)} ${u}` }))));
  for (const t of texts) root.append(el("p", { class: "coupled-why", text: t }));
}

// A list of numbers or of short lists as text: "1.5, 2" or "(1.5, 2); (3, 4)".
function listText(value) {
  return value.map((v) => (Array.isArray(v) ? `(${listText(v)})`
    : v && typeof v === "object" ? Object.entries(v).map(([k, x]) => `${k} ${fmt(x)}`).join(" ")
      : fmt(v))).join(value.some(Array.isArray) ? "; " : ", ");
}

// Any JSON value as nested tables: a mapping as name/value rows, a list of mappings as a table.
export function renderData(value, depth = 0) {
  if (value === null || value === undefined) return el("span", { class: "dim", text: "—" });
  if (typeof value !== "object") return el("span", { text: fmt(value) });
  if (Array.isArray(value)) {
    if (value.length && value.every((v) => v && typeof v === "object" && !Array.isArray(v))) {
      const cols = [...new Set(value.flatMap((v) => Object.keys(v)))];
      return el("table", { class: "data" }, el("tr", {}, ...cols.map((c) => el("th", { text: c.replaceAll("_", " ") }))),
        ...value.map((v) => el("tr", {}, ...cols.map((c) => el("td", {}, renderData(v[c], depth + 1))))));
    }
    return el("span", { text: listText(value) });
  }
  const table = el("table", { class: depth ? "data nested" : "data" });
  for (const [k, v] of Object.entries(value)) {
    table.append(el("tr", {}, el("th", { text: k.replaceAll("_", " ") }), el("td", {}, renderData(v, depth + 1))));
  }
  return table;
}

const SHEET_PARTS = {
  certificate: "Camera certificate",
  interior: "Interior orientation and scales",
  table24: "Table 24: the setup data",
  readings: "Readings of the five stages",
};

// The setup sheet (the core's exercise_sheet): the parts the exercise gives, each as a heading
// and its data, and the parts withheld with the reason; any other sheet as nested tables.
export function showSheet(root, sheet) {
  root.replaceChildren();
  if (sheet.given) {
    for (const part of sheet.given) {
      if (sheet[part] === undefined) continue;
      root.append(el("h3", { text: SHEET_PARTS[part] || part.replaceAll("_", " ") }), renderData(sheet[part]));
    }
    const withheld = Object.entries(sheet.withheld || {});
    if (withheld.length) {
      root.append(el("h3", { text: "Not given in this exercise" }),
        el("ul", {}, ...withheld.map(([part, why]) => el("li", { text: `${SHEET_PARTS[part] || part}: ${why}` }))));
    }
    return;
  }
  const plain = Object.fromEntries(Object.entries(sheet).filter(([, v]) => v === null || typeof v !== "object"));
  if (Object.keys(plain).length) root.append(renderData(plain));
  for (const [k, v] of Object.entries(sheet)) {
    if (v !== null && typeof v === "object") root.append(el("h3", { text: k.replaceAll("_", " ") }), renderData(v));
  }
}

// An action in words (the demonstration's operator, the replay).
export function describe(a) {
  if (!a) return "";
  const what = LABELS[a.control || a.counter] || a.control || a.counter || "";
  const side = a.side ? ` from ${a.side}` : "";
  if (a.kind === "set") return `set ${what} to ${a.value}${side}`;
  if (a.kind === "turn") return `turn ${what} by ${a.delta}`;
  if (a.kind === "read") return `read ${what}`;
  if (a.kind === "record") return `record ${a.name} = ${Array.isArray(a.value) ? a.value.join(", ") : a.value}`;
  if (a.kind === "claim") return `claim stage ${a.step}`;
  return [a.kind, a.value, what, a.side].filter((v) => v !== undefined && v !== "").join(" ");
}

// A typed action of the keyboard box: "X 215.3 [below|above]" or "set X 215.3 …" (set),
// "turn X 0.5 …", "read X", "lock X". The control or counter as the core names it or as the
// page labels it; null (and why) when the text is not an action.
export function parseCommand(text, names) {
  const words = text.trim().split(/\s+/).filter(Boolean);
  const byLabel = Object.fromEntries(Object.entries(LABELS).map(([k, v]) => [v.toLowerCase(), k]));
  const name = (w) => (names.includes(w) ? w : byLabel[String(w).toLowerCase()] || null);
  let verb = "set";
  if (["set", "turn", "read", "lock"].includes((words[0] || "").toLowerCase())) verb = words.shift().toLowerCase();
  const control = name(words[0]);
  if (!control) return { error: `keyboard: expected a control (${names.join(", ")}), found ${words[0] || "nothing"}` };
  if (verb === "read") return { action: { kind: "read", counter: control } };
  if (verb === "lock") return { action: { kind: "lock", control } };
  const value = Number(words[1]);
  if (words[1] === undefined || !Number.isFinite(value)) return { error: `keyboard: ${verb} ${control}: expected a number` };
  const side = (words[2] || "").toLowerCase();
  if (side && side !== "below" && side !== "above") return { error: "keyboard: the side is below or above" };
  const action = verb === "turn" ? { kind: "turn", control, delta: value } : { kind: "set", control, value };
  if (side) action.side = side;
  return { action };
}
