// Contact classes: their colours and which one wins when a surface is in several pairs.

// undecided: nothing could prove the exact faces in contact or apart (see collide.h, "Certified
// decisions"); it may be a contact, so it is drawn in a loud magenta of its own.
export const CLASSES = ['penetrating', 'touching', 'clearance', 'containment', 'undecided'];

export const CLASS_COLOURS = {
  penetrating: 0xe0202a,
  touching: 0xff8c1a,
  clearance: 0xf2d21b,
  containment: 0x9b4dca,
  undecided: 0xf032e6,
};

// Selection colours of side A and side B (unlit, drawn on top of everything).
export const SELECTION_COLOURS = [0x1e90ff, 0x00d084];

// Colour of the surfaces in no reported pair (drawn translucent as context).
export const CONTEXT_COLOUR = 0xa9adb3;

// A surface in several pairs shows its most severe class. An undecided pair may be a contact the
// triangles could not prove: it must stay visible over touching (a class this viewer does not know
// counts as undecided).
const SEVERITY = { penetrating: 4, containment: 3, undecided: 2, touching: 1, clearance: 0 };
const severity = (c) => SEVERITY[c] ?? SEVERITY.undecided;

export function moreSevere(a, b) {
  if (a === undefined) return b;
  return severity(b) > severity(a) ? b : a;
}

// What the distance column shows: a penetrating pair shows minus its crossing-depth estimate,
// like the command line table.
export function distanceText(pair) {
  if (pair.class === 'penetrating') return '-' + formatNumber(pair.penetration);
  return pair.distance === null ? '–' : formatNumber(pair.distance);
}

// The proven interval of the exact face distance, "[lo, hi] mm"; an unbounded end (null in the
// data: infinity) shows ∞, a missing interval '–'.
export function intervalText(pair) {
  const iv = pair.distance_interval;
  if (!Array.isArray(iv) || iv.length !== 2) return '–';
  const end = (v) => (v === null ? '∞' : formatNumber(v));
  return `[${end(iv[0])}, ${end(iv[1])}] mm`;
}

export function formatNumber(v) {
  if (v === null || v === undefined || !Number.isFinite(v)) return '–';
  if (v === 0) return '0';
  return Number(v.toPrecision(4)).toString();
}

// The time slider's colours (timeline.js): a surface pair of the timeline whose span holds the
// shown time is in contact there (the span was proved in contact at both ends) or may begin, end or
// hold a contact there (a narrow span proved neither way; drawn like undecided, for the same reason).
export const TIME_STATES = ['contact', 'may'];
export const TIME_COLOURS = { contact: 0xff8c1a, may: 0xf032e6 };
export const TIME_LABELS = { contact: 'in contact', may: 'contact may begin or end here (not proved)' };
