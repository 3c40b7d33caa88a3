// 3D player in WebGL (three.js, vendored under vendor/three): the motion's skinned body (a glb from the
// server, posed by its animation clip), an optional stick figure drawn over it, a floor with the root's trace,
// lights and shadows. Same interface as the 2D SkeletonPlayer (player.js), which the page falls back to
// without WebGL. World: metres, Y up, floor at y = 0. Drag: orbit; shift/right-drag: pan; wheel: zoom;
// double-click: reset view.

import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";

const FOV = 45;                      // vertical field of view (degrees)
const GRID_STEP = 0.5;               // floor grid spacing (m)
const BODY_MARGIN = [0.3, 0.2];      // the body reaches past the joints: sideways, above the head joint (m)
const LEFT = new Set([1, 4, 7, 10, 13, 16, 18, 20]);
const RIGHT = new Set([2, 5, 8, 11, 14, 17, 19, 21]);
const COLORS = { left: 0x2f6fd0, right: 0xd9482b, centre: 0x3a3a3a };
const HEAD = 15;
const clamp = (x, lo, hi) => Math.min(hi, Math.max(lo, x));

export class BodyPlayer {
  /** @param {HTMLCanvasElement} canvas  @param {{onFrame?: (frame:number, frames:number, playing:boolean) => void}} hooks
   *  Throws when the browser has no WebGL. */
  constructor(canvas, hooks = {}) {
    this.canvas = canvas;
    this.onFrame = hooks.onFrame || (() => {});
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
    this.renderer.shadowMap.enabled = true;
    this.renderer.shadowMap.type = THREE.PCFShadowMap;
    this.renderer.autoClear = false;
    this.motion = null;          // {joints: [T][22][3], fps, parents}
    this.time = 0;               // playback position in frames (fractional)
    this.frame = 0;
    this.playing = false;
    this.follow = false;         // camera target tracks the pelvis
    this.showStick = false;      // draw the stick figure over the body
    this.body = null;            // {root, mesh, mixer, action, motion} of the motion on screen
    this.bodyState = null;       // null (no motion) | "loading" | "ready" | "error"
    this.box = { min: [-0.5, 0, -0.5], max: [0.5, 1.9, 0.5] };
    this._buildScene();
    this.resetView();
    this._last = null;
    this._dirty = true;
    this._bindInput();
    new ResizeObserver(() => { this._dirty = true; }).observe(canvas);
    requestAnimationFrame((t) => this._tick(t));
  }

