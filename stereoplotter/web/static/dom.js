// DOM built from elements and text nodes only: no string of data is ever parsed as HTML.
// el("td", {class: "num"}, "text", child) → <td class="num">text…</td>.
export function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === null || v === undefined || v === false) continue;
    if (k === "class") e.className = v;
    else if (k === "text") e.textContent = v;
    else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v === true ? "" : String(v));
  }
  for (const c of children) if (c !== null && c !== undefined) e.append(c);
  return e;
}

// The key of a session this browser started (kept for reconnecting and for its grade).
export const sessionKey = {
  get: (id) => localStorage.getItem(`stereoplotter-key-${id}`),
  set: (id, key) => localStorage.setItem(`stereoplotter-key-${id}`, key),
};

// A file download of a response that needs a credential in a header.
export async function download(url, headers, name) {
  const r = await fetch(url, { headers });
  if (!r.ok) { alert((await r.json()).error); return; }
  const a = el("a", { href: URL.createObjectURL(await r.blob()), download: name });
  document.body.append(a); a.click(); a.remove();
}
