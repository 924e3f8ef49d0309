// Opens a page in headless Chromium, waits until it says it is ready, takes a screenshot and
// checks it: loaded, no console errors, not blank. Prints one JSON line:
//   {"loaded":bool,"load_ms":N,"console_errors":[...],"nonblank":bool,
//    "differing_fraction":F,"screenshot":"OUT.png"}
// Exit status: 0 when every check passed, 1 when one failed, 77 when Chromium or
// playwright-core is not installed (`npm install` in this folder; Debian's `chromium`).
//
// Usage: node page_check.mjs --url URL --screenshot OUT.png [--timeout-ms N]
//          [--ready-expr 'JS expression'] [--report-expr 'JS expression'] [--width W] [--height H]
//          [--idle-before-ms N]
// --report-expr's value (JSON-serializable) comes back as "reported", taken with the
// screenshot. --idle-before-ms: the browser first shows a blank page and stays idle this long
// before the URL is opened, as a user's browser is running already when they open a page (a
// browser just launched is still starting its processes; its first page pays for that).
// `differing_fraction` is the share of pixels whose colour differs from the top-left pixel's
// (the page's background): a drawn mesh shows as pixels that differ.
import { existsSync, writeFileSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { inflateSync } from 'node:zlib';

const SKIP = 77;

function parseArgs(argv) {
  const options = { timeoutMs: 30000, readyExpr: '', reportExpr: '', width: 1280, height: 800,
                    idleBeforeMs: 0 };
  for (let i = 0; i < argv.length; i += 2) {
    const [key, value] = [argv[i], argv[i + 1]];
    if (value === undefined) throw new Error(`${key} needs a value`);
    if (key === '--url') options.url = value;
    else if (key === '--screenshot') options.screenshot = value;
    else if (key === '--timeout-ms') options.timeoutMs = Number(value);
    else if (key === '--ready-expr') options.readyExpr = value;
    else if (key === '--report-expr') options.reportExpr = value;
    else if (key === '--width') options.width = Number(value);
    else if (key === '--height') options.height = Number(value);
    else if (key === '--idle-before-ms') options.idleBeforeMs = Number(value);
    else throw new Error(`unknown option ${key}`);
  }
  if (!options.url || !options.screenshot) throw new Error('--url and --screenshot are required');
  return options;
}

// Decodes an 8-bit RGB or RGBA, non-interlaced PNG (what Chromium's screenshots are) into
// {width, height, channels, pixels}.
function decodePng(buffer) {
  let offset = 8;
  let width = 0, height = 0, channels = 0;
  const idat = [];
  while (offset < buffer.length) {
    const length = buffer.readUInt32BE(offset);
    const type = buffer.toString('ascii', offset + 4, offset + 8);
    const data = buffer.subarray(offset + 8, offset + 8 + length);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      const [depth, colour, interlace] = [data[8], data[9], data[12]];
      if (depth !== 8 || interlace !== 0 || (colour !== 2 && colour !== 6))
        throw new Error(`unsupported PNG (depth ${depth}, colour ${colour})`);
      channels = colour === 6 ? 4 : 3;
    } else if (type === 'IDAT') {
      idat.push(data);
    }
    offset += 12 + length;
  }
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const pixels = Buffer.alloc(stride * height);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; ++x) {
      const a = x >= channels ? pixels[y * stride + x - channels] : 0;
      const b = y > 0 ? pixels[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? pixels[(y - 1) * stride + x - channels] : 0;
      let predictor = 0;
      if (filter === 1) predictor = a;
      else if (filter === 2) predictor = b;
      else if (filter === 3) predictor = (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c;
        const [pa, pb, pc] = [Math.abs(p - a), Math.abs(p - b), Math.abs(p - c)];
        predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      pixels[y * stride + x] = (line[x] + predictor) & 0xff;
    }
  }
  return { width, height, channels, pixels };
}

function differingFraction(image) {
  const { width, height, channels, pixels } = image;
  let differing = 0;
  for (let i = 0; i < width * height; ++i) {
    for (let k = 0; k < 3; ++k) {
      if (Math.abs(pixels[i * channels + k] - pixels[k]) > 8) {
        ++differing;
        break;
      }
    }
  }
  return differing / (width * height);
}

const options = parseArgs(process.argv.slice(2));
const executable = process.env.FEATSENSE_CHROMIUM || '/usr/bin/chromium';
let chromium;
try {
  ({ chromium } = await import('playwright-core'));
} catch {
  console.log(JSON.stringify({ skipped: 'playwright-core is not installed (npm install in test/tools)' }));
  process.exit(SKIP);
}
if (!existsSync(executable)) {
  console.log(JSON.stringify({ skipped: `no Chromium at ${executable} (Debian package chromium)` }));
  process.exit(SKIP);
}

// Chromium as root in a sandbox-less container, with no network: no background services, and
// WebGL through SwiftShader (software) since there is no GPU.
const profile = mkdtempSync(join(tmpdir(), 'featsense-chromium-'));
const browser = await chromium.launchPersistentContext(profile, {
  executablePath: executable,
  headless: true,
  viewport: { width: options.width, height: options.height },
  args: [
    '--no-sandbox', '--disable-background-networking', '--disable-component-update',
    '--disable-sync', '--disable-quic', '--no-first-run', '--use-angle=swiftshader',
    '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
  ],
});
const result = { loaded: false, load_ms: -1, console_errors: [], nonblank: false,
                 differing_fraction: 0, screenshot: options.screenshot };
try {
  const page = browser.pages()[0] ?? (await browser.newPage());
  page.on('console', (message) => {
    if (message.type() === 'error') result.console_errors.push(message.text());
  });
  page.on('pageerror', (error) => result.console_errors.push(`uncaught: ${error.message}`));
  page.on('requestfailed', (request) =>
    result.console_errors.push(`request failed: ${request.url()} ${request.failure()?.errorText}`));
  if (options.idleBeforeMs > 0) {
    await page.goto('about:blank');
    await new Promise((resolve) => setTimeout(resolve, options.idleBeforeMs));
  }
  const start = performance.now();
  await page.goto(options.url, { waitUntil: 'load', timeout: options.timeoutMs });
  if (options.readyExpr)
    await page.waitForFunction(options.readyExpr, null, { timeout: options.timeoutMs });
  result.load_ms = Math.round(performance.now() - start);
  result.loaded = true;
  if (options.reportExpr) result.reported = await page.evaluate(options.reportExpr);
  const png = await page.screenshot({ fullPage: false });
  writeFileSync(options.screenshot, png);
  result.differing_fraction = differingFraction(decodePng(png));
  result.nonblank = result.differing_fraction > 0;
} catch (error) {
  result.console_errors.push(`page check: ${error.message.split('\n')[0]}`);
} finally {
  await browser.close();
  rmSync(profile, { recursive: true, force: true });
}
console.log(JSON.stringify(result));
process.exit(result.loaded && result.nonblank && result.console_errors.length === 0 ? 0 : 1);
