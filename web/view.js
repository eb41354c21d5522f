// The camproj view page's script (embedded by lib/src/view.cc; data from its SceneJson). It draws;
// every geometric quantity (rays, frustum corners, residuals, the three.js camera) comes computed
// in the page's data. Pixels in the data are kCenter (OpenCV: (0,0) is the centre of the top-left
// pixel); three.js, the canvas and SVG use the corner convention: CornerFromCenter is the one
// place that converts (docs/conventions.md). Positions are in the page's frame, the world moved
// so that the eye is its origin (`*_in_page` = point_in_world - page_origin_in_world; WebGL's
// float32 keeps survey coordinates to centimetres only), and the three.js camera is exported
// relative to that origin.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const data = JSON.parse(document.getElementById('camproj-data').textContent);
const [W, H] = data.image_size;
const kTestMode = location.hash === '#camproj-test';
const points = data.points;

function CornerFromCenter(p) { return [p[0] + 0.5, p[1] + 0.5]; }

// Viridis (matplotlib's colour-blind-safe, perceptually uniform scale), a few stops.
const kViridis = [[68, 1, 84], [72, 40, 120], [62, 74, 137], [49, 104, 142], [38, 130, 142],
                  [31, 158, 137], [53, 183, 121], [110, 206, 88], [181, 222, 43], [253, 231, 37]];
const kOutlierCss = '#ff5a1f';  // vermillion, away from viridis's hues; outliers differ in shape too
function ScaleRgb(t) {
  t = Math.min(1, Math.max(0, t)) * (kViridis.length - 1);
  const i = Math.min(kViridis.length - 2, Math.floor(t));
  const f = t - i;
  return kViridis[i].map((c, k) => Math.round(c + f * (kViridis[i + 1][k] - c)));
}
const inlierResiduals = points.filter(p => !p.outlier && p.residual_px !== null)
                              .map(p => p.residual_px);
const scaleMaxPx = Math.max(1, ...inlierResiduals);
function ResidualCss(p) {
  if (p.outlier) return kOutlierCss;
  if (p.residual_px === null) return '#9aa0a6';
  const [r, g, b] = ScaleRgb(p.residual_px / scaleMaxPx);
  return `rgb(${r},${g},${b})`;
}

// ---- The camera camproj export --to three writes, loaded as docs/exports.md says.
function ExportedCamera(c) {
  let camera;
  if (c.type === 'OrthographicCamera') {
    camera = new THREE.OrthographicCamera(c.left ?? -1, c.right ?? 1, c.top ?? 1, c.bottom ?? -1,
                                          c.near, c.far ?? 1e9);
  } else {
    camera = new THREE.PerspectiveCamera(c.fov ?? 50, c.aspect ?? 1, c.near, c.far ?? 1e9);
  }
  camera.position.fromArray(c.position);
  camera.quaternion.fromArray(c.quaternion);
  if (c.view) {
    camera.setViewOffset(c.view.fullWidth, c.view.fullHeight, c.view.offsetX, c.view.offsetY,
                         c.view.width, c.view.height);
  }
  camera.projectionMatrix.fromArray(c.projectionMatrix);  // exact; never updateProjectionMatrix()
  camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert();
  camera.updateMatrixWorld(true);
  return camera;
}
const throughCamera = ExportedCamera(data.three);

// ---- Page structure.
const stage = document.getElementById('stage');
const frame = document.getElementById('frame');
const overlay = document.getElementById('overlay');
const labels = document.getElementById('labels');
const renderer = new THREE.WebGLRenderer({ antialias: !kTestMode, alpha: true,
                                           preserveDrawingBuffer: true });
renderer.setPixelRatio(kTestMode ? 1 : Math.min(window.devicePixelRatio || 1, 2));
frame.insertBefore(renderer.domElement, overlay);
let photo = null;
if (data.image) {
  photo = document.createElement('img');
  photo.src = data.image.data_url;
  photo.style.cssText = 'position:absolute;left:0;top:0;display:none';
  frame.insertBefore(photo, renderer.domElement);
}

