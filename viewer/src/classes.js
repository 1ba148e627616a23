// Contact classes: their colours and which one wins when a surface is in several pairs.

export const CLASSES = ['penetrating', 'touching', 'clearance', 'containment'];

export const CLASS_COLOURS = {
  penetrating: 0xe0202a,
  touching: 0xff8c1a,
  clearance: 0xf2d21b,
  containment: 0x9b4dca,
};

// Selection colours of side A and side B (unlit, drawn on top of everything).
export const SELECTION_COLOURS = [0x1e90ff, 0x00d084];

// Colour of the surfaces in no reported pair (drawn translucent as context).
export const CONTEXT_COLOUR = 0xa9adb3;

// A surface in several pairs shows its most severe class.
const SEVERITY = { penetrating: 3, containment: 2, touching: 1, clearance: 0 };

export function moreSevere(a, b) {
  if (a === undefined) return b;
  return SEVERITY[b] > SEVERITY[a] ? b : a;
}

// What the distance column shows: a penetrating pair shows minus its crossing-depth estimate,
// like the command line table.
export function distanceText(pair) {
  if (pair.class === 'penetrating') return '-' + formatNumber(pair.penetration);
  return pair.distance === null ? '–' : formatNumber(pair.distance);
}

export function formatNumber(v) {
  if (v === null || v === undefined || !Number.isFinite(v)) return '–';
  if (v === 0) return '0';
  return Number(v.toPrecision(4)).toString();
}
