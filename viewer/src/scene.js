// Builds the three.js scene of a report: every part's triangles once, placed by its instances.
//
// Draw calls stay few for big assemblies: the context (all surfaces, translucent grey) is one
// InstancedMesh per part, and the highlighted surfaces are one InstancedMesh per (surface, class)
// that share the part's vertex and index buffers through a draw range.
import * as THREE from 'three';
import { decodeFloat32, decodeIndices } from './decode.js';
import { CLASS_COLOURS, CONTEXT_COLOUR, SELECTION_COLOURS, moreSevere } from './classes.js';

function partGeometry(part) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(decodeFloat32(part.positions), 3));
  g.setIndex(new THREE.BufferAttribute(decodeIndices(part.indices, part.index_bytes), 1));
  // Each surface has its own vertices, so smooth normals never blend across a CAD face edge.
  g.computeVertexNormals();
  g.computeBoundingBox();
  g.computeBoundingSphere();
  return g;
}

// A view of one surface: the part's buffers, restricted to the surface's triangles.
function surfaceGeometry(partGeom, surface) {
  const g = new THREE.BufferGeometry();
  g.setIndex(partGeom.index);
  g.setAttribute('position', partGeom.getAttribute('position'));
  g.setAttribute('normal', partGeom.getAttribute('normal'));
  g.setDrawRange(surface.first_triangle * 3, surface.triangle_count * 3);
  g.boundingSphere = partGeom.boundingSphere;
  return g;
}

// Part-local box of a surface's triangles (empty box when it has none).
function surfaceBox(partGeom, surface) {
  const box = new THREE.Box3();
  const pos = partGeom.getAttribute('position');
  const idx = partGeom.index.array;
  const v = new THREE.Vector3();
  const end = (surface.first_triangle + surface.triangle_count) * 3;
  for (let i = surface.first_triangle * 3; i < end; ++i) box.expandByPoint(v.fromBufferAttribute(pos, idx[i]));
  return box;
}

function instanceMatrix(instance) {
  return new THREE.Matrix4().fromArray(instance.matrix);  // column-major, like the writer
}

export class ClashScene {
  constructor(data) {
    this.data = data;
    this.root = new THREE.Group();
    this.parts = data.parts.map((p) => (p.triangle_count > 0 ? partGeometry(p) : null));
    this.matrices = data.instances.map(instanceMatrix);
    this.surfaceGeoms = new Map();
    this.surfaceBoxes = new Map();
    this.triangles = 0;  // triangles drawn once per instance (what the GPU sees)
    this.drawCalls = 0;

    this.contextMaterial = new THREE.MeshLambertMaterial({
      color: CONTEXT_COLOUR, transparent: true, opacity: 0.3, depthWrite: false, side: THREE.DoubleSide,
      // Pushed back so a highlighted surface, drawn on the very same triangles, always wins.
      polygonOffset: true, polygonOffsetFactor: 2, polygonOffsetUnits: 2,
    });
    this.classMaterials = {};
    for (const [name, colour] of Object.entries(CLASS_COLOURS))
      this.classMaterials[name] = new THREE.MeshLambertMaterial({ color: colour, side: THREE.DoubleSide });
    this.selectionMaterials = SELECTION_COLOURS.map((colour) => new THREE.MeshBasicMaterial({
      color: colour, side: THREE.DoubleSide, depthTest: false, depthWrite: false,
    }));

    this.buildContext();
    this.buildHighlights();
    this.selection = new THREE.Group();
    this.selection.renderOrder = 10;
    this.root.add(this.selection);
  }

  buildContext() {
    this.context = new THREE.Group();
    const byPart = new Map();
    this.data.instances.forEach((inst, i) => {
      if (!byPart.has(inst.part)) byPart.set(inst.part, []);
      byPart.get(inst.part).push(i);
    });
    this.contextSlots = new Map();  // instance -> [its part's context mesh, its index there]
    for (const [part, instances] of byPart) {
      const g = this.parts[part];
      if (!g) continue;
      const mesh = new THREE.InstancedMesh(g, this.contextMaterial, instances.length);
      instances.forEach((inst, k) => {
        mesh.setMatrixAt(k, this.matrices[inst]);
        this.contextSlots.set(inst, [mesh, k]);
      });
      mesh.computeBoundingSphere();
      this.context.add(mesh);
      this.triangles += (g.index.count / 3) * instances.length;
      ++this.drawCalls;
    }
    this.root.add(this.context);
  }

