// The ssx viewer's page: the scene from the simulation (once), then frames of every body's pose,
// drawn with three.js. A swarm's members share a model: each of its shapes is one InstancedMesh.
"use strict";

const state = {
  bodies: [],       // {name, model}
  models: [],       // per model: [{mesh (InstancedMesh), local (Matrix4)}]
  slots: [],        // per body: its instance index in its model's meshes
  positions: null,  // Float32Array of the newest frame's 7 floats per body
  time: 0,
  details: null,    // the selected robot's details from the simulation (velocities, command, sensors)
  replay: null,     // a recording played: {start, end} (s)
  sliding: false,   // its slider held
  selected: -1, frames: 0, fpsFrames: 0, fpsSince: performance.now(),
};

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
document.body.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x9eb8d9);
const camera = new THREE.PerspectiveCamera(50, window.innerWidth / window.innerHeight, 0.05, 2000);
camera.up.set(0, 0, 1);  // ssx's world: z up
camera.position.set(-12, -12, 9);
const controls = new THREE.OrbitControls(camera, renderer.domElement);
controls.target.set(0, 0, 1.5);
controls.enableKeys = false;  // the keys steer the selected robot
controls.update();
scene.add(new THREE.HemisphereLight(0xffffff, 0x505050, 0.75));
const sun = new THREE.DirectionalLight(0xffffff, 0.6);
sun.position.set(0.35, 0.25, 0.9);
scene.add(sun);
window.addEventListener("resize", () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});

// a shape of the scene as geometry, in its own frame (ssx: cylinders and capsules along z)
function geometries(shape) {
  const [sx, sy, sz] = shape.size;
  const r = shape.radius, l = shape.length;
  const along_z = (g) => g.rotateX(Math.PI / 2);
  switch (shape.kind) {
    case "box": return [new THREE.BoxBufferGeometry(sx, sy, sz)];
    case "sphere": return [new THREE.SphereBufferGeometry(r, 16, 12)];
    case "cylinder": return [along_z(new THREE.CylinderBufferGeometry(r, r, l, 20))];
    case "capsule": return [along_z(new THREE.CylinderBufferGeometry(r, r, l, 20)),
                            new THREE.SphereBufferGeometry(r, 16, 12).translate(0, 0, l / 2),
                            new THREE.SphereBufferGeometry(r, 16, 12).translate(0, 0, -l / 2)];
    case "plane": return [new THREE.PlaneBufferGeometry(sx, sy)];
  }
  return [];
}

function material(shape) {
  const [r, g, b, a] = shape.color;
  return new THREE.MeshLambertMaterial({ color: new THREE.Color(r, g, b), transparent: a < 1, opacity: a,
                                         side: shape.kind === "plane" ? THREE.DoubleSide : THREE.FrontSide });
}

function poseMatrix(p) {
  return new THREE.Matrix4().compose(new THREE.Vector3(p[0], p[1], p[2]), new THREE.Quaternion(p[3], p[4], p[5], p[6]),
                                     new THREE.Vector3(1, 1, 1));
}

const built = [];  // what the last scene message added
function buildScene(msg) {
  for (const object of built) scene.remove(object);
  built.length = 0;
  const add = (object) => { scene.add(object); built.push(object); };
  state.positions = null;
  for (const shape of msg.world) {
    for (const g of geometries(shape)) {
      const mesh = new THREE.Mesh(g, material(shape));
      mesh.applyMatrix(poseMatrix(shape.pose));
      add(mesh);
    }
    if (shape.kind === "plane" && shape.grid) {
      const grid = new THREE.GridHelper(Math.max(shape.size[0], shape.size[1]),
                                        Math.round(Math.max(shape.size[0], shape.size[1])), 0x555555, 0x777777);
      grid.rotateX(Math.PI / 2);
      grid.applyMatrix(poseMatrix(shape.pose));
      grid.position.z += 0.002;
      add(grid);
    }
  }
  state.bodies = msg.bodies;
  const members = msg.models.map(() => 0);
  state.slots = msg.bodies.map((b) => members[b.model]++);
  state.models = msg.models.map((shapes, m) => {
    const parts = [];
    for (const shape of shapes)
      for (const g of geometries(shape)) {
        const mesh = new THREE.InstancedMesh(g, material(shape), Math.max(1, members[m]));
        mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
        mesh.userData.model = m;
        mesh.frustumCulled = false;
        add(mesh);
        parts.push({ mesh, local: poseMatrix(shape.pose) });
      }
    return parts;
  });
  state.byModelSlot = msg.models.map(() => []);
  msg.bodies.forEach((b, i) => { state.byModelSlot[b.model][state.slots[i]] = i; });
  document.getElementById("robots").textContent = msg.bodies.length;
  // a recording played (ssx replay --view): a time slider, and nothing to steer
  state.replay = msg.replay || null;
  document.getElementById("replay").hidden = !state.replay;
  document.getElementById("steer").hidden = !!state.replay;
  if (state.replay) {
    const slider = document.getElementById("slider");
    slider.min = state.replay.start;
    slider.max = state.replay.end;
    document.getElementById("span").textContent = `${state.replay.start.toFixed(1)}-${state.replay.end.toFixed(1)} s`;
  }
}

