// Viewer of vertexflow's HTML report. esbuild bundles this file with three.js into one script
// at build time; the C++ writer (src/report/html_report.cpp) inlines it into every report with
// the data in <script id="vertexflow-data" type="application/json">. Nothing is fetched.
//
// Data layout (all binary arrays base64, little-endian): display.indices uint32 (3 per face,
// shared by both meshes: the flow keeps connectivity), display.result_indices the result's own
// faces when it has them (edge flips: same vertices, other faces; absent otherwise),
// <mesh>.positions float32 (3 per vertex, relative to `offset`), <mesh>.mean_curvature and
// displacement RGB bytes per vertex, <mesh>.quality RGB bytes per face of that mesh's faces,
// and, when both meshes have texture coordinates, <mesh>.uv float32 (u, v per corner of that
// mesh's display faces, face by face) with texture.squares, the checker's squares per unit.
import {
  BufferAttribute,
  BufferGeometry,
  Color,
  DataTexture,
  DirectionalLight,
  DoubleSide,
  HemisphereLight,
  LinearFilter,
  LinearMipmapLinearFilter,
  LinearSRGBColorSpace,
  Mesh,
  MeshBasicMaterial,
  MeshPhongMaterial,
  PerspectiveCamera,
  RepeatWrapping,
  RGBAFormat,
  Scene,
  Sphere,
  WebGLRenderer,
} from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const BACKGROUND = 0xffffff;
const PLAIN = 0xb8b8b8;

