// Entry of the clash viewer: reads the report embedded in the page, draws it, wires the table,
// the filter and the keys.
//
// When everything is drawn the page sets <html data-cadclash-ready="1"> (or data-cadclash-error)
// and exposes window.cadclashViewer for scripted checks (tests/viewer) and load-time measurements.
// <html data-cadclash-filter> holds the filter text last applied (the box applies it after a pause
// in typing) and data-cadclash-selected the selected pair's index; with a time slider (a path
// checked continuously) data-cadclash-time holds the time last drawn.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { assertLittleEndian } from './decode.js';
import { ClashScene } from './scene.js';
import { fillClassToggles, fillLegend, showClassCounts, showSelection } from './panel.js';
import { PairFilter } from './filter.js';
import { PairTable } from './pairtable.js';
import { CLASSES, TIME_LABELS, TIME_STATES } from './classes.js';
import { PathPlayer, poseMatrix } from './path.js';
import { PathBar } from './pathbar.js';
import { TimelineLayer } from './timeline.js';
import { ReviewState, fillReviewBar, showClash, showReviewCounts } from './review.js';

// Pause in typing before the filter applies: one pass over 60 000 pairs is cheap, but redrawing a
// big scene (the 3D view colours only the listed pairs) is not.
const FILTER_DELAY_MS = 150;

const VIEW_DIRECTION = new THREE.Vector3(1, -1.3, 0.9).normalize();  // isometric-like, z up

function fitCamera(camera, controls, box) {
  if (box.isEmpty()) return;
  const sphere = box.getBoundingSphere(new THREE.Sphere());
  const radius = Math.max(sphere.radius, 1e-3);
  const halfFov = THREE.MathUtils.degToRad(camera.fov / 2);
  const distance = (radius / Math.sin(Math.min(halfFov, halfFov * camera.aspect))) * 1.15;
  const dir = camera.position.clone().sub(controls.target);
  if (dir.lengthSq() === 0) dir.copy(VIEW_DIRECTION);
  dir.normalize();
  controls.target.copy(sphere.center);
  camera.position.copy(sphere.center).addScaledVector(dir, distance);
  camera.near = Math.max(distance - radius * 4, distance * 1e-3);
  camera.far = distance + radius * 4 + controls.maxDistanceHint;
  camera.updateProjectionMatrix();
  controls.update();
}