// ---- Scene.
const scene = new THREE.Scene();
const orbitOnly = new THREE.Group();  // frustum, rays, image plane: not in the view through
scene.add(orbitOnly);
const V3 = a => new THREE.Vector3(a[0], a[1], a[2]);
function Segments(pairs, colour, opacity = 1) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(pairs.flat(2), 3));
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({
    color: colour, transparent: opacity < 1, opacity }));
}
const eye = V3(data.eye_in_page);
const fr = data.frustum;
{
  const near = fr.near_corners_in_page, far = fr.far_corners_in_page;
  const lines = [];
  for (let i = 0; i < 4; ++i) {
    lines.push([near[i], near[(i + 1) % 4]], [far[i], far[(i + 1) % 4]], [near[i], far[i]]);
    if (data.projection === 'perspective') lines.push([data.eye_in_page, near[i]]);
  }
  orbitOnly.add(Segments(lines, 0xd8dce3, 0.85));
  // The image plane through the lens (computed by camproj: a grid whose vertices lie on their
  // pixels' rays). Its top edge in colour, so that the frustum's up is obvious.
  const img = fr.image_plane;
  const Polyline = vertices => vertices.slice(0, -1).map((v, i) => [v, vertices[i + 1]]);
  if (img.top_edge_in_page.length > 1) {
    orbitOnly.add(Segments(Polyline(img.top_edge_in_page), 0x56b4e9));
  }
  const plane = new THREE.BufferGeometry();
  plane.setAttribute('position', new THREE.Float32BufferAttribute(img.positions_in_page.flat(), 3));
  // Texture v runs up: the image's top row at v = 1.
  plane.setAttribute('uv', new THREE.Float32BufferAttribute(img.uv.flat(), 2));
  plane.setIndex(img.triangles.flat());
  const material = new THREE.MeshBasicMaterial({ color: 0x60656e, side: THREE.DoubleSide,
                                                 transparent: true, opacity: 0.35,
                                                 depthWrite: false });
  if (data.image) {
    new THREE.TextureLoader().load(data.image.data_url, texture => {
      texture.colorSpace = THREE.SRGBColorSpace;
      material.map = texture;
      material.color.set(0xffffff);
      material.opacity = 0.75;
      material.needsUpdate = true;
    });
  }
  orbitOnly.add(new THREE.Mesh(plane, material));
  for (const run of img.outline_in_page) orbitOnly.add(Segments(Polyline(run), 0x9aa0a6));
}
// Rays from the eye through each observed pixel, to the point's depth, and the residual in the
// world: from the ray's end to the point.
{
  const rays = [], outlierRays = [], gaps = [];
  const gapColours = [];
  for (const p of points) {
    if (!p.ray_end_in_page) continue;
    (p.outlier ? outlierRays : rays).push([p.ray_start_in_page, p.ray_end_in_page]);
    gaps.push([p.ray_end_in_page, p.point_in_page]);
    const c = new THREE.Color(ResidualCss(p));
    gapColours.push(c.r, c.g, c.b, c.r, c.g, c.b);
  }
  if (rays.length) orbitOnly.add(Segments(rays, 0x7fa7c9, 0.35));
  if (outlierRays.length) orbitOnly.add(Segments(outlierRays, kOutlierCss, 0.8));
  if (gaps.length) {
    const g = Segments(gaps, 0xffffff);
    g.geometry.setAttribute('color', new THREE.Float32BufferAttribute(gapColours, 3));
    g.material.vertexColors = true;
    scene.add(g);
  }
}
// The eye.
orbitOnly.add(new THREE.Points(
    new THREE.BufferGeometry().setFromPoints([eye]),
    new THREE.PointsMaterial({ color: 0xffffff, size: 7, sizeAttenuation: false })));

// The model.
if (data.mesh) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(data.mesh.positions_in_page, 3));
  geometry.setIndex(data.mesh.triangles);
  geometry.computeVertexNormals();
  scene.add(new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({
    color: 0x8c96a8, transparent: true, opacity: 0.22, side: THREE.DoubleSide,
    depthWrite: false })));
  if (data.mesh.triangles.length / 3 <= 200000) {
    scene.add(new THREE.LineSegments(new THREE.EdgesGeometry(geometry, 1),
                                     new THREE.LineBasicMaterial({ color: 0xb8c0cc,
                                                                   transparent: true,
                                                                   opacity: 0.45 })));
  }
}

// The points: screen-sized markers coloured by residual; outliers as vermillion rings.
const kMarkerVertex = `
  attribute vec3 colour; attribute float kind; varying vec3 vColour; varying float vKind;
  uniform float size;
  void main() {
    vColour = colour; vKind = kind;
    gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
    gl_PointSize = size;
  }`;
