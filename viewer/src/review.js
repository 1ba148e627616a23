// The clash review in the page (docs/review.md): which clash a pair belongs to, its status and
// approval, the status/approval toggles above the table, approving and unapproving clashes, and the
// approvals file (`cadclash check --approvals`) the page exports.
//
// Approvals made here are by clash id, dated with the report's `review.today` (else today's UTC
// date). A clash approved by an id entry of the report's approvals file can be unapproved here (the
// entry leaves the export); one approved by a rule cannot (edit the rule in the file).
import { escapeHtml } from './panel.js';

export const REVIEW_FILTERS = ['new', 'active', 'changed', 'approved', 'unapproved'];

export class ReviewState {
  constructor(data) {
    this.clashes = data.clashes || [];
    this.review = data.review || null;
    this.clashOfPair = new Int32Array(data.pairs.length).fill(-1);
    this.clashes.forEach((c, k) => {
      for (const s of c.surface_pairs) if (s.pair !== null) this.clashOfPair[s.pair] = k;
    });
    this.entries = (this.review ? this.review.approvals : []).map((u) => u.approval);
    this.removed = new Set();  // indices of file entries unapproved here
    this.added = new Map();    // clash id -> approval made here
    this.today = (this.review && this.review.today) || new Date().toISOString().slice(0, 10);
  }

  // {from: 'page' | 'file', approval, entry?} for clash k, or null when it is not approved.
  approvalOf(k) {
    const c = this.clashes[k];
    if (this.added.has(c.id)) return { from: 'page', approval: this.added.get(c.id) };
    if (c.approval !== null && c.approval !== undefined && !this.removed.has(c.approval))
      return { from: 'file', approval: this.entries[c.approval], entry: c.approval };
    return null;
  }

  canUnapprove(k) {
    const a = this.approvalOf(k);
    return a !== null && (a.from === 'page' || a.approval.id === this.clashes[k].id);
  }

  approve(k, by, reason) {
    const c = this.clashes[k];
    if (!REVIEW_FILTERS.includes(c.status) || this.approvalOf(k)) return;
    this.added.set(c.id, { id: c.id, reason, by, date: this.today });
  }

  unapprove(k) {
    const a = this.approvalOf(k);
    if (!a || !this.canUnapprove(k)) return;
    if (a.from === 'page') this.added.delete(this.clashes[k].id);
    else this.removed.add(a.entry);
  }

  // The approvals file: the report's entries not unapproved here, then the ones made here.
  approvalsText() {
    const approvals = this.entries.filter((_, i) => !this.removed.has(i)).concat([...this.added.values()]);
    return JSON.stringify({ schema: 'cadclash-approvals', version: 1, approvals }, null, 2) + '\n';
  }

  // Whether pair i passes the toggles ({new: bool, ..., approved: bool, unapproved: bool}).
  pairShown(i, shown) {
    const k = this.clashOfPair[i];
    if (k < 0) return true;
    if (shown[this.clashes[k].status] === false) return false;
    return shown[this.approvalOf(k) ? 'approved' : 'unapproved'] !== false;
  }

  // Current clashes per status and per approval.
  counts() {
    const n = Object.fromEntries(REVIEW_FILTERS.map((f) => [f, 0]));
    this.clashes.forEach((c, k) => {
      if (!REVIEW_FILTERS.includes(c.status)) return;  // resolved, unexamined: no pairs now
      ++n[c.status];
      ++n[this.approvalOf(k) ? 'approved' : 'unapproved'];
    });
    return n;
  }
}

// The toggles, the reviewer's name and reason, and the export button; onChange(shown) on a toggle.
export function fillReviewBar(bar, review, onChange) {
  if (!review.clashes.length) {
    bar.hidden = true;
    return;
  }
  const resolved = review.clashes.filter((c) => c.status === 'resolved').length;
  const unexamined = review.clashes.filter((c) => c.status === 'unexamined').length;
  bar.innerHTML =
    `<div>clashes: ${REVIEW_FILTERS.map((f) => `<label><input type="checkbox" data-review="${f}" checked>${f} ` +
      `<span class="count" data-review-count="${f}"></span></label>`).join(' ')}` +
    (resolved ? ` <span class="muted">· ${resolved} resolved</span>` : '') +
    (unexamined ? ` <span class="muted">· ${unexamined} not examined (partial run)</span>` : '') + '</div>' +
    '<div class="review-line"><input id="review-by" placeholder="your name" aria-label="approved by">' +
    '<input id="review-reason" placeholder="reason for approving" aria-label="reason">' +
    '<button id="export-approvals" type="button">export approvals</button></div>';
  bar.addEventListener('change', (e) => {
    if (!e.target.dataset.review) return;
    const shown = {};
    for (const input of bar.querySelectorAll('input[data-review]')) shown[input.dataset.review] = input.checked;
    onChange(shown);
  });
  bar.querySelector('#export-approvals').addEventListener('click', () => {
    const url = URL.createObjectURL(new Blob([review.approvalsText()], { type: 'application/json' }));
    const a = document.createElement('a');
    a.href = url;
    a.download = 'approvals.json';
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 1000);
  });
  showReviewCounts(bar, review);
}

export function showReviewCounts(bar, review) {
  const n = review.counts();
  for (const f of REVIEW_FILTERS) {
    const el = bar.querySelector(`[data-review-count="${f}"]`);
    if (el) el.textContent = n[f].toLocaleString('en');
  }
}

// The selected pair's clash: id, status, approval, and the button that approves or unapproves it;
// onChange() after either.
export function showClash(box, review, pairIndex, onChange) {
  const k = pairIndex >= 0 ? review.clashOfPair[pairIndex] : -1;
  if (k < 0) {
    box.hidden = true;
    return;
  }
  const c = review.clashes[k];
  const a = review.approvalOf(k);
  const what = a ? `approved by ${a.approval.by} (${a.approval.reason})${a.from === 'page' ? ', here' : ''}` : 'not approved';
  let button = '';
  if (!a) button = '<button id="approve-clash" type="button">approve clash</button>';
  else if (review.canUnapprove(k)) button = '<button id="unapprove-clash" type="button">unapprove</button>';
  else button = '<span class="muted">approved by a rule of the file</span>';
  const v = c.interference;
  const measure = !v ? '' : v.measured
    ? ` · interference ${Number(v.volume.toPrecision(4))} mm³, depth ${Number(v.depth.toPrecision(4))} mm`
    : ` · no volume: ${escapeHtml(v.note)}`;
  box.hidden = false;
  box.innerHTML =
    `clash <b data-field="clash-id">${escapeHtml(c.id)}</b> <span data-field="clash-status">${escapeHtml(c.status)}</span>, ` +
    `${escapeHtml(c.class)}, ${c.surface_pairs.length} surface pairs${measure} · ` +
    `<span data-field="clash-approval">${escapeHtml(what)}</span> ${button}`;
  const approve = box.querySelector('#approve-clash');
  if (approve) approve.addEventListener('click', () => {
    const by = document.getElementById('review-by').value.trim() || 'viewer';
    const reason = document.getElementById('review-reason').value.trim() || 'approved in the viewer';
    review.approve(k, by, reason);
    onChange();
  });
  const unapprove = box.querySelector('#unapprove-clash');
  if (unapprove) unapprove.addEventListener('click', () => {
    review.unapprove(k);
    onChange();
  });
}