function start() {
  const t0 = performance.now();
  assertLittleEndian();
  const data = JSON.parse(document.getElementById('cadclash-data').textContent);
  const tParsed = performance.now();

  const view = document.getElementById('view');
  const status = document.getElementById('status');
  const renderer = new THREE.WebGLRenderer({ antialias: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0xf4f5f7, 1);
  view.prepend(renderer.domElement);

  const clash = new ClashScene(data);
  const tBuilt = performance.now();
  const scene = new THREE.Scene();
  scene.add(clash.root);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8f99, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.4);
  scene.add(sun);

  // A path checked continuously: the moving instances go where the slider says, and the timeline's
  // contacts at that time replace the class colours of the last step's check.
  const player = data.path && data.path.steps.length ? new PathPlayer(data.path, data) : null;
  let timeLayer = null;
  const moved = new THREE.Matrix4();
  function placeAt(t) {
    for (const { instance, pose } of player.posesAt(t)) clash.moveInstance(instance, moved.fromArray(poseMatrix(pose)));
  }
  if (player) {
    timeLayer = new TimelineLayer(clash, player);
    clash.replaceHighlights(timeLayer);
  }

  const camera = new THREE.PerspectiveCamera(40, 1, 1, 10);
  camera.up.set(0, 0, 1);
  const controls = new OrbitControls(camera, renderer.domElement);
  // With a path, the box of every step's scene: the camera frames the whole motion.
  const sceneBox = clash.sceneBox();
  if (player) {
    for (const step of player.steps) {
      placeAt(step);
      sceneBox.union(clash.sceneBox());
    }
  }
  controls.maxDistanceHint = sceneBox.isEmpty() ? 1 : sceneBox.getSize(new THREE.Vector3()).length() * 4;

  // Draw on demand only: a big assembly costs nothing while nobody moves it. While the user drags,
  // a scene whose full frame took longer than FRAME_BUDGET_MS draws without the grey context (the
  // bulk of the triangles: software WebGL draws ~1 M triangles in seconds); releasing draws it all.
  const FRAME_BUDGET_MS = 50;
  let pending = false, dragging = false, fullFrameMs = 0, showContext = true;
  function draw() {
    pending = false;
    sun.position.copy(camera.position).sub(controls.target).normalize();  // light from the eye
    const light = dragging && fullFrameMs > FRAME_BUDGET_MS;
    clash.context.visible = showContext && !light;
    const t = performance.now();
    renderer.render(scene, camera);
    if (!light && showContext) {
      syncGpu();
      fullFrameMs = performance.now() - t;
    }
  }
  // Waits for the GPU to finish the frame (a one-pixel read; gl.finish() does not wait in Chromium).
  const onePixel = new Uint8Array(4);
  function syncGpu() {
    const gl = renderer.getContext();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, onePixel);
  }
  function requestDraw() {
    if (!pending) { pending = true; requestAnimationFrame(draw); }
  }
  function resize() {
    const w = Math.max(view.clientWidth, 1), h = Math.max(view.clientHeight, 1);
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
    requestDraw();
  }
  controls.addEventListener('change', requestDraw);
  controls.addEventListener('start', () => { dragging = true; });
  controls.addEventListener('end', () => { dragging = false; requestDraw(); });
  new ResizeObserver(resize).observe(view);
  resize();
  camera.position.copy(VIEW_DIRECTION);
  controls.target.set(0, 0, 0);
  fitCamera(camera, controls, sceneBox);

  const panel = document.getElementById('selection');
  document.getElementById('title').textContent = data.files.join(', ');
  document.getElementById('summary').textContent =
    `${data.pairs.length} pairs · ${data.instances.length} instances · ${data.parts.length} parts · ` +
    `${data.surfaces.length} surfaces · ${clash.triangles.toLocaleString('en')} triangles drawn`;
  fillLegend(document.getElementById('legend'), ({ context }) => {
    showContext = context;
    requestDraw();
  }, player ? TIME_STATES.map((st) => [st, TIME_LABELS[st]]) : undefined);
  const warnings = [...data.diagnostics];
  if (data.stopped_by) warnings.unshift(`PARTIAL REPORT: the ${data.stopped_by} ran out before every pair was examined`);
  else if (data.complete === false) warnings.unshift('PARTIAL REPORT: some input could not be read (see below)');
  if (warnings.length) {
    const err = document.getElementById('error');
    err.hidden = false;
    err.textContent = warnings.join('\n');
  }

  let selected = -1, fullDrawTimer = 0;
  const table = new PairTable(document.getElementById('pairs-wrap'), document.getElementById('pairs'), data,
                              (index) => selectPair(index));
  function frameSelected() {
    if (selected < 0) return;
    const pair = data.pairs[selected];
    const box = clash.worldBox(pair.instance_a, pair.surface_a).union(clash.worldBox(pair.instance_b, pair.surface_b));
    fitCamera(camera, controls, box);
    // Show the framed pair at once (light frame on a slow scene), then everything; a key held down
    // steps through pairs with light frames only, the full one follows the last.
    dragging = true;
    requestDraw();
    clearTimeout(fullDrawTimer);
    fullDrawTimer = setTimeout(() => { dragging = false; requestDraw(); }, 100);
  }
  function selectPair(index) {
    const pair = data.pairs[index];
    if (!pair) throw new RangeError(`no pair ${index}`);
    selected = index;
    table.setSelected(index);
    table.scrollToPair(index);
    clash.select(pair);
    showSelection(panel, data, index);
    showClash(clashBox, review, index, reviewChanged);
    document.documentElement.dataset.cadclashSelected = String(index);
    frameSelected();
  }

  // The filter: text box and class toggles above the table.
  const filter = new PairFilter(data);
  const filterBox = document.getElementById('filter');
  const toggles = document.getElementById('class-toggles');
  const filterCount = document.getElementById('filter-count');
  let shownClasses = Object.fromEntries(CLASSES.map((c) => [c, true]));
  let filterTimer = 0;
  // The clash review: status and approval toggles, approvals made in the page (viewer/src/review.js).
  const review = new ReviewState(data);
  const reviewBar = document.getElementById('review-bar');
  const clashBox = document.getElementById('clash-info');
  let shownReview = {};
  function reviewChanged() {
    showReviewCounts(reviewBar, review);
    showClash(clashBox, review, selected, reviewChanged);
    applyFilter();
  }
  fillReviewBar(reviewBar, review, (shown) => {
    shownReview = shown;
    applyFilter();
  });
  function applyFilter() {
    clearTimeout(filterTimer);
    filterTimer = 0;
    const matched = filter.apply(filterBox.value, shownClasses);
    const counts = matched.counts;
    const indices = Object.values(shownReview).includes(false)
      ? matched.indices.filter((i) => review.pairShown(i, shownReview)) : matched.indices;
    table.setRows(indices);
    if (selected >= 0) table.scrollToPair(selected);
    showClassCounts(toggles, counts);
    const all = data.pairs.length;
    filterCount.textContent = `${indices.length.toLocaleString('en')} of ${all.toLocaleString('en')} pairs`;
    clash.showOnly(indices.length === all ? null : indices);
    requestDraw();
    document.documentElement.dataset.cadclashFilter = filterBox.value;
  }
  filterBox.addEventListener('input', () => {
    clearTimeout(filterTimer);
    filterTimer = setTimeout(applyFilter, FILTER_DELAY_MS);
  });
  fillClassToggles(toggles, (shown) => {
    shownClasses = shown;
    applyFilter();
  });
  applyFilter();

  let pathBar = null;
  function showTime(t) {
    placeAt(t);
    timeLayer.show(player.surfacesAt(t));
    requestDraw();
    document.documentElement.dataset.cadclashTime = String(t);
  }
  if (player) {
    pathBar = new PathBar(document.getElementById('path-bar'), document.getElementById('timeline'), data, player, {
      onTime: showTime,
      onPick(pair) {  // a timeline row: its two surfaces as sides A and B, framed where they are now
        clash.select(pair);
        fitCamera(camera, controls, clash.worldBox(pair.instance_a, pair.surface_a).union(clash.worldBox(pair.instance_b, pair.surface_b)));
        requestDraw();
      },
    });
    pathBar.setTime(player.last);  // as without a slider: the scene of the last step
  }

  // Moves the selection by `step` listed rows (from the nearest listed row when the selected pair
  // is filtered out, from the first or last row when none is selected).
  function moveSelection(step) {
    const n = table.rows.length;
    if (!n) return;
    let pos;
    if (selected < 0) pos = step > 0 ? 0 : n - 1;
    else {
      const at = table.positionOf(selected);
      if (at >= 0) pos = at + step;
      else {
        const next = table.insertionPoint(selected);  // first listed row after the selection
        pos = step > 0 ? next + step - 1 : next + step;
      }
    }
    selectPair(table.rows[Math.min(Math.max(pos, 0), n - 1)]);
  }
  document.addEventListener('keydown', (e) => {
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    if (e.target === filterBox) {
      if (e.key === 'Escape') {
        filterBox.value = '';
        applyFilter();
      } else if (e.key === 'Enter') {
        // Done typing: apply now, leave the box so the keys below work, and frame the selected
        // pair, or the first listed one when the filter hides the selection.
        if (filterTimer) applyFilter();
        filterBox.blur();
        if (table.positionOf(selected) >= 0) frameSelected();
        else if (table.rows.length) selectPair(table.rows[0]);
      } else {
        return;
      }
      e.preventDefault();
      return;
    }
    const t = e.target;
    if (t.isContentEditable || t.tagName === 'TEXTAREA' || t.tagName === 'SELECT' ||
        (t.tagName === 'INPUT' && !['checkbox', 'radio', 'button'].includes(t.type))) return;
    switch (e.key) {
      case 'ArrowDown': case 'j': moveSelection(1); break;
      case 'ArrowUp': case 'k': moveSelection(-1); break;
      case 'Enter': case 'f': frameSelected(); break;
      case '/': filterBox.focus(); filterBox.select(); break;
      default: return;
    }
    e.preventDefault();
  });

  draw();
  syncGpu();
  const gl = renderer.getContext();
  const tReady = performance.now();
  status.textContent = `${clash.triangles.toLocaleString('en')} triangles, ${clash.drawCalls} draw calls · ` +
                       `ready in ${Math.round(tReady)} ms after navigation`;

  window.cadclashViewer = {
    stats: {
      pairs: data.pairs.length,
      triangles: clash.triangles,
      drawCalls: clash.drawCalls,
      parseMs: tParsed - t0,
      buildMs: tBuilt - tParsed,
      firstFrameMs: tReady - tBuilt,
      scriptMs: tReady - t0,
      readyMs: tReady,  // since navigation start: includes reading and parsing the HTML file
    },
    selectPair,
    // The approvals file the export button writes (the report's approvals and the page's changes).
    approvalsText: () => review.approvalsText(),
    // Per class, how many (instance, surface) the 3D view colours with it (unfiltered).
    highlightCounts: () => clash.highlightCounts(),
    // Scrolls the table to a listed pair's row (false when the filter hides it).
    scrollToPair: (index) => table.scrollToPair(index),
    // With a time slider: shows time t (as dragging the slider there) and draws it; state() is what
    // is drawn: the time, each moving instance's world matrix (column-major, as its grey copy is
    // drawn) and each coloured surface with its state and colour.
    path: player && {
      first: player.first,
      last: player.last,
      setTime(t) {
        pathBar.pause();
        pathBar.setTime(t);
        dragging = false;
        draw();
      },
      play: () => pathBar.play(),
      pause: () => pathBar.pause(),
      playing: () => pathBar.playing,
      state: () => ({
        time: pathBar.time,
        instances: data.path.moving.map((i) => ({ instance: i, path: data.instances[i].path, matrix: [...clash.drawnMatrix(i).elements] })),
        coloured: timeLayer.drawn().map((c) => ({ ...c, path: data.instances[c.instance].path, name: data.surfaces[c.surface].name })),
        classColoursShown: clash.highlights.visible,
      }),
    },
    // Fits the whole assembly in view (the selection stays).
    frameAll() {
      fitCamera(camera, controls, sceneBox);
      draw();
    },
    // Draws the chosen layers now and counts the pixels that differ from the background.
    coveredPixels(layers) {
      clash.setLayers(layers);
      const saved = showContext;
      showContext = layers.context !== false;
      dragging = false;
      draw();
      showContext = saved;
      const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
      const px = new Uint8Array(w * h * 4);
      gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
      clash.setLayers({});
      draw();
      let covered = 0;
      for (let i = 0; i < px.length; i += 4)
        if (Math.abs(px[i] - 0xf4) + Math.abs(px[i + 1] - 0xf5) + Math.abs(px[i + 2] - 0xf7) > 12) ++covered;
      return { covered, total: w * h };
    },
    // Turns the view by small steps, drawing each frame to completion; returns ms per frame, for
    // full frames and for the lighter frames drawn while dragging.
    measureFrames(frames = 10) {
      const time = (drag) => {
        dragging = drag;
        const start = performance.now();
        for (let i = 0; i < frames; ++i) {
          camera.position.sub(controls.target).applyAxisAngle(camera.up, 0.02).add(controls.target);
          camera.lookAt(controls.target);
          draw();
          syncGpu();
        }
        dragging = false;
        return (performance.now() - start) / frames;
      };
      const full = time(false);
      return { fullMs: full, draggingMs: time(true) };
    },
    // How long applying a filter text takes (list, table, counts, 3D colours), then its full frame.
    timeFilter(text) {
      filterBox.value = text;
      const start = performance.now();
      applyFilter();
      const applied = performance.now();
      dragging = false;
      draw();
      syncGpu();
      return { filterMs: applied - start, drawMs: performance.now() - applied, listed: table.rows.length };
    },
    // How long one Down key takes, up to the selected pair's first frame drawn.
    timeKeyDown() {
      const start = performance.now();
      document.body.dispatchEvent(new KeyboardEvent('keydown', { key: 'ArrowDown', bubbles: true }));
      draw();
      syncGpu();
      return performance.now() - start;
    },
    // How long selecting a pair takes, up to its first frame drawn (light on a slow scene).
    timeSelect(index) {
      const start = performance.now();
      selectPair(index);
      draw();
      syncGpu();
      return performance.now() - start;
    },
  };
  document.documentElement.dataset.cadclashReady = '1';
}

try {
  start();
} catch (e) {
  const err = document.getElementById('error');
  err.hidden = false;
  err.textContent = 'The viewer failed: ' + (e && e.message ? e.message : e);
  document.documentElement.dataset.cadclashError = String(e && e.message ? e.message : e);
}
