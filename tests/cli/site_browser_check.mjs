// node site_browser_check.mjs NODE_DIR PAGE_DIR SHOT_DIR
// Opens PAGE_DIR/index.html (the results page, pipeline/include/spherekit/pipeline/site_page.h) in Debian's headless
// Chromium through playwright-core, twice: served by a local HTTP server on 127.0.0.1, and from
// disk (file://). Each time it records console errors and warnings, page errors and failed
// requests, waits until the viewer has loaded everything (window.spherekitViewer.pending == 0),
// screenshots every 3-D canvas and counts its pixels that differ from the canvas background,
// for every level of detail (LOD buttons), every model of the selector, the automatic level
// after zooming out with the mouse wheel, every model and all side by side with and without the
// shared texture and on its sphere, and both ends of every morph slider, and checks the
// images and tables. Screenshots go to SHOT_DIR. Prints one JSON document on stdout (the
// caller judges it; "error" when a step threw):
//   {"chromium": version, "modes": [{"mode", "url", "seconds", "error", "console_errors": [], "console_warnings": [],
//     "page_errors": [], "failed_requests": [], "viewer_errors": [], "images", "broken_images", "tables",
//     "models": [{"name", "lods": [{"lod", "triangles", "coverage", "shot"}]}], "auto_lod": {"before", "after_zoom_out"},
//     "morphs": [{"targets", "coverage_start", "coverage_end", "changed_fraction", "shots"}],
//     "textures": [{"model" (index or "all"), "coverage_plain", "coverage_textured", "changed_fraction",
//       "coverage_sphere", "sphere_changed_fraction", "shots"}]}]}
// Packages are loaded from NODE_DIR/node_modules (scripts/setup_viewer.sh --browser installs
// them); Chromium from $CHROMIUM, default /usr/bin/chromium.
// Exit code 0 when it ran (whatever it found), 1 when the browser could not be driven, 2 on usage errors.
import { join, resolve } from 'node:path';
import { inflateSync } from 'node:zlib';
import { runPageChecks } from './browser_harness.mjs';

const [nodeDir, pageDirArg, shotDirArg] = process.argv.slice(2);
if (!nodeDir || !pageDirArg || !shotDirArg) {
  console.error('usage: node site_browser_check.mjs NODE_DIR PAGE_DIR SHOT_DIR');
  process.exit(2);
}
const shotDir = resolve(shotDirArg);
// The page's canvas background (viewer.js BACKGROUND) and how far a pixel must be from it to count.
const BACKGROUND = [0x20, 0x25, 0x2b], THRESHOLD = 30;

// ---- PNG decoding (8-bit, non-interlaced: what Chromium's screenshots are), to count pixels.
function decodePng(buf) {
  if (buf.readUInt32BE(0) !== 0x89504e47) throw new Error('not a PNG');
  let at = 8, width = 0, height = 0, depth = 0, type = 0, interlace = 0;
  const idat = [];
  while (at < buf.length) {
    const len = buf.readUInt32BE(at), kind = buf.toString('latin1', at + 4, at + 8), data = buf.subarray(at + 8, at + 8 + len);
    if (kind === 'IHDR') { width = data.readUInt32BE(0); height = data.readUInt32BE(4); depth = data[8]; type = data[9]; interlace = data[12]; }
    if (kind === 'IDAT') idat.push(data);
    at += 12 + len;
  }
  const channels = { 0: 1, 2: 3, 4: 2, 6: 4 }[type];
  if (depth !== 8 || !channels || interlace) throw new Error(`unsupported PNG (depth ${depth}, type ${type}, interlace ${interlace})`);
  const raw = inflateSync(Buffer.concat(idat)), stride = width * channels, out = Buffer.alloc(height * stride);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)], line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; x++) {
      const a = x >= channels ? out[y * stride + x - channels] : 0, b = y > 0 ? out[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? out[(y - 1) * stride + x - channels] : 0;
      let v = line[x];
      if (filter === 1) v += a;
      else if (filter === 2) v += b;
      else if (filter === 3) v += (a + b) >> 1;
      else if (filter === 4) { const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c); v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c; }
      out[y * stride + x] = v & 255;
    }
  }
  const rgb = (i) => channels >= 3 ? [out[i * channels], out[i * channels + 1], out[i * channels + 2]] : [out[i * channels], out[i * channels], out[i * channels]];
  return { width, height, rgb };
}
function coverage(png) {
  let n = 0;
  for (let i = 0; i < png.width * png.height; i++) {
    const [r, g, b] = png.rgb(i);
    if (Math.abs(r - BACKGROUND[0]) + Math.abs(g - BACKGROUND[1]) + Math.abs(b - BACKGROUND[2]) > THRESHOLD) n++;
  }
  return n / (png.width * png.height);
}
function changedFraction(p, q) {
  if (p.width !== q.width || p.height !== q.height) return 1;
  let n = 0;
  for (let i = 0; i < p.width * p.height; i++) {
    const [a, b, c] = p.rgb(i), [d, e, f] = q.rgb(i);
    if (Math.abs(a - d) + Math.abs(b - e) + Math.abs(c - f) > THRESHOLD) n++;
  }
  return n / (p.width * p.height);
}

