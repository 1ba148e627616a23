// The pair table, drawn virtually: only the rows in (and just around) the scrolled-to window exist
// as DOM nodes, between two spacer rows that give the table its full height. Rows have one fixed
// height (every cell is one or two lines that never wrap), so a row's position is its place in the
// listed pairs times that height: 60 000 rows scroll and filter as fast as 60.
import { distanceText, intervalText } from './classes.js';
import { escapeHtml, surfaceLabel } from './panel.js';

const OVERSCAN = 12;  // rows drawn above and below the visible ones, so a quick scroll shows no gap

function sideCell(data, instanceId, surfaceId) {
  const inst = data.instances[instanceId];
  const part = data.parts[inst.part];
  const surface = surfaceId >= 0 ? data.surfaces[surfaceId] : null;
  const label = surfaceLabel(surface);
  // A long path is cut at its start, keeping the leaf instance in view (the .path line is
  // right-to-left for that; the marks keep its slashes in place); the tooltip and the selection
  // panel show it whole.
  return `<td title="${escapeHtml(`${label} ${part.name}\n${inst.path}`)}">` +
         `<div class="line"><b>${escapeHtml(label)}</b> ${escapeHtml(part.name)}</div>` +
         `<div class="line path muted">\u200e${escapeHtml(inst.path)}\u200e</div></td>`;
}

function rowHtml(data, i, selected) {
  const p = data.pairs[i];
  return `<tr class="${escapeHtml(p.class)}${i === selected ? ' selected' : ''}" data-index="${i}">` +
         `<td class="num">${i + 1}</td><td class="cls"><span class="chip"></span>${escapeHtml(p.class)}</td>` +
         `<td class="num">${distanceText(p)}</td><td class="by" title="exact distance in ${intervalText(p)}">${escapeHtml(p.decided_by ?? '–')}</td>` +
         `${sideCell(data, p.instance_a, p.surface_a)}${sideCell(data, p.instance_b, p.surface_b)}</tr>`;
}

function spacer(height) {
  return height > 0 ? `<tr class="spacer"><td colspan="6" style="height:${height}px"></td></tr>` : '';
}

export class PairTable {
  // wrap: the scrolling element around the table; onPick(pairIndex) is called on a row click.
  constructor(wrap, table, data, onPick) {
    this.wrap = wrap;
    this.table = table;
    this.tbody = table.querySelector('tbody');
    this.data = data;
    this.rows = new Uint32Array(0);  // listed pair indices, ascending
    this.selected = -1;
    this.rowHeight = 0;
    this.drawn = null;  // [first, end) of the rows in the DOM
    this.pending = false;
    wrap.addEventListener('scroll', () => this.requestRender());
    new ResizeObserver(() => this.requestRender()).observe(wrap);
    this.tbody.addEventListener('click', (e) => {
      const tr = e.target.closest('tr[data-index]');
      if (tr) onPick(Number(tr.dataset.index));
    });
  }

  setRows(indices) {
    this.rows = indices;
    this.drawn = null;
    this.render();
  }

  setSelected(pairIndex) {
    this.selected = pairIndex;
    for (const tr of this.tbody.querySelectorAll('tr.selected')) tr.classList.remove('selected');
    const tr = this.tbody.querySelector(`tr[data-index="${pairIndex}"]`);
    if (tr) tr.classList.add('selected');
  }

  // Place of a pair among the listed rows, or -1 when it is filtered out.
  positionOf(pairIndex) {
    const p = this.insertionPoint(pairIndex);
    return p < this.rows.length && this.rows[p] === pairIndex ? p : -1;
  }

  // Number of listed pairs with an index below pairIndex (binary search: rows are ascending).
  insertionPoint(pairIndex) {
    let lo = 0, hi = this.rows.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (this.rows[mid] < pairIndex) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  }

  // Scrolls the least needed to show a listed pair's whole row below the sticky header.
  scrollToPair(pairIndex) {
    const pos = this.positionOf(pairIndex);
    if (pos < 0) return false;
    this.render();  // the spacers must give the table its full height before scrolling
    const head = this.table.tHead.offsetHeight;
    const top = head + pos * this.rowHeight;
    const wrap = this.wrap;
    if (top - head < wrap.scrollTop) wrap.scrollTop = top - head;
    else if (top + this.rowHeight > wrap.scrollTop + wrap.clientHeight)
      wrap.scrollTop = top + this.rowHeight - wrap.clientHeight;
    this.render();
    return true;
  }

  // The height of one row, read from a drawn row once (fonts differ between systems).
  measure() {
    if (this.rowHeight > 0) return;
    if (!this.rows.length) return;
    this.tbody.innerHTML = rowHtml(this.data, this.rows[0], -1);
    this.rowHeight = this.tbody.rows[0].getBoundingClientRect().height || 36;
    this.drawn = null;
  }

  requestRender() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => { this.pending = false; this.render(); });
  }

  render() {
    const n = this.rows.length;
    if (!n) {
      this.tbody.innerHTML = '';
      this.drawn = [0, 0];
      return;
    }
    this.measure();
    const h = this.rowHeight;
    const head = this.table.tHead.offsetHeight;
    const top = Math.max(0, this.wrap.scrollTop - head);
    const first = Math.max(0, Math.floor(top / h) - OVERSCAN);
    const end = Math.min(n, Math.ceil((top + this.wrap.clientHeight) / h) + OVERSCAN);
    if (this.drawn && this.drawn[0] === first && this.drawn[1] === end) return;
    const html = [spacer(first * h)];
    for (let r = first; r < end; ++r) html.push(rowHtml(this.data, this.rows[r], this.selected));
    html.push(spacer((n - end) * h));
    this.tbody.innerHTML = html.join('');
    this.drawn = [first, end];
  }
}
