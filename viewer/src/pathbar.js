// The time slider's controls (plain DOM): play/pause, the slider and a time box over the 3D view,
// and the timeline list in the side panel (each surface pair of the timeline, its spans, and its
// state at the shown time).
import { TIME_LABELS, formatNumber } from './classes.js';
import { escapeHtml, surfaceLabel } from './panel.js';

// Playing crosses the whole path in this long, whatever its number of steps: a reviewer sees the
// motion at once, and stops or drags the slider where it matters.
const PLAY_SECONDS = 10;

// Six digits, as the command line prints spans: a narrow span is 0.001 of a stretch wide.
const timeText = (t) => String(Number(t.toPrecision(6)));

function spanText([t0, t1, ends]) {
  return `${ends ? '' : '~'}[${timeText(t0)}, ${timeText(t1)}]`;
}

function sideText(data, instance, surface) {
  const inst = data.instances[instance];
  const label = surfaceLabel(surface >= 0 ? data.surfaces[surface] : null);
  return `<b>${escapeHtml(label)}</b> ${escapeHtml(data.parts[inst.part].name)}`;
}

export class PathBar {
  // bar: the controls over the 3D view; list: the timeline box in the side panel. onTime(t) draws
  // the scene at time t; onPick(pair) selects a surface pair ({instance_a, surface_a, ...}).
  constructor(bar, list, data, player, { onTime, onPick }) {
    this.data = data;
    this.player = player;
    this.onTime = onTime;
    this.playing = false;
    const { first, last } = player;
    bar.hidden = false;
    bar.innerHTML =
      '<button id="path-play" type="button" title="play or pause the path">play</button>' +
      `<input id="path-slider" type="range" min="${first}" max="${last}" step="any" value="${last}" aria-label="path time">` +
      `<input id="path-time" type="number" min="${first}" max="${last}" step="any" value="${last}" aria-label="time (step number)">` +
      '<span id="path-where" class="muted"></span>';
    this.button = bar.querySelector('#path-play');
    this.slider = bar.querySelector('#path-slider');
    this.box = bar.querySelector('#path-time');
    this.where = bar.querySelector('#path-where');
    this.slider.addEventListener('input', () => { this.pause(); this.setTime(Number(this.slider.value)); });
    this.box.addEventListener('change', () => {
      const t = Number(this.box.value);
      if (Number.isFinite(t)) { this.pause(); this.setTime(t); }
    });
    this.button.addEventListener('click', () => (this.playing ? this.pause() : this.play()));

    const pairs = player.path.pairs;
    const count = pairs.reduce((n, p) => n + p.surfaces.length, 0);
    list.hidden = false;
    const rows = [];
    pairs.forEach((pair, p) => {
      const a = data.instances[pair.instance_a].path, b = data.instances[pair.instance_b].path;
      const moves = player.pairMoves(p) ? '1' : '0';
      rows.push(`<tr class="instance-pair" data-moves="${moves}"><td colspan="4" title="${escapeHtml(a + '\n' + b)}">` +
                `${escapeHtml(a)} × ${escapeHtml(b)}: ${this.spanLinks(pair.spans)}</td></tr>`);
      pair.surfaces.forEach((sp, k) => {
        rows.push(`<tr data-pair="${p}" data-surface="${k}" data-moves="${moves}"><td class="state"><span class="chip"></span></td>` +
                  `<td>${sideText(data, pair.instance_a, sp.surface_a)}</td><td>${sideText(data, pair.instance_b, sp.surface_b)}</td>` +
                  `<td class="spans">${this.spanLinks(sp.spans)}</td></tr>`);
      });
    });
    const moving = pairs.filter((_, p) => player.pairMoves(p)).length;
    // A choice only when some pairs have no instance the path moves.
    const movingOnly = moving === pairs.length ? '' :
      ` <label><input id="timeline-moving" type="checkbox" checked> only the ${moving} of ${pairs.length} instance ` +
      'pairs with a part the path moves</label> (the others keep their state over the whole path).';
    const partial = player.path.complete ? '' :
      ' <b>Partial:</b> a stretch ran out of its checks or the path was cut short; its open spans are listed whole.';
    list.innerHTML =
      `<div><b>Timeline</b>: ${count} surface pair${count === 1 ? '' : 's'} may touch between steps ${first} and ` +
      `${last}; at the shown time <span id="path-now"></span>. Spans in step numbers (~: where a contact may ` +
      `begin or end, not proved); click one to go there, a row to frame its surfaces.${movingOnly}${partial} ` +
      `The table below is the check at step ${last}.</div>` +
      `<div id="timeline-wrap"><table id="timeline-pairs"><tbody>${rows.join('')}</tbody></table></div>`;
    this.now = list.querySelector('#path-now');
    this.rows = [...list.querySelectorAll('tr[data-pair]')];
    this.still = [...list.querySelectorAll('tr[data-moves="0"]')];
    this.movingBox = list.querySelector('#timeline-moving');
    const showMoving = () => {
      player.movingOnly = !this.movingBox || this.movingBox.checked;
      for (const tr of this.still) tr.hidden = player.movingOnly;
    };
    showMoving();
    if (this.movingBox) this.movingBox.addEventListener('change', () => { showMoving(); this.setTime(this.time ?? last); });
    list.addEventListener('click', (e) => {
      const link = e.target.closest('a[data-t]');
      if (link) {
        e.preventDefault();
        this.pause();
        this.setTime(Number(link.dataset.t));
        return;
      }
      const tr = e.target.closest('tr[data-pair]');
      if (!tr) return;
      const pair = pairs[Number(tr.dataset.pair)], sp = pair.surfaces[Number(tr.dataset.surface)];
      onPick({ instance_a: pair.instance_a, surface_a: sp.surface_a, instance_b: pair.instance_b, surface_b: sp.surface_b });
    });
  }

