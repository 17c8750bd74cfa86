// The browser build in headless Chromium on SwiftShader's WebGPU (run by tests/web.sh).
//
// For every technique the page says runs there: opens the viewer on the default scene with
// that technique at a fixed size, reads its third frame back through a buffer (canvas
// screenshots can come back blank under headless SwiftShader), and checks that the frame is
// not empty, that it matches the native lavapipe render of the same scene, view and size,
// and that the console shows no error. Then judges one technique live on the browser's GPU
// and checks its verdict against the native CPU judge's, the arbiter. Prints a table; exits
// non-zero on any failure.
//
// node browser-test.mjs --dist web/dist --native-bin target/debug/shadow-zoo
//     --chromium /usr/bin/chromium --out DIR [--size 256] [--only a,b]
// Serves --dist on loopback itself; renders the native frames with --native-bin into --out.

import { chromium } from "playwright-core";
import { execFileSync } from "node:child_process";
import { readFileSync, writeFileSync } from "node:fs";
import { createServer } from "node:http";
import { extname, join, normalize } from "node:path";
import { crc32, deflateSync, inflateSync } from "node:zlib";

// Agreement with the native render: both are CPU rasterisers in 32-bit float, but they
// differ in rasterisation rules, texture filtering and transcendental functions, so edges
// and filtered penumbrae move by a level or two. A frame passes when its mean absolute
// difference is at most MEAN_BOUND levels (of 255) per channel and at most
// PIXEL_SHARE_BOUND of its pixels differ by more than PIXEL_LEVELS in some channel.
const MEAN_BOUND = 2.0;
const PIXEL_LEVELS = 24;
const PIXEL_SHARE_BOUND = 0.01;
// The frame compared, counted from the technique's first: the browser cannot wait for a
// frame's GPU results within it, so techniques that read them back (sdsm's depth range) use
// the newest that arrived, a frame or two old; on a still view the third frame uses the
// same results as lavapipe's third (`render --frames 3`).
const COMPARED_FRAME = 3;
// Per technique: loading the page and rendering its first frames on SwiftShader.
const FRAME_TIMEOUT_MS = 120_000;
// The live judge's check: the technique, the area rays a pixel it waits for (the GPU judge's
// most), how long that may take, and how far each light's scores may be from the native CPU
// judge's (as the native live judge's test bounds them: the two locate the lit pixels and
// trace on different machines, and both reference and technique render on SwiftShader here).
const JUDGED = "sm-pcf";
const JUDGE_SAMPLES = 64;
const JUDGE_TIMEOUT_MS = 300_000;
const JUDGE_BOUND = 0.01;
const DEFAULT_SCENE = "scenes/planar-room.ron";

function parseArgs() {
  const args = { size: 256, only: null };
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; i += 2) {
    const value = argv[i + 1];
    switch (argv[i]) {
      case "--dist": args.dist = value; break;
      case "--native-bin": args.nativeBin = value; break;
      case "--chromium": args.chromium = value; break;
      case "--out": args.out = value; break;
      case "--size": args.size = Number(value); break;
      case "--only": args.only = value.split(","); break;
      default: throw new Error(`unknown argument ${argv[i]}`);
    }
  }
  if (!args.dist || !args.nativeBin || !args.out || !args.chromium) {
    throw new Error("usage: browser-test.mjs --dist DIR --native-bin FILE --chromium FILE " +
      "--out DIR [--size N] [--only a,b]");
  }
  return args;
}

const TYPES = {
  ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm",
};

// Serves `dist` on a free loopback port; resolves to the server and its address.
function serve(dist) {
  const server = createServer((request, response) => {
    const path = normalize(decodeURIComponent(new URL(request.url, "http://x").pathname));
    const file = join(dist, path.endsWith("/") ? `${path}index.html` : path);
    try {
      const body = readFileSync(file);
      response.writeHead(200, { "content-type": TYPES[extname(file)] ?? "application/octet-stream" });
      response.end(body);
    } catch {
      response.writeHead(404);
      response.end();
    }
  });
  return new Promise((resolve) => server.listen(0, "127.0.0.1", () =>
    resolve({ server, url: `http://127.0.0.1:${server.address().port}/` })));
}

