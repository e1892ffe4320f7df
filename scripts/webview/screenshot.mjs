#!/usr/bin/env node
// Headless-Chromium smoke test for the Rerun web viewer.
//
// Usage: node screenshot.mjs URL OUT.png [--wait-s N] [--hold-s N] [--min-colour-frac F] [--renderer webgl|webgpu] [--verbose]
//
// Opens URL in headless Chromium (via playwright-core, /usr/bin/chromium by default,
// override with $CHROMIUM), waits until the viewer has started and its rendering has
// settled (or --wait-s seconds, default 90, have passed), saves a 1280x800 screenshot to
// OUT.png and prints one JSON line with measurements to stdout. Page console errors go
// to stderr. Exit status: 0 = rendered, 1 = page stayed blank / viewer never started /
// too few coloured pixels, 2 = usage or launch error.
//
// "Coloured" pixels are strongly saturated ones: the Rerun UI itself is greyscale with
// a few blue accents, so coloured pixels mostly come from logged data (boxes, points,
// images); the welcome screen shown when the page has no ?url= data source has ~0.005.
// --min-colour-frac F (default 0.01; 0 = off) requires at least that fraction, and the
// wait goes on until it is reached and two consecutive screenshots 2 s apart are identical.
// --hold-s N keeps the page open (the viewer connected and drawing) until N seconds after the
// start, then takes the screenshot: for soak runs (scripts/soak.sh).

import { chromium } from 'playwright-core';
import { writeFileSync } from 'node:fs';
import { inflateSync } from 'node:zlib';

function usage(msg) {
  if (msg) console.error(`error: ${msg}`);
  console.error('usage: node screenshot.mjs URL OUT.png [--wait-s N] [--hold-s N] [--min-colour-frac F] [--renderer webgl|webgpu] [--verbose]');
  process.exit(2);
}

const argv = process.argv.slice(2);
const positional = [];
const opts = { waitS: 90, holdS: 0, minColourFrac: 0.01, renderer: null, verbose: false };
for (let i = 0; i < argv.length; i++) {
  const a = argv[i];
  const next = () => (i + 1 < argv.length ? argv[++i] : usage(`${a} needs a value`));
  if (a === '--wait-s') opts.waitS = Number(next());
  else if (a === '--hold-s') opts.holdS = Number(next());
  else if (a === '--min-colour-frac') opts.minColourFrac = Number(next());
  else if (a === '--renderer') opts.renderer = next();
  else if (a === '--verbose' || a === '-v') opts.verbose = true;
  else if (a === '-h' || a === '--help') usage();
  else if (a.startsWith('--')) usage(`unknown option ${a}`);
  else positional.push(a);
}
if (positional.length !== 2) usage();
if (!(opts.waitS > 0) || !(opts.minColourFrac >= 0)) usage('bad numeric option');
let [url, outPath] = positional;
if (opts.renderer) {
  const u = new URL(url);
  u.searchParams.set('renderer', opts.renderer);
  url = u.toString();
}

// ---------- minimal PNG decoder (8-bit RGB/RGBA, non-interlaced: what Chromium emits) ----------
function decodePng(buf) {
  if (buf.readUInt32BE(0) !== 0x89504e47) throw new Error('not a PNG');
  let off = 8, width = 0, height = 0, colourType = 0, bitDepth = 0, interlace = 0;
  const idat = [];
  while (off < buf.length) {
    const len = buf.readUInt32BE(off);
    const type = buf.toString('ascii', off + 4, off + 8);
    const data = buf.subarray(off + 8, off + 8 + len);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0); height = data.readUInt32BE(4);
      bitDepth = data[8]; colourType = data[9]; interlace = data[12];
    } else if (type === 'IDAT') idat.push(data);
    else if (type === 'IEND') break;
    off += 12 + len;
  }
  const bpp = { 2: 3, 6: 4 }[colourType];
  if (bitDepth !== 8 || !bpp || interlace) {
    throw new Error(`unsupported PNG (depth ${bitDepth}, colour type ${colourType}, interlace ${interlace})`);
  }
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * bpp;
  const px = Buffer.alloc(stride * height);
  for (let y = 0; y < height; y++) {
    const f = raw[y * (stride + 1)];
    const src = y * (stride + 1) + 1, dst = y * stride, prev = dst - stride;
    for (let x = 0; x < stride; x++) {
      const a = x >= bpp ? px[dst + x - bpp] : 0;
      const b = y > 0 ? px[prev + x] : 0;
      const c = x >= bpp && y > 0 ? px[prev + x - bpp] : 0;
      let v = raw[src + x];
      if (f === 1) v += a;
      else if (f === 2) v += b;
      else if (f === 3) v += (a + b) >> 1;
      else if (f === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      px[dst + x] = v & 0xff;
    }
  }
  return { width, height, bpp, px };
}

