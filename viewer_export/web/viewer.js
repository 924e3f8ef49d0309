// The viewer page of `featsense view`: the mesh of one output folder, its paths and its plan
// view, on three.js (Debian's libjs-three, served by the program under /three/).
//
// The map frame is Z up (metres) and stays so: the camera's up is +Z, so that a clicked
// point's coordinates are the map's. The scene is drawn only when something changed (and on
// every frame while flying): a software renderer takes a while for a million triangles.
'use strict';

(function () {
  // performance.now() counts from the page's navigation: the times below are since then.
  const loadStart = 0;
  // Where the time goes, for whoever measures the page (milliseconds).
  const timings = { script_ms: Math.round(performance.now()) };
  window.__featsenseTimings = timings;
  const statusLine = document.getElementById('status');

  function setStatus(text, isError) {
    statusLine.textContent = text;
    statusLine.classList.toggle('error', Boolean(isError));
  }

  function fail(text) {
    setStatus(text, true);
    console.error('featsense view: ' + text);
  }

  if (typeof THREE === 'undefined' || !THREE.OrbitControls || !THREE.FlyControls) {
    fail('three.js did not load (the server serves it from Debian\'s libjs-three)');
    return;
  }

  // --- The mesh binary, mesh.bin
  function parseMesh(buffer, layerNames) {
    return featsenseMapScene.parseViewerMesh(buffer, 0, buffer.byteLength, layerNames, 'mesh.bin', false);
  }

  // --- Colour maps: each turns a vertex into r, g, b in 0..255.
  const ramp = featsenseMapScene.ramp;
  const cssGradient = featsenseMapScene.cssGradient;
  const HEIGHT_STOPS = featsenseMapScene.HEIGHT_STOPS;
  const ERROR_STOPS = [[0, 0, 255], [255, 255, 255], [255, 0, 0]];
  const COST_STOPS = [[0, 255, 0], [255, 255, 0], [255, 0, 0]];
  const NO_VALUE = [128, 128, 128];

  // The height range: the 1st to 99th percentile of a sample, so that a few stray vertices
  // (a reflection, a bird) do not flatten the colours of the rest.
  function heightRange(positions, n, top) {
    const step = Math.max(1, Math.floor(n / 20000));
    const zs = [];
    for (let v = 0; v < n; v += step) {
      if (positions[3 * v + 2] <= top) zs.push(positions[3 * v + 2]);
    }
    if (zs.length === 0) return [0, 1];
    zs.sort(function (a, b) { return a - b; });
    const lo = zs[Math.floor(0.01 * (zs.length - 1))];
    const hi = zs[Math.ceil(0.99 * (zs.length - 1))];
    return [lo, hi > lo ? hi : lo + 1];
  }

  function colouring(mode, mesh, scene) {
    const fmt = function (x) { return x.toFixed(2); };
    if (mode === 'normal') {
      return {
        colour: function (v) {
          const n = mesh.normals;
          return [n[3 * v] + 127.5, n[3 * v + 1] + 127.5, n[3 * v + 2] + 127.5];
        },
        legend: null,
        hint: 'Red: +X, green: +Y, blue: +Z (up).',
      };
    }
    if (mode === 'signed_distance') {
      const d = mesh.layers.signed_distance;
      const s = scene.error_saturation_m;
      return {
        colour: function (v) { return isNaN(d[v]) ? NO_VALUE : ramp(ERROR_STOPS, 0.5 + 0.5 * d[v] / s); },
        legend: [ERROR_STOPS, '-' + fmt(s) + ' m', '+' + fmt(s) + ' m'],
        hint: 'Distance to the reference: blue behind it, red in front; grey: not compared.',
      };
    }
    if (mode === 'cost') {
      const c = mesh.layers.cost;
      return {
        colour: function (v) {
          if (isNaN(c[v])) return NO_VALUE;
          return c[v] >= 1 ? [128, 0, 0] : ramp(COST_STOPS, c[v]);
        },
        legend: [COST_STOPS, '0 (free)', '1 (lethal: dark red)'],
        hint: 'Traversability cost of navmesh.ply.',
      };
    }
    // The range of what is below the cut: the colours spread over what can be seen.
    const range = heightRange(mesh.positions, mesh.vertexCount, cutPlane.constant);
    return {
      colour: function (v) { return ramp(HEIGHT_STOPS, (mesh.positions[3 * v + 2] - range[0]) / (range[1] - range[0])); },
      legend: [HEIGHT_STOPS, fmt(range[0]) + ' m', fmt(range[1]) + ' m'],
      hint: 'Height (Z) in the map frame.',
    };
  }

  // --- The scene
  const container = document.getElementById('scene');
  const view = featsenseMapScene.create(container, 1000);
  const renderer = view.renderer;
  const scene = view.scene;
  const camera = view.camera;
  const cutPlane = new THREE.Plane(new THREE.Vector3(0, 0, -1), 1e9);

  let renderPending = false;
  let flying = null;
  let lastFrame = performance.now();
  let afterFirstFrame = null;
  function frame(now) {
    renderPending = false;
    if (flying) {
      flying.update((now - lastFrame) / 1000);
      requestRender();
    }
    lastFrame = now;
    renderer.render(scene, camera);
    if (afterFirstFrame) {
      // The next animation frame comes once this one is on the screen.
      requestAnimationFrame(afterFirstFrame);
      afterFirstFrame = null;
    }
  }
  function requestRender() {
    if (renderPending) return;
    renderPending = true;
    requestAnimationFrame(frame);
  }
  window.addEventListener('resize', function () {
    camera.aspect = container.clientWidth / container.clientHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(container.clientWidth, container.clientHeight);
    requestRender();
  });

  function buildMesh(mesh) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(mesh.positions, 3));
    geometry.setAttribute('normal', new THREE.BufferAttribute(mesh.normals, 3, true));
    geometry.setAttribute('color', new THREE.BufferAttribute(new Uint8Array(3 * mesh.vertexCount), 3, true));
    geometry.setIndex(new THREE.BufferAttribute(mesh.indices, 1));
    geometry.computeBoundingBox();
    geometry.computeBoundingSphere();
    const material = new THREE.MeshLambertMaterial({
      vertexColors: THREE.VertexColors,
      side: THREE.DoubleSide,
      clippingPlanes: [cutPlane],
    });
    return new THREE.Mesh(geometry, material);
  }

  function buildPath(path) {
    const positions = new Float32Array(3 * path.positions_m.length);
    path.positions_m.forEach(function (p, i) { positions.set(p, 3 * i); });
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    // Drawn over the mesh: a path inside a room stays visible from outside it.
    const material = new THREE.LineBasicMaterial({
      color: path.label === 'truth' ? 0x40ffff : 0xff40ff, depthTest: false, transparent: true,
    });
    const line = new THREE.Line(geometry, material);
    line.renderOrder = path.label === 'truth' ? 1 : 2;  // the estimate over the truth
    return line;
  }

  function start(sceneInfo, mesh) {
    const meshObject = buildMesh(mesh);
    scene.add(meshObject);
    const box = meshObject.geometry.boundingBox;
    const centre = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3());
    const diagonal = Math.max(size.length(), 1e-3);
    camera.near = diagonal / 2000;
    camera.far = diagonal * 20;
    camera.position.copy(centre).add(new THREE.Vector3(-0.55, -0.75, 0.65).multiplyScalar(diagonal));
    camera.lookAt(centre);
    camera.updateProjectionMatrix();

    // Orbit and fly controls; only one listens at a time.
    const orbit = new THREE.OrbitControls(camera, renderer.domElement);
    orbit.target.copy(centre);
    orbit.screenSpacePanning = true;
    orbit.update();
    orbit.addEventListener('change', requestRender);
    const hint = document.getElementById('controls-hint');
    document.querySelectorAll('input[name=controls]').forEach(function (radio) {
      radio.addEventListener('change', function () {
        if (radio.value === 'fly' && radio.checked && !flying) {
          orbit.enabled = false;
          flying = new THREE.FlyControls(camera, renderer.domElement);
          flying.movementSpeed = diagonal / 8;
          flying.rollSpeed = 0.6;
          flying.dragToLook = true;
          hint.textContent = 'W/S forward/back, A/D sideways, R/F up/down, Q/E roll; drag: look; Shift: slow.';
          lastFrame = performance.now();
          requestRender();
        } else if (radio.value === 'orbit' && radio.checked && flying) {
          flying.dispose();
          flying = null;
          // Orbit about the point ahead of where the flight ended.
          const ahead = new THREE.Vector3(0, 0, -1).applyQuaternion(camera.quaternion);
          orbit.target.copy(camera.position).addScaledVector(ahead, diagonal / 4);
          orbit.enabled = true;
          orbit.update();
          hint.textContent = 'Drag: turn; right drag: pan; wheel: zoom.';
          requestRender();
        }
      });
    });

    // Colouring
    const colourAttribute = meshObject.geometry.getAttribute('color');
    const select = document.getElementById('colouring');
    Array.prototype.forEach.call(select.options, function (option) {
      if ((option.value === 'signed_distance' || option.value === 'cost') && !mesh.layers[option.value]) {
        option.disabled = true;
        option.textContent += option.value === 'cost' ? ' (no navmesh.ply)' : ' (no mesh_error.ply)';
      }
    });
    function applyColouring() {
      const c = colouring(select.value, mesh, sceneInfo);
      const colours = colourAttribute.array;
      for (let v = 0; v < mesh.vertexCount; ++v) {
        const rgb = c.colour(v);
        colours[3 * v] = rgb[0];
        colours[3 * v + 1] = rgb[1];
        colours[3 * v + 2] = rgb[2];
      }
      colourAttribute.needsUpdate = true;
      const legend = document.getElementById('legend');
      legend.hidden = !c.legend;
      if (c.legend) {
        document.getElementById('legend-ramp').style.background = cssGradient(c.legend[0]);
        document.getElementById('legend-low').textContent = c.legend[1];
        document.getElementById('legend-high').textContent = c.legend[2];
      }
      document.getElementById('colouring-hint').textContent = c.hint;
      requestRender();
    }
    select.addEventListener('change', applyColouring);

    // Paths
    const pathObjects = {};
    sceneInfo.paths.forEach(function (path) {
      pathObjects[path.label] = buildPath(path);
      scene.add(pathObjects[path.label]);
    });
    [['estimate', 'show-estimate'], ['truth', 'show-truth']].forEach(function (pair) {
      const checkbox = document.getElementById(pair[1]);
      const object = pathObjects[pair[0]];
      if (!object) {
        checkbox.checked = false;
        checkbox.disabled = true;
        checkbox.parentElement.title = 'No ' + (pair[0] === 'truth' ? 'true path' : 'trajectory.tum') + ' in this folder';
        return;
      }
      checkbox.addEventListener('change', function () {
        object.visible = checkbox.checked;
        requestRender();
      });
    });

    // The cut: indoors the ceiling hides the rooms from above. Where there is a path and the
    // mesh reaches well above it, the cut starts 1 m above the path's highest point.
    const cut = document.getElementById('cut');
    const cutValue = document.getElementById('cut-value');
    function cutHeight() { return box.min.z + (box.max.z - box.min.z) * cut.value / 1000; }
    function applyCut() {
      const z = cutHeight();
      cutPlane.constant = cut.value >= 1000 ? 1e9 : z;
      cutValue.textContent = cut.value >= 1000 ? '(none)' : 'z = ' + z.toFixed(2) + ' m';
      requestRender();
    }
    let pathTop = -Infinity;
    sceneInfo.paths.forEach(function (path) {
      path.positions_m.forEach(function (p) { pathTop = Math.max(pathTop, p[2]); });
    });
    if (isFinite(pathTop) && box.max.z > pathTop + 1.5) {
      cut.value = Math.round(1000 * (pathTop + 1.0 - box.min.z) / (box.max.z - box.min.z));
    }
    cut.addEventListener('input', applyCut);
    cut.addEventListener('change', function () { if (select.value === 'height') applyColouring(); });
    applyCut();
    applyColouring();

    // A click (not a drag) on the mesh: its coordinates, and a marker there.
    const marker = new THREE.Mesh(new THREE.SphereBufferGeometry(diagonal / 300, 12, 8),
                                  new THREE.MeshBasicMaterial({ color: 0xff2020, depthTest: false }));
    marker.renderOrder = 3;
    marker.visible = false;
    scene.add(marker);
    const picked = document.getElementById('picked');
    const raycaster = new THREE.Raycaster();
    let downAt = null;
    renderer.domElement.addEventListener('pointerdown', function (event) { downAt = [event.clientX, event.clientY]; });
    renderer.domElement.addEventListener('pointerup', function (event) {
      if (!downAt || Math.abs(event.clientX - downAt[0]) + Math.abs(event.clientY - downAt[1]) > 4) return;
      const rect = renderer.domElement.getBoundingClientRect();
      const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
                                    -((event.clientY - rect.top) / rect.height) * 2 + 1);
      raycaster.setFromCamera(ndc, camera);
      const limit = cutPlane.constant;
      const hit = raycaster.intersectObject(meshObject).find(function (h) { return h.point.z <= limit; });
      if (!hit) {
        picked.textContent = 'No mesh there.';
        marker.visible = false;
      } else {
        const p = hit.point;
        picked.textContent = 'x ' + p.x.toFixed(3) + ' m\ny ' + p.y.toFixed(3) + ' m\nz ' + p.z.toFixed(3) + ' m';
        marker.position.copy(p);
        marker.visible = true;
      }
      requestRender();
    });

    // The plan view, loaded when first asked for.
    const planButton = document.getElementById('plan-button');
    const plan = document.getElementById('plan');
    if (!sceneInfo.plan) {
      planButton.disabled = true;
      planButton.textContent = 'Plan view (no topdown.png)';
    }
    planButton.addEventListener('click', function () {
      const image = document.getElementById('plan-image');
      if (!image.getAttribute('src')) image.setAttribute('src', 'plan.png');
      plan.hidden = !plan.hidden;
    });
    document.getElementById('plan-close').addEventListener('click', function () { plan.hidden = true; });

    // Ready once the first frame with the mesh has been drawn.
    timings.scene_built_ms = Math.round(performance.now() - loadStart);
    requestRender();
    afterFirstFrame = function () {
      const seconds = (performance.now() - loadStart) / 1000;
      const m = sceneInfo.mesh;
      document.getElementById('title').textContent = sceneInfo.name;
      setStatus(m.triangles.toLocaleString('en') + ' triangles' +
                (m.simplified ? ' (simplified from ' + m.source_triangles.toLocaleString('en') + ')' : '') +
                ', shown in ' + seconds.toFixed(1) + ' s');
      timings.drawn_ms = Math.round(performance.now() - loadStart);
      // What the first frame drew, for tests that check the mesh is on the screen.
      window.__featsenseDrawnTriangles = renderer.info.render.triangles;
      window.__featsenseReady = true;
    };
  }

  // index.html began these requests before three.js loaded.
  function checked(url, request) {
    return (request || fetch(url)).then(function (response) {
      if (!response.ok) throw new Error(url + ': HTTP ' + response.status);
      return response;
    });
  }
  const early = window.__featsenseFiles || {};

  Promise.all([checked('scene.json', early.scene).then(function (r) { return r.json(); }),
               checked('mesh.bin', early.mesh).then(function (r) { return r.arrayBuffer(); })])
      .then(function (results) {
        timings.fetched_ms = Math.round(performance.now() - loadStart);
        const sceneInfo = results[0];
        start(sceneInfo, parseMesh(results[1], sceneInfo.mesh.layers));
      })
      .catch(function (error) { fail('cannot show the map: ' + error.message); });
})();
