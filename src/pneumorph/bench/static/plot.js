// The profile plot: the target curve and an actuator's centreline, in mm, equal scales.

function niceStep(span, count) {
  const raw = span / Math.max(count, 1);
  const power = Math.pow(10, Math.floor(Math.log10(raw)));
  for (const m of [1, 2, 5, 10]) {
    if (m * power >= raw) return m * power;
  }
  return 10 * power;
}

function bounds(sets) {
  let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
  for (const pts of sets) {
    for (const [x, y] of pts) {
      if (!Number.isFinite(x) || !Number.isFinite(y)) continue;
      x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
    }
  }
  if (!Number.isFinite(x0)) return [0, 1, 0, 1];
  return [x0, x1, y0, y1];
}

// Draw on `canvas`: {target: [[x, y]...] or null, point: [x, y] or null,
// profile: [[x, y]...] (base, centres, tip), label: string,
// stages: [{points, point, colour, current, label}] (a staged target's stages) and
// ramp: the profiles of every level (drawn faint behind the profile), both optional;
// vertical: the vertical axis's label, "y (mm)" unless a view from above; axis: the height of the
// undeformed axis, drawn dashed (0 for heights above it; a path's frame has it 6 mm up);
// targetLabel: the target's legend ("target", or what the path is); circle: an object {centre, radius},
// contact: the nodes in contact with it [[x, y]...], fe: the FE centreline solved against it, or null}.
export function drawProfile(canvas, { target, point, profile, label, stages = [], ramp = null, vertical = "y (mm)",
  axis = 0, targetLabel = "target", circle = null, contact = [], fe = null }) {
  const ctx = canvas.getContext("2d");
  const W = canvas.width, H = canvas.height, pad = { l: 48, r: 14, t: 14, b: 34 };
  ctx.clearRect(0, 0, W, H);
  const sets = [profile || [], [[0, 0]]];
  if (target) sets.push(target);
  if (point) sets.push([point]);
  for (const st of stages) { if (st.points) sets.push(st.points); if (st.point) sets.push([st.point]); }
  if (ramp) ramp.forEach((pts) => sets.push(pts));
  if (circle) {
    const [ox, oy] = circle.centre, r = circle.radius;
    sets.push([[ox - r, oy - r], [ox + r, oy + r]]);
  }
  if (fe) sets.push(fe);
  let [x0, x1, y0, y1] = bounds(sets);
  const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
  const pw = W - pad.l - pad.r, ph = H - pad.t - pad.b;
  const scale = Math.min(pw / (Math.max(x1 - x0, 10) * 1.08), ph / (Math.max(y1 - y0, 10) * 1.15));  // px per mm, both axes
  const X = (x) => pad.l + pw / 2 + (x - cx) * scale;
  const Y = (y) => pad.t + ph / 2 - (y - cy) * scale;
  const xmin = cx - pw / 2 / scale, xmax = cx + pw / 2 / scale;
  const ymin = cy - ph / 2 / scale, ymax = cy + ph / 2 / scale;

  // grid and ticks
  const step = niceStep(Math.max(xmax - xmin, ymax - ymin), 8);
  ctx.font = "11px system-ui, sans-serif";
  ctx.fillStyle = "#626a73";
  ctx.strokeStyle = "#eceff2";
  ctx.lineWidth = 1;
  ctx.textAlign = "center";
  for (let v = Math.ceil(xmin / step) * step; v <= xmax; v += step) {
    ctx.beginPath(); ctx.moveTo(X(v), pad.t); ctx.lineTo(X(v), pad.t + ph); ctx.stroke();
    ctx.fillText(String(+v.toFixed(6)), X(v), H - pad.b + 14);
  }
  ctx.textAlign = "right";
  for (let v = Math.ceil(ymin / step) * step; v <= ymax; v += step) {
    ctx.beginPath(); ctx.moveTo(pad.l, Y(v)); ctx.lineTo(pad.l + pw, Y(v)); ctx.stroke();
    ctx.fillText(String(+v.toFixed(6)), pad.l - 5, Y(v) + 4);
  }
  ctx.textAlign = "center";
  ctx.fillText("x (mm)", pad.l + pw / 2, H - 4);
  ctx.save(); ctx.translate(12, pad.t + ph / 2); ctx.rotate(-Math.PI / 2); ctx.fillText(vertical, 0, 0); ctx.restore();
  ctx.strokeStyle = "#b8c0c8";
  ctx.setLineDash([4, 4]);
  ctx.beginPath(); ctx.moveTo(pad.l, Y(axis)); ctx.lineTo(pad.l + pw, Y(axis)); ctx.stroke();
  ctx.setLineDash([]);

  const line = (pts, colour, width) => {
    ctx.strokeStyle = colour; ctx.lineWidth = width; ctx.beginPath();
    pts.forEach(([x, y], i) => (i ? ctx.lineTo(X(x), Y(y)) : ctx.moveTo(X(x), Y(y))));
    ctx.stroke();
  };
  const cross = (pt, colour) => {
    ctx.strokeStyle = colour; ctx.lineWidth = 2;
    const [px, py] = [X(pt[0]), Y(pt[1])];
    ctx.beginPath(); ctx.moveTo(px - 7, py); ctx.lineTo(px + 7, py); ctx.moveTo(px, py - 7); ctx.lineTo(px, py + 7); ctx.stroke();
  };
  if (ramp) ramp.forEach((pts) => line(pts, "#d0d7de", 1));
  if (target) line(target, "#e07b1a", 2.5);
  if (point) cross(point, "#e07b1a");
  for (const st of stages) {
    if (st.points) line(st.points, st.colour, st.current ? 3 : 1.5);
    if (st.point) cross(st.point, st.colour);
  }
  if (circle) {
    ctx.strokeStyle = "#57606a"; ctx.fillStyle = "rgba(87, 96, 106, 0.15)"; ctx.lineWidth = 2;
    ctx.beginPath(); ctx.arc(X(circle.centre[0]), Y(circle.centre[1]), circle.radius * scale, 0, 2 * Math.PI);
    ctx.fill(); ctx.stroke();
  }
  if (fe) line(fe, "#1a7f37", 2);
  ctx.fillStyle = "#cf222e";
  for (const [x, y] of contact) { ctx.beginPath(); ctx.arc(X(x), Y(y), 4, 0, 2 * Math.PI); ctx.fill(); }
  if (profile && profile.length) {
    line(profile, "#0b6bcb", 2);
    ctx.fillStyle = "#0b6bcb";
    profile.slice(1, -1).forEach(([x, y]) => { ctx.beginPath(); ctx.arc(X(x), Y(y), 3, 0, 2 * Math.PI); ctx.fill(); });
  }
  // legend
  ctx.textAlign = "left";
  ctx.font = "12px system-ui, sans-serif";
  let ly = pad.t + 14;
  const legend = (colour, text) => {
    ctx.fillStyle = colour; ctx.fillRect(pad.l + 8, ly - 8, 16, 3);
    ctx.fillStyle = "#1f2328"; ctx.fillText(text, pad.l + 30, ly - 3); ly += 16;
  };
  if (target || point) legend("#e07b1a", target ? targetLabel : "tip goal");
  for (const st of stages) legend(st.colour, st.current ? `${st.label} (this level)` : st.label);
  if (ramp) legend("#d0d7de", "the ramp: every level");
  if (profile) legend("#0b6bcb", label || "unit centres");
  if (circle) legend("#57606a", "object");
  if (fe) legend("#1a7f37", "FE with contact (nodes in contact in red)");
}
