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
  selected: -1, hovered: -1, frames: 0, fpsFrames: 0, fpsSince: performance.now(),
  dirty: true,      // something to draw
  pressedAt: -1e9,  // when the pause button was last pressed
};

const query = new URLSearchParams(location.search);
// Drawing what a page can: antialiased up to kSmoothBodies bodies (?aa=1 or ?aa=0 to choose), and
// a swarm of more than kFullBudget robots drawn in full only for the kFullBudget nearest the camera,
// the rest as dots of the robot's colour and size (?full=N to choose N). Measured in headless
// Chromium with software WebGL (docs/viewer.md): both cost most of the frame rate there.
const kSmoothBodies = 300;
const kFullBudget = Number(query.get("full")) > 0 ? Number(query.get("full")) : 1000;
// the renderer is made when the scene arrives (antialiasing is chosen then); its canvas goes into
// #view, where the orbit controls and the clicks are
const view = document.getElementById("view");
let renderer = null, smooth = null;
function makeRenderer(antialias, shadows) {
  if (renderer && smooth === antialias) return setShadows(shadows);
  if (renderer) {
    view.removeChild(renderer.domElement);
    renderer.dispose();
  }
  renderer = new THREE.WebGLRenderer({ antialias });
  smooth = antialias;
  setShadows(shadows);
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(window.innerWidth, window.innerHeight);
  view.appendChild(renderer.domElement);
}
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x9eb8d9);
const camera = new THREE.PerspectiveCamera(50, window.innerWidth / window.innerHeight, 0.05, 2000);
camera.up.set(0, 0, 1);  // ssx's world: z up
camera.position.set(-12, -12, 9);
const controls = new THREE.OrbitControls(camera, view);
controls.target.set(0, 0, 1.5);
controls.enableKeys = false;  // the keys steer the selected robot
// the camera stays above the ground: at most level with the point it orbits, which stays above z = 0
controls.maxPolarAngle = Math.PI / 2 - 0.02;
controls.minDistance = 0.2;
controls.update();
controls.addEventListener("change", () => {
  if (controls.target.z < 0) controls.target.z = 0;
  if (camera.position.z < 0.05) camera.position.z = 0.05;
  state.dirty = true;
});
scene.add(new THREE.HemisphereLight(0xffffff, 0x505050, 0.75));
const sun = new THREE.DirectionalLight(0xffffff, 0.6);
const kSunDirection = new THREE.Vector3(0.35, 0.25, 0.9).normalize();
sun.position.copy(kSunDirection);
scene.add(sun);
scene.add(sun.target);
// Shadows on the ground, their edges filtered (PCF; as the snapshots draw them: a flying robot's
// height shows in where its shadow falls), up to kSmoothBodies bodies (?shadows=1 or ?shadows=0 to
// choose): a second drawing of every body and a shadow lookup per pixel, which software WebGL pays
// for in frame rate (docs/viewer.md). The sun's shadow covers the bodies' box.
sun.shadow.mapSize.set(1024, 1024);
sun.shadow.bias = -0.0005;
function setShadows(on) {
  renderer.shadowMap.enabled = on;
  renderer.shadowMap.type = THREE.PCFShadowMap;
  sun.castShadow = on;
  state.shadows = on;
}
const shadowBox = new THREE.Box3(), shadowCentre = new THREE.Vector3();
function fitShadow(n) {
  if (!state.shadows || n === 0) return;
  const p = state.positions;
  shadowBox.makeEmpty();
  for (let i = 0; i < n; ++i) shadowBox.expandByPoint(at.set(p[7 * i], p[7 * i + 1], p[7 * i + 2]));
  shadowBox.expandByScalar(2);
  shadowBox.getCenter(shadowCentre);
  shadowCentre.z = 0;
  const r = Math.max(5, 0.5 * shadowBox.getSize(at).length() + 2), c = sun.shadow.camera;
  sun.target.position.copy(shadowCentre);
  sun.position.copy(shadowCentre).addScaledVector(kSunDirection, 2 * r);
  c.left = c.bottom = -r, c.right = c.top = r, c.near = 0.1, c.far = 4 * r;
  c.updateProjectionMatrix();
}
window.addEventListener("resize", () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  if (renderer) renderer.setSize(window.innerWidth, window.innerHeight);
  state.dirty = true;
});