// Waits until the viewer has nothing pending and two more frames were drawn.
async function settle(page) {
  await page.waitForFunction(() => window.spherekitViewer && window.spherekitViewer.pending === 0, null, { timeout: 30000 });
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
}
async function shoot(page, selector, file) {
  const bytes = await page.locator(selector).screenshot({ path: join(shotDir, file) });
  return decodePng(bytes);
}

async function check(context, mode, url) {
  const started = Date.now();
  const page = await context.newPage();
  const r = { mode, url, console_errors: [], console_warnings: [], page_errors: [], failed_requests: [], viewer_errors: [],
              models: [], morphs: [], textures: [] };
  page.on('console', (m) => {
    // Chromium's own performance note when a canvas is read back (the screenshots): not the page's.
    if (/GPU stall due to ReadPixels/.test(m.text())) return;
    if (m.type() === 'error') r.console_errors.push(m.text());
    if (m.type() === 'warning') r.console_warnings.push(m.text());
  });
  page.on('pageerror', (e) => r.page_errors.push(String(e && e.message || e)));
  page.on('requestfailed', (q) => r.failed_requests.push(`${q.url()}: ${q.failure()?.errorText}`));
  try {
    await page.goto(url);
    r.tables = await page.locator('table').count();
    if (await page.evaluate(() => !!window.SPHEREKIT_SITE)) await viewerChecks(page, mode, r);
    const images = await page.evaluate(() => Array.from(document.images).map((i) => ({ src: i.getAttribute('src'), ok: i.complete && i.naturalWidth > 0 })));
    r.images = images.length;
    r.broken_images = images.filter((i) => !i.ok).map((i) => i.src);
    await page.screenshot({ path: join(shotDir, `${mode}_page.png`), fullPage: true });
  } catch (e) {
    r.error = String(e && e.message || e);
  }
  r.seconds = (Date.now() - started) / 1000;
  await page.close();
  return r;
}

