// The three.js export as its users write it (docs/exports.md, section "three"): the doc's loading
// and resizing snippets, cut out of the doc between their `<!-- test: NAME -->` markers and run as
// they stand with the real `three` package (web/node_modules, pinned by web/package-lock.json),
// project the bundled points with Vector3.project(camera) before any render. They must agree with
// `camproj project` in three's corner pixel convention (camproj's kCenter pixel + 0.5).
//
// Usage: node three_export_test.mjs CAMPROJ_BINARY DATA_DIR DOCS_EXPORTS_MD WEB_DIR
//
// Tolerance: both sides compute in float64 from the same 17-digit numbers; three's path (matrix
// products, the inverse in updateMatrixWorld, fov through tan/atan in degrees) loses a few 1e-16
// relative, times a few thousand px: ~1e-12 px. 1e-6 px leaves six orders of margin and still
// catches any convention error (half pixels, a transposed matrix, a stale matrixWorldInverse).
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';

const [camproj, dataDir, docPath, webDir] = process.argv.slice(2);
if (!webDir) {
  console.error('usage: node three_export_test.mjs CAMPROJ DATA_DIR EXPORTS_MD WEB_DIR');
  process.exit(1);
}
const require = createRequire(path.join(webDir, 'package.json'));
const THREE = require('three');
const kTolerancePx = 1e-6;
let failures = 0;
function check(ok, message) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${message}`);
  if (!ok) failures += 1;
}

// The fenced js block after `<!-- test: NAME -->` in the doc, verbatim.
const doc = readFileSync(docPath, 'utf8');
function snippet(name) {
  const match = doc.match(new RegExp(`<!-- test: ${name} -->\\s*\`\`\`js\\n([\\s\\S]*?)\`\`\``));
  if (!match) throw new Error(`${docPath}: no js block after <!-- test: ${name} -->`);
  return match[1];
}
const loadSnippet = snippet('three_load');
const resizeSnippet = snippet('three_resize');
if (!/camera\.updateMatrixWorld\(\)/.test(loadSnippet)) {
  throw new Error(`${docPath}: the three_load snippet does not call camera.updateMatrixWorld()`);
}

const work = mkdtempSync(path.join(os.tmpdir(), 'camproj-three-'));
process.on('exit', () => rmSync(work, { recursive: true, force: true }));
const run = (...args) => execFileSync(camproj, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });

// Runs the doc's snippets with `fetch` and `renderer` standing in for the browser's: the snippet
// text itself is unchanged. Returns the loaded camera, the parsed export and fitCanvas.
const AsyncFunction = (async () => {}).constructor;
async function loadWithDoc(threePath, load = loadSnippet) {
  const fetch = async (url) => {
    if (url !== 'camera.three.json') throw new Error(`the snippet fetched ${url}`);
    return { json: async () => JSON.parse(readFileSync(threePath, 'utf8')) };
  };
  const renderer = { size: null, setSize(w, h) { this.size = [w, h]; } };
  const body = `${load}\n${resizeSnippet}\nreturn { camera, c, fitCanvas: (...a) => fitCanvas(...a) };`;
  const result = await new AsyncFunction('THREE', 'fetch', 'renderer', body)(THREE, fetch, renderer);
  return { ...result, renderer };
}

// camproj project's pixels in the corner convention: kCenter + 0.5 (docs/conventions.md, 2).
function camprojPixels(cameraPath, pointsPath) {
  const rows = run('project', cameraPath, pointsPath).trim().split('\n').slice(1);
  return rows.map((row) => {
    const f = row.split(',');
    return { world: [+f[1], +f[2], +f[3]], corner: [+f[4] + 0.5, +f[5] + 0.5] };
  });
}

// three's canvas pixels of a world point for a canvas of width x height.
function threePixel(camera, world, width, height) {
  const ndc = new THREE.Vector3(...world).project(camera);
  return [(ndc.x + 1) / 2 * width, (1 - ndc.y) / 2 * height];
}

