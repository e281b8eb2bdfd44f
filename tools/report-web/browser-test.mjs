// Opens an HTML report of `tubeplan evaluate --html` in headless Chromium (Debian's `chromium`,
// driven by playwright-core) with the network off, and checks what a user would see:
//   node browser-test.mjs [--stretch-frames N] [--mesh-part D] REPORT.html [SCREENSHOT.png [PLAN_SCREENSHOT.png]]
// (the screenshots: the top of the page, and the first plan's section with its plots;
// --stretch-frames N: every plan's frames repeated, 1 ms apart, to N of them as the page parses
// its data, the arrays of an unbounded recording of N / 50 s at 50 Hz: the page's script must
// cope with arrays of any length; --mesh-part D: every plan's first part made a mesh part of its
// size, each face cut into D x D cells of two triangles, as the page parses its data: the page
// must draw a mesh part of 12 D^2 triangles, D = 29 giving the 10,092 of a large one)
// - the page refers to nothing outside itself (no http(s) or protocol-relative src/href/url());
// - it loads with no console error or warning, no uncaught exception, no request but the file;
// - the screenshot is not blank (many colours, most of it not the background);
// - the 3D view draws the tube: pixels of the tube's hue in the WebGL canvas (read back from the
//   canvas itself) above a threshold, in the first plan and after scrubbing to the last frame.
// Nothing here depends on wall-clock time: no timeouts but ctest's, no frame-rate assumption.
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { chromium } from 'playwright-core';

const args = process.argv.slice(2);
let stretchFrames = 0, meshDivisions = 0;
while (args[0] === '--stretch-frames' || args[0] === '--mesh-part') {
  if (args[0] === '--stretch-frames') stretchFrames = Number(args[1]);
  else meshDivisions = Number(args[1]);
  args.splice(0, 2);
}
const [reportPath, screenshotPath, planShotPath] = args;
if (!reportPath) {
  console.error('usage: node browser-test.mjs REPORT.html [SCREENSHOT.png]');
  process.exit(2);
}
const failures = [];
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures.push(what);
};

