// featsense view on a tile set: the map's 3D Tiles tileset streamed by 3d-tiles-renderer,
// coarse levels far away and full resolution near, coloured by height.
//
// For tests and scripts, window.featsenseTiles holds: firstFrameMs (page start to the first
// frame that shows a tile), visible (content URIs shown now, by level), fullResolutionShown.
// `?focus=x,y,z&distance=d` (map frame, metres) starts the camera looking at a point.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { Scheduler, TilesRenderer } from '3d-tiles-renderer';

const state = { firstFrameMs: null, visible: {}, fullResolutionShown: 0, errors: [] };
window.featsenseTiles = state;

const container = document.getElementById('scene');
const status = document.getElementById('status');
const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.4);
sun.position.set(0.4, 1.0, 0.6);
scene.add(sun);

const camera = new THREE.PerspectiveCamera(55, window.innerWidth / window.innerHeight, 0.1, 1e5);
// Made with the renderer, once the first tiles are on their way.
let controls = null;
const viewTarget = new THREE.Vector3();

const tiles = new TilesRenderer('tileset/tileset.json');
// The tileset is the map frame, Z up; three.js is Y up.
tiles.group.rotation.x = -Math.PI / 2;
scene.add(tiles.group);
tiles.setCamera(camera);
tiles.setResolution(camera, window.innerWidth, window.innerHeight);

const errorTarget = document.getElementById('error-target');
tiles.errorTarget = Number(errorTarget.value);
errorTarget.addEventListener('change', () => {
  tiles.errorTarget = Math.max(1, Number(errorTarget.value) || 8);
});

/// Map frame (Z up) to three.js (Y up), as the group's rotation turns it.
function toView(x, y, z) {
  return new THREE.Vector3(x, z, -y);
}

function parameter(name) {
  return new URLSearchParams(window.location.search).get(name);
}

// Height colours: the same ramp for every tile, from the tileset's box (map frame, metres).
let heightRange = [0, 1];
function colourByHeight(mesh, model) {
  const geometry = mesh.geometry;
  const positions = geometry.getAttribute('position');
  const colours = new Float32Array(positions.count * 3);
  const point = new THREE.Vector3();
  const colour = new THREE.Color();
  // The mesh's place in the tileset's frame (Z up): its transforms up to the tile's model, and
  // the model's own (the renderer turns glTF's Y up into the tileset's Z up there).
  model.updateMatrixWorld(true);
  const toTileset = new THREE.Matrix4();
  if (model.parent) toTileset.copy(model.parent.matrixWorld).invert();
  toTileset.multiply(mesh.matrixWorld);
  for (let i = 0; i < positions.count; ++i) {
    point.fromBufferAttribute(positions, i).applyMatrix4(toTileset);
    const t = Math.min(1, Math.max(0, (point.z - heightRange[0]) / (heightRange[1] - heightRange[0])));
    colour.setHSL(0.66 * (1 - t), 0.55, 0.55);
    colours.set([colour.r, colour.g, colour.b], i * 3);
  }
  geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
  mesh.material = new THREE.MeshLambertMaterial({ vertexColors: true, side: THREE.DoubleSide });
}

tiles.addEventListener('load-tileset', () => {
  const box = new THREE.Box3();
  if (!tiles.getBoundingBox(box)) return;
  heightRange = [box.min.z, box.max.z > box.min.z ? box.max.z : box.min.z + 1];
  tiles.group.updateMatrixWorld(true);
  box.applyMatrix4(tiles.group.matrixWorld);
  const focus = (parameter('focus') || '').split(',').map(Number);
  const distance = Number(parameter('distance'));
  if (focus.length === 3 && focus.every(Number.isFinite) && distance > 0) {
    viewTarget.copy(toView(focus[0], focus[1], focus[2]));
    camera.position.copy(viewTarget).add(new THREE.Vector3(0, 0.8, 0.6).normalize().multiplyScalar(distance));
  } else {
    const centre = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3()).length();
    viewTarget.copy(centre);
    camera.position.copy(centre).add(new THREE.Vector3(0, 0.7, 0.7).multiplyScalar(size));
  }
  camera.far = Math.max(1e4, box.getSize(new THREE.Vector3()).length() * 10);
  camera.updateProjectionMatrix();
  camera.lookAt(viewTarget);
  if (controls) {
    controls.target.copy(viewTarget);
    controls.update();
  }
  // The tiles the view needs are asked for now, not at the next frame.
  camera.updateMatrixWorld();
  tiles.update();
  Scheduler.flushPending();
});

tiles.addEventListener('load-model', ({ scene: model }) => {
  model.updateMatrixWorld(true);
  model.traverse((object) => {
    if (object.isMesh) colourByHeight(object, model);
  });
});

function levelOf(tile) {
  const match = /tiles\/(\d+)\//.exec(tile.content && tile.content.uri ? tile.content.uri : '');
  return match ? Number(match[1]) : -1;
}

tiles.addEventListener('tile-visibility-change', ({ tile, visible }) => {
  const level = levelOf(tile);
  const list = state.visible[level] || (state.visible[level] = []);
  const uri = tile.content.uri;
  if (visible && !list.includes(uri)) list.push(uri);
  if (!visible) state.visible[level] = list.filter((u) => u !== uri);
  state.fullResolutionShown = (state.visible[0] || []).length;
});

tiles.addEventListener('load-error', ({ url, error }) => {
  state.errors.push(String(url) + ': ' + String(error));
  status.textContent = 'A tile could not be loaded: ' + url;
});

function shownText() {
  const levels = Object.keys(state.visible).map(Number).filter((l) => l >= 0).sort((a, b) => a - b);
  return levels.map((l) => (l === 0 ? 'full resolution' : 'level ' + l) + ': ' +
    state.visible[l].length).join(', ');
}

// The tile set and the tiles the view needs are asked for before the WebGL context is made:
// making it holds the page's thread 0.4-1.9 s in a browser just started on a machine without
// a GPU (a software rasterizer), and the downloads run meanwhile. Not longer than a second: a
// slow tile set is waited for with the page drawn.
const tilesetLoaded = new Promise((resolve) => {
  tiles.addEventListener('load-tileset', resolve);
  tiles.addEventListener('load-error', resolve);
  setTimeout(resolve, 1000);
});
camera.updateMatrixWorld();
tiles.update();
Scheduler.flushPending();
await tilesetLoaded;

// No multisampling: on a software rasterizer (a machine without a GPU) it is a large share of
// every frame's work; the page's other viewer does without it too.
const renderer = new THREE.WebGLRenderer({ antialias: false });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.setClearColor(0x20242a);
container.appendChild(renderer.domElement);

controls = new OrbitControls(camera, renderer.domElement);
controls.screenSpacePanning = true;
controls.target.copy(viewTarget);
controls.update();

window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(window.innerWidth, window.innerHeight);
  tiles.setResolutionFromRenderer(camera, renderer);
});

function frame() {
  requestAnimationFrame(frame);
  controls.update();
  camera.updateMatrixWorld();
  tiles.update();
  // The tiles' download and parse queues start their work on the next animation frame; run it
  // now, so that a tile asked for in this frame is on its way while this frame renders.
  Scheduler.flushPending();
  renderer.render(scene, camera);
  if (state.firstFrameMs === null && tiles.visibleTiles.size > 0) {
    state.firstFrameMs = performance.now();
    status.textContent = 'Tile set loaded.';
  }
  document.getElementById('tiles-shown').textContent = shownText();
}
frame();