const kMarkerFragment = `
  precision highp float; varying vec3 vColour; varying float vKind; uniform float size;
  uniform float cross;
  void main() {
    vec2 d = (gl_PointCoord - 0.5) * size;
    float r = length(d);
    float halfSize = 0.5 * size;
    if (cross > 0.5) {  // a thin cross with a dark outline, centred on the projected point
      float a = min(abs(d.x), abs(d.y));
      if (a > 2.0) discard;
      gl_FragColor = vec4(a > 0.9 ? vec3(0.0) : vColour, 1.0);
      return;
    }
    if (r > halfSize) discard;
    if (vKind > 0.5) {  // outlier: a ring
      if (r < halfSize - 3.0) discard;
      gl_FragColor = vec4(vColour, 1.0);
      return;
    }
    gl_FragColor = vec4(r > halfSize - 1.5 ? vec3(0.92) : vColour, 1.0);  // light rim: dark colours show on the dark ground
  }`;
const markerUniforms = { size: { value: 11 }, cross: { value: 0 } };
const markers = (() => {
  const positions = [], colours = [], kinds = [];
  for (const p of points) {
    positions.push(...p.point_in_page);
    const c = new THREE.Color(ResidualCss(p));
    colours.push(c.r, c.g, c.b);
    kinds.push(p.outlier ? 1 : 0);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  geometry.setAttribute('colour', new THREE.Float32BufferAttribute(colours, 3));
  geometry.setAttribute('kind', new THREE.Float32BufferAttribute(kinds, 1));
  const m = new THREE.Points(geometry, new THREE.ShaderMaterial({
    vertexShader: kMarkerVertex, fragmentShader: kMarkerFragment, uniforms: markerUniforms }));
  m.frustumCulled = false;
  return m;
})();
scene.add(markers);

// ---- Orbit camera: above, right of and behind the fitted camera, far enough to see the points,
// the frustum and the eye.
const centre = new THREE.Vector3();
const bounds = new THREE.Box3();
for (const p of points) bounds.expandByPoint(V3(p.point_in_page));
for (const run of fr.image_plane.outline_in_page) for (const c of run) bounds.expandByPoint(V3(c));
bounds.expandByPoint(eye);
const sphere = bounds.getBoundingSphere(new THREE.Sphere());
centre.copy(sphere.center);
const radius = Math.max(1e-9, sphere.radius);
const orbitCamera = new THREE.PerspectiveCamera(45, 1, radius * 1e-3, radius * 100);
{
  const up = new THREE.Vector3(0, 1, 0).applyQuaternion(throughCamera.quaternion);
  const right = new THREE.Vector3(1, 0, 0).applyQuaternion(throughCamera.quaternion);
  const back = new THREE.Vector3(0, 0, 1).applyQuaternion(throughCamera.quaternion);
  const direction = back.clone().multiplyScalar(0.8).addScaledVector(right, 0.9)
                        .addScaledVector(up, 0.6).normalize();
  orbitCamera.up.copy(up);
  orbitCamera.position.copy(centre).addScaledVector(direction, 2.4 * radius);
  orbitCamera.lookAt(centre);
}
const controls = new OrbitControls(orbitCamera, renderer.domElement);
controls.target.copy(centre);
controls.enableDamping = true;
controls.update();

// ---- Views.
let mode = 'orbit';
// The largest buffer WebGL renders into here, per side (MAX_VIEWPORT_DIMS, MAX_RENDERBUFFER_SIZE,
// MAX_TEXTURE_SIZE: 8192 in SwiftShader); the browser may cap a canvas's area further (~33 Mpx).
function LargestSide() {
  const gl = renderer.getContext();
  const dims = gl.getParameter(gl.MAX_VIEWPORT_DIMS);
  return Math.min(dims[0], dims[1], gl.getParameter(gl.MAX_RENDERBUFFER_SIZE),
                  renderer.capabilities.maxTextureSize);
}
// The drawing buffer through the camera: the image, pixel for pixel, where the browser allows it;
// else the image scaled by throughScale < 1 (the largest buffer it allows). The projection maps
// NDC onto the whole buffer and CSS stretches the canvas to the image's shape, so a scaled buffer
// is the same view at a lower resolution. (Before session 44 an image wider than the limit got a
// buffer cut to it while three.js drew as if it were whole: the view through the camera was off.)
let throughScale = 1;
function SizeThroughBuffer() {
  const gl = renderer.getContext();
  // Whole pixels (pixel ratio 1): with a fractional ratio three.js rounds the viewport in one
  // place and floors it in another (setRenderTarget(null)), a pixel short of the buffer.
  renderer.setPixelRatio(1);
  let r = Math.min(1, LargestSide() / Math.max(W, H));
  for (let attempt = 0; attempt < 3; ++attempt) {
    const bw = Math.max(1, Math.round(W * r)), bh = Math.max(1, Math.round(H * r));
    renderer.setSize(bw, bh, false);
    if (gl.drawingBufferWidth === bw && gl.drawingBufferHeight === bh) break;
    // The browser gave less (its cap on a canvas's area): ask for what it gave.
    r = Math.min(r, gl.drawingBufferWidth / W, gl.drawingBufferHeight / H);
  }
  throughScale = r;
  renderer.setViewport(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight);
  if (r < 1 && !document.getElementById('scaled-note')) {
    const note = document.createElement('div');
    note.id = 'scaled-note';
    note.className = 'note';
    note.textContent = `Through the camera: rendered at ${gl.drawingBufferWidth} × ` +
        `${gl.drawingBufferHeight} px, the ${W} × ${H} image scaled by ${r.toPrecision(3)} ` +
        "(the browser's largest WebGL canvas).";
    document.getElementById('legend').appendChild(note);
  }
}
function Layout() {
  const sw = stage.clientWidth, sh = stage.clientHeight;
  if (mode === 'orbit') {
    renderer.setPixelRatio(kTestMode ? 1 : Math.min(window.devicePixelRatio || 1, 2));
    renderer.setSize(sw, sh);
    orbitCamera.aspect = sw / sh;
    orbitCamera.updateProjectionMatrix();
    frame.style.width = sw + 'px';
    frame.style.height = sh + 'px';
    overlay.setAttribute('width', sw);
    overlay.setAttribute('height', sh);
    overlay.innerHTML = '';
  } else {
    // The drawing buffer is the image (SizeThroughBuffer); CSS scales it to the stage.
    const s = Math.min(sw / W, sh / H);
    SizeThroughBuffer();
    const cw = W * s, ch = H * s;
    for (const e of [renderer.domElement, photo].filter(Boolean)) {
      e.style.width = cw + 'px';
      e.style.height = ch + 'px';
    }
    frame.style.width = cw + 'px';
    frame.style.height = ch + 'px';
    DrawThroughOverlay(s, cw, ch);
  }
  labels.innerHTML = '';
  labelDivs.length = 0;
  if (mode === 'orbit') {
    for (const p of points) {
      const div = document.createElement('div');
      div.textContent = p.id;
      if (p.outlier) div.style.color = kOutlierCss;
      labels.appendChild(div);
      labelDivs.push(div);
    }
  }
}
const labelDivs = [];
const kSvg = 'http://www.w3.org/2000/svg';
function SvgElement(name, attributes) {
  const e = document.createElementNS(kSvg, name);
  for (const [k, v] of Object.entries(attributes)) e.setAttribute(k, v);
  return e;
}
// Observed pixels (circles), the residual to where three.js renders the point (its cross) and the
// ids, in image pixels (corner convention) scaled to the canvas's CSS size.
function DrawThroughOverlay(s, cw, ch) {
  overlay.innerHTML = '';
  overlay.setAttribute('width', cw);
  overlay.setAttribute('height', ch);
  overlay.setAttribute('viewBox', `0 0 ${W} ${H}`);
  const px = 1 / s;  // one CSS pixel in image pixels
  for (const p of points) {
    const [x, y] = CornerFromCenter(p.observed_px);
    const colour = ResidualCss(p);
    if (p.predicted_linear_px) {
      const [xp, yp] = CornerFromCenter(p.predicted_linear_px);
      overlay.appendChild(SvgElement('line', { x1: x, y1: y, x2: xp, y2: yp, stroke: colour,
                                               'stroke-width': 1.5 * px }));
    }
    overlay.appendChild(SvgElement('circle', { cx: x, cy: y, r: 7 * px, fill: 'none',
                                               stroke: '#000', 'stroke-width': 3.5 * px,
                                               opacity: 0.6 }));
    overlay.appendChild(SvgElement('circle', { cx: x, cy: y, r: 7 * px, fill: 'none',
                                               stroke: colour, 'stroke-width': 1.8 * px,
                                               'stroke-dasharray': p.outlier ? `${3 * px}` : 'none' }));
    const label = SvgElement('text', { x: x + 10 * px, y: y - 8 * px, 'font-size': 12 * px,
                                       fill: p.outlier ? kOutlierCss : '#fff',
                                       stroke: '#000', 'stroke-width': 3 * px,
                                       'paint-order': 'stroke',
                                       'font-family': 'ui-monospace, monospace' });
    label.textContent = p.id;
    overlay.appendChild(label);
  }
}
function SetMode(next) {
  mode = next;
  document.getElementById('orbit-button').classList.toggle('on', mode === 'orbit');
  document.getElementById('through-button').classList.toggle('on', mode === 'through');
  orbitOnly.visible = mode === 'orbit';
  controls.enabled = mode === 'orbit';
  markerUniforms.cross.value = mode === 'through' ? 1 : 0;
  markerUniforms.size.value = mode === 'through' ? 15 : 11;
  if (photo) photo.style.display = mode === 'through' ? 'block' : 'none';
  // Through the camera the image's own area is a shade lighter than the page, and outlined.
  renderer.setClearColor(mode === 'through' ? 0x2a2d33 : 0x1b1d21, mode === 'through' && photo ? 0 : 1);
  frame.style.outline = mode === 'through' ? '1px solid #5a5f69' : 'none';
  Layout();
  Render();
}
document.getElementById('orbit-button').onclick = () => SetMode('orbit');
document.getElementById('through-button').onclick = () => SetMode('through');
window.addEventListener('resize', () => { Layout(); Render(); });

const projected = new THREE.Vector3();
function Render() {
  if (mode === 'orbit') {
    renderer.render(scene, orbitCamera);
    const w = renderer.domElement.clientWidth, h = renderer.domElement.clientHeight;
    points.forEach((p, i) => {
      projected.fromArray(p.point_in_page).project(orbitCamera);
      const div = labelDivs[i];
      if (!div) return;
      const visible = projected.z < 1 && Math.abs(projected.x) < 1.2 && Math.abs(projected.y) < 1.2;
      div.style.display = visible ? 'block' : 'none';
      div.style.left = ((projected.x + 1) / 2 * w) + 'px';
      div.style.top = ((1 - projected.y) / 2 * h) + 'px';
    });
  } else {
    renderer.render(scene, throughCamera);
  }
}

// ---- The report beside the view.
// Every value from the data goes into the page's HTML through Escape or Fixed (the camera file's
// fit record is checked by camproj view, src/view.cc FitRecordForPage, and escaped here as well).
function Escape(text) {
  if (text === null || text === undefined) return '–';
  return String(text).replace(/[&<>"]/g, c => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;',
                                                 '"': '&quot;' })[c]);
}
function Fixed(x, digits) { return x === null || x === undefined ? '–' : Number(x).toFixed(digits); }
// The unit of a parameter's sigma as the camera file names it (docs/camera-file.md, `sigma`).
function SigmaUnit(name) {
  if (name.endsWith('_deg')) return '°';
  if (name.startsWith('eye_')) return 'world units';
  if (['fx', 'fy', 'skew'].includes(name)) {
    return data.projection === 'perspective' ? 'px' : 'px per world unit';
  }
  if (['cx', 'cy'].includes(name)) return 'px';
  return '';  // k1, k2, p1, p2, k3: no unit
}
function Report() {
  document.getElementById('title').textContent = data.camera_name;
  const bar = kViridis.map(c => `rgb(${c})`).join(',');
  let legend = `<h2>Legend</h2>
    <div>Points coloured by residual (px), colour-blind-safe scale:</div>
    <div id="colourbar" style="background:linear-gradient(to right,${bar})"></div>
    <div class="scale"><span>0</span><span>${Fixed(scaleMaxPx / 2, 2)}</span>
      <span>${Fixed(scaleMaxPx, 2)} px</span></div>
    ${points.some(p => p.outlier) ? `<div><span style="color:${kOutlierCss}">◯ ring, dashed
      circle</span>: left out by the fit (outlier)</div>` : ''}
    <div class="muted">Orbit: frustum (near plane, image plane at ${data.image_depth_is_median
      ? "the points' median depth" : 'depth'} ${Fixed(fr.image_depth, 3)}${fr.image_plane.through_lens
      ? ' drawn through the lens (its edges bend where the linear frustum\'s are straight)' : ''},
      far plane drawn at ${Fixed(fr.far_drawn, 3)}; the camera's far
      is ${typeof fr.far === 'number' ? Number(fr.far).toPrecision(4) : fr.far}), ${data.projection ===
      'perspective' ? 'rays eye → observed pixel' : 'rays (parallel) from the near plane through each observed pixel'},
      coloured segment = the residual in the world.
      Through the camera: circle = observed pixel, cross = where three.js renders the point with
      the exported camera, line = residual.</div>`;
  for (const n of data.notes) legend += `<div class="note">${Escape(n)}</div>`;
  document.getElementById('legend').innerHTML = legend;

  const fit = data.fit;
  let html = '';
  const rows = (pairs) => pairs.map(([k, v]) => `<tr><td>${Escape(k)}</td><td>${v}</td></tr>`).join('');
  const summary = [['image', `${W} × ${H} px, ${Escape(data.projection)}`],
                   ['three.js', `r${data.three_version.split('.')[1]}`]];
  if (fit) {
    summary.unshift(['model', Escape(fit.model)]);
    summary.push(['residuals', `RMS ${Fixed(fit.rms_px, 3)}, median ${Fixed(fit.median_px, 3)},
                                max ${Fixed(fit.max_px, 3)} px over ${Escape(fit.num_points)} points`]);
    if (fit.outliers && fit.outliers.length) {
      summary.push(['outliers', `${fit.outliers.length} left out (${Escape(fit.outlier_method || '')})`]);
    }
    if (fit.linearity) {
      // The camera file's linearity check (docs/camera-file.md).
      const l = fit.linearity;
      const factor = typeof l.worst_deviation === 'number' ? Fixed(1 + l.worst_deviation, 2) : 'unbounded';
      summary.push(['σ', l.linear ? `hold out to the ${Escape(l.level * 100)} % region (error inflation ≤ ${factor})`
                                  : `first-order only: curved within the noise's reach (inflation ${factor} along ${Escape(l.worst_direction)})`]);
    }
  }
  html += `<h2>Camera</h2><table>${rows(summary)}</table>`;
  if (fit && fit.sigma) {
    html += '<h2>Parameters ± σ</h2><table>' +
        Object.entries(fit.sigma).map(([k, v]) =>
            `<tr><td>${Escape(k)}</td><td class="num">± ${Number(v).toPrecision(3)}</td>
             <td class="muted">${SigmaUnit(k)}</td></tr>`)
            .join('') + '</table>';
  }
  if (fit && fit.left_out && fit.left_out.length) {
    html += '<h2>Left out, and why</h2><table>' + fit.left_out.map(e =>
        `<tr><td>${Escape(e.name)}</td><td class="muted">${Escape(e.why)}</td></tr>`).join('') +
        '</table>';
  }
  if (points.length) {
    const worst = points.filter(p => p.residual_px !== null)
                        .sort((a, b) => b.residual_px - a.residual_px).slice(0, 10);
    html += '<h2>Worst points</h2><table><tr><th>id</th><th class="num">residual px</th><th></th></tr>' +
        worst.map(p => `<tr class="${p.outlier ? 'outlier' : ''}"><td>${Escape(p.id)}</td>
          <td class="num">${Fixed(p.residual_px, 3)}</td><td>${p.outlier ? 'outlier' :
          (p.inside_image ? '' : 'outside the image')}</td></tr>`).join('') + '</table>';
  }
  if (fit && fit.selection && fit.selection.candidates) {
    const s = fit.selection;
    html += `<h2>Models tried (${Escape(s.criterion)})</h2><table>
      <tr><th>model</th><th class="num">RMS px</th><th class="num">${Escape(s.criterion)}</th></tr>` +
        s.candidates.map(c => `<tr><td title="${Escape(c.verdict)}">${Escape(c.name)}
          ${c.name === fit.model ? ' ◀' : ''}</td><td class="num">${Fixed(c.rms_px, 3)}</td>
          <td class="num">${c.criterion === undefined ? 'refused' : Fixed(c.criterion, 1)}</td></tr>`)
          .join('') + '</table>';
  }
  if (!fit) html += '<p class="muted">No fit record in the camera file.</p>';
  document.getElementById('report').innerHTML = html;
}

