// The words of the page: every symbol of the book (MO, M_в, n_л, the L-check, decisions,
// equation numbers …) found in a text and wrapped in a term one hover (its title) or one tap
// (the glossary box) away, in English and Russian (the server's glossary, kept with the
// project's glossary). DOM from elements and text nodes only.
import { el } from "./dom.js";

let entries = [];
export const names = { controls: {}, sheet: {} };

export async function loadGlossary() {
  const r = await fetch("/api/glossary");
  if (!r.ok) return;
  const body = await r.json();
  entries = body.symbols.map((s) => ({ ...s, re: new RegExp(s.pattern, "u") }));
  Object.assign(names.controls, body.controls);
  Object.assign(names.sheet, body.sheet);
  document.body.dataset.glossary = String(entries.length);
}

function explain(e) { return `${e.en}\n\n${e.ru}`; }

// A text as nodes: plain text and <span class="term"> for each symbol found (the earliest,
// longest match first).
export function withTerms(text) {
  const out = [];
  let rest = String(text ?? "");
  while (rest) {
    let best = null;
    for (const e of entries) {
      const m = e.re.exec(rest);
      if (m && m[0] && (!best || m.index < best.m.index || (m.index === best.m.index && m[0].length > best.m[0].length))) best = { e, m };
    }
    if (!best) { out.push(rest); break; }
    if (best.m.index > 0) out.push(rest.slice(0, best.m.index));
    out.push(el("span", { class: "term", tabindex: "0", title: explain(best.e), "data-symbol": best.e.symbol, text: best.m[0] }));
    rest = rest.slice(best.m.index + best.m[0].length);
  }
  return out;
}

// An element whose text carries its terms.
export function termEl(tag, attrs, text) {
  return el(tag, attrs, ...withTerms(text));
}

// A tap (or Enter) on a term opens the glossary box with both languages; a tap elsewhere closes.
export function glossaryBox(box) {
  const open = (t) => {
    const e = entries.find((x) => x.symbol === t.dataset.symbol);
    if (!e) return;
    box.replaceChildren(el("b", { text: t.textContent }), el("p", { text: e.en }), el("p", { lang: "ru", text: e.ru }),
      el("button", { text: "close", onclick: () => { box.hidden = true; } }));
    box.hidden = false;
  };
  document.addEventListener("click", (ev) => {
    const t = ev.target.closest && ev.target.closest(".term");
    if (t) open(t);
    else if (!box.contains(ev.target)) box.hidden = true;
  });
  document.addEventListener("keydown", (ev) => {
    if (ev.key === "Enter" && ev.target.classList && ev.target.classList.contains("term")) open(ev.target);
  });
}

// A value of the setup sheet by its part and dotted key (undefined when not given).
export function sheetValue(sheet, part, key) {
  let v = sheet && sheet[part];
  for (const k of key.split(".")) v = v === undefined || v === null ? undefined : v[k];
  return v;
}
