// The web page's tests, in a real browser: Debian's Chromium, headless, WebGPU on SwiftShader.
//
//   node web/tests/browser.mjs [--measure]
//
// Serves web/dist (built by web/build.sh) on 127.0.0.1 and checks, from the page's pixels
// and console: the default scene draws a shaded picture; dragging turns it; the page's link
// opens the same picture in another page; typing a formula changes the picture, its first
// preview drawn on the CPU; a mistyped one keeps the last picture and shows the error; a
// new number draws with the shader on screen, compiling nothing; the longest formulas parse; a share link draws its own formula, and a wrong one opens with
// its errors; no example scene logs an error; a link's settled picture is certified (its
// counts cover the picture, every proved hit drawn), certified=false draws the plain
// pencil; a heavy link is lowered to the page's bounds, says what it lowered and keeps the page answering; embed
// mode shows the picture alone and turns on a drag; the gallery draws the examples and opens
// one; Export animation downloads a GIF and an animated PNG of the frames asked for; a lost GPU device
// restarts the page on its scene; a slice's critical
// values are ticks under its slider that move the slice when clicked, and Export mesh
// downloads the slice as an STL; an undefined constant
// is refused with its culprit; the WGSL of fuzzed formulas (FOURFOLD_WGSL_SAMPLES, a folder)
// compiles in Chromium's WebGPU; without WebGPU the page says what it needs; the wasm is at
// most 2.5 MB gzipped. With --measure it also prints the wasm's size, load
// → first picture, and keystroke → first new preview for three presets, for a keystroke
// that makes a new shader and for one that changes a number (docs/benchmarks.md).

import { chromium } from 'playwright-core';
import { PNG } from 'pngjs';
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import zlib from 'node:zlib';

const here = path.dirname(new URL(import.meta.url).pathname);
const dist = path.resolve(here, '..', 'dist');
const measure = process.argv.includes('--measure');
// A guard against a hang, not a measure: SwiftShader compiles and draws fig-3-12 in 80 s
// on two idle cores, and a busy machine takes twice that.
const TIMEOUT = 300_000;

if (!fs.existsSync(path.join(dist, 'index.html'))) {
  console.error(`no ${dist}/index.html: build the page first (bash web/build.sh)`);
  process.exit(1);
}

// A static server for web/dist.
const types = { '.html': 'text/html', '.js': 'text/javascript', '.wasm': 'application/wasm' };
const server = http.createServer((req, res) => {
  const name = path.normalize(decodeURIComponent(new URL(req.url, 'http://x').pathname));
  const file = path.join(dist, name === '/' ? 'index.html' : name);
  if (!file.startsWith(dist) || !fs.existsSync(file)) {
    res.writeHead(404).end();
    return;
  }
  res.writeHead(200, { 'content-type': types[path.extname(file)] ?? 'application/octet-stream' });
  fs.createReadStream(file).pipe(res);
});
await new Promise((done) => server.listen(0, '127.0.0.1', done));
const page_url = `http://127.0.0.1:${server.address().port}/index.html`;

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  args: [
    '--headless=new', '--no-sandbox', '--enable-unsafe-webgpu', '--enable-features=Vulkan',
    '--use-vulkan=swiftshader', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
    '--no-first-run',
  ],
});

let failures = 0;
// Each check's line says how far into the run it came (minutes:seconds): where CI's time goes.
const began = Date.now();
const check = (ok, what) => {
  const s = Math.round((Date.now() - began) / 1000);
  const clock = `${Math.floor(s / 60)}:${String(s % 60).padStart(2, '0')}`;
  console.log(`${ok ? 'ok  ' : 'FAIL'} [${clock}] ${what}`);
  if (!ok) failures += 1;
};

/** In the page: WebGPU's errors for a shader module and its pipelines (two variants of the
 * pipeline constants, as the ray caster makes them: a plain one, and a certified one, each
 * with the entry point of its MODE, plain or certified). */
async function compile_in_webgpu(code) {
  const adapter = await navigator.gpu.requestAdapter();
  const device = await adapter.requestDevice();
  const problems = [];
  device.pushErrorScope('validation');
  const module = device.createShaderModule({ code });
  const info = await module.getCompilationInfo();
  problems.push(...info.messages.filter((m) => m.type === 'error').map((m) => m.message));
  const variants = [{ MODE: 1, SLOTS: 4, SAMPLING: 0, SECTION: 0, CERTIFY: 0 },
    { MODE: 0, SLOTS: 16, SAMPLING: 1, SECTION: 2, CERTIFY: 1 }];
  for (const constants of variants) {
    try {
      await device.createRenderPipelineAsync({
        layout: 'auto',
        vertex: { module, entryPoint: 'vs_main' },
        fragment: {
          module,
          entryPoint: ['fs_brute_force', 'fs_tiles', 'fs_walk'][constants.MODE] + (constants.CERTIFY ? '_certified' : ''),
          targets: [{ format: 'rgba8unorm' }],
          constants,
        },
      });
    } catch (e) {
      problems.push(String(e.message ?? e));
    }
  }
  const scope = await device.popErrorScope();
  if (scope) problems.push(scope.message);
  device.destroy();
  return problems;
}

