// The legend, the class toggles above the table and the selection panel (plain DOM).
import { CLASSES, formatNumber, intervalText } from './classes.js';

export function escapeHtml(text) {
  return String(text).replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' })[c]);
}

// "#123" for a STEP face, else the file's own name for it, else the surface name.
export function surfaceLabel(surface) {
  if (!surface) return '(whole part)';
  if (surface.step_id !== undefined) return '#' + surface.step_id;
  return surface.source_name || surface.name;
}

// The colour key over the 3D view, with the box that hides the grey context. `keys` ([css class,
// label]) replaces the classes: the time slider colours contact states instead.
export function fillLegend(legend, onChange, keys = CLASSES.map((c) => [c, c])) {
  const items = keys.map(([c, label]) => `<span class="${c}"><span class="chip"></span>${escapeHtml(label)}</span>`);
  items.push('<label><input type="checkbox" id="show-context" checked>other surfaces</label>');
  items.push('<span><span class="chip selA"></span>A</span><span><span class="chip selB"></span>B</span>');
  legend.innerHTML = items.join('');
  legend.addEventListener('change', (e) => {
    if (e.target.id === 'show-context') onChange({ context: e.target.checked });
  });
}

// One checkbox per class above the table; onChange(shown) gets {class: checked}.
export function fillClassToggles(box, onChange) {
  box.innerHTML = CLASSES.map((c) =>
    `<label class="${c}" title="list ${c} pairs"><input type="checkbox" data-class="${c}" checked>` +
    `<span class="chip"></span>${c} <span class="count" data-count="${c}"></span></label>`).join('');
  box.addEventListener('change', () => {
    const shown = {};
    for (const input of box.querySelectorAll('input[data-class]')) shown[input.dataset.class] = input.checked;
    onChange(shown);
  });
}

// How many pairs of each class match the filter text.
export function showClassCounts(box, counts) {
  for (const c of CLASSES) box.querySelector(`[data-count="${c}"]`).textContent = (counts[c] || 0).toLocaleString('en');
}

// "0.01 mm (declared)": the side's model uncertainty and where it came from.
function uncertaintyText(eps, source) {
  if (eps === undefined) return '–';
  return formatNumber(eps) + ' mm' + (source ? ` (${source})` : '');
}

function sideRows(data, label, instanceId, surfaceId, eps, source) {
  const inst = data.instances[instanceId];
  const part = data.parts[inst.part];
  const s = surfaceId >= 0 ? data.surfaces[surfaceId] : null;
  const cls = label === 'A' ? 'selA' : 'selB';
  const rows = [
    [`<span class="chip ${cls}"></span>${label} STEP id`, s && s.step_id !== undefined ? '#' + s.step_id : '–', 'step'],
    ['surface', s ? s.name + (s.source_name ? ` (${s.source_name})` : '') : '(whole part)', 'surface'],
    ['kind', s ? s.kind : '–', 'kind'],
    ['uncertainty ε', s ? uncertaintyText(eps, source) : '–', 'uncertainty'],
    ['part', part.name, 'part'],
    ['instance', inst.path, 'path'],
  ];
  return rows.map(([k, v, field]) =>
    `<tr><td>${k.startsWith('<') ? k : escapeHtml(k)}</td><td data-field="${label.toLowerCase()}-${field}">${escapeHtml(v)}</td></tr>`).join('');
}

// Shows what a CAD user needs to find the two faces: STEP ids, part names, instance paths; and
// what decided the class, with the proven interval of the exact face distance.
export function showSelection(panel, data, index) {
  const p = data.pairs[index];
  const extra = [];
  if (p.class === 'penetrating') extra.push(`crossing depth ${formatNumber(p.penetration)} mm`);
  if (p.intersecting) extra.push('triangles intersect');
  panel.innerHTML =
    `<table><tr><td>pair</td><td data-field="index">${index + 1}</td></tr>` +
    `<tr><td>class</td><td data-field="class"><span class="chip ${escapeHtml(p.class)}"></span>${escapeHtml(p.class)}</td></tr>` +
    `<tr><td>decided by</td><td data-field="decided-by">${escapeHtml(p.decided_by ?? '–')}</td></tr>` +
    `<tr><td>distance</td><td data-field="distance">${p.distance === null ? '–' : formatNumber(p.distance) + ' mm'}` +
    `${extra.length ? ' <span class="muted">(' + extra.join(', ') + ')</span>' : ''}</td></tr>` +
    `<tr><td>exact distance in</td><td data-field="interval">${intervalText(p)}</td></tr>` +
    `<tr><td>contact within</td><td data-field="within">${escapeHtml(p.contact_within ?? '–')}</td></tr>` +
    sideRows(data, 'A', p.instance_a, p.surface_a, p.uncertainty_a, p.uncertainty_source_a) +
    sideRows(data, 'B', p.instance_b, p.surface_b, p.uncertainty_b, p.uncertainty_source_b) + '</table>';
}