// Pixel statistics of a screenshot; `prev` (an earlier result) enables a change measure.
function analyse(png, prev) {
  const { width, height, bpp, px } = decodePng(png);
  const n = width * height;
  const counts = new Map();
  const packed = new Uint32Array(n);
  let coloured = 0;
  for (let i = 0, o = 0; i < n; i++, o += bpp) {
    const r = px[o], g = px[o + 1], b = px[o + 2];
    const k = (r << 16) | (g << 8) | b;
    packed[i] = k;
    counts.set(k, (counts.get(k) || 0) + 1);
    const mx = Math.max(r, g, b), mn = Math.min(r, g, b);
    if (mx - mn > 80 && mx > 80) coloured++;
  }
  let bg = 0, bgCount = -1;
  for (const [k, c] of counts) if (c > bgCount) { bg = k; bgCount = c; }
  const br = bg >> 16, bgG = (bg >> 8) & 0xff, bb = bg & 0xff;
  let nonBg = 0, changed = 0;
  for (let i = 0; i < n; i++) {
    const k = packed[i];
    const d = Math.abs((k >> 16) - br) + Math.abs(((k >> 8) & 0xff) - bgG) + Math.abs((k & 0xff) - bb);
    if (d > 24) nonBg++;
    if (prev && prev.packed.length === n && prev.packed[i] !== k) changed++;
  }
  return {
    packed,
    width, height,
    background: '#' + bg.toString(16).padStart(6, '0'),
    nonBgFrac: nonBg / n,
    colourFrac: coloured / n,
    distinctColours: counts.size,
    changedFrac: prev ? changed / n : null,
  };
}

const isBlank = (s) => s.nonBgFrac < 0.02 || s.distinctColours < 32;
const round = (x, d = 4) => (x == null ? null : Number(x.toFixed(d)));

// ---------- drive the browser ----------
const t0 = Date.now();
const elapsed = () => (Date.now() - t0) / 1000;
const consoleErrors = [];
let browser;
try {
  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    // playwright already adds --enable-unsafe-swiftshader, --disable-background-networking,
    // --disable-component-update, --disable-sync, --no-first-run and a fresh temp profile.
    args: [
      '--no-sandbox', '--disable-gpu', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--no-first-run',
      '--enable-unsafe-swiftshader', '--use-angle=swiftshader',
      // Hermetic: the viewer page also fetches fonts.googleapis.com, tel.rerun.io (analytics) and
      // app.rerun.io (examples manifest). Make every name except loopback/the target host fail fast.
      `--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE localhost, EXCLUDE ${new URL(url).hostname}`,
    ],
  });
} catch (e) {
  console.error(`failed to launch chromium: ${e.message}`);
  process.exit(2);
}