// The native render of `id` on the default scene (lavapipe), decoded, and how long the
// command took (adapter, scene, technique and its frames).
function nativeFrame(args, id) {
  const out = `${args.out}/${id}.native.png`;
  const started = Date.now();
  execFileSync(args.nativeBin,
    ["render", "--technique", id, "--size", `${args.size}x${args.size}`,
      "--frames", String(COMPARED_FRAME), "--out", out],
    { stdio: ["ignore", "ignore", "inherit"] });
  return { ...decodePng(readFileSync(out)), ms: Date.now() - started };
}

// Decodes an 8-bit, non-interlaced RGB or RGBA PNG into RGBA bytes.
function decodePng(bytes) {
  let offset = 8;
  let width = 0, height = 0, channels = 0;
  const data = [];
  while (offset < bytes.length) {
    const length = bytes.readUInt32BE(offset);
    const type = bytes.toString("latin1", offset + 4, offset + 8);
    const body = bytes.subarray(offset + 8, offset + 8 + length);
    if (type === "IHDR") {
      width = body.readUInt32BE(0);
      height = body.readUInt32BE(4);
      const [depth, colour, , , interlace] = body.subarray(8, 13);
      channels = { 2: 3, 6: 4 }[colour];
      if (depth !== 8 || !channels || interlace !== 0) {
        throw new Error(`unsupported PNG (depth ${depth}, colour ${colour})`);
      }
    } else if (type === "IDAT") {
      data.push(body);
    }
    offset += 12 + length;
  }
  const raw = inflateSync(Buffer.concat(data));
  const stride = width * channels;
  const rows = new Uint8Array(height * stride);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; x++) {
      const a = x >= channels ? rows[y * stride + x - channels] : 0;
      const b = y > 0 ? rows[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? rows[(y - 1) * stride + x - channels] : 0;
      let predictor = 0;
      if (filter === 1) predictor = a;
      else if (filter === 2) predictor = b;
      else if (filter === 3) predictor = (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c;
        const [pa, pb, pc] = [Math.abs(p - a), Math.abs(p - b), Math.abs(p - c)];
        predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      rows[y * stride + x] = (line[x] + predictor) & 0xff;
    }
  }
  const rgba = new Uint8Array(width * height * 4);
  for (let i = 0; i < width * height; i++) {
    for (let k = 0; k < 4; k++) {
      rgba[4 * i + k] = k < channels ? rows[channels * i + k] : 255;
    }
  }
  return { width, height, rgba };
}

// Encodes RGBA bytes as an 8-bit RGBA PNG.
function encodePng(width, height, rgba) {
  const chunk = (type, body) => {
    const head = Buffer.alloc(8);
    head.writeUInt32BE(body.length, 0);
    head.write(type, 4, "latin1");
    const tail = Buffer.alloc(4);
    tail.writeUInt32BE(crc32(Buffer.concat([head.subarray(4), body])), 0);
    return Buffer.concat([head, body, tail]);
  };
  const header = Buffer.alloc(13);
  header.writeUInt32BE(width, 0);
  header.writeUInt32BE(height, 4);
  header.set([8, 6, 0, 0, 0], 8);
  const rows = Buffer.alloc(height * (4 * width + 1));
  for (let y = 0; y < height; y++) {
    rows.set(rgba.subarray(4 * width * y, 4 * width * (y + 1)), y * (4 * width + 1) + 1);
  }
  return Buffer.concat([
    Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]),
    chunk("IHDR", header), chunk("IDAT", deflateSync(rows)), chunk("IEND", Buffer.alloc(0)),
  ]);
}

// Mean absolute difference (levels per channel, RGB) and the share of pixels off by more
// than PIXEL_LEVELS.
function compare(a, b) {
  let sum = 0, off = 0;
  const pixels = a.length / 4;
  for (let i = 0; i < pixels; i++) {
    let worst = 0;
    for (let k = 0; k < 3; k++) {
      const d = Math.abs(a[4 * i + k] - b[4 * i + k]);
      sum += d;
      worst = Math.max(worst, d);
    }
    if (worst > PIXEL_LEVELS) off++;
  }
  return { mean: sum / (3 * pixels), share: off / pixels };
}

