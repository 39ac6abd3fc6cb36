// SphereKit results page: the 3-D views (written by spherekit; see site_viewer_js.h).
(function () {
  'use strict';
  var site = window.SPHEREKIT_SITE || { models: [], morphs: [] };
  // What is shown, what is loading, what failed: for the reader of the page and for tests.
  var state = window.spherekitViewer = {
    pending: 0, renders: 0, errors: [],
    model: -1, lod: -1, autoLod: true, levels: 0, triangles: 0,
    morphs: []
  };
  var BACKGROUND = 0x20252b;

  function byId(id) { return document.getElementById(id); }
  function setText(el, text) { if (el) { el.textContent = text; el.className = 'status'; } }
  function fail(statusEl, where, error) {
    var message = where + ': ' + (error && error.message ? error.message : String(error));
    state.errors.push(message);
    if (statusEl) { statusEl.textContent = message; statusEl.className = 'status error'; }
    console.error('spherekit viewer: ' + message);
  }
  function clamp(x, lo, hi) { return Math.min(hi, Math.max(lo, x)); }

  if (typeof THREE === 'undefined' || typeof DracoDecoderModule !== 'function') {
    var lost = typeof THREE === 'undefined' ? 'site/lib/three-viewer.js' : 'site/lib/draco_decoder.js';
    var boxes = document.querySelectorAll('.viewer .status');
    for (var b = 0; b < boxes.length; b++) fail(boxes[b], 'no 3-D view', lost + ' did not load');
    return;
  }

  // ---- .glb bytes: each file is a script of its own, so nothing is fetched (file:// pages
  // may not fetch). The script hands its base64 text to spherekitGlb.
  var waiting = {};   // path -> {resolve, reject}
  var loaded = {};    // path -> Promise<ArrayBuffer>
  // site/glb/*.js call spherekitGlb, the landmark editor's site/mesh/*.js spherekitMesh.
  window.spherekitGlb = window.spherekitMesh = function (path, base64) {
    var w = waiting[path];
    if (!w) return;
    delete waiting[path];
    var binary = atob(base64), bytes = new Uint8Array(binary.length);
    for (var i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    w.resolve(bytes.buffer);
  };
  function loadGlb(entry) {
    if (!loaded[entry.path]) {
      loaded[entry.path] = new Promise(function (resolve, reject) {
        waiting[entry.path] = { resolve: resolve, reject: reject };
        var script = document.createElement('script');
        script.src = entry.script;
        script.onload = function () {
          script.remove();
          if (waiting[entry.path]) {
            delete waiting[entry.path];
            reject(new Error(entry.script + ' does not hold ' + entry.path));
          }
        };
        script.onerror = function () {
          script.remove();
          delete waiting[entry.path];
          reject(new Error('cannot load ' + entry.script));
        };
        document.head.appendChild(script);
      });
    }
    return loaded[entry.path];
  }

  // ---- Draco: decoded here, on the page's thread. GLTFLoader only needs an object with
  // preload() and decodeDracoFile(); three's DRACOLoader would fetch its decoder for a worker.
  var DRACO_TYPES = {
    Float32Array: 'DT_FLOAT32', Int8Array: 'DT_INT8', Int16Array: 'DT_INT16', Int32Array: 'DT_INT32',
    Uint8Array: 'DT_UINT8', Uint16Array: 'DT_UINT16', Uint32Array: 'DT_UINT32'
  };
  var dracoModule = null;
  function draco() {
    if (!dracoModule) {
      dracoModule = new Promise(function (resolve) {
        // Wrapped: the Emscripten module object is itself a thenable.
        DracoDecoderModule({ onModuleLoaded: function (module) { resolve({ module: module }); } });
      });
    }
    return dracoModule;
  }
  function decodeDraco(d, buffer, ids, types) {
    var bytes = new Int8Array(buffer);
    var decoder = new d.Decoder(), mesh = new d.Mesh();
    try {
      if (decoder.GetEncodedGeometryType(bytes) !== d.TRIANGULAR_MESH) throw new Error('Draco data is not a triangle mesh');
      var status = decoder.DecodeArrayToMesh(bytes, bytes.byteLength, mesh);
      if (!status.ok() || mesh.ptr === 0) throw new Error('Draco decoding failed: ' + status.error_msg());
      var geometry = new THREE.BufferGeometry(), points = mesh.num_points();
      Object.keys(ids).forEach(function (name) {
        var attribute = decoder.GetAttributeByUniqueId(mesh, ids[name]);
        if (!attribute || attribute.ptr === 0) throw new Error('no Draco attribute with unique id ' + ids[name] + ' (' + name + ')');
        var typeName = types[name] || 'Float32Array', Type = window[typeName];
        if (!DRACO_TYPES[typeName]) throw new Error('unsupported attribute type ' + typeName);
        var size = attribute.num_components(), count = points * size, byteLength = count * Type.BYTES_PER_ELEMENT;
        var ptr = d._malloc(byteLength), array;
        try {
          decoder.GetAttributeDataArrayForAllPoints(mesh, attribute, d[DRACO_TYPES[typeName]], byteLength, ptr);
          array = new Type(d.HEAPF32.buffer, ptr, count).slice();
        } finally { d._free(ptr); }
        geometry.setAttribute(name, new THREE.BufferAttribute(array, size));
      });
      var indexCount = mesh.num_faces() * 3, indexBytes = indexCount * 4, iptr = d._malloc(indexBytes), index;
      try {
        decoder.GetTrianglesUInt32Array(mesh, indexBytes, iptr);
        index = new Uint32Array(d.HEAPF32.buffer, iptr, indexCount).slice();
      } finally { d._free(iptr); }
      geometry.setIndex(new THREE.BufferAttribute(index, 1));
      return geometry;
    } finally {
      d.destroy(mesh);
      d.destroy(decoder);
    }
  }
  var pageDraco = {
    preload: function () { draco(); return this; },
    decodeDracoFile: function (buffer, onDecoded, ids, types, colorSpace, onError) {
      return draco().then(function (d) {
        onDecoded(decodeDraco(d.module, buffer, ids || {}, types || {}));
      }).catch(function (e) { if (onError) onError(e); });
    }
  };
  function parseGlb(buffer) {
    return new Promise(function (resolve, reject) {
      var loader = new THREE.GLTFLoader();
      loader.setDRACOLoader(pageDraco);
      loader.parse(buffer, '', resolve, reject);
    });
  }

  // ---- A canvas with an orbiting camera, rendered on demand (after a change), not every frame.
  function View(box) {
    var self = this;
    this.box = box;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setClearColor(BACKGROUND);
    box.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.01, 100);
    this.scene.add(this.camera);
    this.scene.add(new THREE.HemisphereLight(0xeef2ff, 0x40382f, 1.3));
    // The key light moves with the camera, so every side of the model can be seen lit.
    var key = new THREE.DirectionalLight(0xffffff, 2.2);
    key.position.set(0.8, 1.2, 1.0);
    key.target.position.set(0, 0, -1);
    this.camera.add(key);
    this.camera.add(key.target);
    this.controls = new THREE.OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', function () { self.requestRender(); });
    this.fitDistance = 1;
    this.object = null;
    this.beforeRender = null;
    this.frameRequested = false;
    this.resize();
    if (window.ResizeObserver) new ResizeObserver(function () { self.resize(); }).observe(box);
  }
  View.prototype.resize = function () {
    var w = Math.max(1, this.box.clientWidth), h = Math.max(1, this.box.clientHeight);
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  };
  View.prototype.requestRender = function () {
    if (this.frameRequested) return;
    this.frameRequested = true;
    var self = this;
    requestAnimationFrame(function () { self.frameRequested = false; self.render(); });
  };
  View.prototype.render = function () {
    if (this.beforeRender) this.beforeRender();
    this.renderer.render(this.scene, this.camera);
    state.renders++;
  };
  View.prototype.show = function (object) {
    if (this.object) this.scene.remove(this.object);
    this.object = object;
    this.scene.add(object);
    this.requestRender();
  };
  // Places the camera on a fixed 3/4 view direction, at the distance where every vertex of
  // `object` (its base shape) falls inside 85 % of the view: a bounding sphere would leave an
  // elongated model small in a wide canvas.
  View.prototype.frame = function (object) {
    object.updateMatrixWorld(true);
    var center = new THREE.Box3().setFromObject(object).getCenter(new THREE.Vector3());
    var back = new THREE.Vector3(0.5, 0.3, 1).normalize();
    var right = new THREE.Vector3().crossVectors(this.camera.up, back).normalize();
    var up = new THREE.Vector3().crossVectors(back, right);
    var tanV = Math.tan(THREE.MathUtils.degToRad(this.camera.fov / 2)) * 0.85, tanH = tanV * this.camera.aspect;
    var d = 0, radius = 0, p = new THREE.Vector3();
    object.traverse(function (o) {
      if (!o.isMesh) return;
      var position = o.geometry.attributes.position;
      for (var i = 0; i < position.count; i++) {
        p.fromBufferAttribute(position, i).applyMatrix4(o.matrixWorld).sub(center);
        var z = p.dot(back);
        d = Math.max(d, z + Math.abs(p.dot(right)) / tanH, z + Math.abs(p.dot(up)) / tanV);
        radius = Math.max(radius, p.length());
      }
    });
    if (!(d > 0)) d = 1;
    this.fitDistance = d;
    this.camera.near = d / 200;
    this.camera.far = (d + radius) * 50;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(center);
    this.controls.maxDistance = d * 20;
    this.camera.position.copy(center).addScaledVector(back, d);
    this.controls.update();
    this.requestRender();
  };
  View.prototype.distanceRatio = function () {
    return this.camera.position.distanceTo(this.controls.target) / this.fitDistance;
  };

  function surfaceMaterial(wireframe, map) {
    return new THREE.MeshStandardMaterial({
      color: map ? 0xffffff : 0xc9ced6, roughness: 0.55, metalness: 0.0, side: THREE.DoubleSide,
      wireframe: wireframe, map: map || null
    });
  }

  // ---- The shared domain made visible (issue 22). Every level of detail carries TEXCOORD_0,
  // the texel centre of its vertex in the octahedral geometry image, which is the same sphere
  // point, and in a consistent collection the same feature, on every member. One labelled grid
  // over that square on every member shows the correspondence.
  var gridTexture = null;
  function sharedGrid() {
    if (gridTexture) return gridTexture;
    var cells = 8, size = 1024, step = size / cells;
    var canvas = document.createElement('canvas');
    canvas.width = canvas.height = size;
    var g = canvas.getContext('2d');
    for (var r = 0; r < cells; r++)
      for (var c = 0; c < cells; c++) {
        g.fillStyle = 'hsl(' + Math.round(((r * 3 + c * 5) % cells) * 360 / cells) + ',' + ((r + c) % 2 ? 70 : 45) + '%,' +
          ((r + c) % 2 ? 62 : 42) + '%)';
        g.fillRect(c * step, r * step, step, step);
        g.fillStyle = (r + c) % 2 ? '#111' : '#fff';
        g.font = 'bold ' + Math.round(step * 0.42) + 'px sans-serif';
        g.textAlign = 'center';
        g.textBaseline = 'middle';
        // Drawn upside down: seen from outside, the octahedral square's t axis runs up the
        // central diamond, so the labels read upright there.
        g.save();
        g.translate((c + 0.5) * step, (r + 0.5) * step);
        g.scale(1, -1);
        g.fillText(String.fromCharCode(65 + r) + (c + 1), 0, 0);
        g.restore();
      }
    g.strokeStyle = '#000';
    g.lineWidth = 3;
    for (var k = 0; k <= cells; k++) {
      g.beginPath(); g.moveTo(k * step, 0); g.lineTo(k * step, size); g.stroke();
      g.beginPath(); g.moveTo(0, k * step); g.lineTo(size, k * step); g.stroke();
    }
    gridTexture = new THREE.CanvasTexture(canvas);
    gridTexture.flipY = false;  // glTF texture coordinates: (0, 0) is the image's top-left
    gridTexture.colorSpace = THREE.SRGBColorSpace;
    gridTexture.anisotropy = 4;
    return gridTexture;
  }

  // The sphere point of a geometry-image texture coordinate: texel centre s = (j + 1/2) / T ->
  // octahedral u = -1 + 2j / (T-1) (gltf_mesh.h), then the octahedral unfolding
  // (geometry_image.h, octahedral_to_sphere).
  function octahedralToSphere(u, v, out) {
    var z = 1 - Math.abs(u) - Math.abs(v), x = u, y = v;
    if (z < 0) {
      x = (1 - Math.abs(v)) * (u < 0 ? -1 : 1);
      y = (1 - Math.abs(u)) * (v < 0 ? -1 : 1);
    }
    return out.set(x, y, z).normalize();
  }
  // Shows each mesh of `root` on its sphere (on) or as itself (off): the sphere of the mesh's
  // bounding radius about its centre, positions from TEXCOORD_0. Meshes without it stay.
  var shapes = new WeakMap();  // geometry -> {surface, sphere} attributes (clones share geometry)
  function onSphere(root, on) {
    root.traverse(function (o) {
      if (!o.isMesh || !o.geometry.attributes.uv) return;
      var geo = o.geometry, d = shapes.get(geo);
      if (!d) {
        d = {};
        shapes.set(geo, d);
        d.surface = { position: geo.attributes.position, normal: geo.attributes.normal };
        geo.computeBoundingSphere();
        var uv = geo.attributes.uv, lo = Infinity;
        for (var i = 0; i < uv.count; i++) lo = Math.min(lo, uv.getX(i), uv.getY(i));
        var T = 0.5 / lo, c = geo.boundingSphere.center, radius = geo.boundingSphere.radius * 0.8;
        var pos = new Float32Array(uv.count * 3), nor = new Float32Array(uv.count * 3), p = new THREE.Vector3();
        for (var k = 0; k < uv.count; k++) {
          var j = uv.getX(k) * T - 0.5, r = uv.getY(k) * T - 0.5;
          octahedralToSphere(-1 + 2 * j / (T - 1), -1 + 2 * r / (T - 1), p);
          nor[3 * k] = p.x; nor[3 * k + 1] = p.y; nor[3 * k + 2] = p.z;
          pos[3 * k] = c.x + radius * p.x; pos[3 * k + 1] = c.y + radius * p.y; pos[3 * k + 2] = c.z + radius * p.z;
        }
        d.sphere = { position: new THREE.BufferAttribute(pos, 3), normal: new THREE.BufferAttribute(nor, 3) };
      }
      var use = on ? d.sphere : d.surface;
      geo.setAttribute('position', use.position);
      if (use.normal) geo.setAttribute('normal', use.normal);
      geo.computeBoundingSphere();
      geo.computeBoundingBox();
    });
  }
  // The files carry no material (glTF's default is a fully metallic one, black without an
  // environment map): every mesh gets the same matte grey.
  function restyle(root, material) {
    root.traverse(function (o) { if (o.isMesh) o.material = material; });
  }
  function triangles(root) {
    var n = 0;
    root.traverse(function (o) {
      if (o.isMesh) n += (o.geometry.index ? o.geometry.index.count : o.geometry.attributes.position.count) / 3;
    });
    return n;
  }
  function button(text, onClick) {
    var el = document.createElement('button');
    el.type = 'button';
    el.textContent = text;
    el.addEventListener('click', onClick);
    return el;
  }

  // ---- The models and their levels of detail.
  function modelViewer(models) {
    var box = byId('model-canvas'), status = byId('model-status');
    if (!box || !models.length) return;
    var view = new View(box);
    var select = byId('model-select'), bar = byId('lod-buttons'), wire = byId('wireframe');
    var texture = byId('shared-texture'), sphere = byId('on-sphere');
    var materials = {};
    function material() {
      var key = (wire && wire.checked ? 'w' : 's') + (state.textured ? 't' : '');
      if (!materials[key]) materials[key] = surfaceMaterial(key[0] === 'w', state.textured ? sharedGrid() : null);
      return materials[key];
    }
    var levels = [], counts = [], token = 0, name = '';
    state.textured = !!(texture && texture.checked);
    state.sphere = !!(sphere && sphere.checked);

    // Auto: level k from 2^(k-1/2) times the framing distance on (each level halves the grid,
    // so it is chosen when the model covers about half as many pixels).
    function chosenLevel() {
      if (!state.autoLod) return clamp(state.lod, 0, levels.length - 1);
      var k = Math.floor(Math.log2(Math.max(view.distanceRatio(), 1e-6)) + 0.5);
      return clamp(k, 0, levels.length - 1);
    }
    function describe() {
      var buttons = bar.querySelectorAll('button');
      for (var i = 0; i < buttons.length; i++) {
        var lod = buttons[i].getAttribute('data-lod');
        var on = lod === 'auto' ? state.autoLod : (!state.autoLod && Number(lod) === state.lod);
        buttons[i].className = on ? 'active' : '';
      }
      setText(status, name + ': LOD ' + state.lod + ' of ' + levels.length + ' (' + (state.lod === 0 ? 'finest, ' : '') +
        state.triangles + ' triangles)' + (state.autoLod ? ', chosen by distance: zoom out for coarser levels' : ''));
    }
    view.beforeRender = function () {
      if (!levels.length) return;
      var k = chosenLevel();
      for (var i = 0; i < levels.length; i++) levels[i].visible = i === k;
      if (k !== state.lod || counts[k] !== state.triangles) {
        state.lod = k;
        state.triangles = counts[k];
        describe();
      }
    };
    function buildButtons() {
      bar.textContent = '';
      var auto = button('auto', function () { state.autoLod = true; view.requestRender(); describe(); });
      auto.setAttribute('data-lod', 'auto');
      auto.title = 'choose the level by the camera distance';
      bar.appendChild(auto);
      levels.forEach(function (_, k) {
        var b = button('LOD ' + k, function () { state.autoLod = false; state.lod = k; view.requestRender(); describe(); });
        b.setAttribute('data-lod', String(k));
        b.title = counts[k] + ' triangles' + (k === 0 ? ' (finest)' : '');
        bar.appendChild(b);
      });
    }
    function loadModel(model) {
      return Promise.all(model.lods.map(function (lod) { return loadGlb(lod).then(parseGlb); }))
        .then(function (gltfs) { return gltfs.map(function (g) { return g.scene; }); });
    }
    // index: a model, or 'all': every model side by side in a row, level k of each in level k
    // (a model with fewer levels shows its coarsest).
    function show(index) {
      var all = index === 'all', chosen = all ? models : [models[index]], mine = ++token;
      var label = all ? 'all ' + models.length + ' models' : chosen[0].name;
      state.model = index;
      state.pending++;
      setText(status, 'loading ' + label + '...');
      Promise.all(chosen.map(loadModel))
        .then(function (perModel) {
          if (mine !== token) return;
          var group = new THREE.Group(), n = 0;
          perModel.forEach(function (ls) { n = Math.max(n, ls.length); });
          levels = [];
          for (var k = 0; k < n; k++) levels.push(new THREE.Group());
          var x = 0;
          perModel.forEach(function (ls) {
            ls.forEach(function (l) { restyle(l, material()); onSphere(l, state.sphere); });
            var size = new THREE.Box3().setFromObject(ls[0]).getSize(new THREE.Vector3());
            var center = new THREE.Box3().setFromObject(ls[0]).getCenter(new THREE.Vector3());
            for (var k = 0; k < n; k++) {
              var l = k < ls.length ? ls[k] : ls[ls.length - 1].clone();
              if (all) l.position.set(x + size.x / 2 - center.x, -center.y, -center.z);
              levels[k].add(l);
            }
            x += size.x * 1.15;
          });
          counts = levels.map(triangles);
          levels.forEach(function (l) { group.add(l); });
          name = label;
          state.levels = levels.length;
          state.lod = -1;
          view.show(group);
          view.frame(levels[0]);
          buildButtons();
        })
        .catch(function (e) { fail(status, label, e); })
        .then(function () { state.pending--; });
    }
    function selected() { return !select ? 0 : select.value === 'all' ? 'all' : Number(select.value); }
    if (select) select.addEventListener('change', function () { show(selected()); });
    function restyleAll() {
      levels.forEach(function (l) { restyle(l, material()); });
      view.requestRender();
    }
    if (wire) wire.addEventListener('change', restyleAll);
    if (texture) texture.addEventListener('change', function () { state.textured = texture.checked; restyleAll(); });
    if (sphere) sphere.addEventListener('change', function () {
      state.sphere = sphere.checked;
      levels.forEach(function (l) { onSphere(l, state.sphere); });
      if (levels.length) view.frame(levels[0]);
      view.requestRender();
    });
    show(selected());
  }

  // ---- Morph targets: "sequence" (successive frames, one slider) or "weights" (one slider each).
  function morphViewer(entry, k) {
    var box = byId('morph-canvas-' + k), status = byId('morph-status-' + k), bar = byId('morph-controls-' + k);
    if (!box) return;
    var view = new View(box);
    var info = state.morphs[k] = { label: entry.label, targets: 0, value: 0, weights: [] };
    state.pending++;
    loadGlb(entry.glb).then(parseGlb).then(function (gltf) {
      var meshes = [];
      gltf.scene.traverse(function (o) {
        if (o.isMesh && o.morphTargetInfluences && o.morphTargetInfluences.length) meshes.push(o);
      });
      restyle(gltf.scene, surfaceMaterial(false));
      view.show(gltf.scene);
      view.frame(gltf.scene);
      if (!meshes.length) { setText(status, 'this glTF file has no morph targets'); return; }
      var count = meshes[0].morphTargetInfluences.length;
      var names = [];
      var dictionary = meshes[0].morphTargetDictionary || {};
      Object.keys(dictionary).forEach(function (n) { names[dictionary[n]] = n; });
      info.targets = count;
      function setWeights(w) {
        info.weights = w.slice();
        meshes.forEach(function (m) {
          for (var i = 0; i < m.morphTargetInfluences.length; i++) m.morphTargetInfluences[i] = w[i] || 0;
        });
        view.requestRender();
      }
      function slider(min, max, value) {
        var el = document.createElement('input');
        el.type = 'range'; el.min = String(min); el.max = String(max); el.step = '0.01'; el.value = String(value);
        return el;
      }
      if (entry.mode === 'weights') {
        var weights = [];
        for (var i = 0; i < count; i++) {
          weights.push(0);
          (function (i) {
            var label = document.createElement('label'), s = slider(-3, 3, 0), out = document.createElement('span');
            label.textContent = (names[i] || 'target ' + i) + ' ';
            out.textContent = '0.00';
            s.setAttribute('data-target', String(i));
            s.addEventListener('input', function () {
              weights[i] = Number(s.value);
              out.textContent = weights[i].toFixed(2);
              setWeights(weights);
            });
            label.appendChild(s); label.appendChild(out); bar.appendChild(label);
          })(i);
        }
        setWeights(weights);
        setText(status, count + ' morph targets: move a slider to add a target with that weight');
      } else {
        // Frame 0 is the base mesh, frame j >= 1 is target j-1 at weight 1; between two frames
        // the weights blend them linearly, so the slider passes through every frame exactly.
        var s = slider(0, count, 0), out = document.createElement('span');
        s.setAttribute('data-target', 'sequence');
        var at = function (t) {
          var w = [], i = Math.floor(t), f = t - i;
          for (var j = 0; j < count; j++) w.push(0);
          if (i >= 1 && i <= count) w[i - 1] += 1 - f;
          if (f > 0 && i < count) w[i] += f;
          info.value = t;
          out.textContent = ' frame ' + t.toFixed(2) + ' of ' + count;
          setWeights(w);
        };
        s.addEventListener('input', function () { playing = false; at(Number(s.value)); });
        var playing = false;
        var play = button('play', function () {
          playing = true;
          var start = performance.now(), seconds = Math.max(2, count * 0.5);
          (function step(now) {
            if (!playing) return;
            var t = Math.min(count, (now - start) / 1000 / seconds * count);
            s.value = String(t);
            at(t);
            if (t < count) requestAnimationFrame(step); else playing = false;
          })(start);
        });
        bar.appendChild(play);
        bar.appendChild(s);
        bar.appendChild(out);
        at(0);
        setText(status, (count + 1) + ' frames: drag the slider or press play');
      }
    }).catch(function (e) { fail(status, entry.label || entry.glb.path, e); })
      .then(function () { state.pending--; });
  }

  // What site/landmarks.js (the landmark editor, loaded after this script) builds on.
  window.spherekitViewerParts = {
    state: state, byId: byId, setText: setText, fail: fail, button: button, View: View, loadScript: loadGlb,
    surfaceMaterial: surfaceMaterial
  };

  try {
    modelViewer(site.models || []);
    (site.morphs || []).forEach(morphViewer);
  } catch (e) {
    fail(byId('model-status'), 'viewer', e);
  }
})();
