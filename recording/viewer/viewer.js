// brickworld replay page: parses the embedded recording (recording/FORMAT.md) and replays it
// with three.js (r111, inlined by `brickworld view`). What it drew is written into
// #bw-report as JSON (frames, bodies, bricks, errors) for the headless browser test.
'use strict';

const report = { ready: false, errors: [], frames: 0, frame: 0, bodies: 0, bodiesDrawn: 0, bricksDrawn: 0, nodeBoxesDrawn: 0,
                 terrainTriangles: 0, contactsDrawn: 0, timelineFrames: 0, webgl: false };
function writeReport() { document.getElementById('bw-report').textContent = JSON.stringify(report); }
window.addEventListener('error', (e) => { report.errors.push(String(e.message || e)); writeReport(); });
{
  const original = console.error.bind(console);
  console.error = (...args) => { report.errors.push(args.map(String).join(' ')); writeReport(); original(...args); };
}

// ---- the recording ----------------------------------------------------------------------

function decodeBase64(text) {
  const clean = text.replace(/\s+/g, '');
  const raw = atob(clean);
  const out = new Uint8Array(raw.length);
  for (let i = 0; i < raw.length; ++i) out[i] = raw.charCodeAt(i);
  return out;
}

const TAG = (s) => s.charCodeAt(0) | (s.charCodeAt(1) << 8) | (s.charCodeAt(2) << 16) | (s.charCodeAt(3) << 24);
const T_HEAD = TAG('HEAD'), T_GRID = TAG('GRID'), T_NODE = TAG('NODE'), T_TERR = TAG('TERR'), T_BODY = TAG('BODY'),
      T_EDIT = TAG('EDIT'), T_SPLT = TAG('SPLT'), T_FRAM = TAG('FRAM'), T_CONT = TAG('CONT'), T_MODE = TAG('MODE'),
      T_END = TAG('END_');

// Reads a brick's 32 bytes at `o`.
function readBrick(dv, o) {
  return { px: dv.getFloat32(o, true), py: dv.getFloat32(o + 4, true), pz: dv.getFloat32(o + 8, true),
           hx: dv.getFloat32(o + 12, true), hy: dv.getFloat32(o + 16, true), hz: dv.getFloat32(o + 20, true),
           material: dv.getUint8(o + 28), rotation: dv.getUint8(o + 29), shape: dv.getUint8(o + 30), sides: dv.getUint8(o + 31) };
}

function parseRecording(bytes) {
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const magic = String.fromCharCode(...bytes.subarray(0, 8));
  if (magic !== 'BWRECORD') throw new Error('not a brickworld recording');
  if (dv.getUint32(8, true) !== 1) throw new Error('recording version ' + dv.getUint32(8, true) + ', this page reads 1');
  const rec = { head: null, grids: [], terrains: [], bodies: [], frames: [], modes: [], complete: false };
  // What blocks before a frame's FRAM bring; the scene's start goes to `start` (frame -1).
  let pending = { edits: [], terrainChunks: [] };
  let started = false;
  let at = 12;
  while (at + 8 <= bytes.length) {
    const tag = dv.getUint32(at, true), length = dv.getUint32(at + 4, true);
    let o = at + 8;
    const end = o + length;
    if (end > bytes.length) break;  // a run that died mid-way: keep its complete frames
    const frameOfBlock = started ? rec.frames.length : -1;
    if (tag === T_HEAD) {
      rec.head = JSON.parse(new TextDecoder().decode(bytes.subarray(o, end)));
    } else if (tag === T_GRID) {
      const index = dv.getUint32(o, true), nameLength = dv.getUint32(o + 4, true);
      const name = new TextDecoder().decode(bytes.subarray(o + 8, o + 8 + nameLength));
      o += 8 + nameLength;
      const brickCount = dv.getUint32(o, true), n = dv.getUint32(o + 4, true);
      o += 8;
      const bricks = new Map();
      for (let k = 0; k < n; ++k, o += 36) bricks.set(dv.getUint32(o, true), readBrick(dv, o + 4));
      rec.grids[index] = { name, brickCount, hasBricks: n > 0 || brickCount === 0, bricks, frame: frameOfBlock, levels: [] };
    } else if (tag === T_NODE) {
      const g = dv.getUint32(o, true), levels = dv.getUint32(o + 4, true);
      o += 8;
      for (let l = 0; l < levels; ++l) {
        const n = dv.getUint32(o, true);
        rec.grids[g].levels.push(new Float32Array(bytes.buffer.slice(bytes.byteOffset + o + 4, bytes.byteOffset + o + 4 + 24 * n)));
        o += 4 + 24 * n;
      }
    } else if (tag === T_TERR) {
      const t = dv.getUint32(o, true), chunks = dv.getUint32(o + 8, true);
      o += 12;
      if (!rec.terrains[t]) rec.terrains[t] = { chunks: new Map() };  // key -> [{frame, positions, indices}]
      for (let c = 0; c < chunks; ++c) {
        const key = dv.getInt32(o, true) + ',' + dv.getInt32(o + 4, true) + ',' + dv.getInt32(o + 8, true);
        const v = dv.getUint32(o + 12, true), tris = dv.getUint32(o + 16, true);
        o += 20;
        const positions = new Float32Array(bytes.buffer.slice(bytes.byteOffset + o, bytes.byteOffset + o + 12 * v));
        o += 12 * v;
        const indices = new Uint32Array(bytes.buffer.slice(bytes.byteOffset + o, bytes.byteOffset + o + 12 * tris));
        o += 12 * tris + tris;
        const versions = rec.terrains[t].chunks.get(key) || [];
        versions.push({ frame: frameOfBlock, positions, indices, geometry: null });
        rec.terrains[t].chunks.set(key, versions);
      }
    } else if (tag === T_BODY) {
      const first = dv.getUint32(o, true), count = dv.getUint32(o + 4, true);
      o += 8;
      for (let k = 0; k < count; ++k, o += 76) {
        const f = (i) => dv.getFloat32(o + 8 + 4 * i, true);
        rec.bodies[first + k] = { motion: dv.getUint8(o), kind: dv.getUint8(o + 1), ref: dv.getUint32(o + 4, true),
                                  size: [f(0), f(1), f(2)], shapePos: [f(3), f(4), f(5)], shapeRot: [f(6), f(7), f(8), f(9)],
                                  pos: [f(10), f(11), f(12)], rot: [f(13), f(14), f(15), f(16)], frame: frameOfBlock };
      }
    } else if (tag === T_EDIT) {
      started = true;
      const n = dv.getUint32(o, true);
      o += 4;
      for (let k = 0; k < n; ++k, o += 41)
        pending.edits.push({ grid: dv.getUint32(o, true), id: dv.getUint32(o + 4, true), placed: dv.getUint8(o + 8) === 1,
                             brick: readBrick(dv, o + 9) });
    } else if (tag === T_SPLT) {
      started = true;
    } else if (tag === T_FRAM) {
      started = true;
      const stages = rec.head.stages.length;
      const frame = { index: dv.getUint32(o, true), stageMs: [], edits: pending.edits, contacts: null };
      o += 4;
      for (let s = 0; s < stages; ++s, o += 4) frame.stageMs.push(dv.getFloat32(o, true));
      frame.bodyCount = dv.getUint32(o, true);
      const m = dv.getUint32(o + 4, true);
      o += 8;
      frame.ids = new Uint32Array(m);
      frame.poses = new Float32Array(7 * m);
      frame.states = new Uint8Array(m);
      for (let k = 0; k < m; ++k, o += 33) {
        frame.ids[k] = dv.getUint32(o, true);
        for (let i = 0; i < 7; ++i) frame.poses[7 * k + i] = dv.getFloat32(o + 4 + 4 * i, true);
        frame.states[k] = dv.getUint8(o + 32);
      }
      frame.total = frame.stageMs.reduce((a, b) => a + b, 0);
      frame.inside = frame.states.reduce((n, state) => n + (state === 2), 0);
      rec.frames.push(frame);
      pending = { edits: [], terrainChunks: [] };
    } else if (tag === T_CONT) {
      const n = dv.getUint32(o, true);
      rec.frames[rec.frames.length - 1].contacts = new Float32Array(bytes.buffer.slice(bytes.byteOffset + o + 4, bytes.byteOffset + o + 4 + 28 * n));
    } else if (tag === T_MODE) {
      const nameLength = dv.getUint32(o, true);
      const name = new TextDecoder().decode(bytes.subarray(o + 4, o + 4 + nameLength));
      const n = dv.getUint32(o + 4 + nameLength, true);
      const start = bytes.byteOffset + o + 8 + nameLength;
      rec.modes.push({ name, times: new Float32Array(bytes.buffer.slice(start, start + 16 * n)) });  // update, submission, commit, wait
    } else if (tag === T_END) {
      rec.complete = true;
    }
    at = end;
  }
  if (!rec.head) throw new Error('the recording has no HEAD block');
  return rec;
}

