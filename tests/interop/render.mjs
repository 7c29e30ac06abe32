// Opens a glTF export in three.js (GLTFLoader) in headless Chromium (puppeteer-core driving
// the system's Chromium, WebGL 2 on SwiftShader), renders one frame with the material as
// loaded and one with iridescence off, and prints one JSON line: the material three.js
// parsed, the share of the frame the model covers, its luminance spread, and the CIEDE2000
// difference between the two frames over the model's pixels. With a third argument, writes
// the frame as PNG there.
//
//   node render.mjs MODEL.glb [SCREENSHOT.png]
//
// CHROMIUM names the browser binary (default /usr/bin/chromium).
import fs from 'node:fs/promises';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import puppeteer from 'puppeteer-core';

const here = path.dirname(fileURLToPath(import.meta.url));
const [model, screenshotPath] = process.argv.slice(2);
if (!model) {
  console.error('usage: node render.mjs MODEL.glb [SCREENSHOT.png]');
  process.exit(2);
}

const types = { '.html': 'text/html', '.js': 'text/javascript', '.glb': 'model/gltf-binary' };
const server = http.createServer(async (req, res) => {
  const url = new URL(req.url, 'http://localhost');
  let file;
  if (url.pathname === '/favicon.ico') {
    res.writeHead(204);
    res.end();
    return;
  }
  if (url.pathname === '/') file = path.join(here, 'viewer.html');
  else if (url.pathname === '/model') file = path.resolve(model);
  else if (url.pathname.startsWith('/three/')) {
    file = path.join(here, 'node_modules', 'three', path.normalize(url.pathname.slice('/three/'.length)));
  }
  try {
    const body = await fs.readFile(file);
    res.writeHead(200, { 'Content-Type': types[path.extname(file)] ?? 'application/octet-stream' });
    res.end(body);
  } catch {
    res.writeHead(404);
    res.end();
  }
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const port = server.address().port;

const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
try {
  const page = await browser.newPage();
  const logs = [];
  page.on('console', (m) => logs.push(`${m.type()}: ${m.text()}`));
  page.on('pageerror', (e) => logs.push(`pageerror: ${e.message}`));
  await page.setViewport({ width: 960, height: 540 });
  await page.goto(`http://127.0.0.1:${port}/?width=960&height=540`);
  await page.waitForFunction(() => window.__result !== undefined, { timeout: 240000 });
  const result = await page.evaluate(() => window.__result);
  if (result.error) {
    console.log(JSON.stringify({ error: result.error, logs }));
    process.exitCode = 1;
  } else {
    const a = result.withFilm;
    const b = result.withoutFilm;
    let covered = 0;
    let sum = 0;
    let sumSq = 0;
    const differences = [];
    for (let i = 0; i < a.length; i += 4) {
      if (a[i + 3] < 255) continue; // background (cleared to alpha 0) and silhouette edges
      covered += 1;
      const luma = 0.2126 * a[i] + 0.7152 * a[i + 1] + 0.0722 * a[i + 2];
      sum += luma;
      sumSq += luma * luma;
      differences.push(ciede2000(lab(a[i], a[i + 1], a[i + 2]), lab(b[i], b[i + 1], b[i + 2])));
    }
    differences.sort((x, y) => x - y);
    const mean = covered ? sum / covered : 0;
    if (screenshotPath) {
      await fs.writeFile(screenshotPath, Buffer.from(result.screenshot.split(',')[1], 'base64'));
    }
    console.log(JSON.stringify({
      material: result.material,
      webgl: result.renderer,
      coverage: covered / (a.length / 4),
      luma_mean: mean,
      luma_std: covered ? Math.sqrt(Math.max(0, sumSq / covered - mean * mean)) : 0,
      delta_e00_mean: differences.reduce((s, d) => s + d, 0) / Math.max(1, differences.length),
      delta_e00_p95: differences.length ? differences[Math.floor(0.95 * (differences.length - 1))] : 0,
      logs: logs.filter((l) => !l.startsWith('log:')).slice(0, 20),
    }));
  }
} finally {
  await browser.close();
  server.close();
}

// sRGB 8-bit to CIELAB (D65), IEC 61966-2-1 and CIE 15.
function lab(r8, g8, b8) {
  const lin = (c) => {
    const s = c / 255;
    return s <= 0.04045 ? s / 12.92 : ((s + 0.055) / 1.055) ** 2.4;
  };
  const [r, g, b] = [lin(r8), lin(g8), lin(b8)];
  const x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047;
  const y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
  const z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883;
  const f = (t) => (t > 216 / 24389 ? Math.cbrt(t) : (24389 / 27 * t + 16) / 116);
  return [116 * f(y) - 16, 500 * (f(x) - f(y)), 200 * (f(y) - f(z))];
}

// CIEDE2000 (Sharma, Wu & Dalal 2005), kL = kC = kH = 1.
function ciede2000([l1, a1, b1], [l2, a2, b2]) {
  const rad = Math.PI / 180;
  const c1 = Math.hypot(a1, b1);
  const c2 = Math.hypot(a2, b2);
  const cm = (c1 + c2) / 2;
  const g = 0.5 * (1 - Math.sqrt(cm ** 7 / (cm ** 7 + 25 ** 7)));
  const a1p = (1 + g) * a1;
  const a2p = (1 + g) * a2;
  const c1p = Math.hypot(a1p, b1);
  const c2p = Math.hypot(a2p, b2);
  const hue = (b, a) => {
    if (a === 0 && b === 0) return 0;
    const h = Math.atan2(b, a) / rad;
    return h < 0 ? h + 360 : h;
  };
  const h1p = hue(b1, a1p);
  const h2p = hue(b2, a2p);
  const dl = l2 - l1;
  const dc = c2p - c1p;
  let dh = 0;
  if (c1p * c2p !== 0) {
    dh = h2p - h1p;
    if (dh > 180) dh -= 360;
    else if (dh < -180) dh += 360;
  }
  const dH = 2 * Math.sqrt(c1p * c2p) * Math.sin((dh / 2) * rad);
  const lm = (l1 + l2) / 2;
  const cmp = (c1p + c2p) / 2;
  let hm = h1p + h2p;
  if (c1p * c2p !== 0) {
    if (Math.abs(h1p - h2p) > 180) hm = h1p + h2p < 360 ? (h1p + h2p + 360) / 2 : (h1p + h2p - 360) / 2;
    else hm = (h1p + h2p) / 2;
  }
  const t = 1 - 0.17 * Math.cos((hm - 30) * rad) + 0.24 * Math.cos(2 * hm * rad)
    + 0.32 * Math.cos((3 * hm + 6) * rad) - 0.2 * Math.cos((4 * hm - 63) * rad);
  const dTheta = 30 * Math.exp(-(((hm - 275) / 25) ** 2));
  const rc = 2 * Math.sqrt(cmp ** 7 / (cmp ** 7 + 25 ** 7));
  const sl = 1 + (0.015 * (lm - 50) ** 2) / Math.sqrt(20 + (lm - 50) ** 2);
  const sc = 1 + 0.045 * cmp;
  const sh = 1 + 0.015 * cmp * t;
  const rt = -Math.sin(2 * dTheta * rad) * rc;
  return Math.sqrt((dl / sl) ** 2 + (dc / sc) ** 2 + (dH / sh) ** 2 + rt * (dc / sc) * (dH / sh));
}
