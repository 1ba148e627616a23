// The pair table and the selection panel (plain DOM).
import { CLASSES, distanceText, formatNumber } from './classes.js';

export function escapeHtml(text) {
  return String(text).replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' })[c]);
}

// "#123" for a STEP face, else the file's own name for it, else the surface name.
export function surfaceLabel(surface) {
  if (!surface) return '(whole part)';
  if (surface.step_id !== undefined) return '#' + surface.step_id;
  return surface.source_name || surface.name;
}

function sideCell(data, instanceId, surfaceId) {
  const inst = data.instances[instanceId];
  const part = data.parts[inst.part];
  const surface = surfaceId >= 0 ? data.surfaces[surfaceId] : null;
  return `<b>${escapeHtml(surfaceLabel(surface))}</b> ${escapeHtml(part.name)}<br>` +
         `<span class="muted">${escapeHtml(inst.path)}</span>`;
}

// Fills the table body in one go (a string is far faster than nodes for thousands of rows).
export function fillTable(tbody, data) {
  const rows = data.pairs.map((p, i) =>
    `<tr class="${p.class}" data-index="${i}"><td class="num">${i + 1}</td>` +
    `<td class="cls"><span class="chip"></span>${p.class}</td><td class="num">${distanceText(p)}</td>` +
    `<td>${sideCell(data, p.instance_a, p.surface_a)}</td><td>${sideCell(data, p.instance_b, p.surface_b)}</td></tr>`);
  tbody.innerHTML = rows.join('');
}

// Legend with one checkbox per class that hides that class's rows.
export function fillLegend(legend, table, counts, onChange) {
  const items = CLASSES.map((c) =>
    `<label class="${c}"><input type="checkbox" data-class="${c}" checked><span class="chip"></span>${c} (${counts[c] || 0})</label>`);
  items.push('<label><input type="checkbox" id="show-context" checked>other surfaces</label>');
  items.push('<label><span class="chip selA"></span>A</label><label><span class="chip selB"></span>B</label>');
  legend.innerHTML = items.join('');
  legend.addEventListener('change', (e) => {
    const cls = e.target.dataset.class;
    if (cls) table.classList.toggle('hide-' + cls, !e.target.checked);
    else if (e.target.id === 'show-context') onChange({ context: e.target.checked });
  });
}

function sideRows(data, label, instanceId, surfaceId) {
  const inst = data.instances[instanceId];
  const part = data.parts[inst.part];
  const s = surfaceId >= 0 ? data.surfaces[surfaceId] : null;
  const cls = label === 'A' ? 'selA' : 'selB';
  const rows = [
    [`<span class="chip ${cls}"></span>${label} STEP id`, s && s.step_id !== undefined ? '#' + s.step_id : '–', 'step'],
    ['surface', s ? s.name + (s.source_name ? ` (${s.source_name})` : '') : '(whole part)', 'surface'],
    ['kind', s ? s.kind : '–', 'kind'],
    ['part', part.name, 'part'],
    ['instance', inst.path, 'path'],
  ];
  return rows.map(([k, v, field]) =>
    `<tr><td>${k.startsWith('<') ? k : escapeHtml(k)}</td><td data-field="${label.toLowerCase()}-${field}">${escapeHtml(v)}</td></tr>`).join('');
}

// Shows what a CAD user needs to find the two faces: STEP ids, part names, instance paths.
export function showSelection(panel, data, index) {
  const p = data.pairs[index];
  const extra = [];
  if (p.class === 'penetrating') extra.push(`crossing depth ${formatNumber(p.penetration)} mm`);
  if (p.intersecting) extra.push('triangles intersect');
  panel.innerHTML =
    `<table><tr><td>pair</td><td data-field="index">${index + 1}</td></tr>` +
    `<tr><td>class</td><td data-field="class"><span class="chip ${p.class}"></span>${p.class}</td></tr>` +
    `<tr><td>distance</td><td data-field="distance">${p.distance === null ? '–' : formatNumber(p.distance) + ' mm'}` +
    `${extra.length ? ' <span class="muted">(' + extra.join(', ') + ')</span>' : ''}</td></tr>` +
    sideRows(data, 'A', p.instance_a, p.surface_a) + sideRows(data, 'B', p.instance_b, p.surface_b) + '</table>';
}