// how far a shape reaches from its origin
function extent(shape) {
  switch (shape.kind) {
    case "box": return 0.5 * Math.hypot(...shape.size);
    case "sphere": return shape.radius;
    case "cylinder": return Math.hypot(shape.radius, shape.length / 2);
    case "capsule": return shape.radius + shape.length / 2;
    case "mesh": return shape.reach;
  }
  return 0;
}

// the scene's meshes, each made once (every shape and every swarm member drawing it shares it):
// flat-shaded, each triangle its own corners with its face's normal
let meshes = [];
function meshGeometries(list) {
  return list.map((m) => {
    const v = m.vertices, t = m.triangles;
    const corners = new Float32Array(3 * t.length);
    for (let i = 0; i < t.length; i++) corners.set(v.slice(3 * t[i], 3 * t[i] + 3), 3 * i);
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.BufferAttribute(corners, 3));
    geometry.computeVertexNormals();
    return geometry;
  });
}

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
    case "mesh": return meshes[shape.mesh] ? [meshes[shape.mesh]] : [];
  }
  return [];
}

function material(shape) {
  const [r, g, b, a] = shape.color;
  return new THREE.MeshLambertMaterial({ color: new THREE.Color(r, g, b), transparent: a < 1, opacity: a,
                                         side: shape.kind === "plane" || shape.kind === "mesh" ? THREE.DoubleSide : THREE.FrontSide });
}

function poseMatrix(p) {
  return new THREE.Matrix4().compose(new THREE.Vector3(p[0], p[1], p[2]), new THREE.Quaternion(p[3], p[4], p[5], p[6]),
                                     new THREE.Vector3(1, 1, 1));
}

// a square grid of `size` m in cells of `cell` m in the plane z = 0, its lines cut into pieces of a
// few cells: a line that reaches behind the camera is clipped, and software WebGL (SwiftShader)
// drops such a line whole, so a grid of whole lines lost every line running away from the camera
function groundGrid(size, cell, colour) {
  const lines = Math.max(1, Math.round(size / cell)), half = (lines * cell) / 2, piece = 5 * cell, points = [];
  for (let k = 0; k <= lines; ++k) {
    const across = -half + k * cell;
    for (let along = -half; along < half - 1e-9; along += piece) {
      const to = Math.min(half, along + piece);
      points.push(along, across, 0, to, across, 0, across, along, 0, across, to, 0);
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.Float32BufferAttribute(points, 3));
  const grid = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: colour }));
  grid.userData.grid = true;
  return grid;
}