// ---- geometry ---------------------------------------------------------------------------

function geometryFrom(positions) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  g.computeVertexNormals();
  return g;
}

// Brick shapes in the unit box [-0.5, 0.5]^3 (collision/bricks/brick.h's canonical shapes).
function brickGeometries() {
  const v = (x, y, z) => [x, y, z];
  const tri = (out, a, b, c) => out.push(...a, ...b, ...c);
  const quad = (out, a, b, c, d) => { tri(out, a, b, c); tri(out, a, c, d); };
  const box = new THREE.BoxBufferGeometry(1, 1, 1);
  // Wedge: full bottom; the top edge along y at x = -0.5, z = +0.5; the slope faces +x and up.
  const w = [];
  const b00 = v(-.5, -.5, -.5), b10 = v(.5, -.5, -.5), b11 = v(.5, .5, -.5), b01 = v(-.5, .5, -.5);
  const t0 = v(-.5, -.5, .5), t1 = v(-.5, .5, .5);
  quad(w, b00, b01, b11, b10);  // bottom
  quad(w, b00, t0, t1, b01);    // back (x = -0.5)
  quad(w, b10, b11, t1, t0);    // slope
  tri(w, b00, b10, t0);         // y = -0.5 side
  tri(w, b01, t1, b11);         // y = +0.5 side
  // Corner wedge: full bottom, apex at (-0.5, -0.5, +0.5).
  const c = [];
  const apex = v(-.5, -.5, .5);
  quad(c, b00, b01, b11, b10);
  tri(c, b00, apex, b01);
  tri(c, b01, apex, b11);
  tri(c, b11, apex, b10);
  tri(c, b10, apex, b00);
  // Cylinder: a 12-sided prism along z (bricks with other side counts are drawn with 12).
  const cyl = new THREE.CylinderBufferGeometry(0.5, 0.5, 1, 12);
  cyl.rotateX(Math.PI / 2);
  return [box, geometryFrom(w), geometryFrom(c), cyl];
}

// A brick's matrix in its grid: position x rotation (the header's table) x size.
function brickMatrix(b, rotations, m) {
  const r = rotations[b.rotation], sx = 2 * b.hx, sy = 2 * b.hy, sz = 2 * b.hz;
  m.set(r[0] * sx, r[1] * sy, r[2] * sz, b.px,
        r[3] * sx, r[4] * sy, r[5] * sz, b.py,
        r[6] * sx, r[7] * sy, r[8] * sz, b.pz,
        0, 0, 0, 1);
  return m;
}

// ---- the page ---------------------------------------------------------------------------

const STATE_COLORS = [0xe8a33d, 0x4f7fd9, 0xe23b3b, 0xb45ad6];  // awake, asleep, inside solid, pushed out
const STATE_NAMES = ['awake', 'asleep', 'inside solid', 'pushed out'];
const STAGE_COLORS = ['#e6c229', '#f17105', '#d11149', '#6610f2', '#1a8fe3', '#17b890', '#8bc34a', '#c2a5ff', '#ff8fab', '#777777'];

