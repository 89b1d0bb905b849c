// Exercise picker: lists the exercises and starts a session on the server.
import { el, sessionKey } from "./dom.js";

const list = document.getElementById("exercises");
const note = document.getElementById("note");

async function start(name) {
  const body = {
    exercise: name,
    trainee: document.getElementById("trainee").value || "trainee",
    demonstration: document.getElementById("demo").checked,
  };
  const r = await fetch("/api/sessions", {
    method: "POST", body: JSON.stringify(body), headers: { "Content-Type": "application/json" },
  });
  const j = await r.json();
  if (!r.ok) { note.textContent = j.error; note.className = "fail"; return; }
  sessionKey.set(j.id, j.secret);
  location.href = `/s/${encodeURIComponent(j.id)}`;
}

const exercises = await (await fetch("/api/exercises")).json();
for (const ex of exercises) {
  const b = el("button", { class: "primary", "data-exercise": ex.name, text: "Start" });
  b.addEventListener("click", () => start(ex.name));
  list.append(el("div", { class: "card" },
    el("h3", { text: `${ex.name}: ${ex.title}` }),
    el("div", { class: "row" },
      el("span", { class: `badge ${ex.mode === "exam" ? "exam" : "practice"}`, text: ex.mode }),
      el("span", { class: "badge", text: `level ${ex.level}` }),
      el("span", { class: "badge", text: ex.instrument })),
    el("p", { text: ex.description }),
    b));
}