// Worst distance (px) between three's pixels and `expected(point)` over the points.
function worstPx(camera, points, width, height, expected) {
  let worst = 0;
  for (const p of points) {
    const got = threePixel(camera, p.world, width, height);
    const want = expected(p);
    worst = Math.max(worst, Math.hypot(got[0] - want[0], got[1] - want[1]));
  }
  return worst;
}

// Where the resize recipe puts a point: the image centred in the canvas at scale s.
function letterboxed(c, width, height) {
  const [W, H] = c.image_size;
  const s = Math.min(width / W, height / H);
  return (p) => [width / 2 + s * (p.corner[0] - W / 2), height / 2 + s * (p.corner[1] - H / 2)];
}

async function testCamera(label, cameraPath, pointsPath, offCentre) {
  const threePath = path.join(work, `${label}.three.json`);
  writeFileSync(threePath, run('export', cameraPath, '--to', 'three', '--quiet'));
  const points = camprojPixels(cameraPath, pointsPath);
  const { camera, c, fitCanvas, renderer } = await loadWithDoc(threePath);
  const [W, H] = c.image_size;
  check(Boolean(c.view) === offCentre, `${label}: view ${c.view ? 'present' : 'absent'} (off-centre: ${offCentre})`);
  check(renderer.size && renderer.size[0] === W && renderer.size[1] === H, `${label}: renderer.setSize(${W}, ${H})`);

  // Before any render: the snippet's updateMatrixWorld() made matrixWorldInverse.
  let worst = worstPx(camera, points, W, H, (p) => p.corner);
  check(worst <= kTolerancePx, `${label}: ${points.length} points, before a render, worst ${worst.toExponential(2)} px <= ${kTolerancePx}`);

  // What a render does to the camera (WebGLRenderer.render: updateMatrixWorld of a parentless
  // camera), and three's own rebuild of projectionMatrix (resize handlers, reversedDepthBuffer).
  camera.updateMatrixWorld();
  worst = worstPx(camera, points, W, H, (p) => p.corner);
  check(worst <= kTolerancePx, `${label}: after the render's updateMatrixWorld, worst ${worst.toExponential(2)} px`);
  camera.updateProjectionMatrix();
  worst = worstPx(camera, points, W, H, (p) => p.corner);
  check(worst <= kTolerancePx, `${label}: after updateProjectionMatrix (rebuilt from fov, aspect, view), worst ${worst.toExponential(2)} px`);

  // Without the snippet's updateMatrixWorld() the projection before a render is garbage: the line
  // is needed.
  const { camera: stale } = await loadWithDoc(threePath, loadSnippet.replace(/^.*updateMatrixWorld\(\).*$/m, ''));
  worst = worstPx(stale, points, W, H, (p) => p.corner);
  check(worst > 1, `${label}: without updateMatrixWorld() the points are off by ${worst.toFixed(1)} px (> 1 px)`);

  // Resizing to other aspects with the doc's recipe, and with the matrix form.
  for (const [width, height] of [[2400, 1000], [1000, 1000], [W / 2, H / 2]]) {
    const { camera: resized, fitCanvas: fit, renderer: r } = await loadWithDoc(threePath);
    fit(resized, c, width, height);
    worst = worstPx(resized, points, width, height, letterboxed(c, width, height));
    check(worst <= kTolerancePx && r.size[0] === width,
          `${label}: fitCanvas to ${width}x${height}, worst ${worst.toExponential(2)} px`);
    const s = Math.min(width / W, height / H);
    resized.projectionMatrix.fromArray(c.projectionMatrix)
        .premultiply(new THREE.Matrix4().makeScale(s * W / width, s * H / height, 1));
    resized.projectionMatrixInverse.copy(resized.projectionMatrix).invert();
    worst = worstPx(resized, points, width, height, letterboxed(c, width, height));
    check(worst <= kTolerancePx, `${label}: scaled projectionMatrix for ${width}x${height}, worst ${worst.toExponential(2)} px`);
  }

  // The usual resize handler, on a canvas wider than the image (where it is right for a centred
  // camera): wrong by hundreds of px for an off-centre one, as the doc warns.
  const [width, height] = [2400, 1000];
  const { camera: naive } = await loadWithDoc(threePath);
  naive.aspect = width / height;
  naive.updateProjectionMatrix();
  worst = worstPx(naive, points, width, height, letterboxed(c, width, height));
  if (offCentre) {
    check(worst > 1, `${label}: camera.aspect = ${width}/${height}; updateProjectionMatrix() is off by ${worst.toFixed(1)} px (> 1 px: the wrong way)`);
  } else {
    // Right only with square pixels (three's aspect is then W/H); this fit frees fy/fx.
    console.log(`info ${label}: centred, fy/fx != 1: camera.aspect = ${width}/${height}; updateProjectionMatrix() is off by ${worst.toFixed(2)} px`);
  }
}

