// Eyepiece drawing on Canvas 2D: the field around a measuring mark, in photo coordinates.
// Photo tiles, when the server sends them, are drawn under the graticule (see drawField).

const COLOURS = { red: [1, 0, 0], cyan: [0, 1, 1], green: [0, 1, 0], magenta: [1, 0, 1] };

// Pixels of the eyepiece canvas per mm of photo at magnification 1 (1 / the imagery's
// SCREEN_PIXEL_MM, sent by the server in its first message).
// formatMm: side of the photo format (the mark is off the photo beyond ±formatMm / 2).
export const scale = { pxPerMmAt1x: 10, formatMm: null };

// Whether a photo patch holds the photo around the mark (a patch left behind by a fast move
// does not: the field shows the graticule until the new one arrives).
export function covers(patch, mark) {
  if (!patch || !mark || !patch.img.complete) return false;
  const half = patch.size / (scale.pxPerMmAt1x * patch.mag) / 2;
  return Math.abs(patch.x_mm - mark.x_mm) < half && Math.abs(patch.y_mm - mark.y_mm) < half;
}

// A mark outside the photo format: the field is the camera's black frame; say so.
function offPhoto(mark) {
  const h = scale.formatMm / 2;
  return scale.formatMm !== null && (Math.abs(mark.x_mm) > h || Math.abs(mark.y_mm) > h);
}

function say(ctx, w, h, lines) {
  ctx.save();
  ctx.fillStyle = "rgba(16,19,20,0.75)"; ctx.fillRect(0, h / 2 - 30, w, 46);
  ctx.fillStyle = "#ffd080"; ctx.font = "13px sans-serif"; ctx.textAlign = "center";
  lines.forEach((t, i) => ctx.fillText(t, w / 2, h / 2 - 10 + 18 * i));
  ctx.restore();
}

// The field of one eye centred on the mark (x_mm, y_mm), turned by the carrier's κ: the photo
// patch the server sent (drawn where it lies on the photo), else a graticule of photo
// coordinates (1 mm, bold every 5 mm) while it loads; then the mark itself at the centre.
export function drawField(ctx, mark, magnification, opts = {}) {
  drawPhoto(ctx, mark, magnification, opts);
  const w = ctx.canvas.width, h = ctx.canvas.height;
  if (mark && offPhoto(mark)) say(ctx, w, h, ["the mark is off the photo", `x ${mark.x_mm.toFixed(1)}  y ${mark.y_mm.toFixed(1)} mm`]);
  else if (mark && !covers(opts.patch, mark)) say(ctx, w, h, ["loading the photo…", "(graticule meanwhile)"]);
}

function drawPhoto(ctx, mark, magnification, { ink = "#e8e4d8", back = "#101314", markColour = "#ff4030", patch = null } = {}) {
  const w = ctx.canvas.width, h = ctx.canvas.height;
  ctx.save();
  ctx.fillStyle = back; ctx.fillRect(0, 0, w, h);
  if (!mark) {
    ctx.fillStyle = "#9aa3a8"; ctx.font = "13px sans-serif"; ctx.textAlign = "center";
    ctx.fillText("no projection yet:", w / 2, h / 2 - 8); ctx.fillText("set f_пр", w / 2, h / 2 + 10);
    ctx.restore(); return;
  }
  const s = scale.pxPerMmAt1x * magnification;
  ctx.translate(w / 2, h / 2);
  ctx.rotate(mark.kappa_rad); // a view column shows photo R(κ)·(du, dv) (imagery.eyepiece)
  if (covers(patch, mark)) {
    const k = magnification / patch.mag; // canvas px per patch px
    const n = patch.size * k;
    const cx = (patch.x_mm - mark.x_mm) * s, cy = -(patch.y_mm - mark.y_mm) * s;
    ctx.imageSmoothingEnabled = true;
    ctx.drawImage(patch.img, cx - n / 2, cy - n / 2, n, n);
    ctx.restore();
    drawMark(ctx, w, h, markColour);
    return;
  }
  const half = Math.hypot(w, h) / 2 / s;
  const x0 = Math.floor(mark.x_mm - half), x1 = Math.ceil(mark.x_mm + half);
  const y0 = Math.floor(mark.y_mm - half), y1 = Math.ceil(mark.y_mm + half);
  ctx.strokeStyle = ink; ctx.fillStyle = ink; ctx.font = "10px sans-serif";
  for (let x = x0; x <= x1; x++) {
    ctx.globalAlpha = x % 5 === 0 ? 0.9 : 0.35; ctx.lineWidth = x === 0 ? 2.5 : x % 5 === 0 ? 1.4 : 0.7;
    const px = (x - mark.x_mm) * s;
    ctx.beginPath(); ctx.moveTo(px, -h); ctx.lineTo(px, h); ctx.stroke();
    if (x % 5 === 0) ctx.fillText(`${x}`, px + 2, -h / 2 + 24);
  }
  for (let y = y0; y <= y1; y++) {
    ctx.globalAlpha = y % 5 === 0 ? 0.9 : 0.35; ctx.lineWidth = y === 0 ? 2.5 : y % 5 === 0 ? 1.4 : 0.7;
    const py = -(y - mark.y_mm) * s; // photo y up
    ctx.beginPath(); ctx.moveTo(-w, py); ctx.lineTo(w, py); ctx.stroke();
    if (y % 5 === 0) ctx.fillText(`${y}`, -w / 2 + 24, py - 2);
  }
  ctx.restore();
  drawMark(ctx, w, h, markColour);
}

function drawMark(ctx, w, h, markColour) {
  ctx.save();
  ctx.fillStyle = markColour; ctx.strokeStyle = markColour; ctx.lineWidth = 1.5;
  ctx.beginPath(); ctx.arc(w / 2, h / 2, 2.5, 0, 2 * Math.PI); ctx.fill();
  ctx.beginPath(); ctx.arc(w / 2, h / 2, 9, 0, 2 * Math.PI); ctx.stroke();
  ctx.restore();
}

// Anaglyph of two grey fields: the left one in colour a, the right in colour b (additive).
export function anaglyph(ctx, leftCanvas, rightCanvas, colours) {
  const w = ctx.canvas.width, h = ctx.canvas.height;
  const lc = leftCanvas.getContext("2d").getImageData(0, 0, w, h).data;
  const rc = rightCanvas.getContext("2d").getImageData(0, 0, w, h).data;
  const [ca, cb] = colours.map((c) => COLOURS[c]);
  const out = ctx.createImageData(w, h), o = out.data;
  for (let i = 0; i < o.length; i += 4) {
    const l = lc[i + 1], r = rc[i + 1]; // green channel: the grey level (the mark is red)
    for (let k = 0; k < 3; k++) o[i + k] = Math.min(255, l * ca[k] + r * cb[k]);
    o[i + 3] = 255;
  }
  ctx.putImageData(out, 0, 0);
}