let result = { ok: false, url };
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.on('console', (msg) => {
    if (opts.verbose && !['error', 'debug'].includes(msg.type())) console.error(`[console.${msg.type()}] ${msg.text().slice(0, 400)}`);
    if (msg.type() === 'error') {
      consoleErrors.push(msg.text());
      console.error(`[console.error] ${msg.text()}`);
    }
  });
  page.on('pageerror', (err) => {
    consoleErrors.push(String(err));
    console.error(`[pageerror] ${err}`);
  });
  page.on('crash', () => console.error('[page crashed]'));
  page.on('requestfailed', (req) => console.error(`[requestfailed] ${req.url()} ${req.failure()?.errorText ?? ''}`));

  await page.goto(url, { waitUntil: 'load', timeout: opts.waitS * 1000 });
  const loadedS = elapsed();

  let startedS = null, settledS = null, shot = null, stats = null, prev = null, stable = 0;
  const deadline = t0 + opts.waitS * 1000;
  while (Date.now() < deadline) {
    await page.waitForTimeout(2000);
    // Once the wasm app has started, index.html's on_app_started() assigns window._handle
    // (to the value start() resolved with, which may be undefined: test with `in`) and
    // makes #the_canvas_id visible.
    const state = await page.evaluate(() => {
      const c = document.getElementById('the_canvas_id') || document.querySelector('canvas');
      const center = document.getElementById('center_text');
      return {
        started: '_handle' in window,
        canvas: c ? { w: c.width, h: c.height, visible: c.classList.contains('visible') } : null,
        centerText: center && center.classList.contains('visible') ? center.innerText.slice(0, 300) : '',
      };
    }).catch(() => ({ started: false, canvas: null, centerText: '' }));
    if (state.centerText && /error|crash|too old/i.test(state.centerText)) {
      console.error(`[viewer] ${state.centerText.replace(/\s+/g, ' ')}`);
      result.viewerMessage = state.centerText.replace(/\s+/g, ' ');
    }
    if (state.started && startedS == null) startedS = elapsed();
    result.canvas = state.canvas;
    shot = await page.screenshot({ type: 'png', timeout: 120000 });
    stats = analyse(shot, prev);
    prev = stats;
    if (opts.verbose) {
      console.error(`[poll ${elapsed().toFixed(1)}s] started=${state.started} nonBg=${round(stats.nonBgFrac)} ` +
        `colour=${round(stats.colourFrac)} distinct=${stats.distinctColours} changed=${round(stats.changedFrac)}`);
    }
    if (!state.started || isBlank(stats) || stats.colourFrac < opts.minColourFrac) { stable = 0; continue; }
    stable = stats.changedFrac != null && stats.changedFrac < 0.002 ? stable + 1 : 0;
    if (stable >= 2) { settledS = elapsed(); break; }
  }
  const holdUntil = t0 + opts.holdS * 1000;
  if (Date.now() < holdUntil) {
    await page.waitForTimeout(holdUntil - Date.now());
    // A page on a CPU the soak keeps busy can take long to paint.
    shot = await page.screenshot({ type: 'png', timeout: 120000 });
    stats = analyse(shot, null);
  }
  if (!shot) shot = await page.screenshot({ type: 'png' });
  writeFileSync(outPath, shot);
  if (!stats) stats = analyse(shot, null);

  const blank = isBlank(stats);
  const colourOk = stats.colourFrac >= opts.minColourFrac;
  result = {
    ...result,
    ok: startedS != null && !blank && colourOk,
    blank,
    started: startedS != null,
    settled: settledS != null,
    out: outPath,
    width: stats.width, height: stats.height,
    background: stats.background,
    nonBgFrac: round(stats.nonBgFrac),
    colourFrac: round(stats.colourFrac),
    distinctColours: stats.distinctColours,
    lastChangedFrac: round(stats.changedFrac),
    loadS: round(loadedS, 1),
    startedS: round(startedS, 1),
    settledS: round(settledS, 1),
    elapsedS: round(elapsed(), 1),
    consoleErrors: consoleErrors.length,
  };
  if (!result.started) console.error('viewer app never started (window._handle not set)');
  if (blank) console.error('page looks blank');
  if (!colourOk) console.error(`coloured-pixel fraction ${round(stats.colourFrac)} < --min-colour-frac ${opts.minColourFrac}`);
} catch (e) {
  console.error(`error: ${e.stack || e}`);
  result.error = String(e.message || e);
} finally {
  await browser.close().catch(() => {});
}
console.log(JSON.stringify(result));
process.exit(result.ok ? 0 : 1);