  // Containment pairs name whole instances; the inner one is the instance whose world box lies
  // in the other's (the containment test requires exactly that), and all its surfaces are marked.
  innerInstances(pair) {
    const a = this.instanceBox(pair.instance_a), b = this.instanceBox(pair.instance_b);
    const inner = [];
    if (b.containsBox(a)) inner.push(pair.instance_a);
    if (a.containsBox(b)) inner.push(pair.instance_b);
    return inner.length ? inner : [pair.instance_a, pair.instance_b];
  }

  // Calls mark(instance, surface) for every surface a pair colours.
  forPairSurfaces(index, mark) {
    const p = this.data.pairs[index];
    if (p.class === 'containment' && (p.surface_a < 0 || p.surface_b < 0)) {
      if (!this.inner.has(index)) this.inner.set(index, this.innerInstances(p));
      for (const inst of this.inner.get(index)) {
        const part = this.data.parts[this.data.instances[inst].part];
        for (let s = 0; s < part.surface_count; ++s) mark(inst, part.first_surface + s);
      }
      return;
    }
    mark(p.instance_a, p.surface_a);
    mark(p.instance_b, p.surface_b);
  }

  buildHighlights() {
    this.inner = new Map();  // containment pair -> its inner instances
    // Most severe class per (instance, surface).
    const worst = new Map();
    this.data.pairs.forEach((p, i) => this.forPairSurfaces(i, (instance, surface) => {
      const key = instance + ':' + surface;
      worst.set(key, moreSevere(worst.get(key), p.class));
    }));
    // Group by (surface, class) so instances of one part share a draw call.
    const groups = new Map();
    for (const [key, cls] of worst) {
      const [inst, surf] = key.split(':').map(Number);
      const gkey = surf + ':' + cls;
      if (!groups.has(gkey)) groups.set(gkey, { surface: surf, cls, instances: [] });
      groups.get(gkey).instances.push(inst);
    }
    this.highlights = new THREE.Group();
    for (const { surface, cls, instances } of groups.values()) {
      const g = this.surfaceGeometry(surface);
      if (!g) continue;
      // A class this viewer does not know is drawn like undecided (moreSevere ranks it so too).
      const material = this.classMaterials[cls] ?? this.classMaterials.undecided;
      const mesh = new THREE.InstancedMesh(g, material, instances.length);
      instances.sort((x, y) => x - y).forEach((inst, k) => mesh.setMatrixAt(k, this.matrices[inst]));
      mesh.computeBoundingSphere();
      mesh.userData = { surface, instances, cls };
      this.highlights.add(mesh);
      ++this.drawCalls;
    }
    this.root.add(this.highlights);
  }

  // How many (instance, surface) are coloured in each class (tests/viewer compares it to the report).
  highlightCounts() {
    const counts = {};
    for (const mesh of this.highlights.children)
      counts[mesh.userData.cls] = (counts[mesh.userData.cls] || 0) + mesh.userData.instances.length;
    return counts;
  }

  // Colours only the surfaces of the listed pairs (null: all); the others are drawn as context.
  // An unlisted copy is scaled to nothing rather than removed, so the buffers keep their size.
  // A surface keeps the colour of its most severe pair, listed or not.
  showOnly(listed) {
    if (listed === null && !this.filtered) return;
    const surfaces = this.data.surfaces.length + 1;  // + 1: surface -1 (whole part) maps to 0
    let keep = null;
    if (listed !== null) {
      keep = new Set();
      for (const i of listed) this.forPairSurfaces(i, (inst, surf) => keep.add(inst * surfaces + surf + 1));
    }
    const hidden = new THREE.Matrix4().makeScale(0, 0, 0);
    for (const mesh of this.highlights.children) {
      const { surface, instances } = mesh.userData;
      let shown = 0;
      instances.forEach((inst, k) => {
        const on = keep === null || keep.has(inst * surfaces + surface + 1);
        mesh.setMatrixAt(k, on ? this.matrices[inst] : hidden);
        if (on) ++shown;
      });
      mesh.instanceMatrix.needsUpdate = true;
      mesh.visible = shown > 0;
    }
    this.filtered = listed !== null;
  }