  // A link per span that shows its middle.
  spanLinks(spans) {
    if (!spans.length) return '<span class="muted">no contact</span>';
    return spans.map((s) => `<a href="#" data-t="${(s[0] + s[1]) / 2}" class="${s[2] ? 'contact' : 'may'}">${spanText(s)}</a>`).join(' ');
  }

  // Shows time t (clamped to the path): the scene, the controls and the list.
  setTime(t) {
    const { first, last } = this.player;
    this.time = Math.min(Math.max(t, first), last);
    this.slider.value = String(this.time);
    if (document.activeElement !== this.box) this.box.value = String(Number(this.time.toPrecision(8)));
    const [k, s] = this.player.stretchAt(this.time);
    const steps = this.player.steps;
    this.where.textContent = s > 0 ? `between steps ${steps[k]} and ${steps[k + 1]} (${formatNumber(s * 100)} % of the way)`
                                   : `at step ${steps[k]}`;
    const now = this.player.pairsAt(this.time);
    const state = new Map(now.map((x) => [x.pair + ':' + x.surface, x.state]));
    for (const tr of this.rows) {
      const st = state.get(tr.dataset.pair + ':' + tr.dataset.surface) ?? '';
      tr.className = st;
      tr.dataset.state = st;
      tr.querySelector('.state').title = st ? TIME_LABELS[st] : 'apart (proved)';
    }
    const n = (st) => now.filter((x) => x.state === st).length;
    this.now.textContent = `${n('contact')} in contact, ${n('may')} may begin or end`;
    this.onTime(this.time);
  }

  play() {
    const { first, last } = this.player;
    if (this.time >= last) this.setTime(first);
    this.playing = true;
    this.button.textContent = 'pause';
    let before = performance.now();
    const tick = (now) => {
      if (!this.playing) return;
      const t = this.time + ((now - before) / 1000) * ((last - first) / PLAY_SECONDS);
      before = now;
      this.setTime(t);
      if (t >= last) this.pause();
      else requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }

  pause() {
    this.playing = false;
    this.button.textContent = 'play';
  }
}