function bytesFromBase64(text) {
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

const float32FromBase64 = (text) => new Float32Array(bytesFromBase64(text).buffer);
const uint32FromBase64 = (text) => new Uint32Array(bytesFromBase64(text).buffer);

// Per-face colours need three unshared corners per face: a non-indexed copy, built the first
// time the quality map is shown.
function faceColoredGeometry(positions, indices, faceColors) {
  const faces = indices.length / 3;
  const p = new Float32Array(faces * 9);
  const c = new Uint8Array(faces * 9);
  for (let f = 0; f < faces; ++f) {
    for (let k = 0; k < 3; ++k) {
      const v = indices[3 * f + k];
      const o = 9 * f + 3 * k;
      p[o] = positions[3 * v];
      p[o + 1] = positions[3 * v + 1];
      p[o + 2] = positions[3 * v + 2];
      c[o] = faceColors[3 * f];
      c[o + 1] = faceColors[3 * f + 1];
      c[o + 2] = faceColors[3 * f + 2];
    }
  }
  const geometry = new BufferGeometry();
  geometry.setAttribute('position', new BufferAttribute(p, 3));
  geometry.setAttribute('color', new BufferAttribute(c, 3, true));
  geometry.computeVertexNormals();
  return geometry;
}

// Per-vertex values (3 per vertex) copied to every corner of every face: what a non-indexed
// geometry needs.
function perCorner(values, indices, ArrayType) {
  const out = new ArrayType(indices.length * 3);
  for (let i = 0; i < indices.length; ++i) {
    const v = indices[i];
    out[3 * i] = values[3 * v];
    out[3 * i + 1] = values[3 * v + 1];
    out[3 * i + 2] = values[3 * v + 2];
  }
  return out;
}

// Per-face values (3 per face) copied to its three corners.
function faceToCorners(values, faces) {
  const out = new Uint8Array(faces * 9);
  for (let f = 0; f < faces; ++f)
    for (let k = 0; k < 3; ++k) out.set(values.subarray(3 * f, 3 * f + 3), 9 * f + 3 * k);
  return out;
}

// The checkerboard: one period of 2 x 2 squares, dark and light grey (0.35 and 0.9, as
// `vertexflow render --texture checker`), repeated squares / 2 times per unit of texture
// coordinate; mipmapped so receding squares fade to grey instead of flickering.
const CHECKER_TEXELS = 128;
function checkerTexture(squares, anisotropy) {
  const n = CHECKER_TEXELS;
  const texels = new Uint8Array(n * n * 4);
  for (let y = 0; y < n; ++y) {
    for (let x = 0; x < n; ++x) {
      const grey = (Math.floor((2 * x) / n) + Math.floor((2 * y) / n)) % 2 ? 89 : 230;
      texels.set([grey, grey, grey, 255], 4 * (y * n + x));
    }
  }
  const texture = new DataTexture(texels, n, n, RGBAFormat);
  texture.wrapS = texture.wrapT = RepeatWrapping;
  texture.magFilter = LinearFilter;
  texture.minFilter = LinearMipmapLinearFilter;
  texture.generateMipmaps = true;
  texture.anisotropy = anisotropy;
  texture.repeat.set(squares / 2, squares / 2);
  texture.needsUpdate = true;
  return texture;
}

class View {
  constructor(canvas, meshData, indices, displacement, camera) {
    this.canvas = canvas;
    this.camera = camera;
    this.renderer = new WebGLRenderer({ canvas, antialias: true });
    // The colours are final sRGB bytes from the C++ colour map: no colour-space conversion.
    this.renderer.outputColorSpace = LinearSRGBColorSpace;
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.scene = new Scene();
    this.scene.background = new Color(BACKGROUND);
    this.scene.add(new HemisphereLight(0xffffff, 0x505050, 2.2));
    this.light = new DirectionalLight(0xffffff, 2.2);
    this.scene.add(this.light);

    this.positions = float32FromBase64(meshData.positions);
    this.indices = indices;
    this.vertexColors = {
      mean_curvature: bytesFromBase64(meshData.mean_curvature),
      displacement,
    };
    this.faceColors = bytesFromBase64(meshData.quality);
    this.faceGeometry = null;
    // Texture coordinates belong to face corners (a seam gives a vertex several): the checker
    // view draws a non-indexed copy, built the first time it is shown.
    this.uv = meshData.uv !== undefined ? float32FromBase64(meshData.uv) : null;
    this.cornerGeometry = null;
    this.cornerColors = {};
    this.texture = null;
    this.colormap = 'none';

    this.geometry = new BufferGeometry();
    this.geometry.setAttribute('position', new BufferAttribute(this.positions, 3));
    this.geometry.setIndex(new BufferAttribute(indices, 1));
    this.geometry.computeVertexNormals();
    this.geometry.computeBoundingSphere();

    this.material = new MeshPhongMaterial({
      color: PLAIN,
      side: DoubleSide,
      shininess: 12,
      specular: 0x222222,
      // Pushed back a little so the wireframe drawn over it is not hidden by depth ties.
      polygonOffset: true,
      polygonOffsetFactor: 1,
      polygonOffsetUnits: 1,
    });
    // Half-transparent lines, so dense meshes do not turn black and the colour map shows through.
    this.wireMaterial = new MeshBasicMaterial({ color: 0x101010, wireframe: true, transparent: true, opacity: 0.45 });
    this.surface = new Mesh(this.geometry, this.material);
    this.wire = new Mesh(this.geometry, this.wireMaterial);
    this.wire.visible = false;
    this.scene.add(this.surface, this.wire);
  }

  setColormap(name) {
    this.colormap = name;
    this.update();
  }

  // squares: checker squares per unit of texture coordinate, or 0 for no texture.
  setChecker(squares) {
    if (!squares || !this.uv) {
      this.material.map = null;
    } else {
      this.texture ??= checkerTexture(squares, this.renderer.capabilities.getMaxAnisotropy());
      this.texture.repeat.set(squares / 2, squares / 2);
      this.material.map = this.texture;
    }
    this.update();
  }

  // The geometry and material for the colour map and texture: the shared indexed geometry, the
  // quality map's per-face copy, or, with the checker, the per-corner copy with smooth normals
  // and the map's colours per corner.
  update() {
    const name = this.colormap;
    const textured = this.material.map !== null;
    let geometry = this.geometry;
    if (textured) {
      if (!this.cornerGeometry) {
        this.cornerGeometry = new BufferGeometry();
        this.cornerGeometry.setAttribute('position', new BufferAttribute(perCorner(this.positions, this.indices, Float32Array), 3));
        this.cornerGeometry.setAttribute('normal',
          new BufferAttribute(perCorner(this.geometry.getAttribute('normal').array, this.indices, Float32Array), 3));
        this.cornerGeometry.setAttribute('uv', new BufferAttribute(this.uv, 2));
      }
      geometry = this.cornerGeometry;
      if (name !== 'none') {
        this.cornerColors[name] ??= name === 'quality'
          ? faceToCorners(this.faceColors, this.indices.length / 3)
          : perCorner(this.vertexColors[name], this.indices, Uint8Array);
        geometry.setAttribute('color', new BufferAttribute(this.cornerColors[name], 3, true));
      }
    } else if (name === 'quality') {
      this.faceGeometry ??= faceColoredGeometry(this.positions, this.indices, this.faceColors);
      geometry = this.faceGeometry;
    } else if (name !== 'none') {
      this.geometry.setAttribute('color', new BufferAttribute(this.vertexColors[name], 3, true));
    }
    this.surface.geometry = geometry;
    this.wire.geometry = geometry;
    const colored = name !== 'none';
    this.material.vertexColors = colored;
    // The texture multiplies the surface colour: a lighter grey keeps the dark squares readable.
    this.material.color.set(colored ? 0xffffff : textured ? 0xe0e0e0 : PLAIN);
    this.material.needsUpdate = true;
  }

  setWireframe(on) {
    this.wire.visible = on;
  }

  resize(width, height) {
    this.renderer.setSize(width, height, false);
  }

  render() {
    // A head light: the key light comes from the camera, so every side one orbits to is lit.
    this.light.position.copy(this.camera.position);
    this.renderer.render(this.scene, this.camera);
  }
}

function formatNumber(value) {
  if (typeof value !== 'number') return String(value);
  if (Number.isInteger(value)) return value.toLocaleString('en-US');
  const magnitude = Math.abs(value);
  if (magnitude !== 0 && (magnitude < 1e-3 || magnitude >= 1e6)) return value.toExponential(3);
  return value.toPrecision(4);
}

function element(tag, attributes = {}, text = undefined) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  if (text !== undefined) node.textContent = text;
  return node;
}

