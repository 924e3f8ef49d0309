// What the viewer page (viewer.js) and the live page (live.js) share: the height colours, the
// mesh binary's parser, and a three.js scene in the map frame (Z up, metres) with its lights,
// camera and renderer.
'use strict';

window.featsenseMapScene = (function () {
  // Viridis at five stops: dark low, yellow high; readable where colours are not told apart.
  const HEIGHT_STOPS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];

  /// `stops` interpolated at t in 0..1 (clamped): r, g, b in 0..255.
  function ramp(stops, t) {
    const x = Math.min(Math.max(t, 0), 1) * (stops.length - 1);
    const i = Math.min(Math.floor(x), stops.length - 2);
    const f = x - i;
    const a = stops[i];
    const b = stops[i + 1];
    return [a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f];
  }

  function cssGradient(stops) {
    return 'linear-gradient(to right, ' +
        stops.map(function (s) { return 'rgb(' + s.join(',') + ')'; }).join(', ') + ')';
  }

  // The viewer's mesh binary (viewer_export/include/featsense/viewer_export/viewer_mesh_binary.hpp).
  const MESH_MAGIC = 'FSVIEW1';
  const MESH_HEADER_BYTES = 32;

  /// The mesh of `length` bytes at `offset` of `buffer`, its layers named by `layerNames`;
  /// `name` says what it is in an error. `copy`: the arrays are copies, so that they do not
  /// keep a larger response alive; else views into `buffer`.
  function parseViewerMesh(buffer, offset, length, layerNames, name, copy) {
    if (length < MESH_HEADER_BYTES) throw new Error(name + ' is too short');
    const magic = String.fromCharCode.apply(null, new Uint8Array(buffer, offset, 7));
    if (magic !== MESH_MAGIC) throw new Error(name + ' is not a featsense viewer mesh');
    const header = new DataView(buffer, offset, MESH_HEADER_BYTES);
    const n = header.getUint32(8, true);
    const m = header.getUint32(12, true);
    const k = header.getUint32(16, true);
    const normalBytes = Math.ceil((3 * n) / 4) * 4;
    const expected = MESH_HEADER_BYTES + n * (3 + k) * 4 + normalBytes + m * 12;
    if (length !== expected) throw new Error(name + ' holds ' + length + ' bytes, expected ' + expected);
    let at = offset + MESH_HEADER_BYTES;
    const take = function (Type, count, bytes) {
      const end = at + count * Type.BYTES_PER_ELEMENT;
      const array = copy ? new Type(buffer.slice(at, end)) : new Type(buffer, at, count);
      at += bytes || count * Type.BYTES_PER_ELEMENT;
      return array;
    };
    const mesh = {
      vertexCount: n,
      triangleCount: m,
      positions: take(Float32Array, 3 * n),
      normals: take(Int8Array, 3 * n, normalBytes),  // times 127
      indices: take(Uint32Array, 3 * m),
      layers: {},
    };
    for (let i = 0; i < k; ++i) mesh.layers[layerNames[i]] = take(Float32Array, n);
    return mesh;
  }

  /// A renderer filling `container` (clipping on), a scene lit from above, a camera whose up
  /// is +Z (far: its far plane, metres).
  function create(container, far) {
    const renderer = new THREE.WebGLRenderer({ antialias: false });
    renderer.setPixelRatio(window.devicePixelRatio);
    renderer.setSize(container.clientWidth, container.clientHeight);
    renderer.setClearColor(0x20242a);
    renderer.localClippingEnabled = true;
    container.appendChild(renderer.domElement);

    const scene = new THREE.Scene();
    scene.add(new THREE.HemisphereLight(0xffffff, 0x606060, 1.0));
    const sun = new THREE.DirectionalLight(0xffffff, 0.5);
    sun.position.set(0.4, 0.7, 1.0);
    scene.add(sun);
    const camera = new THREE.PerspectiveCamera(50, container.clientWidth / container.clientHeight, 0.01, far);
    camera.up.set(0, 0, 1);
    return { renderer: renderer, scene: scene, camera: camera };
  }

  return {
    HEIGHT_STOPS: HEIGHT_STOPS, ramp: ramp, cssGradient: cssGradient,
    parseViewerMesh: parseViewerMesh, create: create,
  };
})();