// ---- Test mode (#camproj-test; tests/view_browser_test.cc): the view through the camera, each
// point rendered alone as a Gaussian spot (sigma 2 px, in a 17 px sprite: the tail cut at the
// sprite's edge moves the centroid by < 1e-3 px) into the page's own canvas as the view through
// the camera sized it (SizeThroughBuffer: the image, or the image scaled to the browser's
// largest canvas); the centroid of the read-back intensities, in kCenter image pixels, is where
// three.js put the point.
function MeasureThrough() {
  const kSize = 17, kSigma = 2.0, kHalf = 16, n = 2 * kHalf + 1;
  const gl = renderer.getContext();
  const TW = gl.drawingBufferWidth, TH = gl.drawingBufferHeight;
  const material = new THREE.ShaderMaterial({
    vertexShader: `void main() {
      gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
      gl_PointSize = ${kSize}.0; }`,
    fragmentShader: `precision highp float; void main() {
      vec2 d = (gl_PointCoord - 0.5) * ${kSize}.0;
      float w = exp(-dot(d, d) / ${2 * kSigma * kSigma}.0);
      gl_FragColor = vec4(w, w, w, 1.0); }`,
    depthTest: false, depthWrite: false, blending: THREE.NoBlending });
  const geometry = new THREE.BufferGeometry();
  const position = new THREE.Float32BufferAttribute(new Float32Array(3), 3);
  geometry.setAttribute('position', position);
  const spot = new THREE.Points(geometry, material);
  spot.frustumCulled = false;
  const alone = new THREE.Scene();
  alone.background = new THREE.Color(0, 0, 0);
  alone.add(spot);
  const buffer = new Uint8Array(n * n * 4);
  const results = [];
  for (const p of points) {
    const result = { id: p.id, u: null, v: null };
    results.push(result);
    if (!p.predicted_linear_px) continue;
    projected.fromArray(p.point_in_page).project(throughCamera);
    const xw = (projected.x + 1) / 2 * W, yw = (projected.y + 1) / 2 * H;
    result.three_math = [xw - 0.5, H - yw - 0.5];
    const xt = xw * TW / W, yt = yw * TH / H;  // in the canvas's pixels
    if (!(xt > kHalf && xt < TW - kHalf && yt > kHalf && yt < TH - kHalf)) continue;  // at the edge
    position.setXYZ(0, ...p.point_in_page);
    position.needsUpdate = true;
    renderer.render(alone, throughCamera);
    const x0 = Math.floor(xt) - kHalf, y0 = Math.floor(yt) - kHalf;
    gl.readPixels(x0, y0, n, n, gl.RGBA, gl.UNSIGNED_BYTE, buffer);
    let mass = 0, sx = 0, sy = 0;
    for (let j = 0; j < n; ++j) {
      for (let i = 0; i < n; ++i) {
        const w = buffer[4 * (j * n + i)];
        mass += w; sx += w * (x0 + i + 0.5); sy += w * (y0 + j + 0.5);
      }
    }
    result.mass = mass;
    if (mass > 0) {
      // Canvas pixels -> window (x up from the bottom) -> kCenter: u = x - 0.5, v = H - y - 0.5.
      result.u = sx / mass * W / TW - 0.5;
      result.v = H - sy / mass * H / TH - 0.5;
    }
  }
  return { points: results, target_size: [TW, TH] };
}

Report();
SetMode('orbit');
if (kTestMode) {
  SetMode('through');
  const measured = MeasureThrough();
  const result = { three_revision: THREE.REVISION, image_size: [W, H],
                   webgl2: renderer.capabilities.isWebGL2, points: measured.points,
                   target_size: measured.target_size, through_scale: throughScale };
  Render();
  document.getElementById('camproj-test-result').textContent = JSON.stringify(result);
} else {
  if (location.hash === '#through') SetMode('through');
  (function Loop() {
    if (mode === 'orbit') controls.update();
    Render();
    requestAnimationFrame(Loop);
  })();
}