const built = [];  // what the last scene message added
function buildScene(msg) {
  for (const object of built) scene.remove(object);
  built.length = 0;
  for (const g of meshes) g.dispose();
  meshes = meshGeometries(msg.meshes || []);
  const add = (object) => { scene.add(object); built.push(object); };
  state.positions = null;
  for (const shape of msg.world) {
    for (const g of geometries(shape)) {
      const mesh = new THREE.Mesh(g, material(shape));
      mesh.receiveShadow = true;
      mesh.castShadow = shape.kind !== "plane";
      if (shape.kind === "plane") {  // (drawn a little behind its grid's lines, which would flicker into it)
        mesh.material.polygonOffset = true;
        mesh.material.polygonOffsetFactor = 2;
        mesh.material.polygonOffsetUnits = 2;
      }
      mesh.applyMatrix(poseMatrix(shape.pose));
      add(mesh);
    }
    if (shape.kind === "plane") {
      // the ground's grid, to judge heights and distances by (as the snapshots draw it): 1 m cells
      // over the middle 100 m, and 10 m cells (or 100 m, ...) over the rest of a larger ground
      const size = Math.max(shape.size[0], shape.size[1]);
      const [fine, coarse] = shape.grid ? [0x5f5f5f, 0x4a4a4a] : [0x6a6a6a, 0x555555];
      const grids = [groundGrid(Math.min(size, 100), 1, fine)];
      if (size > 100) grids.push(groundGrid(size, Math.max(10, 10 ** Math.ceil(Math.log10(size / 100))), coarse));
      for (const grid of grids) {
        grid.applyMatrix(poseMatrix(shape.pose));
        grid.position.z += 0.002;
        add(grid);
      }
    }
  }
  state.bodies = msg.bodies;
  const aa = query.get("aa"), shadows = query.get("shadows");
  makeRenderer(aa === null ? msg.bodies.length <= kSmoothBodies : aa !== "0",
               shadows === null ? msg.bodies.length <= kSmoothBodies : shadows !== "0");
  const members = msg.models.map(() => 0);
  msg.bodies.forEach((b) => members[b.model]++);
  const dots = msg.bodies.length > kFullBudget;
  state.models = msg.models.map((shapes, m) => {
    const parts = [];
    let reach = 0.05;
    for (const shape of shapes) {
      for (const g of geometries(shape)) {
        const mesh = new THREE.InstancedMesh(g, material(shape), Math.max(1, members[m]));
        mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
        mesh.castShadow = mesh.receiveShadow = true;
        mesh.userData.model = m;
        mesh.frustumCulled = false;
        add(mesh);
        parts.push({ mesh, local: poseMatrix(shape.pose) });
      }
      reach = Math.max(reach, Math.hypot(...shape.pose.slice(0, 3)) + extent(shape));
    }
    // the far members as dots: one vertex each, as wide as the robot
    let points = null;
    if (dots && shapes.length > 0) {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(3 * members[m]), 3).setUsage(THREE.DynamicDrawUsage));
      const [r, g, b] = shapes[0].color;
      points = new THREE.Points(geometry, new THREE.PointsMaterial({ color: new THREE.Color(r, g, b), size: 2 * reach }));
      points.userData.model = m;
      points.frustumCulled = false;
      add(points);
    }
    return { parts, points, reach, full: new Int32Array(members[m]), far: new Int32Array(members[m]) };
  });
  // (a robot's joined parts, "robot/wheel", are bodies of their own but not robots; an arm bolted to
  // the world is one robot of moving parts only)
  document.getElementById("robots").textContent = new Set(msg.bodies.map((b) => b.name.split("/")[0])).size;
  const names = document.getElementById("names");
  names.replaceChildren(...msg.bodies.filter((b) => !b.name.includes("/")).slice(0, 20000).map((b) => {
    const option = document.createElement("option");
    option.value = b.name;
    return option;
  }));
  plotHistory.length = 0;
  state.framed = false;
  state.dirty = true;
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

function applyFrame(buffer) {
  const view = new DataView(buffer);
  if (view.getUint32(0, true) !== 0x46585353) return;
  const n = view.getUint32(4, true);
  if (n !== state.bodies.length) return;
  state.time = view.getFloat64(8, true);
  state.positions = new Float32Array(buffer, 32, 7 * n);
  // then the run's pace as set and whether it is paused, and the details of the robots selected (JSON)
  const at = 32 + 28 * n;
  if (buffer.byteLength >= at + 4) {
    const length = view.getUint32(at, true);
    if (length > 0 && buffer.byteLength >= at + 4 + length) {
      const trailer = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, at + 4, length)));
      for (const d of trailer.details || []) if (d.body === state.selected) state.details = d;
      if (trailer.run) showRun(trailer.run);
      // a command of this page a step used: from its key press (sent at once) to this frame, and its wait for the step
      if (trailer.command && trailer.command.page === teleop.page)
        state.latency = { seen: performance.now() - trailer.command.sent, waited: trailer.command.waited_ms };
    }
  }
  if (!state.framed) frameBodies(n);
  placeBodies(n);
  placeHighlight();
  record(view.getFloat32(16, true));
  state.dirty = true;
  document.getElementById("time").textContent = state.time.toFixed(3);
  if (state.replay && !state.sliding) document.getElementById("slider").value = state.time;
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