const body = new THREE.Matrix4(), world = new THREE.Matrix4();
function applyFrame(buffer) {
  const view = new DataView(buffer);
  if (view.getUint32(0, true) !== 0x46585353) return;
  const n = view.getUint32(4, true);
  if (n !== state.bodies.length) return;
  state.time = view.getFloat64(8, true);
  state.positions = new Float32Array(buffer, 32, 7 * n);
  // then the details of the bodies selected (JSON), when any
  const at = 32 + 28 * n;
  if (buffer.byteLength >= at + 4) {
    const length = view.getUint32(at, true);
    if (length > 0 && buffer.byteLength >= at + 4 + length) {
      const details = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, at + 4, length))).details;
      for (const d of details) if (d.body === state.selected) state.details = d;
    }
  }
  const p = state.positions;
  for (let i = 0; i < n; ++i) {
    const k = 7 * i;
    body.compose(new THREE.Vector3(p[k], p[k + 1], p[k + 2]), new THREE.Quaternion(p[k + 3], p[k + 4], p[k + 5], p[k + 6]),
                 new THREE.Vector3(1, 1, 1));
    for (const part of state.models[state.bodies[i].model]) {
      world.multiplyMatrices(body, part.local);
      part.mesh.setMatrixAt(state.slots[i], world);
    }
  }
  for (const parts of state.models) for (const part of parts) part.mesh.instanceMatrix.needsUpdate = true;
  document.getElementById("time").textContent = state.time.toFixed(3);
  if (state.replay && !state.sliding) document.getElementById("slider").value = state.time;
  // a recording stands still at its end (or paused by another page): the button says so
  if (state.replay) pauseButton.textContent = view.getFloat32(16, true) === 0 ? "resume" : "pause";
  document.getElementById("rtf").textContent = view.getFloat32(16, true).toFixed(2);
  document.getElementById("late").textContent = view.getUint32(20, true);
  state.frames++;
  showSelected();
}

const fixed = (values, digits = 2) => values.map((x) => x.toFixed(digits)).join(" ");

// one measurement in a line (ssx::measurementJson's objects)
function measurementText(m) {
  switch (m.kind) {
    case "imu": return `${m.sensor}: accelerometer ${fixed(m.accelerometer)} m/s², gyroscope ${fixed(m.gyroscope)} rad/s`;
    case "pose": return `${m.sensor}: position ${fixed(m.position)} m, velocity ${fixed(m.linear_velocity)} m/s`;
    case "range": {
      const nearest = m.detections.reduce((d, x) => Math.min(d, x.distance), Infinity);
      return `${m.sensor}: ${m.detections.length} in range` + (m.detections.length ? `, nearest ${nearest.toFixed(2)} m` : "");
    }
  }
  return `${m.sensor}: ${m.kind}`;
}

