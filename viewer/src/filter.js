// Which pairs the filter box and the class toggles leave in the table.
//
// A query is whitespace-separated terms ("quoted text" is one term); a pair is listed when every
// term matches one of its two sides. A term matches a side when it is a substring (ignoring case)
// of the instance path, the part name, the surface name or the file's own name for the surface, or
// "#<step id>"; a term "#425" (a hash and digits only) matches STEP id 425 exactly, not #4250.
//
// Matching works on the few distinct instances and surfaces rather than on the pairs: per term,
// one flag per instance and per surface, then four look-ups per pair. 60 000 pairs filter in about
// a millisecond, and nothing is precomputed per pair.
import { CLASSES } from './classes.js';

export function parseQuery(text) {
  const terms = [];
  for (const m of String(text).matchAll(/"([^"]*)"?|(\S+)/g)) {
    const term = (m[1] ?? m[2]).toLowerCase();
    if (!term) continue;
    const id = /^#(\d+)$/.exec(term);
    terms.push(id ? { stepId: Number(id[1]) } : { text: term });
  }
  return terms;
}

export class PairFilter {
  constructor(data) {
    this.data = data;
    this.instanceText = null;  // lower-case searchable text, built on first use
    this.surfaceText = null;
  }

  texts() {
    if (this.instanceText) return;
    const { instances, parts, surfaces } = this.data;
    // "\n" separates fields so that a term never matches across two of them.
    this.instanceText = instances.map((inst) => `${inst.path}\n${parts[inst.part].name}`.toLowerCase());
    this.surfaceText = surfaces.map((s) =>
      `${s.name}\n${s.source_name ?? ''}\n${s.step_id !== undefined ? '#' + s.step_id : ''}`.toLowerCase());
  }

  // Per term, which instances and surfaces match it.
  termFlags(term) {
    const { surfaces } = this.data;
    const inst = new Uint8Array(this.data.instances.length);
    const surf = new Uint8Array(surfaces.length);
    if (term.stepId !== undefined) {
      surfaces.forEach((s, i) => { if (s.step_id === term.stepId) surf[i] = 1; });
    } else {
      this.instanceText.forEach((t, i) => { if (t.includes(term.text)) inst[i] = 1; });
      this.surfaceText.forEach((t, i) => { if (t.includes(term.text)) surf[i] = 1; });
    }
    return { inst, surf };
  }

  // Returns the listed pair indices (ascending, as in the report) and, per class, how many pairs
  // match the query (whether or not the class is shown: the toggles show what they would add).
  apply(query, shownClasses) {
    const pairs = this.data.pairs;
    const terms = parseQuery(query);
    if (terms.length) this.texts();
    const flags = terms.map((t) => this.termFlags(t));
    const counts = Object.fromEntries(CLASSES.map((c) => [c, 0]));
    const listed = new Uint32Array(pairs.length);
    let n = 0;
    for (let i = 0; i < pairs.length; ++i) {
      const p = pairs[i];
      let match = true;
      for (const { inst, surf } of flags) {
        if (!(inst[p.instance_a] || inst[p.instance_b] ||
              (p.surface_a >= 0 && surf[p.surface_a]) || (p.surface_b >= 0 && surf[p.surface_b]))) {
          match = false;
          break;
        }
      }
      if (!match) continue;
      counts[p.class] = (counts[p.class] || 0) + 1;
      if (shownClasses[p.class] !== false) listed[n++] = i;
    }
    return { indices: listed.subarray(0, n), counts };
  }
}