// 1. Self-contained: no external reference an offline browser would try to load.
const html = readFileSync(reportPath, 'utf8');
const external = html.match(/\b(?:src|href|action|poster)\s*=\s*["']?\s*(?:https?:)?\/\/[^"'\s>]*/gi) ?? [];
const cssUrls = html.match(/url\(\s*["']?\s*(?:https?:)?\/\/[^)]*\)/gi) ?? [];
check(external.length === 0 && cssUrls.length === 0,
      `no external src/href/url() in the HTML (${[...external, ...cssUrls].slice(0, 3).join(', ') || 'none'})`);
check(/<canvas id="view"/.test(html), 'the page has the 3D view');

// 2. Headless Chromium, software WebGL (SwiftShader), network disabled three ways: the context is
// offline, the proxy is a closed port, and the page's CSP forbids every fetch.
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  timeout: 0,
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
         '--disable-background-networking', '--disable-component-update', '--disable-sync',
         '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
         '--proxy-server=127.0.0.1:9', '--proxy-bypass-list=<-loopback>'],
});
const context = await browser.newContext({ offline: true, viewport: { width: 1280, height: 1400 },
                                           deviceScaleFactor: 1 });
if (stretchFrames > 0) {
  // Before the page's own script: its data, once parsed, gets every plan's frames repeated (the
  // same arrays by reference, so the browser holds them cheaply) up to N frames.
  await context.addInitScript((n) => {
    const parse = JSON.parse;
    JSON.parse = function (text, reviver) {
      const data = parse(text, reviver);
      for (const p of (data && Array.isArray(data.plans)) ? data.plans : []) {
        const f = p.frames, k0 = f.t_s.length, t0 = f.t_s[k0 - 1];
        for (let k = k0; k < n; ++k) {
          for (const key of Object.keys(f)) if (key !== 't_s') f[key].push(f[key][k % k0]);
          f.t_s.push(t0 + (k - k0 + 1) * 1e-3);
        }
      }
      return data;
    };
  }, stretchFrames);
}
if (meshDivisions > 0) {
  // Before the page's own script: each plan's first part becomes a mesh of its size centred on
  // its frame, in the page's data format (data.meshes, the part's `mesh` index): vertices [mm]
  // in the part's frame, triangles counter-clockwise from outside, feature edges as pairs.
  await context.addInitScript((n) => {
    const parse = JSON.parse;
    JSON.parse = function (text, reviver) {
      const data = parse(text, reviver);
      for (const p of (data && Array.isArray(data.plans)) ? data.plans : []) {
        const part = p.parts[0], half = part.size_mm.map((s) => s / 2);
        const mesh = { file: 'browser-test box', vertices_mm: [], triangles: [], edges: [] };
        for (const [axis, sign] of [[2, 1], [2, -1], [0, 1], [0, -1], [1, 1], [1, -1]]) {
          const u = (axis + 1) % 3, v = (axis + 2) % 3, first = mesh.vertices_mm.length / 3;
          for (let j = 0; j <= n; ++j) for (let i = 0; i <= n; ++i) {
            const q = [0, 0, 0];
            q[axis] = sign * half[axis];
            q[u] = -half[u] + part.size_mm[u] * i / n;
            q[v] = -half[v] + part.size_mm[v] * j / n;
            mesh.vertices_mm.push(...q);
          }
          const at = (i, j) => first + j * (n + 1) + i;
          for (let j = 0; j < n; ++j) for (let i = 0; i < n; ++i) {
            const [a, b, c, d] = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            mesh.triangles.push(...(sign > 0 ? [a, b, c, a, c, d] : [a, c, b, a, d, c]));
          }
          for (let k = 0; k < n; ++k)
            mesh.edges.push(at(k, 0), at(k + 1, 0), at(k, n), at(k + 1, n),
                            at(0, k), at(0, k + 1), at(n, k), at(n, k + 1));
        }
        data.meshes = data.meshes ?? [];
        part.shape = 'mesh';
        part.mesh = data.meshes.length;
        data.meshes.push(mesh);
      }
      return data;
    };
  }, meshDivisions);
}
const page = await context.newPage();
page.setDefaultTimeout(0);
const problems = [];
// Errors and warnings fail, except Chromium's GPU performance notes that the test's own read-back
// of the canvas causes ("GPU stall due to ReadPixels"): they are about the test, not the page.
page.on('console', (m) => {
  const gpuNote = /GL Driver Message \(OpenGL, Performance/.test(m.text());
  if (m.type() === 'error' || (m.type() === 'warning' && !gpuNote))
    problems.push(`console ${m.type()}: ${m.text()}`);
});
// An uncaught exception also ends the wait for the page to be ready (it never will be).
let failedToLoad;
const loadFailure = new Promise((resolve) => { failedToLoad = resolve; });
page.on('pageerror', (e) => { problems.push(`uncaught: ${e.message}`); failedToLoad(e); });
const url = 'file://' + resolve(reportPath);
const requests = [];
page.on('request', (r) => { if (r.url() !== url) requests.push(r.url()); });
await page.goto(url, { waitUntil: 'load' });
const error = await Promise.race([
  page.waitForFunction(() => document.body.dataset.ready === 'true').then(() => null),
  loadFailure]);
if (error) {
  check(false, `the page's script ran to its end (uncaught: ${error.message})`);
  await browser.close();
  console.error('browser test: the page did not load');
  process.exit(1);
}
// Two animation frames: the first render has happened.
const frames = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
await frames();
if (meshDivisions > 0) {
  const drawn = await page.evaluate(() => Number(document.getElementById('view').dataset.meshTriangles));
  check(drawn === 12 * meshDivisions ** 2,
        `3D view draws the mesh part: ${drawn} triangles (${12 * meshDivisions ** 2} expected)`);
}

// Pixels of the tube's hue in the WebGL canvas (its drawing buffer is preserved, so it can be
// copied): hue within 12 degrees of the tube colour's, saturated and not dark (lighting shades
// the tube but keeps its hue; the parts are grey, contacts red, arrows blue, purple and black).
const tubePixels = () => page.evaluate(() => {
  const data = JSON.parse(document.getElementById('tubeplan-data').textContent);
  const hex = data.tube_colour;
  const rgb = [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16) / 255);
  const hue = (r, g, b) => {
    const max = Math.max(r, g, b), min = Math.min(r, g, b), d = max - min;
    if (d === 0) return { h: 0, s: 0, v: max };
    let h = max === r ? ((g - b) / d) % 6 : max === g ? (b - r) / d + 2 : (r - g) / d + 4;
    return { h: (h * 60 + 360) % 360, s: d / max, v: max };
  };
  const target = hue(...rgb).h;
  const view = document.getElementById('view');
  const copy = document.createElement('canvas');
  copy.width = view.width; copy.height = view.height;
  const ctx = copy.getContext('2d');
  ctx.drawImage(view, 0, 0);
  const px = ctx.getImageData(0, 0, copy.width, copy.height).data;
  let tube = 0;
  for (let i = 0; i < px.length; i += 4) {
    const c = hue(px[i] / 255, px[i + 1] / 255, px[i + 2] / 255);
    const dh = Math.min(Math.abs(c.h - target), 360 - Math.abs(c.h - target));
    if (dh <= 12 && c.s >= 0.5 && c.v >= 0.3) ++tube;
  }
  return { tube, total: copy.width * copy.height };
});
// The tube, 16 mm across in a view of the whole groove, covers about 2 % of the canvas; 0.5 %
// is far above what anti-aliased edges of other objects could give and well below the tube.
const first = await tubePixels();
check(first.tube / first.total >= 0.005,
      `3D view draws the tube: ${first.tube} of ${first.total} canvas pixels in its colour (>= 0.5 %)`);
await page.evaluate(() => {
  const scrub = document.getElementById('scrub');
  scrub.value = scrub.max;
  scrub.dispatchEvent(new Event('input'));
});
await frames();
const last = await tubePixels();
check(last.tube / last.total >= 0.005,
      `after scrubbing to the last frame: ${last.tube} tube pixels (>= 0.5 %)`);
// Back to the opening view (the plan's largest force) for the screenshot.
await page.evaluate(() => document.getElementById('plan-select').dispatchEvent(new Event('change')));
await frames();

// 3. The screenshot is not blank: many colours, and most pixels not the page's background.
const png = await page.screenshot({ fullPage: false, path: screenshotPath });
const picture = await page.evaluate(async (b64) => {
  const image = new Image();
  image.src = 'data:image/png;base64,' + b64;
  await image.decode();
  const c = document.createElement('canvas');
  c.width = image.width; c.height = image.height;
  const ctx = c.getContext('2d');
  ctx.drawImage(image, 0, 0);
  const px = ctx.getImageData(0, 0, c.width, c.height).data;
  const colours = new Set();
  let nonWhite = 0;
  for (let i = 0; i < px.length; i += 4) {
    colours.add((px[i] << 16) | (px[i + 1] << 8) | px[i + 2]);
    if (px[i] < 235 || px[i + 1] < 235 || px[i + 2] < 235) ++nonWhite;
  }
  return { colours: colours.size, nonWhite, total: c.width * c.height };
}, png.toString('base64'));
check(picture.colours >= 200 && picture.nonWhite / picture.total >= 0.05,
      `screenshot not blank: ${picture.colours} colours, ${(100 * picture.nonWhite / picture.total).toFixed(1)} % not white`);

if (planShotPath) await page.locator('#plan-0').screenshot({ path: planShotPath });

const charts = await page.evaluate(() => document.querySelectorAll('section.plan svg').length);
check(charts >= 5, `charts in the page: ${charts}`);
check(requests.length === 0, `no request but the file itself (${requests.slice(0, 3).join(', ') || 'none'})`);
check(problems.length === 0, `no console error or warning (${problems.slice(0, 5).join(' | ') || 'none'})`);
await browser.close();
if (failures.length) {
  console.error(`browser test: ${failures.length} check(s) failed`);
  process.exit(1);
}
console.log('browser test: all checks passed');