// the first frame of a scene: the view from the south-west and above, every body in it
function frameBodies(n) {
  const p = state.positions, box = new THREE.Box3();
  for (let i = 0; i < n; ++i) box.expandByPoint(at.set(p[7 * i], p[7 * i + 1], p[7 * i + 2]));
  state.framed = true;
  if (n === 0) return;
  const centre = box.getCenter(new THREE.Vector3()), radius = Math.max(1, 0.5 * box.getSize(new THREE.Vector3()).length());
  const distance = radius / Math.sin((camera.fov * Math.PI) / 360);
  controls.target.copy(centre);
  camera.position.copy(centre).add(new THREE.Vector3(-0.6, -0.6, 0.5).normalize().multiplyScalar(distance));
  camera.near = Math.max(0.05, distance / 2000);
  camera.far = Math.max(2000, distance * 10);
  camera.updateProjectionMatrix();
  controls.update();
}

// each body into its model: in full (an instance of each of its shapes) when near enough, else a dot
const body = new THREE.Matrix4(), world = new THREE.Matrix4(), at = new THREE.Vector3(), turn = new THREE.Quaternion(),
  unit = new THREE.Vector3(1, 1, 1);
function placeBodies(n) {
  const p = state.positions;
  let limit = Infinity;
  if (n > kFullBudget) {  // the distance of the kFullBudget-th nearest
    if (!state.distances || state.distances.length !== n) {
      state.distances = new Float32Array(n);
      state.sorted = new Float32Array(n);
    }
    const d = state.distances, c = camera.position;
    for (let i = 0; i < n; ++i) d[i] = (p[7 * i] - c.x) ** 2 + (p[7 * i + 1] - c.y) ** 2 + (p[7 * i + 2] - c.z) ** 2;
    state.sorted.set(d);
    state.sorted.sort();
    limit = state.sorted[kFullBudget - 1];
  }
  const full = state.models.map(() => 0), far = state.models.map(() => 0);
  for (let i = 0; i < n; ++i) {
    const m = state.bodies[i].model, model = state.models[m], k = 7 * i;
    if (limit === Infinity || state.distances[i] <= limit || !model.points) {
      const slot = full[m]++;
      model.full[slot] = i;
      body.compose(at.set(p[k], p[k + 1], p[k + 2]), turn.set(p[k + 3], p[k + 4], p[k + 5], p[k + 6]), unit);
      for (const part of model.parts) {
        world.multiplyMatrices(body, part.local);
        part.mesh.setMatrixAt(slot, world);
      }
    } else {
      const slot = far[m]++;
      model.far[slot] = i;
      model.points.geometry.attributes.position.array.set([p[k], p[k + 1], p[k + 2]], 3 * slot);
    }
  }
  state.models.forEach((model, m) => {
    for (const part of model.parts) {
      part.mesh.count = full[m];
      part.mesh.instanceMatrix.needsUpdate = true;
    }
    if (model.points) {
      model.points.geometry.setDrawRange(0, far[m]);
      model.points.geometry.attributes.position.needsUpdate = true;
    }
  });
}

// the run as set from pages (this one or another): its factor, and paused or not
function showRun(run) {
  document.getElementById("asked").textContent = run.factor > 0 ? ` (×${run.factor} asked)` : "";
  // (a frame on its way when this page's button was pressed says what was before)
  if (performance.now() - state.pressedAt > 500) pauseButton.textContent = run.paused ? "resume" : "pause";
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
  if (state.latency)
    lines.push(`steering: ${state.latency.waited.toFixed(1)} ms from a command's arrival to its step,`,
               `  ${state.latency.seen.toFixed(0)} ms from the key to the picture of that step`);
  document.getElementById("selected").textContent = lines.join("\n");
  if (document.getElementById("follow").checked) {
    controls.target.set(p[k], p[k + 1], p[k + 2]);
    controls.update();
  }
}

