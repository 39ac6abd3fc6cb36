// What the results page's browser checks share (site_browser_check.mjs, site_landmarks_check.mjs):
// the page served by a static HTTP server on 127.0.0.1, Debian's Chromium (at $CHROMIUM, default
// /usr/bin/chromium) driven through playwright-core from NODE_DIR/node_modules, and the page
// checked twice, served and opened from disk (file://), into one JSON report
// {"chromium", "modes": [what check returned, per mode], "error" when the browser could not be
// driven}, written to OUT_DIR/report.json and printed on stdout. Exits 0 when it ran (whatever
// it found), 1 when the browser could not be driven.
import { createServer } from 'node:http';
import { readFileSync, writeFileSync, mkdtempSync, rmSync, existsSync, statSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve, extname, sep } from 'node:path';
import { pathToFileURL } from 'node:url';
import { createRequire } from 'node:module';

const types = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript', '.png': 'image/png', '.txt': 'text/plain',
                '.glb': 'model/gltf-binary', '.json': 'application/json' };

// check(context, mode, url) -> the mode's report; `name` names the watchdog's message.
export async function runPageChecks({ name, nodeDir, pageDir, outDir, seconds, check }) {
  const watchdog = setTimeout(() => { console.error(`${name}: timed out after ${seconds} s`); process.exit(1); }, seconds * 1000);
  const { chromium } = createRequire(join(resolve(nodeDir), 'package.json'))('playwright-core');
  const root = resolve(pageDir);
  const server = createServer((req, res) => {
    const path = resolve(root, '.' + decodeURIComponent(new URL(req.url, 'http://x').pathname));
    if (!(path === root || path.startsWith(root + sep)) || !existsSync(path) || !statSync(path).isFile()) {
      res.writeHead(404); res.end(); return;
    }
    res.writeHead(200, { 'content-type': types[extname(path)] || 'application/octet-stream' });
    res.end(readFileSync(path));
  });
  await new Promise((ok) => server.listen(0, '127.0.0.1', ok));

  const profile = mkdtempSync(join(tmpdir(), 'spherekit-site-profile-'));
  let context, code = 0;
  const report = { modes: [] };
  try {
    context = await chromium.launchPersistentContext(profile, {
      executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
      headless: true,
      acceptDownloads: true,
      viewport: { width: 1100, height: 900 },
      args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
             '--disable-background-networking', '--disable-component-update', '--disable-sync',
             // WebGL without a GPU: ANGLE on SwiftShader, Chromium's software rasterizer.
             '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
    });
    report.chromium = context.browser()?.version() ?? null;
    report.modes.push(await check(context, 'http', `http://127.0.0.1:${server.address().port}/index.html`));
    report.modes.push(await check(context, 'file', pathToFileURL(join(root, 'index.html')).href));
  } catch (e) {
    report.error = String(e && e.stack || e);
    code = 1;
  } finally {
    if (context) await context.close();
    server.close();
    rmSync(profile, { recursive: true, force: true });
    clearTimeout(watchdog);
  }
  writeFileSync(join(outDir, 'report.json'), JSON.stringify(report, null, 1));
  console.log(JSON.stringify(report, null, 1));
  process.exit(code);
}