// Distinct colours in a frame: an empty (cleared, or all-black) frame has one.
function distinctColours(rgba) {
  const seen = new Set();
  for (let i = 0; i < rgba.length && seen.size < 64; i += 4) {
    seen.add((rgba[i] << 16) | (rgba[i + 1] << 8) | rgba[i + 2]);
  }
  return seen.size;
}

const launchOptions = (chromium) => ({
  executablePath: chromium,
  headless: true,
  args: [
    "--no-sandbox", "--no-first-run", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--disable-quic",
    "--enable-unsafe-webgpu", "--enable-unsafe-swiftshader",
    "--use-webgpu-adapter=swiftshader", "--enable-features=Vulkan",
    // The canvas's shared images through ANGLE on SwiftShader: without them headless
    // Chromium finds no backing for a WebGPU canvas, and under a frame of any weight it
    // destroys the device ("Device was destroyed").
    "--use-gl=angle", "--use-angle=swiftshader", "--use-vulkan=swiftshader",
    // Software rendering takes seconds a frame; the watchdog must not count that as a hang.
    "--disable-gpu-watchdog",
  ],
});

// Opens `url` and waits until `zoo` is on the page and `ready(zoo)` holds.
async function openPage(browser, url, ready) {
  const page = await browser.newPage();
  const errors = [];
  // eframe's logger writes Rust's errors as warnings that start with "ERROR:".
  page.on("console", (message) => {
    const text = message.text();
    if (message.type() === "error" || text.startsWith("ERROR:")) errors.push(text);
  });
  page.on("pageerror", (error) => errors.push(String(error)));
  const started = Date.now();
  try {
    await page.goto(url);
    await page.waitForFunction(ready, null, { timeout: FRAME_TIMEOUT_MS, polling: 100 });
  } catch (error) {
    // A page left open would go on rendering beside the next ones.
    await page.close();
    throw error;
  }
  return { page, errors, ms: Date.now() - started };
}

// A model the user picks (an OBJ and its material library, handed over as the page's file
// picker does) opens in a scene of its own and renders without an error.
async function checkOpenedModel(browser, url, failures) {
  const { page, errors } = await openPage(browser, url,
    () => window.zoo && JSON.parse(window.zoo.status()).frames > 0);
  const files = ["trellis.mtl", "trellis.obj"].map((name) =>
    [name, Array.from(readFileSync(`scenes/models/${name}`))]);
  const frames = await page.evaluate((files) => {
    for (const [name, bytes] of files) window.zoo.open_file(name, Uint8Array.from(bytes));
    return JSON.parse(window.zoo.status()).frames;
  }, files);
  try {
    await page.waitForFunction((before) => {
      const status = JSON.parse(window.zoo.status());
      return status.scene === "user/trellis.obj" && status.frames > before + 1;
    }, frames, { timeout: FRAME_TIMEOUT_MS, polling: 100 });
  } catch (error) {
    failures.push(`an opened model did not show: ${error.message}`);
  }
  const status = JSON.parse(await page.evaluate(() => window.zoo.status()));
  if (status.error) failures.push(`an opened model: ${status.error}`);
  failures.push(...errors.map((e) => `an opened model: ${e}`));
  console.log(`opened model: ${status.scene}, ${status.frames} frames, error ${status.error}`);
  await page.close();
}

// Reads a CSV with a header row into objects.
function readCsv(path) {
  const [header, ...lines] = readFileSync(path, "utf8").trim().split("\n");
  const keys = header.split(",");
  return lines.map((line) => Object.fromEntries(line.split(",").map((v, i) => [keys[i], v])));
}