function main() {
  const bytes = decodeBase64(document.getElementById('bw-data').textContent);
  const rec = parseRecording(bytes);
  const head = rec.head;
  const F = rec.frames.length;
  report.frames = F;
  document.getElementById('title').textContent = head.scene + ' (' + F + ' frames' + (rec.complete ? '' : ', run did not finish') + ')';

  const view = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  report.webgl = !!renderer.getContext();
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  view.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x15181c);
  scene.add(new THREE.HemisphereLight(0xdde6ff, 0x3a3024, 0.75));
  const sun = new THREE.DirectionalLight(0xffffff, 0.65);
  sun.position.set(0.4, 0.7, 1.0);
  scene.add(sun);
  const camera = new THREE.PerspectiveCamera(50, 1, 0.05, 1e6);
  camera.up.set(0, 0, 1);  // the world's z is up
  const controls = new THREE.OrbitControls(camera, renderer.domElement);

  const rotations = head.rotations;
  const shapes = brickGeometries();
  const unitBox = new THREE.BoxBufferGeometry(1, 1, 1);
  const sphere = new THREE.SphereBufferGeometry(1, 16, 12);
  const cylinder = new THREE.CylinderBufferGeometry(1, 1, 1, 16);
  cylinder.rotateX(Math.PI / 2);
  const gridMaterial = (motion) => new THREE.MeshLambertMaterial({ color: motion === 0 ? 0x9aa0a6 : 0x7fa37a });
  const stateMaterials = STATE_COLORS.map((c) => new THREE.MeshLambertMaterial({ color: c }));
  const staticMaterial = new THREE.MeshLambertMaterial({ color: 0x9aa0a6 });
  const terrainMaterial = new THREE.MeshLambertMaterial({ color: 0x8d7b5a, side: THREE.DoubleSide });
  const tmp = new THREE.Matrix4();

  // Grids: bricks in cells, a large grid's OctoBVH boxes of NODE level 3 (at most 512; one cell
  // for grids under CELL_MIN bricks), and per cell and brick shape one instance buffer shared by
  // every body that is a copy of the grid. Cells out of view are not drawn and far cells are
  // drawn as their box (chooseDetail). Removed bricks leave a zero matrix until a placement
  // reuses their slot.
  const CELL_MIN = 20000;
  // The cell whose box holds a point (grid frame): boxes hashed into a 16^3 lattice over their
  // bounds; a point in no box (none should be: the boxes cover every brick) takes the nearest.
  function cellFinder(boxes) {
    const n = boxes.length / 6, R = 16;
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let o = 0; o < boxes.length; o += 6)
      for (let a = 0; a < 3; ++a) { lo[a] = Math.min(lo[a], boxes[o + a]); hi[a] = Math.max(hi[a], boxes[o + 3 + a]); }
    const step = [0, 1, 2].map((a) => Math.max((hi[a] - lo[a]) / R, 1e-6));
    const at = (v, a) => Math.min(R - 1, Math.max(0, Math.floor((v - lo[a]) / step[a])));
    const lattice = Array.from({ length: R * R * R }, () => []);
    for (let c = 0; c < n; ++c) {
      const o = 6 * c;
      for (let z = at(boxes[o + 2], 2); z <= at(boxes[o + 5], 2); ++z)
        for (let y = at(boxes[o + 1], 1); y <= at(boxes[o + 4], 1); ++y)
          for (let x = at(boxes[o], 0); x <= at(boxes[o + 3], 0); ++x) lattice[x + R * (y + R * z)].push(c);
    }
    return (x, y, z) => {
      const list = lattice[at(x, 0) + R * (at(y, 1) + R * at(z, 2))];
      let best = 0, bestDistance = Infinity;
      for (const c of list.length ? list : [...Array(n).keys()]) {
        const o = 6 * c;
        const dx = Math.max(boxes[o] - x, 0, x - boxes[o + 3]), dy = Math.max(boxes[o + 1] - y, 0, y - boxes[o + 4]),
              dz = Math.max(boxes[o + 2] - z, 0, z - boxes[o + 5]);
        const d = dx * dx + dy * dy + dz * dz;
        if (d === 0) return c;
        if (d < bestDistance) { bestDistance = d; best = c; }
      }
      return best;
    };
  }
  function boxSphere(boxes, from, to) {
    const box = new THREE.Box3();
    for (let o = 6 * from; o < 6 * to; o += 6) {
      box.expandByPoint(new THREE.Vector3(boxes[o], boxes[o + 1], boxes[o + 2]));
      box.expandByPoint(new THREE.Vector3(boxes[o + 3], boxes[o + 4], boxes[o + 5]));
    }
    return box.isEmpty() ? null : box.getBoundingSphere(new THREE.Sphere());
  }
  const grids = rec.grids.map((g, gi) => {
    let placements = 0;
    for (let f = 0; f < F; ++f) for (const e of rec.frames[f].edits) placements += e.grid === gi && e.placed && g.frame < f;
    const cellBoxes = g.hasBricks && g.bricks.size + placements >= CELL_MIN && g.levels.length >= 3 && g.levels[2].length >= 12 * 6
                          ? g.levels[2] : null;
    const cells = cellBoxes ? cellBoxes.length / 6 : 1;
    const find = cellBoxes ? cellFinder(cellBoxes) : () => 0;
    const capacity = Array.from({ length: cells }, () => [0, 0, 0, 0]);
    for (const b of g.bricks.values()) capacity[find(b.px, b.py, b.pz)][b.shape]++;
    for (let f = 0; f < F; ++f)
      for (const e of rec.frames[f].edits)
        if (e.grid === gi && e.placed && g.frame < f) capacity[find(e.brick.px, e.brick.py, e.brick.pz)][e.brick.shape]++;
    const attrs = capacity.map((perShape) => perShape.map((n) => new THREE.InstancedBufferAttribute(new Float32Array(16 * Math.max(n, 1)), 16)));
    const whole = g.levels.length ? boxSphere(g.levels[0], 0, g.levels[0].length / 6) : null;
    const spheres = cellBoxes ? Array.from({ length: cells }, (_, c) => boxSphere(cellBoxes, c, c + 1)) : [whole];
    // Per cell and shape a geometry of its own, shared only by the copies of this grid (which
    // share the instance buffer too): three.js r111 does not bind an instanced mesh's matrices
    // again when the previous draw used the same geometry and program, so two instanced meshes
    // with one geometry and different buffers would draw the first one's instances twice.
    const geometries = new Map();
    const geometry = (c, s) => {
      const key = c * 4 + s;
      if (!geometries.has(key)) geometries.set(key, shapes[s].clone());
      return geometries.get(key);
    };
    return { source: g, cellBoxes, find, capacity, attrs, spheres, geometry, slots: null, free: null, used: null };
  });
  function resetGrid(grid) {
    grid.slots = new Map();
    grid.free = grid.capacity.map(() => [[], [], [], []]);
    grid.used = grid.capacity.map(() => [0, 0, 0, 0]);
    for (const perShape of grid.attrs) for (const a of perShape) { a.array.fill(0); a.needsUpdate = true; }
    for (const [id, b] of grid.source.bricks) placeBrick(grid, id, b);
  }
  function placeBrick(grid, id, b) {
    const c = grid.find(b.px, b.py, b.pz), s = b.shape;
    const slot = grid.free[c][s].length ? grid.free[c][s].pop() : grid.used[c][s]++;
    grid.slots.set(id, [c, s, slot]);
    brickMatrix(b, rotations, tmp).toArray(grid.attrs[c][s].array, 16 * slot);
    grid.attrs[c][s].needsUpdate = true;
  }
  function removeBrick(grid, id) {
    const at = grid.slots.get(id);
    if (!at) return;
    const [c, s, slot] = at;
    grid.slots.delete(id);
    grid.attrs[c][s].array.fill(0, 16 * slot, 16 * slot + 16);
    grid.attrs[c][s].needsUpdate = true;
    grid.free[c][s].push(slot);
  }
  grids.forEach(resetGrid);

  // Node boxes (grid frame) of a grid's level as an instanced box mesh.
  function nodeBoxMesh(g, level, material) {
    const boxes = rec.grids[g].levels[level];
    if (!boxes || boxes.length === 0) return null;
    const n = boxes.length / 6;
    const mesh = new THREE.InstancedMesh(unitBox.clone(), material, n);
    for (let k = 0; k < n; ++k) {
      const o = 6 * k;
      tmp.makeScale(Math.max(boxes[o + 3] - boxes[o], 1e-4), Math.max(boxes[o + 4] - boxes[o + 1], 1e-4), Math.max(boxes[o + 5] - boxes[o + 2], 1e-4));
      tmp.setPosition((boxes[o] + boxes[o + 3]) / 2, (boxes[o + 1] + boxes[o + 4]) / 2, (boxes[o + 2] + boxes[o + 5]) / 2);
      mesh.setMatrixAt(k, tmp);
    }
    return mesh;
  }

  // Bodies: grid and terrain bodies are groups posed each frame; primitives are instances.
  const bodyObjects = [];  // per body: {group, meshes, cellBox, lod, bounds, ...}, or null for primitives
  const bodyShapeMatrix = rec.bodies.map((b) => new THREE.Matrix4().compose(
      new THREE.Vector3(...b.shapePos), new THREE.Quaternion(...b.shapeRot), new THREE.Vector3(1, 1, 1)));
  const terrainGroups = [];
  const primitiveCount = [0, 0, 0, 0, 0, 0];
  rec.bodies.forEach((b, i) => {
    if (b.kind === 3) {
      const group = new THREE.Group();
      group.matrixAutoUpdate = false;
      const grid = grids[b.ref];
      const material = b.motion === 2 ? stateMaterials[0] : gridMaterial(b.motion);
      const meshes = [];
      let cellBox = null;
      if (grid.source.hasBricks) {
        grid.attrs.forEach((perShape, c) => perShape.forEach((attr, s) => {
          if (grid.capacity[c][s] === 0) return;
          const mesh = new THREE.InstancedMesh(grid.geometry(c, s), material, grid.capacity[c][s]);
          mesh.instanceMatrix = attr;
          mesh.userData.cell = c;
          mesh.userData.shape = s;
          mesh.frustumCulled = false;  // culled per cell (chooseDetail): the unit geometry's bounds say nothing
          group.add(mesh);
          meshes.push(mesh);
        }));
        if (grid.cellBoxes) {
          // A far cell's box: one instance per cell, zero-sized while the cell shows its bricks.
          cellBox = new THREE.InstancedMesh(unitBox.clone(), material, grid.cellBoxes.length / 6);
          cellBox.frustumCulled = false;
          cellBox.instanceMatrix.array.fill(0);
          group.add(cellBox);
        }
      } else {
        const levels = grid.source.levels.length;
        const mesh = nodeBoxMesh(b.ref, levels - 1, material);
        if (mesh) { mesh.frustumCulled = false; group.add(mesh); meshes.push(mesh); }
      }
      scene.add(group);
      bodyObjects[i] = { group, meshes, cellBox, dynamic: b.motion === 2, grid: b.ref, bounds: grid.spheres.length === 1 ? grid.spheres[0] : boxSphere(grid.source.levels[0], 0, grid.source.levels[0].length / 6), lod: null };
    } else if (b.kind === 4) {
      const group = new THREE.Group();
      group.matrixAutoUpdate = false;
      scene.add(group);
      bodyObjects[i] = { group, meshes: [], dynamic: false, terrain: b.ref };
      terrainGroups[b.ref] = group;
    } else {
      bodyObjects[i] = null;
      primitiveCount[b.kind]++;
    }
  });
  // Primitive instances: per kind and state (static primitives use state 0 in grey), each mesh
  // with a geometry of its own (see the grids' geometry above).
  const primitiveMeshes = {};
  function primitiveMesh(geometry, kind, state, count) {
    const key = kind + ':' + state;
    if (!primitiveMeshes[key]) {
      const mesh = new THREE.InstancedMesh(geometry.clone(), state < 0 ? staticMaterial : stateMaterials[state], Math.max(count, 1));
      mesh.frustumCulled = false;
      mesh.count = 0;
      scene.add(mesh);
      primitiveMeshes[key] = mesh;
    }
    return primitiveMeshes[key];
  }
  // Capsule caps: two spheres per capsule.
  const capsuleCaps = 'caps';

  // Terrain chunks: the latest version at or before the shown frame.
  const terrainMeshes = new Map();  // "t|key" -> mesh
  function showTerrain(frame) {
    let triangles = 0;
    rec.terrains.forEach((t, ti) => {
      if (!t || !terrainGroups[ti]) return;
      for (const [key, versions] of t.chunks) {
        let v = null;
        for (const candidate of versions) if (candidate.frame <= frame) v = candidate;
        const id = ti + '|' + key;
        let mesh = terrainMeshes.get(id);
        if (!v || v.indices.length === 0) { if (mesh) mesh.visible = false; continue; }
        if (!v.geometry) {
          v.geometry = new THREE.BufferGeometry();
          v.geometry.setAttribute('position', new THREE.BufferAttribute(v.positions, 3));
          v.geometry.setIndex(new THREE.BufferAttribute(v.indices, 1));
          v.geometry.computeVertexNormals();
        }
        if (!mesh) {
          mesh = new THREE.Mesh(v.geometry, terrainMaterial);
          terrainGroups[ti].add(mesh);
          terrainMeshes.set(id, mesh);
        }
        mesh.geometry = v.geometry;
        mesh.visible = true;
        triangles += v.indices.length / 3;
      }
    });
    return triangles;
  }

  // Contacts: a point and a 0.25 m normal per contact.
  let maxContacts = 0;
  for (const f of rec.frames) if (f.contacts) maxContacts = Math.max(maxContacts, f.contacts.length / 7);
  const contactPositions = new Float32Array(6 * Math.max(maxContacts, 1));
  const contactGeometry = new THREE.BufferGeometry();
  contactGeometry.setAttribute('position', new THREE.BufferAttribute(contactPositions, 3));
  const contactLines = new THREE.LineSegments(contactGeometry, new THREE.LineBasicMaterial({ color: 0x00e5ff }));
  contactLines.frustumCulled = false;
  contactLines.visible = false;
  scene.add(contactLines);

  // OctoBVH boxes of a picked grid, by depth (wireframe).
  const nodeSelect = document.getElementById('node-grid'), nodeDepth = document.getElementById('node-depth');
  rec.grids.forEach((g, gi) => {
    const o = document.createElement('option');
    o.value = gi;
    o.textContent = (g.name || 'grid ' + gi) + ' (' + g.brickCount + ' bricks)';
    nodeSelect.appendChild(o);
  });
  nodeDepth.max = rec.grids.reduce((most, g) => Math.max(most, g.levels.length), 1);  // the run's --record-depth
  nodeDepth.value = Math.min(3, Number(nodeDepth.max));
  document.getElementById('node-depth-label').textContent = nodeDepth.value;
  const nodeMaterial = new THREE.MeshBasicMaterial({ color: 0x00ff88, wireframe: true, transparent: true, opacity: 0.5 });
  let nodeOverlay = null;
  function updateNodeOverlay() {
    document.getElementById('node-depth-label').textContent = nodeDepth.value;
    if (nodeOverlay) { nodeOverlay.parent.remove(nodeOverlay); nodeOverlay = null; }
    const g = Number(nodeSelect.value);
    if (g < 0) { report.nodeBoxesDrawn = 0; return; }
    const body = rec.bodies.findIndex((b) => b.kind === 3 && b.ref === g);
    if (body < 0 || !bodyObjects[body]) return;
    nodeOverlay = nodeBoxMesh(g, Number(nodeDepth.value) - 1, nodeMaterial);
    if (nodeOverlay) {
      nodeOverlay.frustumCulled = false;
      bodyObjects[body].group.add(nodeOverlay);
      report.nodeBoxesDrawn = nodeOverlay.count;
    }
    draw();
  }
  nodeSelect.addEventListener('change', updateNodeOverlay);
  nodeDepth.addEventListener('input', updateNodeOverlay);

  // ---- showing a frame ----
  let shown = -2;  // frame whose edits the grids hold (-1: the start)
  const pose = new THREE.Matrix4(), q = new THREE.Quaternion(), p = new THREE.Vector3(), s = new THREE.Vector3();
  function applyEdits(frame) {
    for (const e of rec.frames[frame].edits) {
      const grid = grids[e.grid];
      // A grid made this frame (a split part) was recorded as the frame left it.
      if (!grid || !grid.source.hasBricks || grid.source.frame >= frame) continue;
      if (e.placed) { removeBrick(grid, e.id); placeBrick(grid, e.id, e.brick); } else removeBrick(grid, e.id);
    }
  }
  function setFrame(target) {
    target = Math.max(0, Math.min(F - 1, target));
    if (target < shown) { grids.forEach(resetGrid); shown = -1; }
    for (let f = Math.max(shown + 1, 0); f <= target; ++f) applyEdits(f);
    shown = target;
    const frame = rec.frames[target];

    // Poses: the BODY pose, replaced by this frame's for bodies that move.
    const poseOf = new Map();
    for (let k = 0; k < frame.ids.length; ++k) poseOf.set(frame.ids[k], k);
    for (const key in primitiveMeshes) primitiveMeshes[key].count = 0;
    let drawn = 0;
    rec.bodies.forEach((b, i) => {
      const exists = b.frame <= target;
      const obj = bodyObjects[i];
      if (!exists) { if (obj) obj.group.visible = false; return; }
      ++drawn;
      const k = poseOf.get(i);
      const P = k === undefined ? b.pos : [frame.poses[7 * k], frame.poses[7 * k + 1], frame.poses[7 * k + 2]];
      const Q = k === undefined ? b.rot : [frame.poses[7 * k + 3], frame.poses[7 * k + 4], frame.poses[7 * k + 5], frame.poses[7 * k + 6]];
      const state = k === undefined ? (b.motion === 0 ? -1 : 0) : frame.states[k];
      pose.compose(p.set(P[0], P[1], P[2]), q.set(Q[0], Q[1], Q[2], Q[3]), s.set(1, 1, 1)).multiply(bodyShapeMatrix[i]);
      if (obj) {
        obj.group.visible = true;
        obj.group.matrix.copy(pose);
        obj.group.matrixWorldNeedsUpdate = true;
        if (obj.dynamic) {
          const material = stateMaterials[state < 0 ? 0 : state];
          for (const m of obj.meshes) m.material = material;
          if (obj.lod) obj.lod.material = material;
          if (obj.cellBox) obj.cellBox.material = material;
        }
        return;
      }
      const addInstance = (geometry, kind, m) => {
        const mesh = primitiveMesh(geometry, kind, b.motion === 0 ? -1 : state, primitiveCount[b.kind] * (kind === capsuleCaps ? 2 : 1));
        mesh.setMatrixAt(mesh.count++, m);
        mesh.instanceMatrix.needsUpdate = true;
      };
      const z = b.size;
      if (b.kind === 0) addInstance(sphere, 0, tmp.copy(pose).scale(s.set(z[0], z[0], z[0])));
      else if (b.kind === 1 || b.kind === 5) addInstance(unitBox, b.kind, tmp.copy(pose).scale(s.set(2 * z[0], 2 * z[1], 2 * z[2])));
      else if (b.kind === 2) {
        addInstance(cylinder, 2, tmp.copy(pose).scale(s.set(z[0], z[0], 2 * z[1])));
        for (const side of [-1, 1]) {
          tmp.makeTranslation(0, 0, side * z[1]).premultiply(pose).scale(s.set(z[0], z[0], z[0]));
          addInstance(sphere, capsuleCaps, tmp);
        }
      }
    });
    report.terrainTriangles = showTerrain(target);

    // Contacts.
    let nc = 0;
    if (frame.contacts) {
      nc = frame.contacts.length / 7;
      for (let k = 0; k < nc; ++k) {
        const c = frame.contacts.subarray(7 * k, 7 * k + 7);
        contactPositions.set([c[0], c[1], c[2], c[0] + 0.25 * c[3], c[1] + 0.25 * c[4], c[2] + 0.25 * c[5]], 6 * k);
      }
    }
    contactGeometry.setDrawRange(0, 2 * nc);
    contactGeometry.attributes.position.needsUpdate = true;

    // Bricks drawn: every visible body's copy of its grid; instances up to the slots in use.
    let bricks = 0;
    rec.bodies.forEach((b, i) => {
      const obj = bodyObjects[i];
      if (!obj || !obj.group.visible || b.kind !== 3 || !grids[b.ref].source.hasBricks) return;
      bricks += grids[b.ref].slots.size;
      obj.meshes.forEach((m) => { m.count = grids[b.ref].used[m.userData.cell][m.userData.shape]; });
    });
    listInside(frame);
    report.insideSolid = frame.inside;
    report.frame = target;
    report.bodies = frame.bodyCount;
    report.bodiesDrawn = drawn;
    report.bricksDrawn = bricks;
    report.contactsDrawn = contactLines.visible ? nc : 0;
    document.getElementById('scrub').value = target;
    document.getElementById('frame-label').textContent = 'frame ' + (target + 1) + ' / ' + F + ' \u2014 ' + frame.total.toFixed(2) +
        ' ms, ' + frame.bodyCount + ' bodies' + (nc ? ', ' + nc + ' contacts' : '');
    drawTimeline();
    draw();
  }

  // The camera a few sizes away from body b as the shown frame has it.
  function focusBody(b) {
    const frame = rec.frames[shown], body = rec.bodies[b];
    if (!body || !frame) return;
    const k = frame.ids.indexOf(b);
    const at = k >= 0 ? frame.poses.subarray(7 * k, 7 * k + 3) : body.pos;
    const obj = bodyObjects[b];
    const radius = obj && obj.bounds ? obj.bounds.radius : Math.max(...body.size, 0.5);
    controls.target.set(at[0], at[1], at[2]);
    camera.position.set(at[0] + 3 * radius, at[1] - 4 * radius, at[2] + 2.5 * radius);
    controls.update();
    draw();
  }
  // Bodies inside solid at the shown frame, each a link that looks at it.
  const insideList = document.getElementById('inside');
  function listInside(frame) {
    insideList.textContent = '';
    if (!frame.inside) return;
    insideList.append('inside solid at this frame (' + frame.inside + '): ');
    let listed = 0;
    for (let k = 0; k < frame.ids.length && listed < 20; ++k) {
      if (frame.states[k] !== 2) continue;
      const link = document.createElement('a');
      link.href = '#';
      link.textContent = 'body ' + frame.ids[k];
      const id = frame.ids[k];
      link.addEventListener('click', (e) => { e.preventDefault(); focusBody(id); });
      insideList.append(link, ' ');
      ++listed;
    }
  }

  // ---- the timeline: frame times stacked by stage; a click jumps to that frame ----
  const timeline = document.getElementById('timeline');
  const stages = head.stages;
  let scaleMs = 0;
  for (const f of rec.frames) scaleMs = Math.max(scaleMs, f.total);
  scaleMs = Math.max(scaleMs, 1e-3);
  const legend = document.getElementById('legend');
  stages.forEach((name, k) => {
    const span = document.createElement('span');
    span.innerHTML = '<i style="background:' + STAGE_COLORS[k % STAGE_COLORS.length] + '"></i>' + name;
    legend.appendChild(span);
  });
  STATE_NAMES.forEach((name, k) => {
    const span = document.createElement('span');
    span.innerHTML = '<i style="background:#' + STATE_COLORS[k].toString(16).padStart(6, '0') + '"></i>body ' + name;
    legend.appendChild(span);
  });
  // `--submission all`: a lane per submission mode below the stages, its render frame stacked
  // as transform update, submission, commit and wait, on one scale for every lane.
  const MODE_PARTS = ['update', 'submission', 'commit', 'render wait'], MODE_COLORS = ['#ff8fab', '#f4d35e', '#0ead69', '#5e6472'];
  const LANE = 34, MAIN = 150;
  // The lanes' scale: the 95th percentile of every lane's frames (a stray 17 ms frame would
  // flatten the rest); taller frames are clipped and marked red.
  const laneSums = rec.modes.map((m) => {
    const sums = [];
    for (let f = 0; f < F; ++f) sums.push(m.times[4 * f] + m.times[4 * f + 1] + m.times[4 * f + 2] + m.times[4 * f + 3]);
    return sums;
  });
  const quantile = (values, q) => {
    const sorted = values.slice().sort((a, b) => a - b);
    return sorted.length ? sorted[Math.min(sorted.length - 1, Math.floor(q * sorted.length))] : 0;
  };
  const modeScale = Math.max(1.2 * quantile([].concat(...laneSums), 0.95), 1e-3);
  timeline.height = MAIN + LANE * rec.modes.length;
  if (rec.modes.length) MODE_PARTS.forEach((name, k) => {
    const span = document.createElement('span');
    span.innerHTML = '<i style="background:' + MODE_COLORS[k] + '"></i>mode lanes: ' + name;
    legend.appendChild(span);
  });
  report.modeLanes = rec.modes.length;
  function drawModeLanes(ctx, w, bar) {
    rec.modes.forEach((m, lane) => {
      const top = MAIN + LANE * lane, base = top + LANE - 4;
      ctx.fillStyle = '#23292f';
      ctx.fillRect(0, top, w, LANE - 2);
      const width = Math.max(bar - (bar > 3 ? 1 : 0), 1), room = LANE - 8;
      for (let f = 0; f < F; ++f) {
        let y = base;
        for (let k = 0; k < 4; ++k) {
          const hh = Math.min((m.times[4 * f + k] / modeScale) * room, y - (base - room));
          ctx.fillStyle = MODE_COLORS[k];
          ctx.fillRect(f * bar, y - hh, width, hh);
          y -= hh;
        }
        if (laneSums[lane][f] > modeScale) {
          ctx.fillStyle = '#e23b3b';
          ctx.fillRect(f * bar, base - room - 2, width, 2);
        }
      }
      ctx.fillStyle = '#d8dde3';
      ctx.font = '11px system-ui, sans-serif';
      ctx.fillText(m.name + ': render frame median ' + quantile(laneSums[lane], 0.5).toFixed(3) + ' ms, max ' +
                   Math.max(...laneSums[lane]).toFixed(3) + ' ms (lane height ' + modeScale.toFixed(3) + ' ms)', 4, top + 12);
    });
  }
  function drawTimeline() {
    const w = timeline.clientWidth || 800, h = MAIN;
    if (timeline.width !== w) timeline.width = w;
    const ctx = timeline.getContext('2d');
    ctx.fillStyle = '#1b1f24';
    ctx.fillRect(0, 0, w, timeline.height);
    const bar = w / Math.max(F, 1);
    drawModeLanes(ctx, w, bar);
    const plot = h - 14;
    for (let f = 0; f < F; ++f) {
      let y = plot;
      rec.frames[f].stageMs.forEach((ms, k) => {
        const hh = (ms / scaleMs) * (plot - 4);
        ctx.fillStyle = STAGE_COLORS[k % STAGE_COLORS.length];
        ctx.fillRect(f * bar, y - hh, Math.max(bar - (bar > 3 ? 1 : 0), 1), hh);
        y -= hh;
      });
    }
    // Frames that end with a body inside solid: a red mark on top.
    ctx.fillStyle = '#e23b3b';
    for (let f = 0; f < F; ++f) if (rec.frames[f].inside) ctx.fillRect(f * bar, 0, Math.max(bar, 2), 3);
    ctx.fillStyle = '#ffffff';
    ctx.fillRect(Math.max(shown, 0) * bar + bar / 2 - 1, 0, 2, plot);
    if (rec.modes.length) ctx.fillRect(Math.max(shown, 0) * bar + bar / 2 - 1, MAIN, 2, timeline.height - MAIN);
    ctx.fillStyle = '#9aa5b1';
    ctx.font = '11px system-ui, sans-serif';
    ctx.fillText('frame time, max ' + scaleMs.toFixed(2) + ' ms (click a frame to jump to it; red on top: a body inside solid)', 4, h - 2);
    report.timelineFrames = F;
  }
  timeline.addEventListener('click', (e) => {
    const rect = timeline.getBoundingClientRect();
    setFrame(Math.floor(((e.clientX - rect.left) / rect.width) * F));
  });

  // ---- camera: look at everything at the start ----
  const bounds = new THREE.Box3();
  const grow = (x, y, z) => bounds.expandByPoint(new THREE.Vector3(x, y, z));
  rec.bodies.forEach((b, i) => {
    pose.compose(p.set(...b.pos), q.set(...b.rot), s.set(1, 1, 1)).multiply(bodyShapeMatrix[i]);
    if (b.kind === 3) {
      const levels = rec.grids[b.ref].levels;
      const boxes = levels.length ? levels[0] : null;
      if (boxes) for (let o = 0; o < boxes.length; o += 6) {
        bounds.expandByPoint(new THREE.Vector3(boxes[o], boxes[o + 1], boxes[o + 2]).applyMatrix4(pose));
        bounds.expandByPoint(new THREE.Vector3(boxes[o + 3], boxes[o + 4], boxes[o + 5]).applyMatrix4(pose));
      }
    } else if (b.kind === 4) {
      const t = rec.terrains[b.ref];
      if (t) for (const versions of t.chunks.values()) {
        const v = versions[0].positions;
        for (let k = 0; k < v.length; k += 3 * 64) bounds.expandByPoint(new THREE.Vector3(v[k], v[k + 1], v[k + 2]).applyMatrix4(pose));
      }
    } else grow(...b.pos);
  });
  if (bounds.isEmpty()) grow(0, 0, 0);
  const centre = bounds.getCenter(new THREE.Vector3()), size = bounds.getSize(new THREE.Vector3()).length() || 10;
  controls.target.copy(centre);
  camera.position.copy(centre).add(new THREE.Vector3(0.55, -0.75, 0.45).multiplyScalar(size * 0.8));
  camera.near = Math.max(size * 1e-4, 0.01);
  camera.far = size * 20;
  camera.updateProjectionMatrix();
  controls.update();

  function resize() {
    const w = view.clientWidth || 800, h = view.clientHeight || 500;
    renderer.setSize(w, h);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
    drawTimeline();
    draw();
  }
  // Level of detail and culling, per cell of a grid drawn brick by brick: a cell out of the view
  // is not drawn; a cell (or a one-cell grid) whose bounds cover less than ~4% of the view's
  // height is drawn as its box (one-cell grids: their NODE level 3 boxes, at most 512). Then a
  // brick budget: the cells left are drawn brick by brick largest on screen first until their
  // bricks reach `budget`, the rest as boxes. The budget is #budget=N, else it follows the frame
  // rate while playing (adaptBudget).
  const lodSphere = new THREE.Sphere(), frustum = new THREE.Frustum(), viewProjection = new THREE.Matrix4();
  const cellMatrix = new THREE.Matrix4();
  const BUDGET_MIN = 20000, BUDGET_MAX = 8000000;
  const budgetText = new URLSearchParams(location.hash.slice(1)).get('budget');
  const asked = budgetText ? Number(budgetText) : NaN;
  const fixedBudget = Number.isFinite(asked) && asked >= 0;  // else (absent or not a count) it adapts
  let budget = fixedBudget ? asked : 500000;
  let budgetLimited = false;  // the last choice left cells as boxes for the budget alone
  const cellBricks = (grid, c) => grid.used[c][0] + grid.used[c][1] + grid.used[c][2] + grid.used[c][3];
  function chooseDetail() {
    camera.updateMatrixWorld();
    frustum.setFromMatrix(viewProjection.multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse));
    const tanHalf = Math.tan((camera.fov * Math.PI) / 360);
    const chosen = [], fine = [];
    bodyObjects.forEach((obj) => {
      if (!obj || obj.grid === undefined || !obj.group.visible) return;
      const grid = grids[obj.grid];
      if (!grid.source.hasBricks) return;
      const entry = { obj, grid, state: [] };
      grid.spheres.forEach((sphere, c) => {
        let size = Infinity;  // no bounds (an empty grid): drawn as it is
        if (sphere) {
          lodSphere.copy(sphere).applyMatrix4(obj.group.matrix);
          if (!frustum.intersectsSphere(lodSphere)) { entry.state.push('culled'); return; }
          size = lodSphere.radius / (Math.max(lodSphere.center.distanceTo(camera.position), 1e-6) * tanHalf);
          if (size < 0.04) { entry.state.push('coarse'); return; }
        }
        entry.state.push('fine');
        fine.push({ entry, c, size, bricks: cellBricks(grid, c) });
      });
      chosen.push(entry);
    });
    fine.sort((a, b) => b.size - a.size);
    let inFull = 0;
    budgetLimited = false;
    for (const f of fine) {
      // A cell with no box to stand in for it (a one-cell grid without NODE boxes) is drawn anyway.
      const standIn = f.entry.grid.cellBoxes || f.entry.grid.source.levels.length;
      if (inFull + f.bricks > budget && standIn && f.size !== Infinity) { f.entry.state[f.c] = 'coarse'; budgetLimited = true; }
      else inFull += f.bricks;
    }
    let coarseCells = 0, culledCells = 0, gridsAsBoxes = 0;
    for (const { obj, grid, state } of chosen) {
      for (const m of obj.meshes) m.visible = state[m.userData.cell] === 'fine';
      if (obj.cellBox) {
        const boxes = grid.cellBoxes, a = obj.cellBox.instanceMatrix.array;
        state.forEach((st, c) => {
          const o = 6 * c;
          if (st === 'coarse') {
            cellMatrix.makeScale(Math.max(boxes[o + 3] - boxes[o], 1e-4), Math.max(boxes[o + 4] - boxes[o + 1], 1e-4), Math.max(boxes[o + 5] - boxes[o + 2], 1e-4));
            cellMatrix.setPosition((boxes[o] + boxes[o + 3]) / 2, (boxes[o + 1] + boxes[o + 4]) / 2, (boxes[o + 2] + boxes[o + 5]) / 2);
            cellMatrix.toArray(a, 16 * c);
          } else a.fill(0, 16 * c, 16 * c + 16);
        });
        obj.cellBox.instanceMatrix.needsUpdate = true;
      } else if (state[0] === 'coarse') {
        if (!obj.lod) {
          obj.lod = nodeBoxMesh(obj.grid, Math.min(2, grid.source.levels.length - 1), obj.meshes.length ? obj.meshes[0].material : staticMaterial);
          if (obj.lod) { obj.lod.frustumCulled = false; obj.group.add(obj.lod); }
        }
        if (!obj.lod) for (const m of obj.meshes) m.visible = true;  // no boxes to stand in
      }
      if (obj.lod) obj.lod.visible = state[0] === 'coarse' && !obj.cellBox;
      gridsAsBoxes += !obj.cellBox && state[0] === 'coarse' && !!obj.lod;
      for (const st of state) { coarseCells += st === 'coarse'; culledCells += st === 'culled'; }
    }
    report.gridsAsBoxes = gridsAsBoxes;
    report.cellsAsBoxes = coarseCells;
    report.cellsCulled = culledCells;
    report.bricksInFull = inFull;
    report.brickBudget = budget;
  }
  // While playing, the budget follows the frame rate: the average time between frames above
  // 50 ms (under 20 fps) shrinks it, under 25 ms grows it again while it is what holds cells back.
  let frameInterval = 0;
  function adaptBudget(ms) {
    if (fixedBudget) return;
    frameInterval = frameInterval ? 0.8 * frameInterval + 0.2 * ms : ms;
    if (frameInterval > 50) budget = Math.max(BUDGET_MIN, Math.round(budget * 0.8));
    else if (frameInterval < 25 && budgetLimited) budget = Math.min(BUDGET_MAX, Math.round(budget * 1.2));
  }
  const status = document.getElementById('status');
  function draw() {
    chooseDetail();
    renderer.render(scene, camera);
    status.textContent = rec.bodies.length + ' bodies, ' + rec.grids.length + ' grids, ' + report.bricksDrawn + ' bricks, ' +
        report.bricksInFull + ' of them drawn brick by brick (budget ' + budget + (fixedBudget ? '' : ', follows the frame rate') +
        '); drag to orbit, wheel to zoom, right-drag to pan';
  }
  controls.addEventListener('change', draw);
  window.addEventListener('resize', resize);
  if (window.ResizeObserver) new ResizeObserver(resize).observe(view);

  // ---- playback ----
  const scrub = document.getElementById('scrub');
  scrub.max = Math.max(F - 1, 0);
  scrub.addEventListener('input', () => setFrame(Number(scrub.value)));
  let playing = false, last = 0, carry = 0;
  const playButton = document.getElementById('play');
  function tick(t) {
    if (!playing) return;
    carry += (t - last) / 1000;
    adaptBudget(t - last);
    last = t;
    const steps = Math.floor(carry / head.timestep);
    if (steps > 0) {
      carry -= steps * head.timestep;
      if (shown + steps >= F - 1) { setFrame(F - 1); togglePlay(); return; }
      setFrame(shown + steps);
    }
    requestAnimationFrame(tick);
  }
  function togglePlay() {
    playing = !playing;
    playButton.textContent = playing ? 'Pause' : 'Play';
    if (playing) {
      if (shown >= F - 1) setFrame(0);
      last = performance.now();
      carry = 0;
      requestAnimationFrame(tick);
    }
  }
  playButton.addEventListener('click', togglePlay);
  document.getElementById('back').addEventListener('click', () => setFrame(shown - 1));
  document.getElementById('forward').addEventListener('click', () => setFrame(shown + 1));
  document.getElementById('show-contacts').addEventListener('change', (e) => {
    contactLines.visible = e.target.checked;
    setFrame(shown);
  });
  window.addEventListener('keydown', (e) => {
    if (e.key === ' ') { togglePlay(); e.preventDefault(); }
    if (e.key === 'ArrowLeft') setFrame(shown - 1);
    if (e.key === 'ArrowRight') setFrame(shown + 1);
  });

  // Options in the address: #frame=N (or last), contacts, grid=G&depth=D.
  const params = new URLSearchParams(location.hash.slice(1));
  if (params.has('contacts')) { document.getElementById('show-contacts').checked = true; contactLines.visible = true; }
  if (params.has('grid')) { nodeSelect.value = params.get('grid'); nodeDepth.value = params.get('depth') || '3'; }
  const wanted = params.get('frame');
  resize();
  if (F > 0) setFrame(wanted === 'last' ? F - 1 : wanted ? Number(wanted) : 0);
  if (params.has('grid')) updateNodeOverlay();
  // #body=N: look at body N from a few of its sizes away (where did it end up?).
  if (params.has('body') && F > 0) focusBody(Number(params.get('body')));
  // #bench: the time of a draw, averaged over 20 (what the page costs a frame on this machine).
  if (params.has('bench')) {
    // A pixel read after each draw waits for the GPU (or the CPU's SwiftShader) to finish it.
    const gl = renderer.getContext(), pixel = new Uint8Array(4);
    const t0 = performance.now();
    for (let k = 0; k < 20; ++k) {
      draw();
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    }
    report.drawMs = (performance.now() - t0) / 20;
  }
  report.ready = true;
  writeReport();
}

try {
  main();
} catch (e) {
  report.errors.push('viewer: ' + (e && e.stack ? e.stack : String(e)));
  writeReport();
  document.getElementById('status').textContent = 'Could not show the recording: ' + e;
}
