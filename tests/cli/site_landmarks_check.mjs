// node site_landmarks_check.mjs NODE_DIR PAGE_DIR WORK_DIR
// The results page's landmark editor (issue 25; pipeline/site/landmarks.js) driven like a user
// in Debian's headless Chromium through playwright-core, twice: the page served by a local
// HTTP server on 127.0.0.1, and opened from disk (file://). Each time, on the first member:
//   - place: clicks the canvas exactly on the screen position of a visible vertex V1 (found by
//     the test itself: a vertex of the triangle three.js's raycaster meets at a pixel, kept only
//     when the ray through the vertex's own projection meets the surface at that vertex), so
//     the nearest vertex to the picking ray is V1;
//   - drag: a drag across the canvas turns the view and places nothing;
//   - move: the first landmark's "move" button, then a click on another such vertex V2;
//   - rename: types a new name into the second landmark's field (Enter); and a name with a
//     space, which must be refused;
//   - download: the member's button; the file is saved into WORK_DIR/MODE/; then "download all"
//     (one file per member, into WORK_DIR/MODE/all/);
//   - another member: its own mesh and landmarks.
// The caller (site_landmarks_test.cpp) judges the report and reads the downloads back with
// `spherekit check --landmarks`. Prints one JSON document on stdout:
//   {"chromium", "modes": [{"mode", "url", "error", "console_errors", "page_errors", "failed_requests",
//     "viewer_errors", "member", "file", "vertices", "initial": [{name, vertex}], "labels": n, "confidences": n,
//     "placed": {"vertex", "name", "point", "click"}, "drag": {"picks_before", "picks_after", "camera_moved",
//     "landmarks_before", "landmarks_after"}, "moved": {"name", "from", "to"}, "renamed": {"from", "to", "vertex"},
//     "refused_rename": {"tried", "name_after", "message"}, "final": [...], "labels_final", "confidences_final", "download": {"suggested", "path"},
//     "download_all": {"members", "files", "dir"}, "second": {"member", "vertices", "landmarks", "labels"}}]}
// Exit code 0 when it ran (whatever it found), 1 when the browser could not be driven, 2 on usage errors.
import { mkdirSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { runPageChecks } from './browser_harness.mjs';

const [nodeDir, pageDirArg, workDirArg] = process.argv.slice(2);
if (!nodeDir || !pageDirArg || !workDirArg) {
  console.error('usage: node site_landmarks_check.mjs NODE_DIR PAGE_DIR WORK_DIR');
  process.exit(2);
}
const workDir = resolve(workDirArg);

async function settle(page) {
  await page.waitForFunction(() => window.spherekitViewer && window.spherekitViewer.pending === 0 &&
                                   window.spherekitViewer.landmarks && window.spherekitViewer.landmarks.mesh, null, { timeout: 30000 });
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
}
const landmarks = (page) => page.evaluate(() => {
  const ed = window.spherekitViewer.landmarks;
  return ed.members[ed.member].landmarks.map((l) => ({ name: l.name, vertex: l.vertex }));
});

// A vertex the user can click: near the canvas point (fx, fy) (fractions of its size), not
// holding a landmark, whose own projection is a pixel where the first surface the ray meets is
// a triangle of that vertex, at that vertex. Returns page coordinates of that pixel.
function findTarget(page, fx, fy) {
  return page.evaluate(([fx, fy]) => {
    const ed = window.spherekitViewer.landmarks, mesh = ed.mesh, camera = ed.view.camera;
    const canvas = ed.view.renderer.domElement, rect = canvas.getBoundingClientRect();
    const taken = new Set(ed.members[ed.member].landmarks.map((l) => l.vertex));
    const pos = mesh.geometry.attributes.position, ray = new THREE.Raycaster();
    const radius = mesh.geometry.boundingSphere.radius;
    camera.updateMatrixWorld();
    const cast = (px, py) => {
      ray.setFromCamera(new THREE.Vector2(px / rect.width * 2 - 1, 1 - py / rect.height * 2), camera);
      return ray.intersectObject(mesh, false)[0];
    };
    for (let ring = 0; ring < 40; ring++) {
      for (let k = 0; k < Math.max(1, 8 * ring); k++) {
        const a = ring ? (2 * Math.PI * k) / (8 * ring) : 0;
        const px = fx * rect.width + 6 * ring * Math.cos(a), py = fy * rect.height + 6 * ring * Math.sin(a);
        const hit = cast(px, py);
        if (!hit) continue;
        for (const v of [hit.face.a, hit.face.b, hit.face.c]) {
          if (taken.has(v)) continue;
          const p = new THREE.Vector3().fromBufferAttribute(pos, v), s = p.clone().project(camera);
          const vx = (s.x + 1) / 2 * rect.width, vy = (1 - s.y) / 2 * rect.height;
          // Whole pixels (where the mouse can be) near the pixel centre the vertex projects to.
          const cx = Math.floor(vx) + 0.5, cy = Math.floor(vy) + 0.5;
          if (Math.abs(cx - vx) > 0.2 || Math.abs(cy - vy) > 0.2) continue;
          const back = cast(cx, cy);
          if (!back || ![back.face.a, back.face.b, back.face.c].includes(v)) continue;
          if (back.point.distanceTo(p) > 1e-3 * radius) continue;
          return { vertex: v, x: rect.left + cx, y: rect.top + cy };
        }
      }
    }
    return null;
  }, [fx, fy]);
}

async function check(context, mode, url) {
  const page = await context.newPage();
  const r = { mode, url, console_errors: [], page_errors: [], failed_requests: [], viewer_errors: [] };
  page.on('console', (m) => {
    if (/GPU stall due to ReadPixels/.test(m.text())) return;
    if (m.type() === 'error') r.console_errors.push(m.text());
  });
  page.on('pageerror', (e) => r.page_errors.push(String(e && e.message || e)));
  page.on('requestfailed', (q) => r.failed_requests.push(`${q.url()}: ${q.failure()?.errorText}`));
  try {
    await page.goto(url);
    await settle(page);
    await page.locator('#landmark-canvas').scrollIntoViewIfNeeded();
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    Object.assign(r, await page.evaluate(() => {
      const ed = window.spherekitViewer.landmarks, m = ed.members[ed.member];
      return { member: m.name, file: m.file, vertices: m.vertices };
    }));
    r.initial = await landmarks(page);
    r.labels = await page.locator('#landmark-canvas .landmark-label').count();
    r.confidences = await page.locator('#landmark-list .landmark-confidence').count();
    const shot = await page.locator('#landmark-canvas').screenshot({ path: join(workDir, `${mode}_landmarks.png`) });
    r.screenshot_bytes = shot.length;

    // Place.
    const t1 = await findTarget(page, 0.5, 0.5);
    if (!t1) throw new Error('no clickable vertex near the canvas centre');
    const picks0 = await page.evaluate(() => window.spherekitViewer.landmarks.picks);
    await page.mouse.click(t1.x, t1.y);
    await page.waitForFunction((n) => window.spherekitViewer.landmarks.picks > n, picks0, { timeout: 5000 });
    const afterPlace = await landmarks(page);
    const last = afterPlace[afterPlace.length - 1];
    r.placed = { target: t1.vertex, vertex: afterPlace.length === r.initial.length + 1 ? last.vertex : null,
                 name: last.name, click: [t1.x, t1.y],
                 point: await page.evaluate(() => window.spherekitViewer.landmarks.lastPick.point),
                 labels: await page.locator('#landmark-canvas .landmark-label').count() };

    // Drag: turns the view, places nothing.
    const box = await page.locator('#landmark-canvas').boundingBox();
    const camera = () => page.evaluate(() => window.spherekitViewer.landmarks.view.camera.position.toArray());
    const before = await camera(), picks1 = await page.evaluate(() => window.spherekitViewer.landmarks.picks);
    await page.mouse.move(box.x + box.width * 0.3, box.y + box.height * 0.5);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width * 0.4, box.y + box.height * 0.55, { steps: 6 });
    await page.mouse.up();
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    const after = await camera();
    r.drag = { picks_before: picks1, picks_after: await page.evaluate(() => window.spherekitViewer.landmarks.picks),
               camera_moved: Math.hypot(...after.map((a, i) => a - before[i])),
               landmarks_before: afterPlace.length, landmarks_after: (await landmarks(page)).length };

    // Move the first landmark.
    const from = (await landmarks(page))[0];
    await page.click('#landmark-list li:nth-child(1) .landmark-move');
    const t2 = await findTarget(page, 0.35, 0.45);
    if (!t2) throw new Error('no second clickable vertex');
    const picks2 = await page.evaluate(() => window.spherekitViewer.landmarks.picks);
    await page.mouse.click(t2.x, t2.y);
    await page.waitForFunction((n) => window.spherekitViewer.landmarks.picks > n, picks2, { timeout: 5000 });
    const moved = (await landmarks(page))[0];
    r.moved = { name: from.name, from: from.vertex, target: t2.vertex, to: moved.vertex, name_after: moved.name };

    // Rename the second one, then try a name the file format cannot hold.
    const second = (await landmarks(page))[1];
    const field = page.locator('#landmark-list li:nth-child(2) input.landmark-name');
    await field.fill('renamed_on_page');
    await field.press('Enter');
    const renamed = (await landmarks(page))[1];
    r.renamed = { from: second.name, to: renamed.name, vertex_before: second.vertex, vertex: renamed.vertex };
    const third = page.locator('#landmark-list li:nth-child(3) input.landmark-name');
    const thirdName = (await landmarks(page))[2].name;
    await third.fill('two words');
    await third.press('Enter');
    r.refused_rename = { tried: 'two words', name_before: thirdName, name_after: (await landmarks(page))[2].name,
                         message: await page.locator('#landmark-status').textContent(),
                         status_class: await page.locator('#landmark-status').getAttribute('class') };

    r.final = await landmarks(page);
    r.labels_final = await page.locator('#landmark-canvas .landmark-label').count();
    r.confidences_final = await page.locator('#landmark-list .landmark-confidence').count();
    await page.locator('#landmark-canvas').screenshot({ path: join(workDir, `${mode}_landmarks_edited.png`) });

    // Download.
    const dir = join(workDir, mode);
    mkdirSync(dir, { recursive: true });
    const [download] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), page.click('#landmark-download')]);
    const saved = join(dir, download.suggestedFilename());
    await download.saveAs(saved);
    r.download = { suggested: download.suggestedFilename(), path: saved, failure: await download.failure() };

    // "download all": one file per member, each after the other.
    const members = await page.evaluate(() => window.spherekitViewer.landmarks.members.length);
    const all = [], allDir = join(dir, 'all');
    mkdirSync(allDir, { recursive: true });
    const saving = [];
    const onDownload = (d) => saving.push(d.saveAs(join(allDir, d.suggestedFilename())).then(() => all.push(d.suggestedFilename())));
    page.on('download', onDownload);
    await page.click('#landmark-download-all');
    await page.waitForFunction((n) => window.spherekitViewer.landmarks.downloads >= n + 1, members, { timeout: 10000 });
    await page.waitForTimeout(300);
    await Promise.all(saving);
    page.off('download', onDownload);
    r.download_all = { members, files: all.sort(), dir: allDir };

    // Another member: its own mesh and landmark file.
    await page.selectOption('#landmark-member', '1');
    await page.waitForFunction(() => window.spherekitViewer.landmarks.member === 1);
    await settle(page);
    r.second = await page.evaluate(() => {
      const ed = window.spherekitViewer.landmarks, m = ed.members[1];
      return { member: m.name, vertices: ed.mesh.geometry.attributes.position.count,
               landmarks: m.landmarks.map((l) => ({ name: l.name, vertex: l.vertex })) };
    });
    r.second.labels = await page.locator('#landmark-canvas .landmark-label').count();
    r.viewer_errors = await page.evaluate(() => window.spherekitViewer.errors);
  } catch (e) {
    r.error = String(e && e.message || e);
  }
  await page.close();
  return r;
}

await runPageChecks({ name: 'site_landmarks_check', nodeDir, pageDir: pageDirArg, outDir: workDir, seconds: 180, check });