// The 3-D views: every level of every model, both ends of every morph. Interactions stop at
// the first failure the viewer reports (its errors are in the report).
async function viewerChecks(page, mode, r) {
  await settle(page);
  const failed = () => page.evaluate(() => window.spherekitViewer ? window.spherekitViewer.errors.length > 0 : true);
  const models = await page.evaluate(() => window.SPHEREKIT_SITE.models.map((m) => m.name));
  for (let m = 0; m < models.length && !(await failed()); m++) {
    if (m > 0) {
      await page.selectOption('#model-select', String(m));
      await page.waitForFunction((m) => window.spherekitViewer.model === m, m);
      await settle(page);
    }
    const entry = { name: models[m], lods: [] };
    r.models.push(entry);
    const levels = await page.evaluate(() => window.spherekitViewer.levels);
    for (let k = 0; k < levels && !(await failed()); k++) {
      await page.click(`#lod-buttons button[data-lod="${k}"]`);
      await page.waitForFunction((k) => window.spherekitViewer.lod === k, k);
      await settle(page);
      const shot = `${mode}_model${m}_lod${k}.png`;
      const png = await shoot(page, '#model-canvas', shot);
      entry.lods.push({ lod: k, triangles: await page.evaluate(() => window.spherekitViewer.triangles), coverage: coverage(png), shot });
    }
    if (levels > 0) await page.click('#lod-buttons button[data-lod="auto"]');
  }
  // Automatic switching: zooming out with the mouse wheel (orbit controls) picks a coarser level.
  if (r.models.length && r.models[0].lods.length > 1 && !(await failed())) {
    const box = await page.locator('#model-canvas').boundingBox();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    const before = await page.evaluate(() => window.spherekitViewer.lod);
    await page.mouse.wheel(0, 3000);
    await page.waitForFunction(() => window.spherekitViewer.lod > 0, null, { timeout: 10000 }).catch(() => {});
    await settle(page);
    r.auto_lod = { before, after_zoom_out: await page.evaluate(() => window.spherekitViewer.lod) };
    await shoot(page, '#model-canvas', `${mode}_auto_zoomed_out.png`);
  }
  // The shared texture (issue 22): on every model, and on all side by side, the grid through
  // TEXCOORD_0 changes the model's pixels against the grey render; each is also shown on its
  // sphere.
  const hasTexture = await page.evaluate(() => !!document.querySelector('#shared-texture'));
  if (hasTexture && r.models.length) {
    const targets = r.models.length > 1 ? ['all', ...r.models.map((_, m) => m)] : [0];
    for (const target of targets) {
      if (await failed()) break;
      await page.evaluate((v) => {
        const s = document.querySelector('#model-select');
        s.value = v;
        s.dispatchEvent(new Event('change'));
      }, String(target));
      await page.waitForFunction((t) => window.spherekitViewer.model === t, target);
      await settle(page);
      await page.click('#lod-buttons button[data-lod="0"]');
      await page.waitForFunction(() => window.spherekitViewer.lod === 0);
      await settle(page);
      const tag = `${mode}_texture_${target}`;
      const plain = await shoot(page, '#model-canvas', `${tag}_plain.png`);
      await page.check('#shared-texture');
      await settle(page);
      const textured = await shoot(page, '#model-canvas', `${tag}_textured.png`);
      await page.check('#on-sphere');
      await settle(page);
      const sphere = await shoot(page, '#model-canvas', `${tag}_sphere.png`);
      await page.uncheck('#on-sphere');
      await page.uncheck('#shared-texture');
      await page.click('#lod-buttons button[data-lod="auto"]');
      await settle(page);
      r.textures.push({ model: target, coverage_plain: coverage(plain), coverage_textured: coverage(textured),
                        changed_fraction: changedFraction(plain, textured), coverage_sphere: coverage(sphere),
                        sphere_changed_fraction: changedFraction(textured, sphere),
                        shots: [`${tag}_plain.png`, `${tag}_textured.png`, `${tag}_sphere.png`] });
    }
  }
  const morphs = await page.evaluate(() => window.spherekitViewer ? window.spherekitViewer.morphs.length : 0);
  for (let k = 0; k < morphs && !(await failed()); k++) {
    const targets = await page.evaluate((k) => window.spherekitViewer.morphs[k].targets, k);
    const set = async (value) => {
      await page.evaluate(([k, value]) => {
        for (const s of document.querySelectorAll(`#morph-controls-${k} input[type=range]`)) {
          s.value = String(value);
          s.dispatchEvent(new Event('input'));
        }
      }, [k, value]);
      await settle(page);
    };
    const kind = await page.evaluate((k) => document.querySelector(`#morph-controls-${k} input[data-target="sequence"]`) ? 'sequence' : 'weights', k);
    await set(kind === 'sequence' ? 0 : -2);
    const start = await shoot(page, `#morph-canvas-${k}`, `${mode}_morph${k}_start.png`);
    await set(kind === 'sequence' ? targets : 2);
    const end = await shoot(page, `#morph-canvas-${k}`, `${mode}_morph${k}_end.png`);
    r.morphs.push({ targets, mode: kind, coverage_start: coverage(start), coverage_end: coverage(end),
                    changed_fraction: changedFraction(start, end),
                    shots: [`${mode}_morph${k}_start.png`, `${mode}_morph${k}_end.png`] });
  }
  r.viewer_errors = await page.evaluate(() => window.spherekitViewer ? window.spherekitViewer.errors : ['viewer.js did not run']);
}

// Whole run: well under the test's budget even on a loaded machine.
await runPageChecks({ name: 'site_browser_check', nodeDir, pageDir: pageDirArg, outDir: shotDir, seconds: 240, check });