// Rows of the metrics table: nested objects become dotted names; an object whose keys are
// `input` and `result`, or a key pair NAME_input / NAME_result, becomes one row with two
// columns. Histograms (arrays) are left to the chart.
function metricRows(metrics) {
  const rows = [];
  const visit = (prefix, value) => {
    if (Array.isArray(value)) return;
    if (value !== null && typeof value === 'object') {
      const keys = Object.keys(value);
      if (keys.length === 2 && 'input' in value && 'result' in value &&
          typeof value.input !== 'object' && typeof value.result !== 'object') {
        rows.push([prefix, value.input, value.result]);
        return;
      }
      for (const key of keys) visit(prefix ? `${prefix}.${key}` : key, value[key]);
      return;
    }
    rows.push([prefix, value]);
  };
  const paired = {};
  for (const [key, value] of Object.entries(metrics)) {
    const match = /^(.*)_(input|result)$/.exec(key);
    if (match && value !== null && typeof value === 'object') {
      paired[match[1]] ??= {};
      paired[match[1]][match[2]] = value;
    } else {
      visit(key, value);
    }
  }
  for (const [name, sides] of Object.entries(paired)) {
    const keys = new Set([...Object.keys(sides.input ?? {}), ...Object.keys(sides.result ?? {})]);
    for (const key of keys) {
      const a = sides.input?.[key];
      const b = sides.result?.[key];
      if (Array.isArray(a) || Array.isArray(b)) continue;
      rows.push([`${name}.${key}`, a ?? '', b ?? '']);
    }
  }
  return rows;
}

function metricsTable(metrics, labels) {
  const table = element('table', { id: 'metrics-table' });
  const head = table.createTHead().insertRow();
  for (const title of ['metric', labels.input, labels.result]) head.appendChild(element('th', {}, title));
  const body = table.createTBody();
  for (const row of metricRows(metrics)) {
    const tr = body.insertRow();
    tr.appendChild(element('td', {}, row[0]));
    if (row.length === 2) {
      tr.appendChild(element('td', { class: 'num', colspan: '2' }, formatNumber(row[1])));
    } else {
      tr.appendChild(element('td', { class: 'num' }, formatNumber(row[1])));
      tr.appendChild(element('td', { class: 'num' }, formatNumber(row[2])));
    }
  }
  return table;
}

