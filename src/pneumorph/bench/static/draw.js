// The drawing area: a stroke over the actuator's length, in mm (x from the base, y up).

export class DrawArea {
  constructor(canvas, length, onStroke) {
    this.canvas = canvas; this.length = length; this.onStroke = onStroke;
    this.points = [];
    this.scale = (canvas.width - 40) / length;          // px per mm
    this.x0 = 20; this.y0 = canvas.height / 2;
    let drawing = false;
    const at = (e) => {
      const r = canvas.getBoundingClientRect();
      const px = (e.clientX - r.left) * (canvas.width / r.width), py = (e.clientY - r.top) * (canvas.height / r.height);
      return [(px - this.x0) / this.scale, (this.y0 - py) / this.scale];
    };
    canvas.addEventListener("pointerdown", (e) => {
      drawing = true; canvas.setPointerCapture(e.pointerId); this.points = [at(e)]; this.render();
    });
    canvas.addEventListener("pointermove", (e) => {
      if (!drawing) return;
      this.points.push(at(e)); this.render();
    });
    const end = () => {
      if (!drawing) return;
      drawing = false;
      if (this.points.length > 1) this.onStroke(this.points.map(([x, y]) => [+x.toFixed(3), +y.toFixed(3)]));
    };
    canvas.addEventListener("pointerup", end);
    canvas.addEventListener("pointercancel", end);
    this.render();
  }

  clear() { this.points = []; this.render(); }

  render() {
    const ctx = this.canvas.getContext("2d"), W = this.canvas.width, H = this.canvas.height;
    ctx.clearRect(0, 0, W, H);
    ctx.strokeStyle = "#c9d1d9"; ctx.lineWidth = 1; ctx.font = "11px system-ui"; ctx.fillStyle = "#626a73";
    for (let x = 0; x <= this.length + 1e-9; x += 25) {
      const px = this.x0 + x * this.scale;
      ctx.beginPath(); ctx.moveTo(px, 0); ctx.lineTo(px, H); ctx.stroke();
      ctx.fillText(`${x}`, px + 2, H - 4);
    }
    ctx.strokeStyle = "#8c959f"; ctx.setLineDash([5, 4]);
    ctx.beginPath(); ctx.moveTo(this.x0, this.y0); ctx.lineTo(this.x0 + this.length * this.scale, this.y0); ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillText("base", 2, this.y0 - 4);
    ctx.fillText(`tip (${this.length} mm)`, this.x0 + this.length * this.scale - 70, this.y0 - 4);
    if (this.points.length) {
      ctx.strokeStyle = "#e07b1a"; ctx.lineWidth = 2.5; ctx.beginPath();
      this.points.forEach(([x, y], i) => {
        const px = this.x0 + x * this.scale, py = this.y0 - y * this.scale;
        i ? ctx.lineTo(px, py) : ctx.moveTo(px, py);
      });
      ctx.stroke();
    }
  }
}