  _buildScene() {
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0xf3f4f6);
    scene.fog = new THREE.Fog(0xf3f4f6, 10, 40);  // the floor fades into the background far away
    this.camera = new THREE.PerspectiveCamera(FOV, 1, 0.05, 500);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8478, 1.1));
    const sun = new THREE.DirectionalLight(0xffffff, 2.8);
    sun.castShadow = true;
    sun.shadow.mapSize.set(2048, 2048);
    sun.shadow.bias = -0.0005;
    sun.shadow.normalBias = 0.02;
    scene.add(sun, sun.target);
    this.sun = sun;
    this.floor = new THREE.Mesh(new THREE.PlaneGeometry(1, 1),
      new THREE.MeshStandardMaterial({ color: 0xe4e7eb, roughness: 1, metalness: 0 }));
    this.floor.rotation.x = -Math.PI / 2;
    this.floor.receiveShadow = true;
    scene.add(this.floor);
    this.grid = null;
    for (const [end, color] of [[[0.4, 0, 0], 0xc0392b], [[0, 0, 0.4], 0x2471a3]]) {  // +X red, +Z (facing) blue
      const geometry = new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(0, 0.003, 0), new THREE.Vector3(end[0], 0.003, end[2])]);
      scene.add(new THREE.Line(geometry, new THREE.LineBasicMaterial({ color })));
    }
    this.trace = new THREE.Group();
    scene.add(this.trace);
    this.marker = new THREE.Mesh(new THREE.CircleGeometry(0.04, 24), new THREE.MeshBasicMaterial({ color: 0xe69a1c }));
    this.marker.rotation.x = -Math.PI / 2;
    this.marker.visible = false;
    scene.add(this.marker);
    this.scene = scene;
    // the stick figure lives in its own scene, drawn after the body with a cleared depth buffer: always in front
    this.overlay = new THREE.Scene();
    const unit = new THREE.CylinderGeometry(1, 1, 1, 10, 1).translate(0, 0.5, 0);  // along +Y from 0 to 1
    const material = (color) => new THREE.MeshBasicMaterial({ color });
    this.bones = [];
    for (let j = 1; j < 22; j++) {
      const bone = new THREE.Mesh(unit, material(LEFT.has(j) ? COLORS.left : RIGHT.has(j) ? COLORS.right : COLORS.centre));
      this.bones.push(bone);
      this.overlay.add(bone);
    }
    this.head = new THREE.Mesh(new THREE.SphereGeometry(0.09, 16, 12), material(COLORS.centre));
    this.overlay.add(this.head);
    this.overlay.visible = false;
  }

  /** Show a motion ({joints, fps, parents}); starts playing from frame 0. Its body comes with setBody. */
  load(motion) {
    this.motion = motion;
    this._dropBody();
    this.bodyState = "loading";
    this._fitCamera();
    this._buildTrace();
    this.time = 0;
    this.frame = 0;
    this.playing = motion.joints.length > 1;
    this._changed();
  }

  /** Parse and show the body (glb bytes) of `motion`, when that is still the motion on screen. */
  async setBody(motion, bytes) {
    let gltf;
    try {
      gltf = await new GLTFLoader().parseAsync(bytes, "");
    } catch (err) {
      if (motion === this.motion) this.bodyState = "error";
      throw new Error(`cannot read the body: ${err.message || err}`);
    }
    if (motion !== this.motion) return;  // a newer motion came while this one was read
    let mesh = null;
    gltf.scene.traverse((o) => { if (o.isSkinnedMesh) mesh = o; });
    if (!mesh || !gltf.animations.length) { this.bodyState = "error"; throw new Error("the body has no skinned mesh or animation"); }
    mesh.castShadow = true;
    mesh.frustumCulled = false;  // its bounding sphere is the rest pose's; the motion goes elsewhere
    const mixer = new THREE.AnimationMixer(gltf.scene);
    const action = mixer.clipAction(gltf.animations[0]);
    action.setLoop(THREE.LoopOnce, 1);  // LoopRepeat would show frame 0 at exactly the clip's end
    action.clampWhenFinished = true;
    action.play();
    this._dropBody();
    this.body = { root: gltf.scene, mesh, mixer, action };
    this.scene.add(gltf.scene);
    this.bodyState = "ready";
    this._dirty = true;
  }

  /** The motion has no body (the server could not give one): the stick figure stands in. */
  bodyFailed() { this.bodyState = "error"; this._dirty = true; }

  setStick(on) { this.showStick = Boolean(on); this._dirty = true; }

  /** The stick figure is drawn when asked for, and stands in for a body not (yet) there. */
  _stickShown() { return Boolean(this.motion) && (this.showStick || !this.body); }

  _dropBody() {
    if (!this.body) return;
    this.scene.remove(this.body.root);
    this.body.root.traverse((o) => {
      if (o.isSkinnedMesh) o.skeleton.dispose();
      if (o.isMesh) { o.geometry.dispose(); o.material.dispose(); }
    });
    this.body = null;
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
    this.view = { yaw: 0.55, pitch: 0.25, zoom: 1, pan: [0, 0, 0] };
    this._dirty = true;
  }

  _changed() { this._dirty = true; this.onFrame(this.frame, this.frames, this.playing); }

  /** The box the whole motion (body included) stays in; the camera's distance follows from it each frame. */
  _fitCamera() {
    const lo = [Infinity, 0, Infinity];
    const hi = [-Infinity, 1.8, -Infinity];
    for (const pose of this.motion.joints) {
      for (const p of pose) {
        for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
      }
    }
    const [side, top] = BODY_MARGIN;
    this.box = { min: [lo[0] - side, Math.min(0, lo[1]), lo[2] - side], max: [hi[0] + side, hi[1] + top, hi[2] + side] };
    this.view.pan = [0, 0, 0];
    const [x0, , z0] = this.box.min;
    const [x1, , z1] = this.box.max;
    const span = Math.max(x1 - x0, z1 - z0) + 6;
    this.floor.scale.set(400, 400, 1);
    this.floor.position.set((x0 + x1) / 2, 0, (z0 + z1) / 2);
    if (this.grid) { this.scene.remove(this.grid); this.grid.geometry.dispose(); }
    const cells = 2 * Math.ceil(span / GRID_STEP / 2);
    this.grid = new THREE.GridHelper(cells * GRID_STEP, cells, 0xc3c8cf, 0xd3d7dc);
    this.grid.position.set(Math.round((x0 + x1) / 2 / GRID_STEP) * GRID_STEP, 0.001, Math.round((z0 + z1) / 2 / GRID_STEP) * GRID_STEP);
    this.scene.add(this.grid);
    const centre = new THREE.Vector3((x0 + x1) / 2, 0, (z0 + z1) / 2);
    const reach = 0.5 * Math.hypot(x1 - x0, this.box.max[1], z1 - z0) + 1;
    Object.assign(this.sun.shadow.camera, { left: -reach, right: reach, top: reach, bottom: -reach, near: 0.1, far: 6 * reach + 20 });
    this.sun.shadow.camera.updateProjectionMatrix();
    this.sun.target.position.copy(centre);
    this.sun.position.copy(centre).add(new THREE.Vector3(-0.8, 4, 1.0).multiplyScalar(reach + 2));
  }

  _buildTrace() {
    for (const child of [...this.trace.children]) { this.trace.remove(child); child.geometry.dispose(); }
    const points = this.motion.joints.map((pose) => new THREE.Vector3(pose[0][0], 0.004, pose[0][2]));
    const geometry = new THREE.BufferGeometry().setFromPoints(points);
    this.trace.add(new THREE.Line(geometry, new THREE.LineBasicMaterial({ color: 0xe69a1c, transparent: true, opacity: 0.35 })));
    this.played = new THREE.Line(geometry.clone(), new THREE.LineBasicMaterial({ color: 0xe69a1c }));
    this.trace.add(this.played);
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

  /** Aim the camera at the motion's box from the view's yaw and pitch, just far enough that all eight corners
   *  of the box are in the picture; returns the distance. */
  _placeCamera(aspect) {
    const { yaw, pitch, zoom, pan } = this.view;
    const { min, max } = this.box;
    const centre = new THREE.Vector3((min[0] + max[0]) / 2, (min[1] + max[1]) / 2, (min[2] + max[2]) / 2);
    const back = new THREE.Vector3(Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch), Math.cos(pitch) * Math.cos(yaw));
    const right = new THREE.Vector3(0, 1, 0).cross(back).normalize();
    const up = back.clone().cross(right);
    const tanV = Math.tan(THREE.MathUtils.degToRad(FOV) / 2);
    const tanH = tanV * aspect;
    let d = 1;
    const v = new THREE.Vector3();
    for (const x of [min[0], max[0]]) {
      for (const y of [min[1], max[1]]) {
        for (const z of [min[2], max[2]]) {
          v.set(x, y, z).sub(centre);
          const depth = v.dot(back);
          d = Math.max(d, depth + Math.abs(v.dot(right)) / tanH, depth + Math.abs(v.dot(up)) / tanV);
        }
      }
    }
    d *= 1.06 * zoom;
    const t = centre.clone();
    if (this.follow && this.motion) {
      const root = this.motion.joints[this.frame][0];
      t.x = root[0];
      t.z = root[2];
    }
    t.add(new THREE.Vector3(...pan));
    this.camera.position.copy(t).addScaledVector(back, d);
    this.camera.aspect = aspect;
    this.camera.far = 10 * d + 100;
    this.camera.updateProjectionMatrix();
    this.camera.lookAt(t);
    const radius = 0.5 * Math.hypot(max[0] - min[0], max[1] - min[1], max[2] - min[2]);
    Object.assign(this.scene.fog, { near: d + radius + 2, far: 3 * d + radius + 20 });
    return d;
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
        const d = this._placeCamera(c.clientWidth / Math.max(1, c.clientHeight));
        const scale = (2 * d * Math.tan(THREE.MathUtils.degToRad(FOV) / 2)) / Math.max(1, c.clientHeight);
        const right = new THREE.Vector3().setFromMatrixColumn(this.camera.matrixWorld, 0);
        const up = new THREE.Vector3().setFromMatrixColumn(this.camera.matrixWorld, 1);
        for (let k = 0; k < 3; k++) this.view.pan[k] += scale * (-dx * right.getComponent(k) + dy * up.getComponent(k));
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

  /** Pose the body at the current frame: the clip's time is frame / fps (LoopOnce: the last frame is its end). */
  _poseBody() {
    const { mixer, action } = this.body;
    action.paused = false;  // reaching the clip's end pauses the action; the next setTime must still move it
    mixer.setTime(this.frame / this.motion.fps);
  }

  _poseStick(pose) {
    const parents = this.motion.parents;
    const a = new THREE.Vector3();
    const b = new THREE.Vector3();
    const up = new THREE.Vector3(0, 1, 0);
    const width = this.body ? 0.012 : 0.02;
    for (let j = 1; j < pose.length; j++) {
      a.fromArray(pose[parents[j]]);
      b.fromArray(pose[j]).sub(a);
      const bone = this.bones[j - 1];
      const length = b.length();
      bone.position.copy(a);
      bone.quaternion.setFromUnitVectors(up, length > 1e-9 ? b.divideScalar(length) : up);
      bone.scale.set(width, Math.max(length, 1e-6), width);
    }
    this.head.position.fromArray(pose[HEAD]);
    this.head.scale.setScalar(this.body ? 0.5 : 1);
  }

  draw() {
    const c = this.canvas;
    const width = Math.max(1, c.clientWidth);
    const height = Math.max(1, c.clientHeight);
    const dpr = window.devicePixelRatio || 1;
    if (c.width !== Math.round(width * dpr) || c.height !== Math.round(height * dpr)) {
      this.renderer.setPixelRatio(dpr);
      this.renderer.setSize(width, height, false);
    }
    this._placeCamera(width / height);
    const stick = this._stickShown();
    if (this.motion) {
      const pose = this.motion.joints[this.frame];
      if (this.body) this._poseBody();
      if (stick) this._poseStick(pose);
      this.played.geometry.setDrawRange(0, this.frame + 1);
      this.marker.position.set(pose[0][0], 0.005, pose[0][2]);
      this.marker.visible = true;
    }
    this.overlay.visible = stick;
    this.renderer.clear();
    this.renderer.render(this.scene, this.camera);
    if (stick) {
      this.renderer.clearDepth();
      this.renderer.render(this.overlay, this.camera);
    }
  }

  /** Numbers for tests and scripts (window.simdiffViewer.debug()). */
  debug() {
    const counts = { skinnedMeshes: 0, bones: 0 };
    this.scene.traverse((o) => { if (o.isSkinnedMesh) { counts.skinnedMeshes += 1; counts.bones += o.skeleton.bones.length; } });
    let boneErrorMm = null;
    if (this.body && this.motion) {
      this._poseBody();
      this.body.root.updateMatrixWorld(true);
      const pose = this.motion.joints[this.frame];
      const p = new THREE.Vector3();
      boneErrorMm = 0;
      this.body.mesh.skeleton.bones.forEach((bone, j) => {
        boneErrorMm = Math.max(boneErrorMm, 1000 * bone.getWorldPosition(p).distanceTo(new THREE.Vector3().fromArray(pose[j])));
      });
    }
    return { renderer: "webgl", ...counts, body: this.bodyState, stick: this._stickShown(), frame: this.frame, boneErrorMm,
      camera: this.camera.position.toArray(), box: this.box };
  }
}
