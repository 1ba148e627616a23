// The time slider's 3D layer: the surfaces the timeline has in contact at the shown time, in
// their own colours (they replace the class colours of the last step's check, which say nothing
// about other times).
//
// One mesh per (instance, surface) the timeline names, shown or hidden and recoloured per time:
// a timeline lists only the surfaces that may touch somewhere on the path, a few per contact, so
// this stays a few draw calls where the class highlights need instancing for thousands.
import * as THREE from 'three';
import { TIME_COLOURS } from './classes.js';

export class TimelineLayer extends THREE.Group {
  constructor(clash, player) {
    super();
    this.clash = clash;
    this.materials = Object.fromEntries(Object.entries(TIME_COLOURS).map(([state, colour]) =>
      [state, new THREE.MeshLambertMaterial({ color: colour, side: THREE.DoubleSide })]));
    this.meshes = new Map();  // "instance:surface" -> mesh
    for (const pair of player.path.pairs)
      for (const sp of pair.surfaces)
        for (const [inst, surf] of [...player.sideSurfaces(pair.instance_a, sp.surface_a),
                                    ...player.sideSurfaces(pair.instance_b, sp.surface_b)]) {
          const key = inst + ':' + surf;
          const g = clash.surfaceGeometry(surf);
          if (this.meshes.has(key) || !g) continue;
          const mesh = new THREE.Mesh(g, this.materials.contact);
          mesh.matrixAutoUpdate = false;
          mesh.frustumCulled = false;  // it moves; its part's bounding sphere is not its place
          mesh.visible = false;
          mesh.userData = { instance: inst, surface: surf, state: null };
          this.meshes.set(key, mesh);
          this.add(mesh);
        }
  }

  // Colours the surfaces of `states` ("instance:surface" -> state, path.js) at their instances'
  // current places; hides the others.
  show(states) {
    for (const [key, mesh] of this.meshes) {
      const state = states.get(key) ?? null;
      mesh.userData.state = state;
      mesh.visible = state !== null;
      if (!state) continue;
      mesh.material = this.materials[state];
      mesh.matrix.copy(this.clash.matrices[mesh.userData.instance]);
    }
  }

  // What is drawn coloured: [{instance, surface, state, colour}] (tests/viewer checks it).
  drawn() {
    const out = [];
    for (const mesh of this.meshes.values())
      if (mesh.visible)
        out.push({ instance: mesh.userData.instance, surface: mesh.userData.surface, state: mesh.userData.state,
                   colour: mesh.material.color.getHex(), matrix: [...mesh.matrix.elements] });
    return out;
  }
}
