// The Delta E 2000 heat map of a fit over (angle, eta_i), drawn on a canvas
// from GET /api/v1/fits/{id}/error-map.

// Stops of the colour scale (dark blue, teal, yellow, red), Delta E at each.
const STOPS = [
  [0.0, [12, 20, 60]],
  [0.5, [30, 120, 140]],
  [1.0, [120, 190, 90]],
  [2.0, [240, 210, 60]],
  [5.0, [230, 60, 50]],
];

export function colourOf(dE) {
  for (let i = 1; i < STOPS.length; i++) {
    const [v1, c1] = STOPS[i];
    const [v0, c0] = STOPS[i - 1];
    if (dE <= v1) {
      const f = (dE - v0) / (v1 - v0);
      return c0.map((c, k) => Math.round(c + f * (c1[k] - c)));
    }
  }
  return STOPS[STOPS.length - 1][1];
}

export function drawErrorMap(canvas, map) {
  const ctx = canvas.getContext("2d");
  const W = canvas.width, H = canvas.height;
  const left = 34, bottom = 22, right = 46, top = 6;
  const w = W - left - right, h = H - top - bottom;
  ctx.fillStyle = "#0c0d10";
  ctx.fillRect(0, 0, W, H);
  const rows = map.delta_E.length, cols = map.theta_deg.length;
  // Rows bottom to top: low eta_i at the bottom.
  for (let r = 0; r < rows; r++) {
    for (let c = 0; c < cols; c++) {
      const [R, G, B] = colourOf(map.delta_E[r][c]);
      ctx.fillStyle = `rgb(${R},${G},${B})`;
      const x0 = left + (c / cols) * w, y0 = top + h - ((r + 1) / rows) * h;
      ctx.fillRect(Math.floor(x0), Math.floor(y0), Math.ceil(w / cols) + 1, Math.ceil(h / rows) + 1);
    }
  }
  ctx.fillStyle = "#9aa3b2";
  ctx.font = "10px system-ui, sans-serif";
  ctx.textAlign = "center";
  for (const t of [0, 30, 60, 90]) ctx.fillText(`${t}°`, left + (t / 90) * w, H - 8);
  ctx.textAlign = "right";
  const eta = map.eta_i;
  ctx.fillText(eta[0].toFixed(2), left - 4, top + h);
  ctx.fillText(eta[eta.length - 1].toFixed(2), left - 4, top + 10);
  ctx.save();
  ctx.translate(10, top + h / 2);
  ctx.rotate(-Math.PI / 2);
  ctx.textAlign = "center";
  ctx.fillText("η_i", 0, 0);
  ctx.restore();
  // Legend: the colour scale from 0 to 5.
  const lx = W - right + 12;
  for (let y = 0; y < h; y++) {
    const [R, G, B] = colourOf(5 * (1 - y / h));
    ctx.fillStyle = `rgb(${R},${G},${B})`;
    ctx.fillRect(lx, top + y, 10, 1);
  }
  ctx.fillStyle = "#9aa3b2";
  ctx.textAlign = "left";
  ctx.fillText("5", lx + 13, top + 8);
  ctx.fillText("0", lx + 13, top + h);
}