  surfaceGeometry(surfaceId) {
    if (this.surfaceGeoms.has(surfaceId)) return this.surfaceGeoms.get(surfaceId);
    const s = this.data.surfaces[surfaceId];
    const pg = this.parts[s.part];
    const g = pg && s.triangle_count > 0 ? surfaceGeometry(pg, s) : null;
    this.surfaceGeoms.set(surfaceId, g);
    return g;
  }

  // World box of one instance's surface, or of the whole instance when surfaceId < 0.
  worldBox(instanceId, surfaceId) {
    if (surfaceId < 0) return this.instanceBox(instanceId);
    if (!this.surfaceBoxes.has(surfaceId)) {
      const s = this.data.surfaces[surfaceId];
      const pg = this.parts[s.part];
      this.surfaceBoxes.set(surfaceId, pg ? surfaceBox(pg, s) : new THREE.Box3());
    }
    return this.surfaceBoxes.get(surfaceId).clone().applyMatrix4(this.matrices[instanceId]);
  }

  instanceBox(instanceId) {
    const g = this.parts[this.data.instances[instanceId].part];
    return g ? g.boundingBox.clone().applyMatrix4(this.matrices[instanceId]) : new THREE.Box3();
  }

  sceneBox() {
    const box = new THREE.Box3();
    this.data.instances.forEach((_, i) => box.union(this.instanceBox(i)));
    return box;
  }

  // Shows side A and side B of a pair in the selection colours, on top of everything.
  select(pair) {
    this.selection.clear();
    if (!pair) return;
    const sides = [[pair.instance_a, pair.surface_a], [pair.instance_b, pair.surface_b]];
    sides.forEach(([inst, surf], k) => {
      const g = surf >= 0 ? this.surfaceGeometry(surf) : this.parts[this.data.instances[inst].part];
      if (!g) return;
      const mesh = new THREE.Mesh(g, this.selectionMaterials[k]);
      mesh.matrixAutoUpdate = false;
      mesh.matrix.copy(this.matrices[inst]);
      mesh.renderOrder = 10 + k;
      mesh.userData.side = k;
      mesh.userData.instance = inst;
      mesh.frustumCulled = false;
      this.selection.add(mesh);
    });
  }

  // Which layers are drawn: the pixel checks of the test draw one selected side alone. With a time
  // slider (timeline.js) its layer takes the place of the class highlights.
  setLayers({ context = true, highlights = true, sides = [true, true] } = {}) {
    this.context.visible = context;
    this.highlights.visible = highlights && !this.timeLayer;
    if (this.timeLayer) this.timeLayer.visible = highlights;
    this.selection.children.forEach((m) => { m.visible = sides[m.userData.side] !== false; });
  }

  // A layer drawn instead of the class highlights (the time slider's); hides them.
  replaceHighlights(layer) {
    this.timeLayer = layer;
    this.root.add(layer);
    this.highlights.visible = false;
  }

  // Places an instance (a path's moving one) at a new world matrix: its context copy, its class
  // highlights (a copy the filter hides stays hidden) and its selected sides follow.
  moveInstance(instance, matrix) {
    this.matrices[instance].copy(matrix);
    const slot = this.contextSlots.get(instance);
    if (slot) {
      slot[0].setMatrixAt(slot[1], matrix);
      slot[0].instanceMatrix.needsUpdate = true;
      slot[0].computeBoundingSphere();
    }
    const m = new THREE.Matrix4();
    for (const mesh of this.highlights.children) {
      const k = mesh.userData.instances.indexOf(instance);
      if (k < 0) continue;
      mesh.getMatrixAt(k, m);
      if (m.elements[0] === 0 && m.elements[1] === 0 && m.elements[2] === 0) continue;  // scaled to nothing: filtered out
      mesh.setMatrixAt(k, matrix);
      mesh.instanceMatrix.needsUpdate = true;
      mesh.computeBoundingSphere();
    }
    for (const mesh of this.selection.children)
      if (mesh.userData.instance === instance) mesh.matrix.copy(matrix);
  }

  // The world matrix an instance is drawn with (its context copy's; tests/viewer reads it).
  drawnMatrix(instance) {
    const slot = this.contextSlots.get(instance);
    const m = new THREE.Matrix4();
    if (slot) slot[0].getMatrixAt(slot[1], m);
    return m;
  }
}
