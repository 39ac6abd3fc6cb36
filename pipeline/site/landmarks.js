// SphereKit results page: the landmark editor (issue 25; written by spherekit, see site_page.h).
// Each member is shown as its own input mesh, exactly as spherekit reads it (site/mesh/*.js), so
// a vertex picked here is the vertex number its NAME.lm.txt file, `spherekit check --landmarks`
// and `spherekit consistent` use. Edits stay in the page until downloaded (a Blob URL: no
// request, so it works from disk too).
(function () {
  'use strict';
  var parts = window.spherekitViewerParts, site = window.SPHEREKIT_SITE || {};
  var members = site.landmarks || [];
  // No parts: viewer.js did not run (three.js missing), and has said so in every status box.
  if (!parts || !members.length || !document.getElementById('landmark-canvas')) return;
  var state = parts.state, byId = parts.byId;
  var MARKER = 0x35c3ff, SELECTED = 0xffa526, MOVING = 0xff3b30;

  var ed = state.landmarks = {
    member: -1, selected: -1, moving: -1, picks: 0, downloads: 0, message: '', lastPick: null, mesh: null, view: null,
    members: members.map(function (m) {
      return {
        name: m.name, file: m.file, source: m.source || '', error: m.error || '', note: m.note || '',
        vertices: m.vertices, offset: m.offset || [0, 0, 0], revision: 0, saved: 0,
        // A proposal's confidence belongs to its point: kept on rename, dropped on a move.
        landmarks: (m.landmarks || []).map(function (l) {
          var c = m.confidence && typeof m.confidence[l.name] === 'number' ? m.confidence[l.name] : null;
          return { name: l.name, vertex: l.vertex, confidence: c };
        })
      };
    })
  };

  // ---- the file: what formats::read_landmarks accepts (formats/src/feature_io.cpp).
  function nameProblem(name, landmarks, except) {
    if (!name) return 'a name cannot be empty';
    if (/[\u0000-\u0020\u007f#]/.test(name)) return 'a name is one word, without spaces or "#"';
    for (var i = 0; i < landmarks.length; i++)
      if (i !== except && landmarks[i].name === name) return 'this member already has a landmark named ' + name;
    return '';
  }
  function fileText(m) {
    var lines = ['# name vertex_index (0-based vertex numbers of the input mesh), from the SphereKit results page'];
    m.landmarks.forEach(function (l) { lines.push(l.name + ' ' + l.vertex); });
    return lines.join('\n') + '\n';
  }
  function download(m) {
    var a = document.createElement('a');
    a.href = URL.createObjectURL(new Blob([fileText(m)], { type: 'text/plain' }));
    a.download = m.file;
    document.body.appendChild(a);
    a.click();
    a.remove();
    setTimeout(function () { URL.revokeObjectURL(a.href); }, 60000);
    m.saved = m.revision;
    ed.downloads++;
  }

  // ---- names across members: the consistent collection needs every name on every member.
  function allNames() {
    var seen = {}, names = [];
    ed.members.forEach(function (m) {
      m.landmarks.forEach(function (l) { if (!seen[l.name]) { seen[l.name] = true; names.push(l.name); } });
    });
    return names;
  }
  function has(m, name) {
    for (var i = 0; i < m.landmarks.length; i++) if (m.landmarks[i].name === name) return true;
    return false;
  }
  function missingOn(name) {
    return ed.members.filter(function (m) { return !has(m, name); }).map(function (m) { return m.name; });
  }
  // A new landmark takes the first name other members have and this one lacks, else point_N.
  function freeName(m) {
    var names = allNames();
    for (var i = 0; i < names.length; i++) if (!has(m, names[i])) return names[i];
    for (var n = m.landmarks.length + 1; ; n++) {
      var name = 'point_' + n;
      if (names.indexOf(name) < 0) return name;
    }
  }
  function owner(m, vertex) {
    for (var i = 0; i < m.landmarks.length; i++) if (m.landmarks[i].vertex === vertex) return i;
    return -1;
  }

  // ---- the view
  var box = byId('landmark-canvas'), status = byId('landmark-status'), sourceEl = byId('landmark-source');
  var list = byId('landmark-list'), select = byId('landmark-member'), labelsBox = byId('landmark-labels');
  var edges = byId('landmark-wireframe'), downloadButton = byId('landmark-download');
  var view = ed.view = new parts.View(box);
  var material = parts.surfaceMaterial(false), wireMaterial = parts.surfaceMaterial(true);
  var sphere = new THREE.SphereGeometry(1, 16, 12), markerMaterials = {};
  var labels = document.createElement('div');
  labels.className = 'landmark-labels';
  box.appendChild(labels);
  var mesh = null, markers = null, markerRadius = 1, token = 0;
  var raycaster = new THREE.Raycaster(), p = new THREE.Vector3(), n = new THREE.Vector3(), eye = new THREE.Vector3();

  function current() { return ed.members[ed.member]; }
  function say(text, isError) {
    ed.message = text;
    status.textContent = text;
    status.className = isError ? 'status error' : 'status';
  }
  function markerMaterial(color) {
    if (!markerMaterials[color]) markerMaterials[color] = new THREE.MeshBasicMaterial({ color: color });
    return markerMaterials[color];
  }

  // Markers, labels and the list from the member's landmarks. `list` false keeps the list's
  // inputs (and the focus in one of them).
  function refresh(rebuildList) {
    var m = current();
    if (!mesh || !m) return;
    var pos = mesh.geometry.attributes.position;
    markers.clear();
    labels.textContent = '';
    m.landmarks.forEach(function (l, i) {
      var active = i === ed.selected || i === ed.moving;
      var s = new THREE.Mesh(sphere, markerMaterial(i === ed.moving ? MOVING : i === ed.selected ? SELECTED : MARKER));
      s.position.fromBufferAttribute(pos, l.vertex);
      s.scale.setScalar(markerRadius * (active ? 1.5 : 1));
      markers.add(s);
      var label = document.createElement('div');
      label.className = 'landmark-label' + (active ? ' selected' : '');
      label.textContent = l.name;
      labels.appendChild(label);
    });
    if (rebuildList !== false) buildList();
    var rows = list.children;
    for (var r = 0; r < rows.length; r++) rows[r].className = r === ed.moving ? 'moving' : r === ed.selected ? 'selected' : '';
    describe();
    view.requestRender();
  }
  function describe() {
    var m = current(), lacking = allNames().filter(function (name) { return !has(m, name); });
    var text = m.source ? 'landmarks: ' + m.source : '';
    if (m.error) text += (text ? '. ' : '') + 'The landmark file could not be read: ' + m.error;
    if (m.note) text += (text ? '. ' : '') + m.note;
    text += (text ? '. ' : '') + m.name + ': ' + m.landmarks.length + ' landmarks on ' + m.vertices + ' vertices' +
      (m.revision !== m.saved ? ', edited since the last download' : '') +
      (lacking.length ? '; missing here, on other members: ' + lacking.join(', ') : '');
    sourceEl.textContent = text;
    sourceEl.className = m.error ? 'status error' : m.note ? 'status warn' : 'status';
    if (downloadButton) downloadButton.textContent = 'download ' + m.file;
  }
  function buildList() {
    var m = current();
    list.textContent = '';
    m.landmarks.forEach(function (l, i) {
      var li = document.createElement('li'), input = document.createElement('input'), where = document.createElement('span');
      input.type = 'text';
      input.className = 'landmark-name';
      input.value = l.name;
      input.spellcheck = false;
      input.addEventListener('focus', function () { ed.selected = i; refresh(false); });
      input.addEventListener('change', function () { rename(i, input.value.trim()); });
      input.addEventListener('keydown', function (e) { if (e.key === 'Enter') input.blur(); });
      where.textContent = ' vertex ' + l.vertex;
      var missing = missingOn(l.name);
      if (missing.length) where.textContent += ' (not on ' + missing.join(', ') + ')';
      li.appendChild(input);
      li.appendChild(where);
      if (l.confidence !== null && l.confidence !== undefined) {
        // Below one half the proposal was unsure of this match: the first ones to check.
        var sure = document.createElement('span');
        sure.className = 'landmark-confidence' + (l.confidence < 0.5 ? ' low' : '');
        sure.textContent = ' confidence ' + l.confidence.toFixed(2);
        sure.title = 'how sure the proposal is of this match (landmarks_report.json)';
        li.appendChild(sure);
      }
      var move = parts.button('move', function () {
        ed.moving = ed.moving === i ? -1 : i;
        ed.selected = i;
        say(ed.moving >= 0 ? 'click the surface where ' + l.name + ' belongs ("move" again cancels)' : 'move cancelled');
        refresh(false);
      });
      move.className = 'landmark-move';
      var del = parts.button('delete', function () {
        m.landmarks.splice(i, 1);
        ed.selected = ed.moving = -1;
        m.revision++;
        say('deleted ' + l.name + ' (vertex ' + l.vertex + ') from ' + m.name);
        refresh();
      });
      del.className = 'landmark-delete';
      li.appendChild(move);
      li.appendChild(del);
      list.appendChild(li);
    });
  }
  function rename(i, name) {
    var m = current(), old = m.landmarks[i].name;
    if (name === old) return;
    var problem = nameProblem(name, m.landmarks, i);
    if (problem) {
      say('cannot rename ' + old + ': ' + problem, true);
      refresh();
      return;
    }
    m.landmarks[i].name = name;
    m.revision++;
    say('renamed ' + old + ' to ' + name + ' on ' + m.name);
    refresh();
  }

  // Labels follow their vertices; a label whose vertex faces away from the camera is dimmed.
  view.beforeRender = function () {
    var m = current(), show = !labelsBox || labelsBox.checked;
    labels.style.display = show ? '' : 'none';
    if (!mesh || !m || !show) return;
    var pos = mesh.geometry.attributes.position, nor = mesh.geometry.attributes.normal, nodes = labels.children;
    var w = box.clientWidth, h = box.clientHeight;
    view.camera.updateMatrixWorld();
    for (var i = 0; i < nodes.length && i < m.landmarks.length; i++) {
      p.fromBufferAttribute(pos, m.landmarks[i].vertex);
      n.fromBufferAttribute(nor, m.landmarks[i].vertex);
      var facing = n.dot(eye.copy(view.camera.position).sub(p)) >= 0;
      p.project(view.camera);
      nodes[i].style.transform = 'translate(' + Math.round((p.x + 1) / 2 * w + 7) + 'px,' + Math.round((1 - p.y) / 2 * h - 9) + 'px)';
      nodes[i].style.opacity = facing ? '1' : '0.35';
      nodes[i].style.visibility = p.z > -1 && p.z < 1 ? 'visible' : 'hidden';
    }
  };

  // The vertex under the pointer: of the triangle the ray meets first, the corner nearest to
  // where it meets it.
  var canvas = view.renderer.domElement;
  function vertexAt(clientX, clientY) {
    var rect = canvas.getBoundingClientRect();
    var ndc = new THREE.Vector2((clientX - rect.left) / rect.width * 2 - 1, 1 - (clientY - rect.top) / rect.height * 2);
    view.camera.updateMatrixWorld();
    raycaster.setFromCamera(ndc, view.camera);
    var hit = raycaster.intersectObject(mesh, false)[0];
    if (!hit || !hit.face) return null;
    var pos = mesh.geometry.attributes.position, best = -1, bestDistance = Infinity;
    [hit.face.a, hit.face.b, hit.face.c].forEach(function (v) {
      var d = p.fromBufferAttribute(pos, v).distanceToSquared(hit.point);
      if (d < bestDistance) { bestDistance = d; best = v; }
    });
    return { vertex: best, point: hit.point };
  }
  function pick(clientX, clientY) {
    var m = current();
    if (!mesh || !m) return;
    var at = vertexAt(clientX, clientY);
    if (!at) { say('no surface under the pointer: click on the mesh'); return; }
    var o = m.offset;
    ed.picks++;
    ed.lastPick = { vertex: at.vertex, point: [at.point.x + o[0], at.point.y + o[1], at.point.z + o[2]] };
    var held = owner(m, at.vertex);
    if (ed.moving >= 0) {
      var l = m.landmarks[ed.moving];
      if (held >= 0 && held !== ed.moving) {
        say('vertex ' + at.vertex + ' already holds ' + m.landmarks[held].name + ' (one landmark per vertex)', true);
        return;
      }
      var from = l.vertex;
      l.vertex = at.vertex;
      l.confidence = null;
      ed.selected = ed.moving;
      ed.moving = -1;
      m.revision++;
      say('moved ' + l.name + ' from vertex ' + from + ' to vertex ' + at.vertex);
    } else if (held >= 0) {
      ed.selected = held;
      say('selected ' + m.landmarks[held].name + ' (vertex ' + at.vertex + '): "move" moves it');
    } else {
      var name = freeName(m);
      m.landmarks.push({ name: name, vertex: at.vertex, confidence: null });
      ed.selected = m.landmarks.length - 1;
      m.revision++;
      say('placed ' + name + ' at vertex ' + at.vertex + ' (edit its name below to rename it)');
    }
    refresh();
  }
  // A click picks; a drag (more than a few pixels) turns the view, as before.
  var down = null;
  canvas.addEventListener('pointerdown', function (e) { down = e.button === 0 ? { x: e.clientX, y: e.clientY } : null; });
  canvas.addEventListener('pointerup', function (e) {
    var d = down;
    down = null;
    if (d && e.button === 0 && Math.abs(e.clientX - d.x) + Math.abs(e.clientY - d.y) <= 4) pick(e.clientX, e.clientY);
  });
  window.addEventListener('keydown', function (e) {
    if (e.key === 'Escape' && ed.moving >= 0) { ed.moving = -1; say('move cancelled'); refresh(false); }
  });

  function show(k) {
    var entry = members[k], mine = ++token;
    ed.member = k;
    ed.selected = ed.moving = -1;
    state.pending++;
    say('loading ' + entry.name + '...');
    parts.loadScript(entry.mesh).then(function (buffer) {
      if (mine !== token) return;
      var head = new Uint32Array(buffer, 0, 2), nv = head[0], nf = head[1];
      if (buffer.byteLength !== 8 + 12 * nv + 12 * nf)
        throw new Error(entry.mesh.script + ' holds ' + buffer.byteLength + ' bytes, not ' + nv + ' vertices and ' + nf + ' triangles');
      var geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(buffer, 8, 3 * nv), 3));
      geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(buffer, 8 + 12 * nv, 3 * nf), 1));
      geometry.computeVertexNormals();
      geometry.computeBoundingSphere();
      mesh = ed.mesh = new THREE.Mesh(geometry, edges && edges.checked ? wireMaterial : material);
      markers = new THREE.Group();
      var group = new THREE.Group();
      group.add(mesh);
      group.add(markers);
      markerRadius = geometry.boundingSphere.radius * 0.012;
      view.show(group);
      view.frame(mesh);
      refresh();
      say(entry.name + ': ' + nv + ' vertices, ' + nf + ' triangles. Click the surface to place a landmark.');
    }).catch(function (e) { parts.fail(status, entry.name + ' landmarks', e); })
      .then(function () { state.pending--; });
  }

  if (select) select.addEventListener('change', function () { show(Number(select.value)); });
  if (labelsBox) labelsBox.addEventListener('change', function () { view.requestRender(); });
  if (edges) edges.addEventListener('change', function () {
    if (mesh) mesh.material = edges.checked ? wireMaterial : material;
    view.requestRender();
  });
  if (downloadButton) downloadButton.addEventListener('click', function () {
    var m = current();
    if (!m) return;
    download(m);
    say('downloaded ' + m.file + ' (' + m.landmarks.length + ' landmarks)');
    describe();
  });
  var all = byId('landmark-download-all');
  if (all) all.addEventListener('click', function () {
    // One file after the other: browsers may refuse several downloads started at once.
    ed.members.forEach(function (m, k) { setTimeout(function () { download(m); if (k === ed.members.length - 1) describe(); }, 250 * k); });
    say('downloading ' + ed.members.map(function (m) { return m.file; }).join(', '));
  });
  // Leaving the page loses edits that were not downloaded: the browser asks first.
  window.addEventListener('beforeunload', function (e) {
    if (ed.members.some(function (m) { return m.revision !== m.saved; })) { e.preventDefault(); e.returnValue = ''; }
  });

  try {
    show(select ? Number(select.value) || 0 : 0);
  } catch (e) {
    parts.fail(status, 'landmarks', e);
  }
})();