function showSelected() {
  const i = state.selected;
  if (i < 0 || !state.positions) return;
  const p = state.positions, k = 7 * i;
  // the pose as drawn; the rest from the simulation's details of this robot (at most a frame older)
  const euler = new THREE.Euler().setFromQuaternion(new THREE.Quaternion(p[k + 3], p[k + 4], p[k + 5], p[k + 6]), "ZYX");
  const lines = [state.bodies[i].name, `position ${fixed([p[k], p[k + 1], p[k + 2]])} m`,
                 `roll pitch yaw ${fixed([euler.x, euler.y, euler.z].map((a) => (a * 180) / Math.PI), 1)}°`];
  const d = state.details && state.details.body === i ? state.details : null;
  if (d) {
    lines.push(`velocity ${fixed(d.v)} m/s`, `angular velocity ${fixed(d.w)} rad/s`);
    if (d.command) {
      lines.push(`command (${d.command.level}) ${fixed(d.command.values)}`);
      if (d.command.level === "velocity")
        lines.push(`commanded ${fixed(d.command.values.slice(0, 3))} m/s, achieved ${fixed(d.v)} m/s`);
    }
    for (const m of d.sensors) lines.push(measurementText(m));
  }
  document.getElementById("selected").textContent = lines.join("\n");
  if (document.getElementById("follow").checked) controls.target.set(p[k], p[k + 1], p[k + 2]);
}

// a click selects the robot under the pointer
const raycaster = new THREE.Raycaster();
renderer.domElement.addEventListener("click", (event) => {
  const pointer = new THREE.Vector2((event.clientX / window.innerWidth) * 2 - 1, -(event.clientY / window.innerHeight) * 2 + 1);
  raycaster.setFromCamera(pointer, camera);
  const meshes = state.models.flat().map((part) => part.mesh);
  const hit = raycaster.intersectObjects(meshes)[0];
  if (hit && hit.instanceId !== undefined) select(state.byModelSlot[hit.object.userData.model][hit.instanceId]);
});

function select(i) {
  state.selected = i;
  state.details = null;
  teleop.sent = null;
  teleop.asked = 0;  // its details asked for at once (then each second)
  showSelected();
}

// teleoperation of the selected robot, or of every robot (the formation): W/S (or the arrows)
// forward and back along the view, A/D sideways, R/F up and down, Q/E turn; or a gamepad's sticks.
// Sent 20 times a second while held; the simulation stops the robots when nothing comes for 0.5 s
// (the dead-man rule).
const teleop = { keys: new Set(), socket: null, sent: null, last: 0, asked: 0 };
const kSpeed = 1.0, kClimb = 0.5, kTurn = 0.8;
window.addEventListener("keydown", (e) => { teleop.keys.add(e.key.toLowerCase()); });
window.addEventListener("keyup", (e) => { teleop.keys.delete(e.key.toLowerCase()); });
window.addEventListener("blur", () => teleop.keys.clear());

function teleopCommand() {
  const k = teleop.keys, has = (...names) => names.some((n) => k.has(n));
  let forward = (has("w", "arrowup") ? 1 : 0) - (has("s", "arrowdown") ? 1 : 0);
  let side = (has("a", "arrowleft") ? 1 : 0) - (has("d", "arrowright") ? 1 : 0);
  let up = (has("r") ? 1 : 0) - (has("f") ? 1 : 0);
  let turn = (has("q") ? 1 : 0) - (has("e") ? 1 : 0);
  for (const pad of navigator.getGamepads ? navigator.getGamepads() : []) {
    if (!pad) continue;
    const axis = (i) => (Math.abs(pad.axes[i] || 0) > 0.15 ? pad.axes[i] : 0);
    forward -= axis(1); side -= axis(0); up -= axis(3); turn -= axis(2);
  }
  if (!forward && !side && !up && !turn) return null;
  // along the view, on the ground
  const look = new THREE.Vector3().subVectors(controls.target, camera.position);
  look.z = 0;
  if (look.lengthSq() < 1e-9) look.set(1, 0, 0);
  look.normalize();
  const left = new THREE.Vector3(-look.y, look.x, 0);
  const v = look.multiplyScalar(forward * kSpeed).add(left.multiplyScalar(side * kSpeed));
  return [v.x, v.y, up * kClimb, turn * kTurn];
}