// Judges JUDGED live on the browser's GPU (`judge=live`) until the reference has
// JUDGE_SAMPLES area rays a pixel, and compares each light's scores with the native CPU
// judge's (`compare`, same scene, view and size).
async function checkLiveJudge(args, browser, failures) {
  const size = `${args.size}x${args.size}`;
  const url = `${args.url}?technique=${JUDGED}&size=${size}&judge=live`;
  let opened;
  try {
    opened = await openPage(browser, url, () => window.zoo && JSON.parse(window.zoo.status()).judge);
  } catch (error) {
    failures.push(`live judge: no verdict within ${FRAME_TIMEOUT_MS} ms (${error})`);
    return [];
  }
  const { page, errors, ms } = opened;
  const started = Date.now();
  let verdict;
  try {
    await page.waitForFunction((samples) => {
      const status = JSON.parse(window.zoo.status());
      return status.error || status.judge?.samples >= samples;
    }, JUDGE_SAMPLES, { timeout: JUDGE_TIMEOUT_MS, polling: 250 });
  } catch (error) {
    failures.push(`live judge: ${JUDGE_SAMPLES} area rays not reached (${error.message})`);
  }
  const status = JSON.parse(await page.evaluate(() => window.zoo.status()));
  verdict = status.judge;
  await page.close();
  if (status.error) failures.push(`live judge: ${status.error}`);
  failures.push(...errors.map((e) => `live judge: ${e}`));
  const out = `${args.out}/judge`;
  execFileSync(args.nativeBin,
    ["compare", "--scene", DEFAULT_SCENE, "--techniques", JUDGED, "--size", size, "--out", out],
    { stdio: ["ignore", "ignore", "inherit"] });
  const cpu = readCsv(`${out}/results.csv`).filter((row) => row.technique === JUDGED);
  const rows = [`live judge of ${JUDGED}: first verdict ${ms} ms after load, ` +
    `${verdict?.samples} area rays a pixel ${Date.now() - started} ms later; ` +
    `bound: each score within ${JUDGE_BOUND} of the native CPU judge's`,
  "| light | browser live: false shadow / false lit / mae | native CPU judge | verdict |",
  "|---|---|---|---|"];
  if (!verdict || verdict.lights.length !== cpu.length) {
    failures.push(`live judge: ${verdict?.lights.length} lights judged, native ${cpu.length}`);
    return rows;
  }
  cpu.forEach((row, light) => {
    const live = verdict.lights[light];
    const scores = ["false_shadow", "false_lit", "mae"];
    const unsupported = row.pixels === "";
    let off;
    if (!live || unsupported) {
      off = !live === unsupported ? [] : [live ? "scored, native not" : "not scored, native is"];
    } else {
      off = scores.filter((k) => Math.abs(live[k] - Number(row[k])) > JUDGE_BOUND);
    }
    const show = (m) => m ? scores.map((k) => Number(m[k]).toFixed(4)).join(" / ") : "-";
    rows.push(`| ${light} | ${show(live)} | ${show(unsupported ? null : row)} | ` +
      `${off.length ? "FAIL" : "ok"} |`);
    if (off.length) failures.push(`live judge, light ${light}: ${off.join(", ")} off by > ${JUDGE_BOUND}`);
  });
  return rows;
}