// Fitted cameras: the projector (principal point on the bottom edge: off-centre, a view offset)
// and the synthetic scene with the principal point fixed at the centre (no view).
const projector = path.join(work, 'projector.json');
run('fit', path.join(dataDir, 'projector/points.csv'), '--image-size', '1920x1080', '-o', projector);
await testCamera('projector', projector, path.join(dataDir, 'projector/points.csv'), true);
const centred = path.join(work, 'centred.json');
// (--sigma 3: the scene's principal point is not at the centre, so the centred fit leaves ~3 px.)
run('fit', path.join(dataDir, 'synthetic/points.csv'), '--image-size', '1280x800', '--fix',
    'principal-point', '--sigma', '3', '-o', centred);
await testCamera('centred', centred, path.join(dataDir, 'synthetic/points.csv'), false);

// zo reversed-Z, where a renderer made with reversedDepthBuffer: true runs, on its first render,
// what three r187's WebGLRenderer does for a camera whose reversedDepth is not yet true:
// `camera._reversedDepth = true; camera.updateProjectionMatrix()`. The snippet sets the field, so
// the exact matrix stays -- also for a skewed camera, which three cannot rebuild (that rebuild put
// points 20-29 px off) -- and a later rebuild of a camera three can rebuild is reversed too.
async function testReversedZ(label, cameraPath, pointsPath) {
  const threePath = path.join(work, `${label}.zo-reversed.three.json`);
  writeFileSync(threePath, run('export', cameraPath, '--to', 'three', '--depth', 'zo', '--reversed-z', '--quiet'));
  const points = camprojPixels(cameraPath, pointsPath);
  const { camera, c } = await loadWithDoc(threePath);
  const [W, H] = c.image_size;
  check(c.type === 'PerspectiveCamera', `${label}: type ${c.type}`);
  const reversedDepthBuffer = true;
  if (reversedDepthBuffer && camera.reversedDepth !== true) {
    camera._reversedDepth = true;
    camera.updateProjectionMatrix();
  }
  let worst = worstPx(camera, points, W, H, (p) => p.corner);
  check(worst <= kTolerancePx, `${label}: zo reversed-Z after the renderer's first-render check, worst ${worst.toExponential(2)} px`);
  const exact = camera.projectionMatrix.elements.slice();
  check(exact.every((v, i) => v === c.projectionMatrix[i]), `${label}: zo reversed-Z projectionMatrix kept exactly`);
  if (c.fov !== undefined) {
    camera.updateProjectionMatrix();
    worst = worstPx(camera, points, W, H, (p) => p.corner);
    check(worst <= kTolerancePx, `${label}: zo reversed-Z rebuilt by updateProjectionMatrix, worst ${worst.toExponential(2)} px`);
  }
}
await testReversedZ('projector', projector, path.join(dataDir, 'projector/points.csv'));
// The projector with skew (no fov, aspect or view form): a minimal camera file.
const fitted = JSON.parse(readFileSync(projector, 'utf8'));
const skewed = path.join(work, 'skewed.json');
writeFileSync(skewed, JSON.stringify({
  image_size: fitted.image_size,
  intrinsics: { ...fitted.intrinsics, skew: 35 },
  cam_from_world: fitted.cam_from_world,
  frustum: { near: fitted.frustum.near, far: fitted.frustum.far },
}));
await testReversedZ('skewed', skewed, path.join(dataDir, 'projector/points.csv'));

console.log(failures === 0 ? 'three_export_test: all passed' : `three_export_test: ${failures} failed`);
process.exit(failures === 0 ? 0 : 1);