function teleopTick(now) {
  const socket = teleop.socket;
  if (!socket || socket.readyState !== 1) return;
  if (state.replay) return;  // nothing to steer in a recording
  if (state.selected >= 0 && now - teleop.asked >= 1000) {  // the selected robot's details, for 3 s more
    teleop.asked = now;
    socket.send(JSON.stringify({ type: "select", body: state.selected }));
  }
  const all = document.getElementById("steer_all").checked;
  if (state.selected < 0 && !all) return;
  const c = teleopCommand();
  if (!c && !teleop.sent) return;
  if (now - teleop.last < 45) return;
  teleop.last = now;
  const command = c || [0, 0, 0, 0];  // released: stop now (the dead-man rule would in 0.5 s)
  const target = all ? { all: true } : { body: state.selected };
  socket.send(JSON.stringify({ type: "velocity", ...target, v: command.slice(0, 3), yaw_rate: command[3] }));
  teleop.sent = c ? command.slice(0, 3) : null;
}

// the run from the page: pause and resume, one step while paused, the real-time factor
function send(message) {
  if (teleop.socket && teleop.socket.readyState === 1) teleop.socket.send(JSON.stringify(message));
}
const pauseButton = document.getElementById("pause");
pauseButton.addEventListener("click", () => {
  const pausing = pauseButton.textContent === "pause";
  send({ type: pausing ? "pause" : "resume" });
  pauseButton.textContent = pausing ? "resume" : "pause";
});
document.getElementById("step").addEventListener("click", () => send({ type: "step" }));
// a recording's slider: where it is dragged to is shown at once, paused or playing
const slider = document.getElementById("slider");
slider.addEventListener("pointerdown", () => { state.sliding = true; });
slider.addEventListener("pointerup", () => { state.sliding = false; });
slider.addEventListener("input", () => send({ type: "seek", time: Number(slider.value) }));
document.getElementById("factor").addEventListener("change", (e) => send({ type: "rate", factor: Number(e.target.value) }));

function connect() {
  const query = new URLSearchParams(location.search), token = query.get("token");
  const socket = new WebSocket(`ws://${location.host}/ws${token ? "?token=" + encodeURIComponent(token) : ""}`);
  teleop.socket = socket;
  socket.binaryType = "arraybuffer";
  const status = document.getElementById("status");
  // ?rate=R asks for at most R frames a second (the run's rate_hz otherwise)
  const rate = Number(query.get("rate"));
  socket.onopen = () => {
    status.textContent = "";
    socket.send(JSON.stringify(rate > 0 ? { type: "hello", rate_hz: rate } : { type: "hello" }));
  };
  socket.onmessage = (event) => {
    if (typeof event.data === "string") {
      const msg = JSON.parse(event.data);
      if (msg.type === "scene") buildScene(msg);
    } else if (state.bodies.length > 0) {
      applyFrame(event.data);
    }
  };
  socket.onclose = () => { status.textContent = "disconnected (the run ended?)"; };
}

function animate() {
  requestAnimationFrame(animate);
  controls.update();
  renderer.render(scene, camera);
  state.drawn = state.positions;  // what the picture shows now
  state.fpsFrames++;
  const now = performance.now();
  if (now - state.fpsSince > 1000) {
    document.getElementById("fps").textContent = Math.round((1000 * state.fpsFrames) / (now - state.fpsSince));
    state.fpsFrames = 0;
    state.fpsSince = now;
  }
}

// for tests and for a look from the browser's console
window.ssxViewer = {
  state, camera, controls, renderer, select,
  // where body i appears in the picture drawn last, in CSS pixels from the top left (null: behind the camera)
  project(i) {
    const p = state.drawn, k = 7 * i;
    const v = new THREE.Vector3(p[k], p[k + 1], p[k + 2]).project(camera);
    if (v.z > 1) return null;
    return [((v.x + 1) / 2) * window.innerWidth, ((1 - v.y) / 2) * window.innerHeight];
  },
  // the colour drawn at a point of the page (CSS pixels), as 0-255 RGBA
  pixel(x, y) {
    const gl = renderer.getContext(), ratio = renderer.getPixelRatio(), out = new Uint8Array(4);
    gl.readPixels(Math.round(x * ratio), Math.round(gl.drawingBufferHeight - y * ratio), 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, out);
    return Array.from(out);
  },
};

connect();
animate();
setInterval(() => teleopTick(performance.now()), 50);  // not tied to the drawing rate
