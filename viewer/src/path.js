// A path checked continuously (`check --path --continuous`), played at any time: where the moving
// instances are, and which surface pairs of the timeline are in contact then. Pure arithmetic on
// the page's "path" record (tools/html_path.cpp); no drawing here.
//
// Times are the path's step numbers. Between steps k and k + 1 the fraction s = (t - step_k) /
// (step_{k+1} - step_k) of the motion is done, and the pose is cadclash's interpolate_pose
// (collide/src/motion.cpp, trajectory.h "Motion between steps"): the screw of the displacement
// from a to b, its rotation a slerp along the shorter arc at constant angular speed, each point on
// a helix about the screw's axis. It is written here with the same steps (angle from atan2, not
// acos; the origin's drift across the axis) so that the page shows the pose the check placed, not
// a look-alike.

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

const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

// v turned by the unit quaternion q.
function rotate(q, v) {
  const u = [q[1], q[2], q[3]];
  const c1 = cross(u, v), c2 = cross(u, c1);
  return [0, 1, 2].map((k) => v[k] + 2 * q[0] * c1[k] + 2 * c2[k]);
}

// The pose at fraction s of the motion from a to b, each [tx, ty, tz, qw, qx, qy, qz].
export function interpolatePose(a, b, s) {
  const qa = a.slice(3, 7), qb = b.slice(3, 7);
  // The turn from a to b in a's frame: r = qa^-1 qb on the shorter arc (w >= 0).
  let r = multiply([qa[0], -qa[1], -qa[2], -qa[3]], qb);
  if (r[0] < 0) r = r.map((c) => -c);
  const v = Math.hypot(r[1], r[2], r[3]);
  const angle = 2 * Math.atan2(v, r[0]);
  const local = v > 0 ? [r[1] / v, r[2] / v, r[3] / v] : [1, 0, 0];
  const half = (s * angle) / 2;  // constant angular speed
  const step = [Math.cos(half), local[0] * Math.sin(half), local[1] * Math.sin(half), local[2] * Math.sin(half)];
  const q = normalized(multiply(qa, step));
  if (s === 0 || s === 1) return [...(s === 0 ? a : b).slice(0, 3), ...q];
  // The screw (motion.cpp, screw_of): its world axis, M's translation t = t_b - R t_a split along
  // and across it, and the drift of a's origin across it.
  const ta = a.slice(0, 3);
  const axis = rotate(qa, local);
  const whole = [Math.cos(angle / 2), ...axis.map((c) => c * Math.sin(angle / 2))];
  const turned = rotate(whole, ta);
  const t = [0, 1, 2].map((k) => b[k] - turned[k]);
  const along = dot(axis, t);
  const across = t.map((c, k) => c - along * axis[k]);
  const g = angle === 0 ? 2 : (angle * Math.cos(angle / 2)) / Math.sin(angle / 2);
  const ia = dot(axis, ta);
  const ac = cross(axis, across);
  const drift = [0, 1, 2].map((k) => angle * (ta[k] - ia * axis[k]) - 0.5 * angle * across[k] - 0.5 * g * ac[k]);
  const h = 0.5 * s * angle;
  const chord = angle === 0 ? s : (2 * Math.sin(h)) / angle;
  const ad = cross(axis, drift);
  const out = [0, 1, 2].map((k) => ta[k] + chord * (Math.cos(h) * ad[k] - Math.sin(h) * drift[k]) + s * along * axis[k]);
  return [...out, ...q];
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
    // The instances the path moves: those its rows place at poses that change from one step to the
    // next (a row may place an instance where it already is).
    this.moves = new Set(path.moving.filter((_, i) =>
      path.steps.some((st, k) => k > 0 && st.poses[i].some((c, j) => c !== path.steps[k - 1].poses[i][j]))));
    // Whether the pairs of two instances the path does not move are left out (timeline list and
    // colours): their contact lasts the whole path, and a review of a motion is about what moves.
    this.movingOnly = true;
  }

  // Whether timeline pair p has an instance the path moves.
  pairMoves(p) {
    const pair = this.path.pairs[p];
    return this.moves.has(pair.instance_a) || this.moves.has(pair.instance_b);
  }

  // Whether timeline pair p is shown (listed and coloured).
  shown(p) {
    return !this.movingOnly || this.pairMoves(p);
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

  // Per timeline surface pair shown, its state at time t: [{pair, surface, state}] for those not free.
  pairsAt(t) {
    const out = [];
    this.path.pairs.forEach((pair, p) => {
      if (!this.shown(p)) return;
      pair.surfaces.forEach((sp, k) => {
        const state = spanState(sp.spans, t);
        if (state) out.push({ pair: p, surface: k, state });
      });
    });
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