// a click selects the robot under the pointer
const raycaster = new THREE.Raycaster();
view.addEventListener("click", (event) => {
  const i = bodyAt(event);
  if (i >= 0) select(i);
});

function select(i) {
  state.selected = i;
  state.details = null;
  teleop.sent = null;
  teleop.asked = 0;  // its details asked for at once (then each second)
  plotHistory.length = 0;
  placeHighlight();
  showSelected();
  state.dirty = true;
}

// the selected robot: a ring around it, as wide as its model, and its name above it
const ring = new THREE.Mesh(new THREE.TorusGeometry(1, 0.08, 8, 48), new THREE.MeshBasicMaterial({ color: 0xffd34d }));
ring.visible = false;
scene.add(ring);
function placeHighlight() {
  const i = state.selected, p = state.positions;
  ring.visible = i >= 0 && !!p && i < state.bodies.length;
  if (!ring.visible) return;
  const reach = state.models[state.bodies[i].model].reach;
  ring.position.set(p[7 * i], p[7 * i + 1], p[7 * i + 2]);
  ring.scale.setScalar(1.3 * reach);
}
const pickLabel = document.getElementById("pick"), hoverLabel = document.getElementById("hover");
function placeLabel(label, i, text) {
  const where = i >= 0 && state.drawn ? window.ssxViewer.project(i) : null;
  label.hidden = !where;
  if (!where) return;
  label.textContent = text;
  label.style.left = `${where[0]}px`;
  label.style.top = `${where[1]}px`;
}
const bodyAt = (event) => {
  const pointer = new THREE.Vector2((event.clientX / window.innerWidth) * 2 - 1, -(event.clientY / window.innerHeight) * 2 + 1);
  raycaster.setFromCamera(pointer, camera);
  const objects = state.models.flatMap((model) => [...model.parts.map((part) => part.mesh), ...(model.points ? [model.points] : [])]);
  const hit = raycaster.intersectObjects(objects)[0];
  if (!hit) return -1;
  const model = state.models[hit.object.userData.model];
  if (hit.object.isPoints) return model.far[hit.index];
  return hit.instanceId !== undefined ? model.full[hit.instanceId] : -1;
};
// a name under the pointer, looked up at most 10 times a second
let hoverAt = 0;
view.addEventListener("pointermove", (event) => {
  const now = performance.now();
  if (now - hoverAt < 100 || !state.positions) return;
  hoverAt = now;
  state.hovered = bodyAt(event);
  state.dirty = true;
});
view.addEventListener("pointerleave", () => { state.hovered = -1; state.dirty = true; });

// a robot found by name: selected and followed
document.getElementById("find").addEventListener("change", (event) => {
  const wanted = event.target.value.trim();
  if (!wanted) return;
  let i = state.bodies.findIndex((b) => b.name === wanted);
  if (i < 0) i = state.bodies.findIndex((b) => b.name.startsWith(wanted));
  if (i < 0) return;
  document.getElementById("follow").checked = true;
  select(i);
});
// the view of the first frame again, following nobody
document.getElementById("reset").addEventListener("click", () => {
  document.getElementById("follow").checked = false;
  if (state.positions) frameBodies(state.bodies.length);
  state.dirty = true;
});

