// A small WebGL viewer for the actuator's surface: Lambert shading, orbit and zoom.

const VERTEX = `
attribute vec3 position;
attribute vec3 normal;
uniform mat4 view;
uniform mat4 projection;
varying vec3 vNormal;
void main() {
  vNormal = mat3(view) * normal;
  gl_Position = projection * view * vec4(position, 1.0);
}`;

const FRAGMENT = `
precision mediump float;
varying vec3 vNormal;
uniform vec3 colour;
void main() {
  vec3 n = normalize(vNormal);
  float light = 0.35 + 0.65 * abs(dot(n, normalize(vec3(0.3, 0.5, 1.0))));
  gl_FragColor = vec4(colour * light, 1.0);
}`;

function compile(gl, type, source) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(shader));
  return shader;
}

function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
  return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0]);
}

// view = translate(0, 0, -distance) * rotateX(pitch) * rotateY(yaw) * translate(-centre)
function viewMatrix(yaw, pitch, distance, c) {
  const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
  const r = [cy, sp * sy, -cp * sy, 0, 0, cp, sp, 0, sy, -sp * cy, cp * cy, 0];
  const t = [
    -(r[0] * c[0] + r[4] * c[1] + r[8] * c[2]),
    -(r[1] * c[0] + r[5] * c[1] + r[9] * c[2]),
    -(r[2] * c[0] + r[6] * c[1] + r[10] * c[2]) - distance,
  ];
  return new Float32Array([r[0], r[1], r[2], 0, r[4], r[5], r[6], 0, r[8], r[9], r[10], 0, t[0], t[1], t[2], 1]);
}

function vertexNormals(pos, idx) {
  const n = new Float32Array(pos.length);
  for (let i = 0; i < idx.length; i += 3) {
    const a = 3 * idx[i], b = 3 * idx[i + 1], c = 3 * idx[i + 2];
    const ux = pos[b] - pos[a], uy = pos[b + 1] - pos[a + 1], uz = pos[b + 2] - pos[a + 2];
    const vx = pos[c] - pos[a], vy = pos[c + 1] - pos[a + 1], vz = pos[c + 2] - pos[a + 2];
    const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    for (const k of [a, b, c]) { n[k] += nx; n[k + 1] += ny; n[k + 2] += nz; }
  }
  return n;
}

export class Viewer {
  constructor(canvas) {
    this.canvas = canvas;
    this.gl = canvas.getContext("webgl", { antialias: true }) || canvas.getContext("experimental-webgl");
    this.yaw = -0.5; this.pitch = 0.45; this.zoom = 1; this.count = 0;
    if (!this.gl) { this.fail("WebGL is not available in this browser"); return; }
    const gl = this.gl;
    this.uint32 = !!gl.getExtension("OES_element_index_uint");
    const program = gl.createProgram();
    gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, VERTEX));
    gl.attachShader(program, compile(gl, gl.FRAGMENT_SHADER, FRAGMENT));
    gl.linkProgram(program);
    this.program = program;
    this.loc = {
      position: gl.getAttribLocation(program, "position"), normal: gl.getAttribLocation(program, "normal"),
      view: gl.getUniformLocation(program, "view"), projection: gl.getUniformLocation(program, "projection"),
      colour: gl.getUniformLocation(program, "colour"),
    };
    this.buffers = { position: gl.createBuffer(), normal: gl.createBuffer(), index: gl.createBuffer() };
    let drag = null;
    canvas.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener("pointerup", () => { drag = null; });
    canvas.addEventListener("pointermove", (e) => {
      if (!drag) return;
      this.yaw += (e.clientX - drag[0]) * 0.01;
      this.pitch = Math.max(-1.5, Math.min(1.5, this.pitch + (e.clientY - drag[1]) * 0.01));
      drag = [e.clientX, e.clientY];
      this.draw();
    });
    canvas.addEventListener("wheel", (e) => {
      e.preventDefault();
      this.zoom = Math.max(0.2, Math.min(5, this.zoom * Math.exp(e.deltaY * 0.001)));
      this.draw();
    }, { passive: false });
  }

  fail(text) {
    const ctx = this.canvas.getContext("2d");
    if (ctx) { ctx.font = "14px system-ui"; ctx.fillText(text, 16, 30); }
  }

  // shape: {positions: [x, y, z, ...], indices: [...], bounds: [[min], [max]]}
  show(shape, colour = [0.35, 0.55, 0.8]) {
    const gl = this.gl;
    if (!gl) return;
    const pos = new Float32Array(shape.positions);
    const big = pos.length / 3 > 65535;
    if (big && !this.uint32) { this.fail("the mesh is too large for this WebGL"); return; }
    const idx = big ? new Uint32Array(shape.indices) : new Uint16Array(shape.indices);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.buffers.position); gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.buffers.normal);
    gl.bufferData(gl.ARRAY_BUFFER, vertexNormals(pos, idx), gl.STATIC_DRAW);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.buffers.index); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
    this.indexType = big ? gl.UNSIGNED_INT : gl.UNSIGNED_SHORT;
    this.count = idx.length;
    const [lo, hi] = shape.bounds;
    this.centre = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
    this.radius = Math.max(1, Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2);
    this.colour = colour;
    this.draw();
  }

  draw() {
    const gl = this.gl;
    if (!gl || !this.count) return;
    const c = this.canvas;
    gl.viewport(0, 0, c.width, c.height);
    gl.clearColor(1, 1, 1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(this.program);
    const distance = this.radius * 2.6 * this.zoom;
    gl.uniformMatrix4fv(this.loc.projection, false, perspective(0.75, c.width / c.height, distance / 50, distance * 4));
    gl.uniformMatrix4fv(this.loc.view, false, viewMatrix(this.yaw, this.pitch, distance, this.centre));
    gl.uniform3fv(this.loc.colour, this.colour);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.buffers.position);
    gl.enableVertexAttribArray(this.loc.position);
    gl.vertexAttribPointer(this.loc.position, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.buffers.normal);
    gl.enableVertexAttribArray(this.loc.normal);
    gl.vertexAttribPointer(this.loc.normal, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.buffers.index);
    gl.drawElements(gl.TRIANGLES, this.count, this.indexType, 0);
  }
}