async function main() {
  const args = parseArgs();
  const { server, url } = await serve(args.dist);
  args.url = url;
  const browser = await chromium.launch(launchOptions(args.chromium));
  const failures = [];
  const rows = [];
  let judged = [];
  try {
    // The page lists what runs here.
    const first = await openPage(browser, args.url,
      () => window.zoo && JSON.parse(window.zoo.status()).frames > 0);
    const techniques = JSON.parse(await first.page.evaluate(() => window.zoo.techniques()));
    // Every technique of the native build registered in the browser's too (registrations
    // are link-time statics, which wasm-ld drops unless something keeps them).
    const listed = execFileSync(args.nativeBin, ["list"], { encoding: "utf8" })
      .split("\n").map((line) => /^([a-z0-9-]+)\s{2,}/.exec(line)?.[1]).filter(Boolean);
    const missing = listed.filter((id) => !techniques.some((t) => t.id === id));
    if (missing.length) failures.push(`not registered in the browser: ${missing.join(", ")}`);
    console.log(`${techniques.length} techniques registered (native: ${listed.length})`);
    const status = JSON.parse(await first.page.evaluate(() => window.zoo.status()));
    console.log(`adapter: ${status.adapter}`);
    console.log(`first page: ${first.ms} ms to its first frame`);
    await first.page.close();
    await checkOpenedModel(browser, args.url, failures);
    const size = `${args.size}x${args.size}`;
    for (const technique of techniques) {
      if (args.only && !args.only.includes(technique.id)) continue;
      if (technique.unavailable) {
        rows.push(`| ${technique.id} | unavailable: ${technique.unavailable} | | | | |`);
        continue;
      }
      const url = `${args.url}?technique=${technique.id}&size=${size}&capture=${COMPARED_FRAME}`;
      let opened;
      try {
        opened = await openPage(browser, url, () => window.zoo &&
          (window.zoo.frame() !== null || JSON.parse(window.zoo.status()).error !== null));
      } catch (error) {
        failures.push(`${technique.id}: no frame within ${FRAME_TIMEOUT_MS} ms (${error})`);
        rows.push(`| ${technique.id} | no frame | | | | FAIL |`);
        continue;
      }
      const { page, errors, ms } = opened;
      const shown = JSON.parse(await page.evaluate(() => window.zoo.status()));
      const frame = await page.evaluate(() => {
        const f = window.zoo.frame();
        return f && { width: f.width, height: f.height, rgba: Array.from(f.rgba) };
      });
      await page.close();
      if (!frame) {
        failures.push(`${technique.id}: ${shown.error}`, ...errors.map((e) => `${technique.id}: ${e}`));
        rows.push(`| ${technique.id} | failed: ${shown.error} | | | | FAIL |`);
        continue;
      }
      const rgba = Uint8Array.from(frame.rgba);
      let native;
      try {
        native = nativeFrame(args, technique.id);
      } catch (error) {
        failures.push(`${technique.id}: the native render failed: ${error.message}`);
        rows.push(`| ${technique.id} | ${ms} | failed | | | FAIL |`);
        continue;
      }
      const problems = [];
      if (shown.technique !== technique.id) {
        problems.push(`shows ${shown.technique}: ${shown.error}`);
      }
      if (shown.error) problems.push(`error: ${shown.error}`);
      if (errors.length) problems.push(`console: ${errors.join(" | ")}`);
      if (frame.width !== native.width || frame.height !== native.height) {
        problems.push(`size ${frame.width}x${frame.height}, native ${native.width}x${native.height}`);
      }
      if (distinctColours(rgba) < 2) problems.push("the frame is empty");
      const { mean, share } = compare(rgba, native.rgba);
      if (mean > MEAN_BOUND || share > PIXEL_SHARE_BOUND) {
        problems.push(`differs from native: mean ${mean.toFixed(2)} > ${MEAN_BOUND} levels or ` +
          `${(100 * share).toFixed(2)} % > ${100 * PIXEL_SHARE_BOUND} % of pixels`);
      }
      writeFileSync(`${args.out}/${technique.id}.web.png`, encodePng(frame.width, frame.height, rgba));
      rows.push(`| ${technique.id} | ${ms} | ${native.ms} | ${mean.toFixed(2)} | ` +
        `${(100 * share).toFixed(2)} | ` +
        `${problems.length ? "FAIL" : "ok"} |`);
      for (const problem of problems) failures.push(`${technique.id}: ${problem}`);
    }
    if (!args.only || args.only.includes(JUDGED)) {
      judged = await checkLiveJudge(args, browser, failures);
    }
  } finally {
    await browser.close();
    server.close();
  }
  const table = [
    `size ${args.size}x${args.size}; bounds: mean <= ${MEAN_BOUND} levels, ` +
      `<= ${100 * PIXEL_SHARE_BOUND} % of pixels off by > ${PIXEL_LEVELS}`,
    `| technique | browser: frame ${COMPARED_FRAME} (ms, page load included) | ` +
      `native: \`render --frames ${COMPARED_FRAME}\` (ms) | mean difference (levels) | ` +
      "pixels off (%) | verdict |",
    "|---|---|---|---|---|---|",
    ...rows,
    "",
    ...judged,
  ].join("\n");
  console.log(table);
  writeFileSync(`${args.out}/report.md`, table + "\n");
  if (failures.length) {
    console.error(`\n${failures.length} failure(s):\n${failures.join("\n")}`);
    process.exit(1);
  }
}

main().catch((error) => {
  console.error(error);
  process.exit(1);
});