// the last 20 s (simulated) of the selected robot's height, speed and commanded speed, and of the
// run's real-time factor, plotted in the panel
const plotHistory = [];
function record(rtf) {
  const i = state.selected, p = state.positions;
  const last = plotHistory[plotHistory.length - 1];
  if (last && state.time <= last.t) plotHistory.length = 0;  // (a seek back, a restored state)
  const entry = { t: state.time, rtf, z: NaN, speed: NaN, commanded: NaN };
  if (i >= 0 && p) {
    const k = 7 * i;
    entry.z = p[k + 2];
    entry.x = p[k];
    entry.y = p[k + 1];
    if (last && last.x !== undefined && state.time > last.t)
      entry.speed = Math.hypot(p[k] - last.x, p[k + 1] - last.y, p[k + 2] - last.z) / (state.time - last.t);
    const d = state.details && state.details.body === i ? state.details : null;
    if (d && d.command && d.command.level === "velocity") entry.commanded = Math.hypot(...d.command.values.slice(0, 3));
    // its sensors: the first IMU's specific force and turn rate, the first range sensor's nearest
    const imu = d && d.sensors.find((m) => m.kind === "imu"), range = d && d.sensors.find((m) => m.kind === "range");
    if (imu) entry.accel = Math.hypot(...imu.accelerometer), entry.gyro = Math.hypot(...imu.gyroscope);
    if (range) entry.nearest = range.detections.reduce((n, x) => Math.min(n, x.distance), Infinity);
  }
  plotHistory.push(entry);
  while (plotHistory.length > 2 && plotHistory[0].t < state.time - 20) plotHistory.shift();
  // drawn 4 times a second, at most 150 points a line: a canvas drawn in software (no graphics card)
  // took longer than a frame's time for every frame's 4 lines of 600 points, and the page fell behind
  const now = performance.now();
  if (now - plottedAt >= 250) {
    plottedAt = now;
    drawPlot();
  }
}
let plottedAt = 0;
const plot = document.getElementById("plot"), sensorPlot = document.getElementById("sensor_plot");
const kSeries = [["z", "height m", "#6fd3ff"], ["speed", "speed m/s", "#ffd34d"], ["commanded", "commanded m/s", "#ff8a65"],
                 ["rtf", "× real time", "#a5e07a"]];
const kSensorSeries = [["accel", "|accel| m/s²", "#c792ea"], ["gyro", "|gyro| rad/s", "#f78c6c"],
                       ["nearest", "nearest m", "#89ddff"]];
function drawPlot() {
  state.plotted = drawSeries(plot, kSeries);
  // the sensors' plot only for a robot that has some
  const sensed = plotHistory.some((e) => Number.isFinite(e.accel) || Number.isFinite(e.nearest));
  sensorPlot.hidden = !sensed;
  state.sensorPlotted = sensed ? drawSeries(sensorPlot, kSensorSeries) : 0;
}
// each series over the last 20 s on `canvas`, scaled to its own range from 0; the samples drawn
function drawSeries(canvas, series) {
  const g = canvas.getContext("2d"), w = canvas.width, h = canvas.height;
  g.clearRect(0, 0, w, h);
  if (plotHistory.length < 2) return 0;
  const t0 = plotHistory[0].t, t1 = Math.max(plotHistory[plotHistory.length - 1].t, t0 + 1e-6);
  g.font = "10px system-ui, sans-serif";
  let legend = 4;
  for (const [key, name, colour] of series) {
    const values = plotHistory.map((e) => e[key]).filter(Number.isFinite);
    if (values.length < 2) continue;
    const lo = Math.min(0, ...values), hi = Math.max(lo + 1e-3, ...values);
    g.strokeStyle = colour;
    g.beginPath();
    let started = false;
    const every = Math.ceil(plotHistory.length / 150);
    for (let n = 0; n < plotHistory.length; n += every) {
      const e = plotHistory[n];
      if (!Number.isFinite(e[key])) continue;
      const x = ((e.t - t0) / (t1 - t0)) * (w - 4) + 2, y = h - 14 - ((e[key] - lo) / (hi - lo)) * (h - 20);
      if (started) g.lineTo(x, y);
      else g.moveTo(x, y), (started = true);
    }
    g.stroke();
    g.fillStyle = colour;
    const text = `${name} ${values[values.length - 1].toFixed(2)}`;
    g.fillText(text, legend, h - 2);
    legend += g.measureText(text).width + 8;
  }
  return plotHistory.length;
}

// teleoperation of the selected robot, or of every robot (the formation): W/S (or the arrows)
// forward and back along the view, A/D sideways, R/F up and down, Q/E turn; or a gamepad's sticks.
// Sent 20 times a second while held; the simulation stops the robots when nothing comes for 0.5 s
// (the dead-man rule).
const teleop = { keys: new Set(), socket: null, sent: null, last: 0, asked: 0,
                 page: 1 + Math.floor(Math.random() * 1e9) };  // (this page's number in its commands)
