// Exercise picker: lists the shipped exercises and starts a session on the server.
const list = document.getElementById("exercises");

async function start(name) {
  const body = {
    exercise: name,
    trainee: document.getElementById("trainee").value || "trainee",
    demonstration: document.getElementById("demo").checked,
  };
  const r = await fetch("/api/sessions", { method: "POST", body: JSON.stringify(body) });
  const j = await r.json();
  if (!r.ok) { alert(j.error); return; }
  location.href = `/s/${j.id}`;
}

const exercises = await (await fetch("/api/exercises")).json();
for (const ex of exercises) {
  const card = document.createElement("div");
  card.className = "card";
  card.innerHTML = `<h3></h3><div class="row"><span class="badge ${ex.mode}">${ex.mode}</span>
    <span class="badge">level ${ex.level}</span><span class="badge">${ex.instrument}</span></div><p></p>`;
  card.querySelector("h3").textContent = `${ex.name}: ${ex.title}`;
  card.querySelector("p").textContent = ex.description;
  const b = document.createElement("button");
  b.className = "primary"; b.textContent = "Start"; b.dataset.exercise = ex.name;
  b.onclick = () => start(ex.name);
  card.appendChild(b);
  list.appendChild(card);
}