// Grouped bars, share of faces per 2r/R bin (10 bins over [0, 1]).
function histogramChart(histograms, labels) {
  const NS = 'http://www.w3.org/2000/svg';
  const width = 640, height = 240, left = 48, bottom = 34, top = 24, right = 12;
  const svg = document.createElementNS(NS, 'svg');
  svg.setAttribute('width', width);
  svg.setAttribute('height', height);
  svg.setAttribute('id', 'histogram-chart');
  const add = (tag, attributes, text) => {
    const node = document.createElementNS(NS, tag);
    for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
    if (text !== undefined) node.textContent = text;
    svg.appendChild(node);
    return node;
  };
  const share = (counts) => {
    const total = counts.reduce((a, b) => a + b, 0) || 1;
    return counts.map((c) => c / total);
  };
  const series = [
    { name: labels.input, values: share(histograms.input), counts: histograms.input, color: '#9a9a9a' },
    { name: labels.result, values: share(histograms.result), counts: histograms.result, color: '#b40426' },
  ];
  // Axis up to the next 10%, in steps of a quarter of that.
  const maximum = Math.max(0.1, Math.ceil(10 * Math.max(...series.flatMap((s) => s.values)) - 1e-9) / 10);
  const plotW = width - left - right, plotH = height - top - bottom;
  const binW = plotW / 10;
  const y = (v) => top + plotH * (1 - v / maximum);
  for (let t = 0; t <= 4; ++t) {
    const v = (maximum * t) / 4;
    add('line', { x1: left, x2: width - right, y1: y(v), y2: y(v), stroke: '#e4e4e4' });
    add('text', { x: left - 4, y: y(v) + 4, 'text-anchor': 'end' }, `${(100 * v).toFixed(0)}%`);
  }
  series.forEach((s, k) => {
    s.values.forEach((v, bin) => {
      const x = left + bin * binW + 3 + k * (binW - 6) / 2;
      const rect = add('rect', { x, y: y(v), width: (binW - 6) / 2, height: top + plotH - y(v), fill: s.color });
      const title = document.createElementNS(NS, 'title');
      title.textContent = `${s.name}, 2r/R in [${(bin / 10).toFixed(1)}, ${((bin + 1) / 10).toFixed(1)}): ` +
        `${s.counts[bin]} faces (${(100 * v).toFixed(1)}%)`;
      rect.appendChild(title);
    });
    add('rect', { x: left + 10 + k * 120, y: 6, width: 12, height: 10, fill: s.color });
    add('text', { x: left + 26 + k * 120, y: 15 }, s.name);
  });
  for (let bin = 0; bin <= 10; ++bin)
    add('text', { x: left + bin * binW, y: top + plotH + 14, 'text-anchor': 'middle' }, (bin / 10).toFixed(1));
  add('text', { x: left + plotW / 2, y: height - 4, 'text-anchor': 'middle' }, '2r/R (1 = equilateral)');
  add('line', { x1: left, x2: width - right, y1: top + plotH, y2: top + plotH, stroke: '#666' });
  return svg;
}

function showLegend(data, name) {
  const legend = document.getElementById('legend');
  legend.replaceChildren();
  const entry = data.legend[name];
  if (!entry) return;
  const bar = element('span', { id: 'legend-bar' });
  bar.style.background = `linear-gradient(to right, ${entry.colors.map((c) => `rgb(${c.join(',')})`).join(', ')})`;
  legend.append(element('span', {}, entry.labels[0]), bar, element('span', {}, entry.labels[1]));
  if (entry.unit) legend.append(element('span', {}, entry.unit));
}