const kSpeed = 1.0, kClimb = 0.5, kTurn = 0.8;
window.addEventListener("keydown", (e) => {
  teleop.keys.add(e.key.toLowerCase());
  teleopTick(performance.now());  // the first command at the key press
});
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
  if (state.selected >= 0 && now - teleop.asked >= 1000) {  // the selected robot's details, for 3 s more
    teleop.asked = now;
    socket.send(JSON.stringify({ type: "select", body: state.selected }));
  }
  if (state.replay) return;  // nothing to steer in a recording (its details are as recorded)
  const all = document.getElementById("steer_all").checked;
  if (state.selected < 0 && !all) return;
  const c = teleopCommand();
  if (!c && !teleop.sent) return;
  if (now - teleop.last < 45) return;
  teleop.last = now;
  const command = c || [0, 0, 0, 0];  // released: stop now (the dead-man rule would in 0.5 s)
  const target = all ? { all: true } : { body: state.selected };
  socket.send(JSON.stringify({ type: "velocity", ...target, v: command.slice(0, 3), yaw_rate: command[3],
                               page: teleop.page, sent: now }));
  teleop.sent = c ? command.slice(0, 3) : null;
}

// the run from the page: pause and resume, one step while paused, the real-time factor
function send(message) {
  if (teleop.socket && teleop.socket.readyState === 1) teleop.socket.send(JSON.stringify(message));
}
const pauseButton = document.getElementById("pause");
pauseButton.addEventListener("click", () => {
  const pausing = pauseButton.textContent === "pause";
  state.pressedAt = performance.now();
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
      if (msg.type === "end") state.summary = msg.summary;
    } else if (state.bodies.length > 0) {
      applyFrame(event.data);
    }
  };
  // the last frame stays, with what the run said as it ended
  socket.onclose = () => {
    state.ended = true;
    status.textContent = state.summary ? `the run ended: ${state.summary}` : "disconnected (the run ended?)";
  };
}

// drawn when something changed (a frame, the view, the window): a page that keeps up draws each
// frame once and leaves the cores to the simulation otherwise; the fps shown counts the drawings
function animate() {
  requestAnimationFrame(animate);
  const now = performance.now();
  if (renderer && state.dirty) {
    state.dirty = false;
    if (state.positions) fitShadow(state.positions.length / 7);
    renderer.render(scene, camera);
    state.drawn = state.positions;  // what the picture shows now
    state.fpsFrames++;
    const named = (i) => (i >= 0 && i < state.bodies.length ? state.bodies[i].name : "");
    placeLabel(pickLabel, state.selected, named(state.selected));
    placeLabel(hoverLabel, state.hovered !== state.selected ? state.hovered : -1, named(state.hovered));
  }
  if (now - state.fpsSince > 1000) {
    document.getElementById("fps").textContent = Math.round((1000 * state.fpsFrames) / (now - state.fpsSince));
    state.fpsFrames = 0;
    state.fpsSince = now;
  }
}

// for tests and for a look from the browser's console
window.ssxViewer = {
  state, scene, camera, controls, select, plotHistory, ring,
  get renderer() { return renderer; },
  get meshes() { return meshes; },  // the scene's mesh geometries, as the scene message lists them
  // draws now (for a test: pixel() reads this picture in the same task)
  draw() {
    renderer.render(scene, camera);
    state.drawn = state.positions;
  },
  // where body i appears in the picture drawn last, in CSS pixels from the top left (null: behind the camera)
  project(i) {
    const p = state.drawn, k = 7 * i;
    const v = new THREE.Vector3(p[k], p[k + 1], p[k + 2]).project(camera);
    if (v.z > 1) return null;
    return [((v.x + 1) / 2) * window.innerWidth, ((1 - v.y) / 2) * window.innerHeight];
  },
  // soft shadows on or off (for a test, and from the console): every material made again
  shadows(on) {
    setShadows(on);
    scene.traverse((o) => { if (o.material) o.material.needsUpdate = true; });
    state.dirty = true;
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