/** An animated GIF's size and frame count, read block by block. */
function gif_frames(bytes) {
  const skip_sub_blocks = (at) => {
    while (bytes[at] !== 0) at += bytes[at] + 1;
    return at + 1;
  };
  if (bytes.toString('latin1', 0, 3) !== 'GIF') return { frames: 0, width: 0, height: 0 };
  const [width, height] = [bytes.readUInt16LE(6), bytes.readUInt16LE(8)];
  let at = 13 + (bytes[10] & 0x80 ? 3 * 2 ** ((bytes[10] & 7) + 1) : 0);
  let frames = 0;
  while (at < bytes.length && bytes[at] !== 0x3b) {
    if (bytes[at] === 0x21) {
      at = skip_sub_blocks(at + 2);
    } else if (bytes[at] === 0x2c) {
      frames += 1;
      const flags = bytes[at + 9];
      at += 10 + (flags & 0x80 ? 3 * 2 ** ((flags & 7) + 1) : 0);
      at = skip_sub_blocks(at + 1);
    } else {
      return { frames: -1, width, height };
    }
  }
  return { frames, width, height };
}

/** An animated PNG's size, the frame count it states (acTL) and the frames it holds (fcTL). */
function apng_frames(bytes) {
  if (bytes.toString('latin1', 1, 4) !== 'PNG') return { stated: 0, frames: 0, width: 0, height: 0 };
  const [width, height] = [bytes.readUInt32BE(16), bytes.readUInt32BE(20)];
  let [at, stated, frames] = [8, 0, 0];
  while (at + 8 <= bytes.length) {
    const [length, type] = [bytes.readUInt32BE(at), bytes.toString('latin1', at + 4, at + 8)];
    if (type === 'acTL') stated = bytes.readUInt32BE(at + 8);
    if (type === 'fcTL') frames += 1;
    if (type === 'IEND') break;
    at += 12 + length;
  }
  return { stated, frames, width, height };
}

/** The window pages open in: a small laptop's. SwiftShader's time goes with the pixels,
 * and most checks wait for a complete, certified picture. */
const WINDOW = { width: 800, height: 500 };
/** A taller window, for the checks that type formulas or click in the side panel's lower
 * sections (below a small window's fold), and those that compare their pictures. */
const TALL = { width: 800, height: 800 };

/** A new page at `hash` in a window of `size`, with its console errors collected (`init`:
 * a script run in it before the page's own, at every load, given `arg`). */
async function open(hash = '', init = null, arg = undefined, size = WINDOW) {
  const page = await browser.newPage({ viewport: size });
  if (init) await page.addInitScript(init, arg);
  const errors = [];
  page.on('console', (m) => m.type() === 'error' && errors.push(m.text()));
  page.on('pageerror', (e) => errors.push(String(e)));
  const started = Date.now();
  await page.goto(page_url + hash);
  await page.waitForFunction(() => window.fourfold || document.getElementById('message').className === 'error',
    null, { timeout: TIMEOUT });
  const failed = await page.evaluate(() => !window.fourfold && document.getElementById('message').textContent);
  if (failed) throw new Error(`the page did not start: ${failed}`);
  return { page, errors, started };
}

const status = (page) => page.evaluate(() => JSON.parse(window.fourfold.status()));

/** Waits until the picture of generation > `after` is drawn and complete; its status. */
async function settled(page, after = 0) {
  await page.waitForFunction((after) => {
    const s = JSON.parse(window.fourfold.status());
    return s.panic || (s.generation > after && s.first_frame_of === s.generation && !s.drawing && !s.building);
  }, after, { timeout: TIMEOUT, polling: 50 });
  const s = await status(page);
  if (s.panic) throw new Error(`the page panicked: ${s.panic}`);
  return s;
}

/** The picture's pixels (RGBA) as the page shows them. */
async function picture(page) {
  const s = await status(page);
  const [x0, y0, x1, y1] = s.picture;
  const png = PNG.sync.read(await page.screenshot({
    clip: { x: x0, y: y0, width: x1 - x0, height: y1 - y0 },
  }));
  return png;
}

/** Pixels that differ from the picture's corner (the background), and the grey levels among them. */
function coverage(png) {
  const { data } = png;
  const bg = [data[0], data[1], data[2]];
  let covered = 0;
  const levels = new Set();
  for (let i = 0; i < data.length; i += 4) {
    if (Math.abs(data[i] - bg[0]) + Math.abs(data[i + 1] - bg[1]) + Math.abs(data[i + 2] - bg[2]) > 24) {
      covered += 1;
      levels.add((data[i] + data[i + 1] + data[i + 2]) >> 2);
    }
  }
  return { share: covered / (data.length / 4), levels: levels.size };
}

/**
 * The share of pixels whose colour differs by more than 32 levels between two pictures, over
 * the middle part they share (the picture is centred in its panel, which a one-line
 * description above it makes a little shorter).
 */
function changed(a, b) {
  const [w, h] = [Math.min(a.width, b.width), Math.min(a.height, b.height)];
  const at = (p, x, y) => 4 * ((y + ((p.height - h) >> 1)) * p.width + x + ((p.width - w) >> 1));
  let n = 0;
  for (let y = 0; y < h; y++) {
    for (let x = 0; x < w; x++) {
      const [i, j] = [at(a, x, y), at(b, x, y)];
      const d = Math.abs(a.data[i] - b.data[j]) + Math.abs(a.data[i + 1] - b.data[j + 1])
        + Math.abs(a.data[i + 2] - b.data[j + 2]);
      if (d > 32) n += 1;
    }
  }
  return n / (w * h);
}

