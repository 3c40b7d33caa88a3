// 3D skeleton player drawn on a 2D canvas with its own perspective projection.
// World: metres, Y up, floor at y = 0 (HumanML3D). Drag: orbit; shift/right-drag: pan;
// wheel: zoom; double-click: reset view.

const FOV = (45 * Math.PI) / 180;  // vertical field of view
const NEAR = 0.05;                 // near plane (m): segments behind it are clipped
const GRID_STEP = 0.5;             // ground grid spacing (m)
const LEFT = new Set([1, 4, 7, 10, 13, 16, 18, 20]);
const RIGHT = new Set([2, 5, 8, 11, 14, 17, 19, 21]);
const COLORS = { left: "#2f6fd0", right: "#d9482b", centre: "#3a3a3a" };
const HEAD = 15;

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => { const n = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / n, a[1] / n, a[2] / n]; };
const clamp = (x, lo, hi) => Math.min(hi, Math.max(lo, x));

function boneColor(child) {
  return LEFT.has(child) ? COLORS.left : RIGHT.has(child) ? COLORS.right : COLORS.centre;
}

export class SkeletonPlayer {
  /** @param {HTMLCanvasElement} canvas  @param {{onFrame?: (frame:number, frames:number, playing:boolean) => void}} hooks */
  constructor(canvas, hooks = {}) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d");
    this.onFrame = hooks.onFrame || (() => {});
    this.motion = null;          // {joints: [T][22][3], fps, parents}
    this.time = 0;               // playback position in frames (fractional)
    this.frame = 0;
    this.playing = false;
    this.follow = false;         // camera target tracks the pelvis
    this.fit = { target: [0, 0.9, 0], distance: 4, bounds: [-1, -1, 1, 1] };
    this.resetView();
    this._last = null;
    this._dirty = true;
    this._bindInput();
    new ResizeObserver(() => { this._dirty = true; }).observe(canvas);
    requestAnimationFrame((t) => this._tick(t));
  }

  /** Show a motion ({joints, fps, parents}); starts playing from frame 0. */
  load(motion) {
    this.motion = motion;
    this._fitCamera();
    this.time = 0;
    this.frame = 0;
    this.playing = motion.joints.length > 1;
    this._changed();
  }

  get frames() { return this.motion ? this.motion.joints.length : 0; }
  play() { if (this.frames > 1) { this.playing = true; this._changed(); } }
  pause() { this.playing = false; this._changed(); }
  toggle() { this.playing ? this.pause() : this.play(); }

  /** Jump to a frame (clamped); keeps the play state. */
  setFrame(i) {
    if (!this.motion) return;
    this.frame = clamp(Math.round(i), 0, this.frames - 1);
    this.time = this.frame;
    this._changed();
  }

  resetView() {
    this.view = { yaw: 0.55, pitch: 0.28, zoom: 1, pan: [0, 0, 0] };
    this._dirty = true;
  }

  _changed() { this._dirty = true; this.onFrame(this.frame, this.frames, this.playing); }

  _fitCamera() {
    let [x0, z0, x1, z1, top] = [Infinity, Infinity, -Infinity, -Infinity, 1.8];
    for (const pose of this.motion.joints) {
      for (const [x, y, z] of pose) {
        x0 = Math.min(x0, x); x1 = Math.max(x1, x); z0 = Math.min(z0, z); z1 = Math.max(z1, z);
        top = Math.max(top, y);
      }
    }
    const radius = 0.5 * Math.hypot(x1 - x0, z1 - z0, top);
    this.fit = {
      target: [(x0 + x1) / 2, Math.min(top / 2, 1.0), (z0 + z1) / 2],
      distance: Math.max(2.5, radius / Math.sin(FOV / 2)),
      bounds: [x0, z0, x1, z1],
    };
    this.view.pan = [0, 0, 0];
  }

  _tick(now) {
    if (this._last !== null && this.playing && this.motion) {
      const dt = Math.min(0.25, (now - this._last) / 1000);
      this.time = (this.time + dt * this.motion.fps) % this.frames;
      const frame = Math.floor(this.time);
      if (frame !== this.frame) { this.frame = frame; this._changed(); }
    }
    this._last = now;
    if (this._dirty) { this._dirty = false; this.draw(); }
    requestAnimationFrame((t) => this._tick(t));
  }

  // -- camera ---------------------------------------------------------------------------------

  _camera(width, height) {
    const { yaw, pitch, zoom, pan } = this.view;
    let target = this.fit.target;
    if (this.follow && this.motion) {
      const root = this.motion.joints[this.frame][0];
      target = [root[0], target[1], root[2]];
    }
    target = [target[0] + pan[0], target[1] + pan[1], target[2] + pan[2]];
    const d = this.fit.distance * zoom;
    const eye = [target[0] + d * Math.cos(pitch) * Math.sin(yaw), target[1] + d * Math.sin(pitch),
      target[2] + d * Math.cos(pitch) * Math.cos(yaw)];
    const forward = norm(sub(target, eye));
    const right = norm(cross(forward, [0, 1, 0]));
    const up = cross(right, forward);
    const focal = (0.5 * height) / Math.tan(FOV / 2);
    return { eye, forward, right, up, focal, cx: width / 2, cy: height / 2 };
  }

  /** World point → camera space [x, y, depth]. */
  _toCamera(cam, p) {
    const v = sub(p, cam.eye);
    return [dot(v, cam.right), dot(v, cam.up), dot(v, cam.forward)];
  }

  _toScreen(cam, c) { return [cam.cx + (cam.focal * c[0]) / c[2], cam.cy - (cam.focal * c[1]) / c[2]]; }

  /** Project a world segment, clipped at the near plane; null when wholly behind the camera. */
  _segment(cam, a, b) {
    let ca = this._toCamera(cam, a);
    let cb = this._toCamera(cam, b);
    if (ca[2] < NEAR && cb[2] < NEAR) return null;
    if (ca[2] < NEAR || cb[2] < NEAR) {
      const t = (NEAR - ca[2]) / (cb[2] - ca[2]);
      const hit = [ca[0] + t * (cb[0] - ca[0]), ca[1] + t * (cb[1] - ca[1]), NEAR];
      if (ca[2] < NEAR) ca = hit; else cb = hit;
    }
    return { a: this._toScreen(cam, ca), b: this._toScreen(cam, cb), depth: (ca[2] + cb[2]) / 2 };
  }

  _bindInput() {
    const c = this.canvas;
    let drag = null;
    c.addEventListener("contextmenu", (e) => e.preventDefault());
    c.addEventListener("pointerdown", (e) => {
      drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
      c.setPointerCapture(e.pointerId);
    });
    c.addEventListener("pointerup", () => { drag = null; });
    c.addEventListener("pointermove", (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x;
      const dy = e.clientY - drag.y;
      drag.x = e.clientX;
      drag.y = e.clientY;
      if (drag.pan) {
        const cam = this._camera(c.clientWidth, c.clientHeight);
        const scale = (this.fit.distance * this.view.zoom) / cam.focal;
        for (let k = 0; k < 3; k++) this.view.pan[k] += scale * (-dx * cam.right[k] + dy * cam.up[k]);
      } else {
        this.view.yaw -= dx * 0.008;
        this.view.pitch = clamp(this.view.pitch + dy * 0.008, -0.15, 1.5);
      }
      this._dirty = true;
    });
    c.addEventListener("wheel", (e) => {
      e.preventDefault();
      this.view.zoom = clamp(this.view.zoom * Math.exp(e.deltaY * 0.001), 0.1, 8);
      this._dirty = true;
    }, { passive: false });
    c.addEventListener("dblclick", () => this.resetView());
  }

  // -- drawing --------------------------------------------------------------------------------

  draw() {
    const c = this.canvas;
    const dpr = window.devicePixelRatio || 1;
    const width = c.clientWidth;
    const height = c.clientHeight;
    if (c.width !== Math.round(width * dpr) || c.height !== Math.round(height * dpr)) {
      c.width = Math.round(width * dpr);
      c.height = Math.round(height * dpr);
    }
    const ctx = this.ctx;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, width, height);
    const cam = this._camera(width, height);
    this._drawGrid(ctx, cam);
    if (!this.motion) return;
    this._drawTrace(ctx, cam);
    this._drawSkeleton(ctx, cam, this.motion.joints[this.frame]);
  }

  _line(ctx, cam, a, b) {
    const s = this._segment(cam, a, b);
    if (!s) return;
    ctx.moveTo(s.a[0], s.a[1]);
    ctx.lineTo(s.b[0], s.b[1]);
  }

  _drawGrid(ctx, cam) {
    const [x0, z0, x1, z1] = this.fit.bounds;
    const lo = (v) => Math.floor((v - 1.5) / GRID_STEP) * GRID_STEP;
    const hi = (v) => Math.ceil((v + 1.5) / GRID_STEP) * GRID_STEP;
    const [gx0, gx1, gz0, gz1] = [lo(x0), hi(x1), lo(z0), hi(z1)];
    ctx.lineWidth = 1;
    ctx.strokeStyle = "#d4d8de";
    ctx.beginPath();
    for (let x = gx0; x <= gx1 + 1e-6; x += GRID_STEP) this._line(ctx, cam, [x, 0, gz0], [x, 0, gz1]);
    for (let z = gz0; z <= gz1 + 1e-6; z += GRID_STEP) this._line(ctx, cam, [gx0, 0, z], [gx1, 0, z]);
    ctx.stroke();
    // origin axes: +X (the character's left at frame 0) red, +Z (its facing) blue
    for (const [end, color] of [[[0.4, 0, 0], "#c0392b"], [[0, 0, 0.4], "#2471a3"]]) {
      ctx.strokeStyle = color;
      ctx.lineWidth = 2;
      ctx.beginPath();
      this._line(ctx, cam, [0, 0.001, 0], end);
      ctx.stroke();
    }
  }

  _drawTrace(ctx, cam) {
    const poses = this.motion.joints;
    const ground = (i) => [poses[i][0][0], 0.002, poses[i][0][2]];
    ctx.lineWidth = 2;
    for (const [from, to, style] of [[0, this.frame, "#e69a1c"], [this.frame, poses.length - 1, "rgba(230,154,28,0.35)"]]) {
      ctx.strokeStyle = style;
      ctx.beginPath();
      for (let i = from; i < to; i++) this._line(ctx, cam, ground(i), ground(i + 1));
      ctx.stroke();
    }
    const here = this._toCamera(cam, ground(this.frame));
    if (here[2] > NEAR) {
      const [sx, sy] = this._toScreen(cam, here);
      ctx.fillStyle = "#e69a1c";
      ctx.beginPath();
      ctx.arc(sx, sy, 4, 0, 2 * Math.PI);
      ctx.fill();
    }
  }

  _drawSkeleton(ctx, cam, pose) {
    const parents = this.motion.parents;
    ctx.lineCap = "round";
    // shadow: the skeleton flattened onto the floor
    ctx.strokeStyle = "rgba(0,0,0,0.12)";
    ctx.lineWidth = 3;
    ctx.beginPath();
    for (let j = 1; j < pose.length; j++) {
      const p = pose[parents[j]];
      this._line(ctx, cam, [p[0], 0.001, p[2]], [pose[j][0], 0.001, pose[j][2]]);
    }
    ctx.stroke();
    // bones far to near so nearer limbs cover farther ones
    const bones = [];
    for (let j = 1; j < pose.length; j++) {
      const s = this._segment(cam, pose[parents[j]], pose[j]);
      if (s) bones.push({ ...s, color: boneColor(j) });
    }
    bones.sort((u, v) => v.depth - u.depth);
    for (const b of bones) {
      ctx.strokeStyle = b.color;
      ctx.lineWidth = clamp((cam.focal * 0.03) / b.depth, 1.5, 10);
      ctx.beginPath();
      ctx.moveTo(b.a[0], b.a[1]);
      ctx.lineTo(b.b[0], b.b[1]);
      ctx.stroke();
    }
    const head = this._toCamera(cam, pose[HEAD]);
    if (head[2] > NEAR) {
      const [sx, sy] = this._toScreen(cam, head);
      ctx.fillStyle = COLORS.centre;
      ctx.beginPath();
      ctx.arc(sx, sy, clamp((cam.focal * 0.09) / head[2], 3, 40), 0, 2 * Math.PI);
      ctx.fill();
    }
  }
}
