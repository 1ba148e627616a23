// Entry of the clash viewer: reads the report embedded in the page, draws it, wires the table.
//
// When everything is drawn the page sets <html data-cadclash-ready="1"> (or data-cadclash-error)
// and exposes window.cadclashViewer for scripted checks (tests/viewer) and load-time measurements.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { assertLittleEndian } from './decode.js';
import { ClashScene } from './scene.js';
import { fillLegend, fillTable, showSelection } from './panel.js';

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

  const camera = new THREE.PerspectiveCamera(40, 1, 1, 10);
  camera.up.set(0, 0, 1);
  const controls = new OrbitControls(camera, renderer.domElement);
  const sceneBox = clash.sceneBox();
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

  const table = document.getElementById('pairs');
  const tbody = table.querySelector('tbody');
  const panel = document.getElementById('selection');
  const counts = {};
  for (const p of data.pairs) counts[p.class] = (counts[p.class] || 0) + 1;
  document.getElementById('title').textContent = data.files.join(', ');
  document.getElementById('summary').textContent =
    `${data.pairs.length} pairs · ${data.instances.length} instances · ${data.parts.length} parts · ` +
    `${data.surfaces.length} surfaces · ${clash.triangles.toLocaleString('en')} triangles drawn`;
  fillTable(tbody, data);
  fillLegend(document.getElementById('legend'), table, counts, ({ context }) => {
    showContext = context;
    requestDraw();
  });
  const warnings = [...data.diagnostics];
  if (data.stopped_by) warnings.unshift(`PARTIAL REPORT: the ${data.stopped_by} ran out before every pair was examined`);
  else if (data.complete === false) warnings.unshift('PARTIAL REPORT: some input could not be read (see below)');
  if (warnings.length) {
    const err = document.getElementById('error');
    err.hidden = false;
    err.textContent = warnings.join('\n');
  }

  let selectedRow = null;
  function selectPair(index) {
    const pair = data.pairs[index];
    if (!pair) throw new RangeError(`no pair ${index}`);
    if (selectedRow) selectedRow.classList.remove('selected');
    selectedRow = tbody.children[index];
    selectedRow.classList.add('selected');
    selectedRow.scrollIntoView({ block: 'nearest' });
    clash.select(pair);
    const box = clash.worldBox(pair.instance_a, pair.surface_a).union(clash.worldBox(pair.instance_b, pair.surface_b));
    fitCamera(camera, controls, box);
    showSelection(panel, data, index);
    document.documentElement.dataset.cadclashSelected = String(index);
    // Show the framed pair at once (light frame on a slow scene), then everything.
    dragging = true;
    requestDraw();
    setTimeout(() => { dragging = false; requestDraw(); }, 100);
  }
  tbody.addEventListener('click', (e) => {
    const tr = e.target.closest('tr');
    if (tr) selectPair(Number(tr.dataset.index));
  });

  draw();
  syncGpu();
  const gl = renderer.getContext();
  const tReady = performance.now();
  status.textContent = `${clash.triangles.toLocaleString('en')} triangles, ${clash.drawCalls} draw calls · ` +
                       `ready in ${Math.round(tReady)} ms after navigation`;

  window.cadclashViewer = {
    stats: {
      triangles: clash.triangles,
      drawCalls: clash.drawCalls,
      parseMs: tParsed - t0,
      buildMs: tBuilt - tParsed,
      firstFrameMs: tReady - tBuilt,
      scriptMs: tReady - t0,
      readyMs: tReady,  // since navigation start: includes reading and parsing the HTML file
    },
    selectPair,
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
