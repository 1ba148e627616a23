// A path checked continuously (`check --path --continuous`), played at any time: where the moving
// instances are, and which surface pairs of the timeline are in contact then. Pure arithmetic on
// the page's "path" record (tools/html_path.cpp); no drawing here.
//
// Times are the path's step numbers. Between steps k and k + 1 the fraction s = (t - step_k) /
// (step_{k+1} - step_k) of the motion is done, and the pose is cadclash's interpolate_pose
// (collide/src/motion.cpp, trajectory.h "Motion between steps"): translation linear, rotation
// slerp along the shorter arc at constant angular speed. It is written here with the same steps
// (angle from atan2, not acos) so that the page shows the pose the check placed, not a look-alike.

// Quaternions are [w, x, y, z].
function multiply(a, b) {
  const [aw, ax, ay, az] = a, [bw, bx, by, bz] = b;
  return [
    aw * bw - ax * bx - ay * by - az * bz,
    aw * bx + ax * bw + ay * bz - az * by,
    aw * by - ax * bz + ay * bw + az * bx,
    aw * bz + ax * by - ay * bx + az * bw,
  ];
}

function normalized(q) {
  const n = Math.hypot(q[0], q[1], q[2], q[3]);
  return q.map((c) => c / n);
}

// The pose at fraction s of the motion from a to b, each [tx, ty, tz, qw, qx, qy, qz].
export function interpolatePose(a, b, s) {
  const qa = a.slice(3, 7), qb = b.slice(3, 7);
  // The turn from a to b in a's frame: r = qa^-1 qb on the shorter arc (w >= 0).
  let r = multiply([qa[0], -qa[1], -qa[2], -qa[3]], qb);
  if (r[0] < 0) r = r.map((c) => -c);
  const v = Math.hypot(r[1], r[2], r[3]);
  const angle = 2 * Math.atan2(v, r[0]);
  const axis = v > 0 ? [r[1] / v, r[2] / v, r[3] / v] : [1, 0, 0];
  const half = (s * angle) / 2;  // constant angular speed
  const step = [Math.cos(half), axis[0] * Math.sin(half), axis[1] * Math.sin(half), axis[2] * Math.sin(half)];
  const q = normalized(multiply(qa, step));
  const t = [0, 1, 2].map((k) => (1 - s) * a[k] + s * b[k]);
  return [...t, ...q];
}

// Column-major 4x4 matrix (three.js's Matrix4.elements order) of a pose [t, q].
export function poseMatrix(p) {
  const [tx, ty, tz, w, x, y, z] = p;
  return [
    1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y), 0,
    2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x), 0,
    2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y), 0,
    tx, ty, tz, 1,
  ];
}

// What a span says about the time it contains: proved in contact at both ends, or a narrow span
// where a contact may begin, end or hold (not proved either way).
export const CONTACT = 'contact';
export const MAY = 'may';

// The state of a list of spans [t0, t1, contact_at_ends] at time t: CONTACT, MAY or null (free:
// between spans nothing is in contact). Where a narrow span meets a contact span, contact wins.
export function spanState(spans, t) {
  let state = null;
  for (const [t0, t1, ends] of spans) {
    if (t < t0 || t > t1) continue;
    if (ends) return CONTACT;
    state = MAY;
  }
  return state;
}

export class PathPlayer {
  constructor(path, data) {
    this.path = path;
    this.data = data;
    this.steps = path.steps.map((s) => s.step);
    this.first = this.steps[0];
    this.last = this.steps[this.steps.length - 1];
  }

  // The stretch of time t: [k, s] with steps[k] <= t and s the fraction done towards step k + 1
  // (at or past the last step: the last step, s = 0).
  stretchAt(t) {
    const n = this.steps.length;
    if (!(t > this.first)) return [0, 0];
    if (t >= this.last) return [n - 1, 0];
    let lo = 0, hi = n - 1;  // steps[lo] <= t < steps[hi]
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (this.steps[mid] <= t) lo = mid;
      else hi = mid;
    }
    return [lo, (t - this.steps[lo]) / (this.steps[lo + 1] - this.steps[lo])];
  }

  // Each moving instance's pose at time t: [{instance, pose: [tx, ty, tz, qw, qx, qy, qz]}].
  posesAt(t) {
    const [k, s] = this.stretchAt(t);
    const at = this.path.steps[k].poses, next = this.path.steps[Math.min(k + 1, this.steps.length - 1)].poses;
    return this.path.moving.map((instance, i) => ({ instance, pose: s > 0 ? interpolatePose(at[i], next[i], s) : at[i] }));
  }

  // Per timeline surface pair, its state at time t: [{pair, surface, state}] for those not free.
  pairsAt(t) {
    const out = [];
    this.path.pairs.forEach((pair, p) => pair.surfaces.forEach((sp, k) => {
      const state = spanState(sp.spans, t);
      if (state) out.push({ pair: p, surface: k, state });
    }));
    return out;
  }

  // Every (instance, surface) a timeline side names, as [instance, surface] (a whole-part side,
  // surface -1, names each surface of its part).
  sideSurfaces(instance, surface) {
    if (surface >= 0) return [[instance, surface]];
    const part = this.data.parts[this.data.instances[instance].part];
    return Array.from({ length: part.surface_count }, (_, k) => [instance, part.first_surface + k]);
  }

  // The state of each coloured surface at time t, by "instance:surface". A surface in contact in
  // one pair and possibly in another is in contact: CONTACT wins.
  surfacesAt(t) {
    const states = new Map();
    for (const { pair, surface, state } of this.pairsAt(t)) {
      const ip = this.path.pairs[pair], sp = ip.surfaces[surface];
      for (const [inst, surf] of [...this.sideSurfaces(ip.instance_a, sp.surface_a), ...this.sideSurfaces(ip.instance_b, sp.surface_b)]) {
        const key = inst + ':' + surf;
        if (states.get(key) !== CONTACT) states.set(key, state);
      }
    }
    return states;
  }
}
