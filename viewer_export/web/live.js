// The live page of `featsense live --view`: the map as it is being made. About every second
// it asks the program for the run's figures and the path (/live/status.json) and, where the
// map changed, for the chunks re-meshed since the version it holds (/live/mesh.bin, laid out
// in app/live_view.hpp); each chunk is one three.js mesh, replaced when it comes again.
//
// The map frame is Z up (metres), as in the viewer page (viewer.js).
'use strict';

(function () {
  const POLL_MS = 1000;
  const statusLine = document.getElementById('status');
  const figures = document.getElementById('figures');

  function setStatus(text, isError) {
    statusLine.textContent = text;
    statusLine.classList.toggle('error', Boolean(isError));
  }

  if (typeof THREE === 'undefined' || !THREE.OrbitControls) {
    setStatus('three.js did not load (the program serves it from Debian\'s libjs-three)', true);
    console.error('featsense live: three.js did not load');
    return;
  }

  // What tests and people measuring the page read.
  // drawn: the triangles of the last frame on the screen.
  window.__featsenseLive = { refreshes: 0, triangles: 0, chunks: 0, version: 0, drawn: 0, ready: false };

  // --- The changes' binary (app/live_view.hpp): chunk meshes in the viewer's binary
  const LIVE_MAGIC = 'FSLIVE1';

  function magicOf(buffer, offset) {
    return String.fromCharCode.apply(null, new Uint8Array(buffer, offset, 7));
  }

  function parseChunkMesh(buffer, offset, length) {
    // Copies: the views must not keep the whole response alive once it is parsed.
    return featsenseMapScene.parseViewerMesh(buffer, offset, length, [], 'a chunk mesh', true);
  }

  // --- Colours: height above the first pose, on a fixed ramp, so that a chunk keeps its
  // colours whatever comes later.
  const HEIGHT_STOPS = featsenseMapScene.HEIGHT_STOPS;
  const BELOW_M = 2.0;
  const ABOVE_M = 6.0;
  let baseZ = null;

  function ramp(t) { return featsenseMapScene.ramp(HEIGHT_STOPS, t); }

  function heightColours(positions, n) {
    const colours = new Uint8Array(3 * n);
    const z0 = baseZ === null ? 0 : baseZ;
    for (let v = 0; v < n; ++v) {
      const rgb = ramp((positions[3 * v + 2] - (z0 - BELOW_M)) / (BELOW_M + ABOVE_M));
      colours[3 * v] = rgb[0];
      colours[3 * v + 1] = rgb[1];
      colours[3 * v + 2] = rgb[2];
    }
    return colours;
  }

  function showLegend() {
    const z0 = baseZ === null ? 0 : baseZ;
    document.getElementById('legend-ramp').style.background = featsenseMapScene.cssGradient(HEIGHT_STOPS);
    document.getElementById('legend-low').textContent = (z0 - BELOW_M).toFixed(1) + ' m';
    document.getElementById('legend-high').textContent = (z0 + ABOVE_M).toFixed(1) + ' m';
  }

  // --- The scene
  const container = document.getElementById('scene');
  const view = featsenseMapScene.create(container, 5000);
  const renderer = view.renderer;
  const scene = view.scene;
  const camera = view.camera;
  camera.position.set(-25, -35, 30);
  camera.lookAt(0, 0, 0);
  const cutPlane = new THREE.Plane(new THREE.Vector3(0, 0, -1), 1e9);
  const material = new THREE.MeshLambertMaterial({
    vertexColors: THREE.VertexColors, side: THREE.DoubleSide, clippingPlanes: [cutPlane],
  });

  const orbit = new THREE.OrbitControls(camera, renderer.domElement);
  orbit.screenSpacePanning = true;
  orbit.addEventListener('change', requestRender);

  let renderPending = false;
  function requestRender() {
    if (renderPending) return;
    renderPending = true;
    requestAnimationFrame(function () {
      renderPending = false;
      renderer.render(scene, camera);
      window.__featsenseLive.drawn = renderer.info.render.triangles;
    });
  }
  window.addEventListener('resize', function () {
    camera.aspect = container.clientWidth / container.clientHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(container.clientWidth, container.clientHeight);
    requestRender();
  });

  // --- Chunks, by "x,y,z"
  const chunks = new Map();
  let triangles = 0;
  let meshTop = -Infinity;  // the highest chunk's top, for the automatic cut
  let firstMeshBox = null;  // what the camera frames when the first mesh comes

  function replaceChunk(id, part) {
    const old = chunks.get(id);
    if (old) {
      scene.remove(old.object);
      old.object.geometry.dispose();
      triangles -= old.triangles;
      chunks.delete(id);
    }
    if (!part || part.triangleCount === 0) return;
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(part.positions, 3));
    geometry.setAttribute('normal', new THREE.BufferAttribute(part.normals, 3, true));
    geometry.setAttribute('color', new THREE.BufferAttribute(heightColours(part.positions, part.vertexCount), 3, true));
    geometry.setIndex(new THREE.BufferAttribute(part.indices, 1));
    geometry.computeBoundingSphere();
    geometry.computeBoundingBox();
    meshTop = Math.max(meshTop, geometry.boundingBox.max.z);
    if (firstMeshBox === null) firstMeshBox = geometry.boundingBox.clone();
    else if (!framed) firstMeshBox.union(geometry.boundingBox);
    const object = new THREE.Mesh(geometry, material);
    scene.add(object);
    chunks.set(id, { object: object, triangles: part.triangleCount });
    triangles += part.triangleCount;
  }

  function applyChanges(buffer) {
    if (buffer.byteLength < 16 || magicOf(buffer, 0) !== LIVE_MAGIC)
      throw new Error('/live/mesh.bin is not the live map\'s changes');
    const view = new DataView(buffer);
    const version = view.getUint32(8, true);
    const count = view.getUint32(12, true);
    let offset = 16;
    for (let i = 0; i < count; ++i) {
      if (offset + 16 > buffer.byteLength) throw new Error('/live/mesh.bin is cut short');
      const id = view.getInt32(offset, true) + ',' + view.getInt32(offset + 4, true) + ',' +
                 view.getInt32(offset + 8, true);
      const length = view.getUint32(offset + 12, true);
      offset += 16;
      if (offset + length > buffer.byteLength) throw new Error('/live/mesh.bin is cut short');
      replaceChunk(id, length > 0 ? parseChunkMesh(buffer, offset, length) : null);
      offset += length;
    }
    return version;
  }

  // --- The path and the sensor
  const pathPositions = [];
  const pathGeometry = new THREE.BufferGeometry();
  const pathLine = new THREE.Line(pathGeometry, new THREE.LineBasicMaterial({
    color: 0xff40ff, depthTest: false, transparent: true,
  }));
  pathLine.renderOrder = 2;
  pathLine.frustumCulled = false;
  scene.add(pathLine);
  const sensor = new THREE.Mesh(new THREE.ConeBufferGeometry(0.5, 1.6, 12),
                                new THREE.MeshBasicMaterial({ color: 0xff2020, depthTest: false }));
  sensor.renderOrder = 3;
  sensor.visible = false;
  scene.add(sensor);
  const coneAxis = new THREE.Vector3(0, 1, 0);  // a cone points along +Y

  function extendPath(status) {
    if (status.path_from !== pathPositions.length / 3) return;  // a stale answer
    status.path_m.forEach(function (p) { pathPositions.push(p[0], p[1], p[2]); });
    if (baseZ === null && pathPositions.length >= 3) {
      baseZ = pathPositions[2];
      showLegend();
    }
    pathGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pathPositions), 3));
    pathGeometry.computeBoundingSphere();
  }

  // The camera's place relative to the sensor: set from the first mesh's size (a room is seen
  // from close, a street from farther), kept while it follows.
  let framed = false;
  const cameraOffset = new THREE.Vector3(-25, -35, 30);
  function frameFirstMesh() {
    if (framed || firstMeshBox === null) return;
    framed = true;
    const diagonal = firstMeshBox.getSize(new THREE.Vector3()).length();
    const distance = Math.min(Math.max(diagonal, 8), 80);
    cameraOffset.set(-0.55, -0.75, 0.65).multiplyScalar(distance);
    if (document.getElementById('follow').checked) {
      const centre = lastSensor || firstMeshBox.getCenter(new THREE.Vector3());
      orbit.target.copy(centre);
      camera.position.copy(centre).add(cameraOffset);
      orbit.update();
    }
  }

  let lastSensor = null;
  function moveSensor(pose) {
    if (!pose) return;
    const p = new THREE.Vector3().fromArray(pose.position_m);
    const forward = new THREE.Vector3().fromArray(pose.forward).normalize();
    sensor.position.copy(p);
    sensor.quaternion.setFromUnitVectors(coneAxis, forward);
    sensor.visible = true;
    if (baseZ === null) {
      baseZ = p.z;
      showLegend();
    }
    if (document.getElementById('follow').checked) {
      // The camera keeps its place relative to the sensor: the view travels along.
      if (lastSensor === null) {
        orbit.target.copy(p);
        camera.position.copy(p).add(cameraOffset);
      } else {
        const moved = p.clone().sub(lastSensor);
        orbit.target.add(moved);
        camera.position.add(moved);
      }
      orbit.update();
    }
    lastSensor = p;
  }

  function showFigures(status) {
    const ms = function (x) { return x === null ? '-' : x.toFixed(0) + ' ms'; };
    figures.textContent =
        status.frames_read + ' scans read, ' + status.frames_mapped + ' mapped' +
        (status.integrations_skipped ? ', ' + status.integrations_skipped + ' integrations skipped' : '') +
        '\nlatency: pose ' + ms(status.pose_latency_ms) + ', map ' + ms(status.integration_latency_ms) +
        '\n' + status.triangles.toLocaleString('en') + ' triangles in ' + status.chunks + ' chunks' +
        (status.chunks_waiting ? ' (' + status.chunks_waiting + ' waiting)' : '') +
        '\nmeshing ' + ms(status.meshing_ms) + ' a refresh';
  }

  // --- Controls
  document.getElementById('show-path').addEventListener('change', function (event) {
    pathLine.visible = event.target.checked;
    requestRender();
  });
  // The cut: indoors the ceiling hides the rooms. Until the slider is moved, where the mesh
  // reaches well above the path the cut lies 1 m above the path's highest point (as in the
  // viewer page), else there is none.
  const cut = document.getElementById('cut');
  const cutValue = document.getElementById('cut-value');
  let cutByHand = false;
  function pathTop() {
    let top = -Infinity;
    for (let i = 2; i < pathPositions.length; i += 3) top = Math.max(top, pathPositions[i]);
    if (lastSensor !== null) top = Math.max(top, lastSensor.z);
    return top;
  }
  function applyCut() {
    const z0 = baseZ === null ? 0 : baseZ;
    if (!cutByHand) {
      const top = pathTop();
      const automatic = isFinite(top) && meshTop > top + 1.5;
      cut.value = automatic ? String(Math.min(top + 1.0 - z0, Number(cut.max) - 0.5)) : cut.max;
    }
    const above = Number(cut.value);
    cutPlane.constant = above >= Number(cut.max) ? 1e9 : z0 + above;
    cutValue.textContent = above >= Number(cut.max) ? '(none)' : 'z = ' + (z0 + above).toFixed(1) + ' m';
    requestRender();
  }
  cut.addEventListener('input', function () {
    cutByHand = true;
    applyCut();
  });
  applyCut();

  // --- The polling loop: one request at a time, the next a second after the last answer.
  let version = 0;
  let stopped = false;

  function checked(url) {
    return fetch(url, { cache: 'no-store' }).then(function (response) {
      if (!response.ok) throw new Error(url + ': HTTP ' + response.status);
      return response;
    });
  }

  function poll() {
    checked('live/status.json?path_from=' + pathPositions.length / 3)
        .then(function (r) { return r.json(); })
        .then(function (status) {
          document.getElementById('title').textContent = 'featsense live: ' + status.name;
          extendPath(status);
          moveSensor(status.pose);
          showFigures(status);
          if (status.finished) stopped = true;
          if (status.version === version) return null;
          return checked('live/mesh.bin?since=' + version).then(function (r) { return r.arrayBuffer(); });
        })
        .then(function (buffer) {
          if (buffer) {
            version = applyChanges(buffer);
            window.__featsenseLive.refreshes += 1;
          }
          frameFirstMesh();
          applyCut();
          const live = window.__featsenseLive;
          live.triangles = triangles;
          live.chunks = chunks.size;
          live.version = version;
          live.ready = true;
          setStatus(stopped ? 'The run has ended: its outputs are written.'
                            : 'Mapping: the map refreshes about every second.');
          requestRender();
        })
        .catch(function (error) {
          // The program has ended (Ctrl+C or silence) or is busy: say so, keep trying.
          setStatus('No answer from featsense (' + error.message + '); trying again.', true);
        })
        .then(function () {
          if (!stopped) setTimeout(poll, POLL_MS);
        });
  }
  requestRender();
  poll();
})();