/** Replaces the editor's text by `text`, entered at once (as a paste is). */
async function type(page, text) {
  // (Its top line in view: a long formula makes the editor taller than its scrolled panel.)
  const s = await status(page);
  const [x0, y0, x1] = s.editor;
  await page.mouse.click((x0 + x1) / 2, Math.max(y0, s.controls[1]) + 8);
  await page.keyboard.press('Control+A');
  await page.keyboard.press('Backspace');
  await page.keyboard.insertText(text);
}

try {
  // The default scene.
  // (In a tall window: the checks that type reach the editor's lower lines.)
  const { page, errors, started } = await open('', null, undefined, TALL);
  await page.waitForFunction(() => JSON.parse(window.fourfold.status()).first_frame_of >= 1,
    null, { timeout: TIMEOUT, polling: 20 });
  const first_ms = Date.now() - started;
  const first = await settled(page);
  const load_ms = Date.now() - started;
  const home = await picture(page);
  const seen = coverage(home);
  check(seen.share > 0.02 && seen.levels > 20,
    `the default scene draws a shaded picture (${(100 * seen.share).toFixed(1)}% covered, ${seen.levels} grey levels)`);

  // The download: at most 2.5 MB of wasm gzipped (web/build.sh shrinks it with wasm-opt),
  // its progress counted against its size while it loads.
  const wasm_bytes = fs.readFileSync(path.join(dist, 'fourfold_web_bg.wasm'));
  const gzipped = zlib.gzipSync(wasm_bytes, { level: 9 }).length;
  const bar = await page.evaluate(() => [document.getElementById('progress').max, document.getElementById('progress').value]);
  check(gzipped <= 2_500_000 && bar[0] === wasm_bytes.length && bar[1] === 0,
    `the wasm is ${(wasm_bytes.length / 1e6).toFixed(2)} MB, ${(gzipped / 1e6).toFixed(2)} MB gzipped (at most 2.50; `
    + `web/build.sh shrinks it with binaryen's wasm-opt), its download's progress bar out of ${bar[0]} bytes`);

  // Dragging the picture turns the manifold in 4D.
  const [px0, py0, px1, py1] = first.picture;
  const [cx, cy] = [(px0 + px1) / 2, (py0 + py1) / 2];
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  await page.mouse.move(cx + 80, cy + 40, { steps: 8 });
  await page.mouse.up();
  await page.waitForFunction((link) => {
    const s = JSON.parse(window.fourfold.status());
    return s.link !== link && !s.drawing && !s.building;
  }, first.link, { timeout: TIMEOUT, polling: 50 });
  const dragged = await status(page);
  const angles = (s) => s.link.match(/angles=[^&]*/)?.[0];
  const turned = await picture(page);
  check(angles(dragged) !== angles(first) && changed(home, turned) > 0.01,
    `dragging turns the manifold: ${angles(first)} → ${angles(dragged)}, `
    + `${(100 * changed(home, turned)).toFixed(1)}% of pixels changed`);

  // The page's link opens the same picture in another page.
  const again = await open('#' + dragged.link.split('#')[1], null, undefined, TALL);
  await settled(again.page);
  const reopened = await picture(again.page);
  check(changed(turned, reopened) < 0.01,
    `the page's link opens the same picture elsewhere (${(100 * changed(turned, reopened)).toFixed(2)}% of pixels differ)`);
  await again.page.close();

  // Typing a formula changes the picture.
  await type(page, 'x^2 + y^2 + z^2 + w^2 - 0.7');
  const typed = await settled(page, first.generation);
  const glome = await picture(page);
  check(typed.formula === 'x^2 + y^2 + z^2 + w^2 - 0.7' && changed(home, glome) > 0.02,
    `typing a formula changes the picture (${(100 * changed(home, glome)).toFixed(1)}% of pixels changed)`);
  check(typed.progress.cpu_previews > dragged.progress.cpu_previews,
    `the new formula's first preview is drawn on the CPU while the browser compiles its shader `
    + `(on screen ${typed.edit_latency_ms?.toFixed(0)} ms after the edit)`);
  check(/formula=x%5E2/.test(await page.evaluate(() => location.hash)),
    'the address bar holds the link of the scene on screen');

  // A mistyped formula keeps the last picture and says what is wrong.
  await type(page, 'x^2 + y^2 + (z');
  await page.waitForFunction(() => JSON.parse(window.fourfold.status()).error, null, { timeout: TIMEOUT });
  await page.waitForTimeout(500);
  const kept = await picture(page);
  const wrong = await status(page);
  check(wrong.generation === typed.generation && changed(glome, kept) < 0.002,
    `a mistyped formula keeps the last picture (${(100 * changed(glome, kept)).toFixed(2)}% changed)`);
  check(/\^/.test(wrong.error) && wrong.formula === typed.formula,
    `the error is shown with its caret: ${JSON.stringify(wrong.error.split('\n')[0])}`);

  // A formula whose numbers alone differ from the picture's has its shader: the caster on
  // screen draws it, with nothing compiled (its first preview still on the CPU).
  await type(page, 'x^2 + y^2 + z^2 + w^2 - 0.5');
  const renumbered = await settled(page, typed.generation);
  const smaller = await picture(page);
  check(renumbered.formula === 'x^2 + y^2 + z^2 + w^2 - 0.5' && changed(glome, smaller) > 0.003
    && renumbered.pipelines === typed.pipelines,
    `a new number draws with the shader on screen (${renumbered.pipelines - typed.pipelines} new, `
    + `${(100 * changed(glome, smaller)).toFixed(2)}% of pixels changed, on screen `
    + `${renumbered.edit_latency_ms?.toFixed(0)} ms after the edit)`);

  // Issue 38's formulas, the list every front end's test reads: a constant outside its
  // function's domain is refused with the culprit underlined, as the command line refuses
  // it, and the last picture stays; an overflow is ∞, drawn without an error.
  const undefined_constants = fs.readFileSync(
    path.resolve(here, '..', '..', 'crates/fourfold/tests/data/undefined-constants.txt'), 'utf8')
    .split('\n').filter((l) => l && !l.startsWith('#')).map((l) => l.split('\t'));
  const carets = (error) => {
    const line = error.split('\n').map((l) => (l.split('│')[1] ?? '').trimStart())
      .find((rest) => rest.startsWith('^'));
    return line ? line.length - line.replace(/^\^+/, '').length : 0;
  };
  let refused = 0;
  let drawn = 0;
  for (const [formula, culprit] of undefined_constants) {
    const before = await status(page);
    const shown = await picture(page);
    await type(page, formula);
    if (culprit) {
      await page.waitForFunction((f) => {
        const s = JSON.parse(window.fourfold.status());
        return s.panic || (s.text === f && s.error);
      }, formula, { timeout: TIMEOUT, polling: 50 });
      await page.waitForTimeout(300);
      const s = await status(page);
      const now = await picture(page);
      const ok = /F is undefined everywhere in the domain/.test(s.error)
        && carets(s.error) === [...culprit].length && s.generation === before.generation
        && changed(shown, now) < 0.002;
      if (ok) refused += 1;
      else {
        check(false, `${formula} is refused with ${culprit} underlined (${carets(s.error)} carets), `
          + `the picture kept (generation ${before.generation} → ${s.generation}, `
          + `${(100 * changed(shown, now)).toFixed(2)}% changed, ${shown.width}×${shown.height} → `
          + `${now.width}×${now.height}): ${s.error}`);
      }
    } else {
      await page.waitForFunction(([f, after]) => {
        const s = JSON.parse(window.fourfold.status());
        return s.panic || (s.text === f && (s.error
          || (s.formula === f && !s.building && s.first_frame_of === s.generation && s.generation > after)));
      }, [formula, before.generation], { timeout: TIMEOUT, polling: 50 });
      const s = await status(page);
      if (!s.panic && s.error === null) drawn += 1;
      else check(false, `${formula} draws without an error: ${s.panic ?? s.error}`);
    }
  }
  check(undefined_constants.length === 12 && refused === 7 && drawn === 5,
    `the issue's undefined constants are refused with their culprit, the picture kept (${refused}), or drawn (${drawn})`);

  // The deepest formulas the page accepts parse on the browser's stack; a longer one is refused.
  for (const [what, deep] of [['4 KiB of unary minus', '-'.repeat(4095) + 'x'],
    ['a 4 KiB tower of powers', 'x^'.repeat(2047) + 'x'], ['a 4 KiB sum', 'x+'.repeat(2047) + 'x']]) {
    await type(page, deep);
    await page.waitForFunction((t) => JSON.parse(window.fourfold.status()).text === t, deep, { timeout: TIMEOUT });
    const d = await status(page);
    check(!d.panic && (d.error === null || !/internal/.test(d.error)), `${what} is taken without a crash`);
  }
  await type(page, 'x+'.repeat(2100) + 'x');
  await page.waitForFunction(() => JSON.parse(window.fourfold.status()).error, null, { timeout: TIMEOUT });
  check(/4096/.test((await status(page)).error), 'a formula over 4 KiB is refused with the limit named');
  check(errors.length === 0, `no error in the console (${errors.join(' | ') || 'none'})`);
  await page.close();

  // A share link opens its own scene, a different picture.
  const link = '#formula=' + encodeURIComponent('x^2 + y^2 - z^2 - w^2 - 0.1') + '&angles=0.3,0,0,0.5,0,0';
  const shared = await open(link);
  const s = await settled(shared.page);
  const linked = await picture(shared.page);
  check(s.formula === 'x^2 + y^2 - z^2 - w^2 - 0.1' && changed(home, linked) > 0.02,
    `a share link draws its formula (${(100 * changed(home, linked)).toFixed(1)}% of pixels differ from the default)`);

  // Certified pixels in the page, by default as on the desktop: a link's settled picture is
  // proved, its counts in the status once the certified pass is read back (they cover the
  // picture, at most 0.5% of the pixels that may show M undecided, and every proved hit is
  // drawn: the picture's covered share is the hits' share); certified=false draws the plain
  // pencil without counts. Either way the link keeps the setting.
  for (const [asked, tail] of [[true, ''], [false, '&render.certified=false']]) {
    const opened = await open('#formula=' + encodeURIComponent('x^2 + y^2 + z^2 + w^2 - 1') +
      '&render.rays=4' + tail);
    const t0 = Date.now();
    let s = await settled(opened.page);
    if (asked) {
      await opened.page.waitForFunction(() => JSON.parse(window.fourfold.status()).verdicts,
        null, { timeout: TIMEOUT, polling: 100 });
      s = await status(opened.page);
    }
    const shown = coverage(await picture(opened.page));
    const linked = /certified=false/.test(s.link) === !asked;
    if (asked) {
      const v = s.verdicts;
      const [x0, y0, x1, y1] = s.picture;
      const total = v.hit + v.empty + v.undecided;
      const undecided = v.undecided / Math.max(v.hit + v.undecided, 1);
      check(s.certified && total === Math.round(x1 - x0) * Math.round(y1 - y0) && v.hit > 0
        && undecided <= 0.005 && Math.abs(shown.share - v.hit / total) < 0.005 && linked
        && opened.errors.length === 0,
        `the page's settled picture is certified by default: ${v.hit} hit, ${v.empty} empty, `
        + `${v.undecided} undecided (${(100 * undecided).toFixed(2)}%) after ${Date.now() - t0} ms; `
        + `${(100 * shown.share).toFixed(2)}% of the picture covered against ${(100 * v.hit / total).toFixed(2)}% proved hit`);
    } else {
      check(shown.share > 0.01 && !s.certified && s.verdicts === null && linked
        && opened.errors.length === 0,
        `a link with certified=false draws the plain pencil without counts, its link keeping the setting: ${s.link.split('#')[1]}`);
    }
    await opened.page.close();
  }

  // A stranger's heavy link (every setting that multiplies the work at its most): lowered to
  // the page's bounds, with a notice naming each key; the page keeps answering a script
  // call within 2 s while it builds and draws, and draws a picture.
  const heavy = await open('#formula=' + encodeURIComponent('x^2 + y^2 + z^2 + w^2 - 1') +
    '&render.rays=1024&render.hits=16&tree.max_level=12&tree.min_level=12' +
    '&tree.node_budget=100000000&render.steps=256&render.bisection_iters=256&render.brute_force=true');
  let slowest = 0;
  let hs = null;
  for (const deadline = Date.now() + TIMEOUT; Date.now() < deadline;) {
    const asked = Date.now();
    hs = await status(heavy.page);
    slowest = Math.max(slowest, Date.now() - asked);
    if (hs.panic || (hs.generation > 0 && hs.first_frame_of === hs.generation && !hs.drawing && !hs.building)) break;
    await new Promise((r) => setTimeout(r, 100));
  }
  const heavy_ms = Date.now() - heavy.started;
  const lowered = ['render.rays', 'render.hits', 'tree.max_level', 'tree.min_level', 'tree.node_budget',
    'render.steps', 'render.bisection_iters', 'render.brute_force'].filter((k) => (hs.notice ?? '').includes(k));
  const heavy_drawn = coverage(await picture(heavy.page));
  check(slowest < 2000 && lowered.length === 8 && /render.rays 1024 → 100/.test(hs.notice) && heavy_drawn.share > 0.01 &&
    !hs.panic && heavy.errors.length === 0,
    `a heavy link is lowered (${lowered.length} of 8 keys named) and drawn (${(100 * heavy_drawn.share).toFixed(1)}% ` +
    `covered, ${heavy_ms} ms after opening), the page answering within ${slowest} ms`);
  await heavy.page.close();

  // Embed mode (`#embed&…`, for an iframe): the picture alone, filling the page, no editor;
  // a drag turns it; the address keeps `embed`; a link opens the full page on the scene.
  const embedded = await open('#embed&formula=' + encodeURIComponent('x^2 + y^2 - z^2 - w^2 - 0.1') +
    '&angles=0.3,0,0,0.5,0,0');
  const es = await settled(embedded.page);
  const eshown = await picture(embedded.page);
  const [ex0, ey0, ex1, ey1] = es.picture;
  const fills = (ex1 - ex0) >= WINDOW.width - 10 && (ey1 - ey0) >= WINDOW.height - 10;
  await embedded.page.mouse.move((ex0 + ex1) / 2, (ey0 + ey1) / 2);
  await embedded.page.mouse.down();
  await embedded.page.mouse.move((ex0 + ex1) / 2 + 80, (ey0 + ey1) / 2 + 40, { steps: 8 });
  await embedded.page.mouse.up();
  await embedded.page.waitForFunction((link) => {
    const s = JSON.parse(window.fourfold.status());
    return s.link !== link && !s.drawing && !s.building;
  }, es.link, { timeout: TIMEOUT, polling: 50 });
  const eturned = await status(embedded.page);
  const eangles = (s) => s.link.match(/angles=[^&]*/)?.[0];
  const moved = changed(eshown, await picture(embedded.page));
  await embedded.page.waitForFunction(() => /^#embed&/.test(location.hash), null, { timeout: 5000 });
  const [lx0, ly0, lx1, ly1] = eturned.embed_link;
  const [full] = await Promise.all([
    embedded.page.waitForEvent('popup', { timeout: 10000 }),
    embedded.page.mouse.click((lx0 + lx1) / 2, (ly0 + ly1) / 2),
  ]);
  const full_url = decodeURIComponent(full.url());
  await full.close();
  check(es.embed && es.editor === null && es.controls === null && fills && coverage(eshown).share > 0.01 &&
    eangles(eturned) !== eangles(es) && moved > 0.01 && !/embed/.test(full_url) &&
    full_url.includes(eangles(eturned)) && embedded.errors.length === 0,
    `embed mode shows the picture alone (${ex1 - ex0}x${ey1 - ey0}, no editor), a drag turns it `
    + `(${eangles(es)} → ${eangles(eturned)}, ${(100 * moved).toFixed(1)}% of pixels changed), `
    + `and its link opens the full page on the turned scene`);
  await embedded.page.close();

  // The gallery: every example as a picture drawn in the page; a click on a name opens it.
  const gallery = await open();
  let gs = await settled(gallery.page);
  const middle = ([x0, y0, x1, y1]) => [(x0 + x1) / 2, (y0 + y1) / 2];
  await gallery.page.mouse.click(...middle(gs.gallery.button));
  await gallery.page.waitForFunction(() => JSON.parse(window.fourfold.status()).gallery.pictures >= 2,
    null, { timeout: TIMEOUT, polling: 100 });
  gs = await status(gallery.page);
  const [pick, at] = gs.gallery.names.find(([name, r]) => name !== gs.preset && r[3] < WINDOW.height - 10);
  await gallery.page.mouse.click(...middle(at));
  const picked = await settled(gallery.page, gs.generation);
  const picked_drawn = coverage(await picture(gallery.page));
  check(gs.gallery.open && gs.gallery.names.length === JSON.parse(await gallery.page.evaluate(() => window.fourfold.example_links())).length && picked.preset === pick &&
    !picked.gallery.open && picked_drawn.share > 0.01 && gallery.errors.length === 0,
    `the gallery lists ${gs.gallery.names.length} examples, draws their pictures (${gs.gallery.pictures} so far), `
    + `and a click on ${pick} opens it (${(100 * picked_drawn.share).toFixed(1)}% covered)`);
  await gallery.page.close();

  // Animation export: a GIF and an animated PNG of the frames asked for (the settings the
  // page keeps, set before it loads: 3 frames of 48×32, the file's kind), drawn over the
  // page's frames and downloaded.
  for (const name of ['fourfold.gif', 'fourfold.png']) {
    const animated = await open('', (name) => localStorage.setItem('fourfold.ui',
      `(export_size: (48, 32), animation: (path: "${name}", motion: Turn, plane: "xw", frames: 3, fps: 10.0))`), name,
    TALL);
    const as0 = await settled(animated.page);
    await animated.page.mouse.click(...middle(as0.animation_header));
    // (The section opens over a few frames: its button is clicked once it stays put.)
    let ab = null;
    for (const deadline = Date.now() + TIMEOUT; Date.now() < deadline;) {
      const seen = (await status(animated.page)).animation_button;
      if (seen && JSON.stringify(seen) === JSON.stringify(ab)) break;
      ab = seen;
      await new Promise((r) => setTimeout(r, 500));
    }
    // (A click that lands while egui still settles the panel is lost: it is clicked again
    // until the export says it started.)
    const downloaded = animated.page.waitForEvent('download', { timeout: TIMEOUT }).catch((e) => e);
    let started_notice = '';
    const started = () => started_notice.includes(`into ${name}`);
    for (let tries = 0; tries < 5 && !started(); tries++) {
      await animated.page.mouse.click(...middle(ab));
      for (let waited = 0; waited < 20 && !started(); waited++) {
        await new Promise((r) => setTimeout(r, 500));
        started_notice = (await status(animated.page)).notice ?? '';
      }
    }
    const download = await downloaded;
    if (download instanceof Error) throw new Error(`no ${name} downloaded (the page said ${JSON.stringify(started_notice)}): ${download.message}`);
    const bytes = fs.readFileSync(await download.path());
    const notice = (await status(animated.page)).notice ?? '';
    const said = /downloaded \(3 frames/.test(notice) && /certified pixels: \d+ hit/.test(notice);
    if (name.endsWith('.gif')) {
      const gif = gif_frames(bytes);
      check(download.suggestedFilename() === name && gif.frames === 3 && gif.width === 48 &&
        gif.height === 32 && said && animated.errors.length === 0,
        `Export animation downloads an animated GIF of ${gif.frames} frames of ${gif.width}×${gif.height}: ${JSON.stringify(notice)}`);
    } else {
      const apng = apng_frames(bytes);
      check(download.suggestedFilename() === name && apng.stated === 3 && apng.frames === 3 &&
        apng.width === 48 && apng.height === 32 && said && animated.errors.length === 0,
        `Export animation downloads an animated PNG of ${apng.frames} frames (${apng.stated} stated) of ${apng.width}×${apng.height}: ${JSON.stringify(notice)}`);
    }
    await animated.page.close();
  }

  // A lost GPU device (the test destroys it, as a driver reset would) restarts the page on
  // the scene it had, saying so.
  const lost = await open(link, () => {
    window.devices = [];
    const request = window.GPUAdapter?.prototype.requestDevice;
    if (request) {
      GPUAdapter.prototype.requestDevice = async function (...args) {
        const device = await request.apply(this, args);
        window.devices.push(device);
        return device;
      };
    }
  });
  const before_loss = await settled(lost.page);
  await lost.page.evaluate(() => window.devices.forEach((d) => d.destroy()));
  let after_loss = null;
  for (const deadline = Date.now() + TIMEOUT; Date.now() < deadline && !after_loss;) {
    await new Promise((r) => setTimeout(r, 200));
    // (The page reloads: a call may meet the old page, or the new one before it starts.)
    after_loss = await lost.page.evaluate(() => window.fourfold && JSON.parse(window.fourfold.status()))
      .then((s) => (s && /GPU device was lost/.test(s.notice ?? '') ? s : null), () => null);
  }
  const recovered = after_loss && await settled(lost.page);
  const recovered_drawn = recovered && coverage(await picture(lost.page));
  check(recovered && recovered.formula === before_loss.formula && recovered_drawn.share > 0.01,
    `a lost GPU device restarts the page on its formula (${recovered?.formula}), drawn `
    + `(${(100 * (recovered_drawn?.share ?? 0)).toFixed(1)}% covered), saying: ${JSON.stringify(after_loss?.notice)}`);
  await lost.page.close();

  // A slice's critical values: ticks under the slider, coloured by index; a click on one
  // moves the slice there.
  const sliced = await open('#formula=' + encodeURIComponent('x^2 + y^2 + z^2 + w^2 - 1') +
    '&angles=0.3,0.5,0.7,0.2,0.9,1.1&slice=-1.5', null, undefined, TALL);
  await settled(sliced.page);
  await sliced.page.waitForFunction(() => {
    const s = JSON.parse(window.fourfold.status());
    return s.panic || (s.critical && s.critical_strip);
  }, null, { timeout: TIMEOUT, polling: 100 });
  const cr = await status(sliced.page);
  const poles = (cr.critical ?? []).map((c) => `${((c.value[0] + c.value[1]) / 2).toFixed(6)}:${c.index}:${c.status}`);
  check(poles.join(' ') === '-1.000000:0:proved 1.000000:3:proved',
    `the glome's slice has two proved critical values, ±1, indices 0 and 3: ${poles.join(' ')}`);
  const [sx0, sy0, sx1, sy1] = cr.critical_strip;
  const strip = PNG.sync.read(await sliced.page.screenshot({
    clip: { x: sx0, y: sy0, width: sx1 - sx0, height: sy1 - sy0 },
  }));
  const columns = (want) => {
    const found = [];
    const y = strip.height - 2;
    for (let x = 0; x < strip.width; x++) {
      const i = 4 * (y * strip.width + x);
      if (want(strip.data[i], strip.data[i + 1], strip.data[i + 2])) found.push(x);
    }
    return found;
  };
  const green = columns((r, g, b) => g > 150 && r < 140 && b < 170);
  const red = columns((r, g, b) => r > 180 && g < 120 && b < 120);
  check(green.length > 0 && red.length > 0 && green[0] < red[0],
    `the ticks are drawn, green (born) left of red (vanishes): at ${green[0]} and ${red[0]} of ${strip.width}`);
  if (red.length > 0) {
    await sliced.page.mouse.click(sx0 + red[Math.floor(red.length / 2)] + 0.5, (sy0 + sy1) / 2);
    await sliced.page.waitForFunction(() => Math.abs(JSON.parse(window.fourfold.status()).slice - 1) < 1e-9,
      null, { timeout: 30_000, polling: 100 }).catch(() => {});
    const moved = await status(sliced.page);
    check(Math.abs(moved.slice - 1) < 1e-9, `a click on the red tick moves the slice to c = 1: ${moved.slice}`);
  }
  // Export mesh: the slice shown as an STL download.
  await sliced.page.evaluate(() => { location.hash = location.hash.replace(/slice=[^&]*/, 'slice=0.3'); });
  await sliced.page.waitForFunction(() => Math.abs(JSON.parse(window.fourfold.status()).slice - 0.3) < 1e-12,
    null, { timeout: TIMEOUT, polling: 100 });
  const mb = (await status(sliced.page)).mesh_button;
  const [download] = await Promise.all([
    sliced.page.waitForEvent('download', { timeout: TIMEOUT }),
    sliced.page.mouse.click((mb[0] + mb[2]) / 2, (mb[1] + mb[3]) / 2),
  ]);
  const stl = fs.readFileSync(await download.path());
  const triangles = stl.length >= 84 ? stl.readUInt32LE(80) : 0;
  const notice = (await status(sliced.page)).notice ?? '';
  check(download.suggestedFilename() === 'fourfold-slice.stl' && triangles > 500 &&
    stl.length === 84 + 50 * triangles && notice.includes(`${triangles} triangles`),
    `Export mesh downloads the slice as a binary STL (${triangles} triangles): ${JSON.stringify(notice)}`);
  check(sliced.errors.length === 0, `no error in the console with critical values (${sliced.errors.join(' | ') || 'none'})`);
  await sliced.page.close();

  // A link with a mistyped formula opens the editor on it, with the error.
  const bad = await open('#formula=' + encodeURIComponent('sn(x) + y') + '&zoom=nine');
  await bad.page.waitForFunction(() => JSON.parse(window.fourfold.status()).error, null, { timeout: TIMEOUT });
  const b = await status(bad.page);
  check(b.text === 'sn(x) + y' && /sin/.test(b.error) && /zoom/.test(b.notice ?? ''),
    `a link with a mistyped formula and value opens with both errors: ${JSON.stringify(b.notice)}`);
  await bad.page.close();

  // Every example scene, opened by its link in one page: drawn, and nothing in the console.
  const examples = JSON.parse(await shared.page.evaluate(() => window.fourfold.example_links()));
  let generation = s.generation;
  for (const [name, fragment] of examples) {
    const opened = Date.now();
    await shared.page.evaluate((f) => { location.hash = f; }, fragment);
    const done = await settled(shared.page, generation);
    generation = done.generation;
    const c = coverage(await picture(shared.page));
    const seconds = ((Date.now() - opened) / 1000).toFixed(1);
    check(c.share > 0.001 && !done.error,
      `example ${name} draws (${(100 * c.share).toFixed(1)}% covered, ${seconds} s)`);
  }
  check(shared.errors.length === 0, `no error in the console for any example (${shared.errors.join(' | ') || 'none'})`);

  // The WGSL of fuzzed formulas (written by `fourfold-fuzz --wgsl-out`, see .ci/run)
  // compiles in Chromium's WebGPU, pipeline constants and all: its compiler evaluates
  // constant expressions more strictly than naga.
  const samples = process.env.FOURFOLD_WGSL_SAMPLES;
  if (samples) {
    const files = fs.readdirSync(samples).filter((f) => f.endsWith('.wgsl')).sort();
    let compiled = 0;
    for (const file of files) {
      const code = fs.readFileSync(path.join(samples, file), 'utf8');
      const problems = await shared.page.evaluate(compile_in_webgpu, code);
      if (problems.length === 0) compiled += 1;
      else check(false, `fuzzed WGSL ${file} (${code.split('\n')[0]}) compiles: ${problems.join(' | ')}`);
    }
    check(files.length > 0 && compiled === files.length,
      `the WGSL of ${files.length} fuzzed formulas compiles in Chromium's WebGPU (${compiled} did)`);
  }

  // Without WebGPU the page says what it needs, never a blank canvas.
  const plain = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    args: ['--headless=new', '--no-sandbox', '--disable-features=WebGPU', '--no-first-run'],
  });
  const without = await plain.newPage();
  await without.goto(page_url);
  await without.waitForFunction(() => document.getElementById('message').className === 'error',
    null, { timeout: TIMEOUT });
  const said = await without.textContent('#message');
  check(/WebGPU/.test(said) && /browser/.test(said), `without WebGPU the page says so: ${JSON.stringify(said.split('\n')[0])}`);
  await plain.close();

  if (measure) {
    const wasm = fs.readFileSync(path.join(dist, 'fourfold_web_bg.wasm'));
    const mb = (n) => (n / 1e6).toFixed(2);
    console.log(`\nwasm: ${mb(wasm.length)} MB raw, ${mb(zlib.gzipSync(wasm, { level: 9 }).length)} MB gzipped`);
    console.log(`page load → first picture: ${first_ms} ms; → complete picture (16 passes): ${load_ms} ms`);
    console.log('keystroke → first new preview (the page\'s own clock, text change → first frame),');
    console.log('and the stages of the best: compile, WGSL + naga, tree, pipeline → ready; then the first frame:');
    for (const [name, fragment] of examples.filter(([n]) => ['fig-3-9-left', 'glome', 'tiger'].includes(n))) {
      await shared.page.evaluate((f) => { location.hash = f; }, fragment);
      const before = await settled(shared.page, generation);
      generation = before.generation;
      const runs = [];
      for (let i = 0; i < 3; i++) {
        await type(shared.page, before.formula + ' + 0.0');
        generation = (await settled(shared.page, generation)).generation;
        // One keystroke: 0.0 becomes 0.0i, a new constant.
        await shared.page.keyboard.press(String(i + 1));
        const done = await settled(shared.page, generation);
        runs.push(done);
        generation = done.generation;
      }
      // Then keystrokes that change a number only: no compile (the same shader).
      await type(shared.page, before.formula + ' + 0.01');
      let numbered = await settled(shared.page, generation);
      generation = numbered.generation;
      const numbers = [];
      for (const key of ['2', '3', '4']) {
        await shared.page.keyboard.press(key);
        const done = await settled(shared.page, generation);
        numbers.push(`${done.edit_latency_ms.toFixed(0)}${done.pipelines === numbered.pipelines ? '' : ' (compiled)'}`);
        generation = done.generation;
        numbered = done;
      }
      const best = runs.reduce((a, b) => (b.edit_latency_ms < a.edit_latency_ms ? b : a));
      const t = best.edit_stages_ms;
      console.log(`  ${name}: ${runs.map((r) => r.edit_latency_ms.toFixed(0)).join(', ')} ms; best: `
        + `${t.compile.toFixed(1)} + ${t.codegen.toFixed(1)} + ${t.tree.toFixed(0)} + ${t.pipeline.toFixed(0)} → `
        + `${t.ready.toFixed(0)}, first frame at ${best.edit_latency_ms.toFixed(0)} ms; `
        + `UI frames ${best.ui_frame_ms.toFixed(0)} ms; tree in each run `
        + `${runs.map((r) => r.edit_stages_ms.tree.toFixed(0)).join(', ')} ms; the preview drawn in `
        + `${runs.map((r) => r.progress.preview_ms.toFixed(0)).join(', ')} ms`
        + `${runs.every((r, i) => i === 0 || r.progress.cpu_previews > runs[i - 1].progress.cpu_previews) ? ' on the CPU' : ''}`
        + `; a number's keystroke → first preview: ${numbers.join(', ')} ms`);
    }
  }
  await shared.page.close();
} catch (e) {
  check(false, e.stack ?? String(e));
} finally {
  await browser.close();
  server.close();
}
console.log(failures ? `\n${failures} browser check(s) failed` : '\nall browser checks passed');
process.exit(failures ? 1 : 0);