function main() {
  const data = JSON.parse(document.getElementById('vertexflow-data').textContent);
  const ownFaces = data.display.result_indices !== undefined;
  document.getElementById('title').textContent = data.title;
  document.getElementById('subtitle').textContent =
    `${data.labels.input} vs ${data.labels.result}: ${data.counts.vertices.toLocaleString('en-US')} vertices, ` +
    `${data.counts.faces.toLocaleString('en-US')} faces` +
    (ownFaces ? '; the result has faces of its own (edge flips)' : '');
  document.getElementById('caption-input').textContent = `Input: ${data.labels.input}`;
  document.getElementById('caption-result').textContent = `Result: ${data.labels.result}`;
  const notes = document.getElementById('notes');
  if (data.display.note) notes.appendChild(element('p', { class: 'note', id: 'decimation-note' }, data.display.note));

  document.getElementById('histogram').appendChild(histogramChart(data.histograms, data.labels));
  document.getElementById('metrics').appendChild(metricsTable(data.metrics, data.labels));

  const indices = uint32FromBase64(data.display.indices);
  const resultIndices = ownFaces ? uint32FromBase64(data.display.result_indices) : indices;
  const displacement = bytesFromBase64(data.displacement);
  const camera = new PerspectiveCamera(35, 1, 1e-3, 1e3);
  let views;
  try {
    views = [
      new View(document.getElementById('view-input'), data.input, indices, displacement, camera),
      new View(document.getElementById('view-result'), data.result, resultIndices, displacement, camera),
    ];
  } catch (error) {
    notes.appendChild(element('p', { class: 'error' }, `3D views unavailable (WebGL): ${error.message}`));
    document.body.dataset.ready = 'error';
    return;
  }
  // For the browser test: the faces each view draws.
  document.body.dataset.faces = views.map((view) => view.geometry.index.count / 3).join(' ');

  // Both views look at the input's bounding sphere; positions are already centred on it.
  const sphere = views[0].geometry.boundingSphere ?? new Sphere();
  const radius = sphere.radius > 0 ? sphere.radius : 1;
  camera.near = radius / 100;
  camera.far = radius * 100;
  camera.position.set(sphere.center.x, sphere.center.y, sphere.center.z + radius / Math.tan((35 / 2) * Math.PI / 180) * 1.1);
  camera.updateProjectionMatrix();

  let pending = false;
  const renderAll = () => {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      for (const view of views) view.render();
      document.body.dataset.frames = String(Number(document.body.dataset.frames ?? 0) + 1);
    });
  };

  // One camera for both views; each canvas has its own controls, and moving one carries the
  // other's orbit centre along so the next drag on it continues from the same state.
  const controls = views.map((view) => {
    const c = new OrbitControls(camera, view.canvas);
    c.target.copy(sphere.center);
    c.update();
    return c;
  });
  controls.forEach((c, i) =>
    c.addEventListener('change', () => {
      controls[1 - i].target.copy(c.target);
      renderAll();
    }));

  const resize = () => {
    const width = views[0].canvas.clientWidth, height = views[0].canvas.clientHeight;
    if (!width || !height) return;
    camera.aspect = width / height;
    camera.updateProjectionMatrix();
    for (const view of views) view.resize(width, height);
    renderAll();
  };
  new ResizeObserver(resize).observe(views[0].canvas);

  const wireframe = document.getElementById('wireframe');
  const colormap = document.getElementById('colormap');
  // The checker texture: offered only when both meshes have texture coordinates.
  const checker = document.getElementById('checker');
  const checkerSquares = document.getElementById('checker-squares');
  if (data.texture) {
    document.getElementById('checker-controls').hidden = false;
    checkerSquares.value = String(data.texture.squares);
    const applyChecker = () => {
      const squares = Math.min(256, Math.max(1, Math.round(Number(checkerSquares.value) || data.texture.squares)));
      for (const view of views) view.setChecker(checker.checked ? squares : 0);
      document.body.dataset.checker = checker.checked ? String(squares) : '0';
      renderAll();
    };
    checker.addEventListener('change', applyChecker);
    checkerSquares.addEventListener('change', applyChecker);
    if (checker.checked) applyChecker();
  }
  wireframe.addEventListener('change', () => {
    for (const view of views) view.setWireframe(wireframe.checked);
    renderAll();
  });
  colormap.addEventListener('change', () => {
    for (const view of views) view.setColormap(colormap.value);
    showLegend(data, colormap.value);
    renderAll();
  });
  for (const view of views) view.setColormap(colormap.value);
  showLegend(data, colormap.value);
  resize();
  document.body.dataset.ready = '1';
}

main();
