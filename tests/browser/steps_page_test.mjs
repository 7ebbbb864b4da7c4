// The stage-stepper page in a real browser (Debian's /usr/bin/chromium driven by playwright-core).
//
//   node steps_page_test.mjs --focal PATH/TO/focal [--work DIR]   `focal steps` on builtin:demo, every method
//   node steps_page_test.mjs --fixture [--work DIR]               the page alone, on make_fixture.py's folder
//
// For each folder it opens DIR/index.html from file:// and checks: no console or page errors and no
// error messages on the page; every stage selectable by click and by keyboard, with its images
// loaded; a click on a probed pixel shows exactly the rgba that `focal probe` prints for it (the
// fixture: that steps.json holds); a click elsewhere names the nearest probe and the command to
// probe the clicked pixel; next/previous pixel keys; integer zoom. FOCAL_UPDATE_SCREENSHOTS=1
// writes docs/images/steps/<method>.png. Exit 0 when every check passed, 1 otherwise.
// Element ids and data attributes used here are listed at the top of apps/steps_page/steps.js.
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.resolve(here, '..', '..');
const kMethods = ['multiview', 'multilayer', 'gather', 'accum'];
const kSize = ['--width', '160', '--height', '120', '--samples', '8'];
const kStepsOnly = ['--reference-samples', '32']; // the side-by-side's accum: fast, not converged

function parseArgs(argv) {
  const args = { focal: process.env.FOCAL_BINARY || '', fixture: false, work: '' };
  for (let i = 0; i < argv.length; ++i) {
    if (argv[i] === '--focal') args.focal = argv[++i];
    else if (argv[i] === '--fixture') args.fixture = true;
    else if (argv[i] === '--work') args.work = argv[++i];
    else throw new Error(`unknown argument ${argv[i]} (usage: --focal PATH | --fixture, [--work DIR])`);
  }
  if (!args.fixture && !args.focal) throw new Error('give --focal PATH (or FOCAL_BINARY) or --fixture');
  args.work = path.resolve(args.work || fs.mkdtempSync(path.join(os.tmpdir(), 'focal-steps-page-')));
  fs.mkdirSync(args.work, { recursive: true });
  return args;
}

// ---- Checks: each failure is recorded and the run goes on, so one run lists every problem. ----

const failures = [];
let context = '';
function check(ok, message) {
  if (!ok) {
    failures.push(`${context}: ${message}`);
    console.log(`  FAIL ${message}`);
  }
  return ok;
}
const sameNumbers = (a, b) => Array.isArray(a) && Array.isArray(b) && a.length === b.length &&
  a.every((v, i) => v === b[i]);

// ---- Folders ----

function makeFolder(args, method) {
  const dir = path.join(args.work, method);
  fs.rmSync(dir, { recursive: true, force: true });
  if (args.fixture) {
    execFileSync('python3', [path.join(here, 'make_fixture.py'), dir, path.join(root, 'apps', 'steps_page')]);
  } else {
    // Run in the work folder with a relative -o, so the page's command line reads "-o METHOD".
    execFileSync(path.resolve(args.focal), ['steps', 'builtin:demo', '--method', method, ...kSize, ...kStepsOnly,
                 '-o', method], { cwd: args.work, stdio: ['ignore', 'ignore', 'inherit'] });
  }
  // focal writes the page from its embedded copy (apps/steps_page.h).
  for (const name of ['index.html', 'steps.css', 'steps.js']) {
    if (!check(fs.existsSync(path.join(dir, name)), `the folder holds ${name}`)) return null;
    const same = fs.readFileSync(path.join(dir, name), 'utf8') ===
                 fs.readFileSync(path.join(root, 'apps', 'steps_page', name), 'utf8');
    check(same, `${name} is apps/steps_page/${name} (rebuild focal after editing the page)`);
  }
  return dir;
}

// The probe the page must agree with: `focal probe` as the folder's probe_command says, or, for the
// fixture (which has no program behind it), the probe stored in steps.json.
function expectedProbe(args, data, probe) {
  if (args.fixture) return probe;
  const words = data.probe_command.replace('X,Y', `${probe.x},${probe.y}`).split(/\s+/).filter(Boolean);
  check(words[0] === 'focal', `probe_command starts with "focal": ${data.probe_command}`);
  const out = execFileSync(args.focal, words.slice(1), { encoding: 'utf8' });
  return JSON.parse(out);
}

// ---- The page ----

async function attr(page, selector, name) {
  return page.locator(selector).getAttribute(name);
}

async function displayOrder(page) {
  return page.locator('#stage-list li[data-stage-id]').evaluateAll(
    (items) => items.map((li) => li.getAttribute('data-stage-id')));
}

// Waits until the stage image has loaded or failed, then checks that it loaded.
async function checkStageImage(page, stageId, image) {
  const img = page.locator('#stage-image');
  await page.waitForSelector('#stage-image[data-loaded]', { state: 'attached' });
  const loaded = await img.getAttribute('data-loaded');
  const natural = await img.evaluate((e) => [e.naturalWidth, e.naturalHeight]);
  check(loaded === 'true' && natural[0] > 0, `stage ${stageId}: image ${image.file} loaded (${loaded}, ${natural})`);
  check(natural[0] === image.width && natural[1] === image.height,
        `stage ${stageId}: ${image.file} is ${natural} as steps.json says (${image.width},${image.height})`);
}

async function checkEveryStageByClick(page, data) {
  const order = await displayOrder(page);
  check(order.length === data.stages.length &&
        data.stages.every((s) => order.includes(s.id)), `the list shows every stage (${order})`);
  for (const stage of data.stages) {
    await page.locator(`#stage-list li[data-stage-id="${stage.id}"]`).click();
    check(await attr(page, '#stage-view', 'data-stage-id') === stage.id, `clicking ${stage.id} shows it`);
    const images = stage.images || [];
    for (let k = 0; k < images.length; ++k) {
      if (images.length > 1) await page.locator(`#image-picker button[data-image-index="${k}"]`).click();
      await checkStageImage(page, stage.id, images[k]);
    }
    if (images.length > 1) {
      await page.keyboard.press('i'); // wraps from the last image to the first
      check(await attr(page, '#stage-image', 'data-file') === images[0].file, `${stage.id}: i cycles to the first image`);
    }
    if (images.length === 0) check(await page.locator('#stage-image').count() === 0, `${stage.id}: no image shown`);
  }
  for (const key of ['result', 'reference', 'difference']) {
    const ok = await page.locator(`#compare-${key}`).evaluate((e) => e.complete && e.naturalWidth > 0);
    check(ok, `the compare ${key} image loaded`);
  }
}

async function checkKeyboardStepping(page) {
  const order = await displayOrder(page);
  await page.locator('#stage-list li[data-stage-id]').first().click();
  const keysForward = ['ArrowRight', 'j'], keysBack = ['ArrowLeft', 'k'];
  for (let i = 1; i < order.length; ++i) {
    await page.keyboard.press(keysForward[i % 2]);
    check(await attr(page, '#stage-view', 'data-stage-id') === order[i], `${keysForward[i % 2]} moves to ${order[i]}`);
  }
  await page.keyboard.press('ArrowRight');
  check(await attr(page, '#stage-view', 'data-stage-id') === order[order.length - 1], 'ArrowRight stops at the last stage');
  for (let i = order.length - 2; i >= 0; --i) {
    await page.keyboard.press(keysBack[i % 2]);
    check(await attr(page, '#stage-view', 'data-stage-id') === order[i], `${keysBack[i % 2]} moves back to ${order[i]}`);
  }
}

// A stage whose shown image is in frame pixels, preferably one the probe draws shapes on.
function frameStage(data, probe) {
  const framed = data.stages.filter((s) => (s.images || []).length > 0 &&
    (s.images[0].scale || 1) === 1 && s.images[0].width === data.width);
  const drawn = framed.find((s) => (probe.draw || []).some((d) => (d.stages || []).includes(s.id) && !(d.stages || []).includes('*')));
  return drawn || framed.find((s) => s.group === data.method) || framed[0];
}

async function clickFramePixel(page, x, y) {
  const zoom = Number(await attr(page, '#zoom-level', 'data-zoom'));
  await page.locator('#stage-image').click({ position: { x: (x + 0.5) * zoom, y: (y + 0.5) * zoom } });
}

async function panelProbe(page) {
  return {
    x: Number(await attr(page, '#probe-xy', 'data-x')),
    y: Number(await attr(page, '#probe-xy', 'data-y')),
    index: Number(await attr(page, '#probe-panel', 'data-probe-index')),
    rgba: JSON.parse(await attr(page, '#probe-rgba', 'data-rgba') || 'null'),
    reference: JSON.parse(await attr(page, '#probe-reference-rgba', 'data-rgba') || 'null'),
    exact: await attr(page, '#probe-exact', 'data-exact'),
  };
}

async function checkProbes(page, args, data) {
  const probes = data.probes;
  if (!check(probes.length >= 2, `at least two probes (${probes.length})`)) return;
  const sorted = probes.every((p, i) => i === 0 || p.y > probes[i - 1].y || (p.y === probes[i - 1].y && p.x > probes[i - 1].x));
  check(sorted, 'probes are sorted by (y, x)');
  const pick = Math.floor(probes.length / 2);
  const probe = probes[pick];
  const stage = frameStage(data, probe);
  if (!check(stage, 'a stage with a frame-size image to click on')) return;
  await page.locator(`#stage-list li[data-stage-id="${stage.id}"]`).click();
  await page.waitForSelector('#stage-image[data-loaded="true"]', { state: 'attached' });

  // A probed pixel: the panel shows exactly what focal probe prints.
  await clickFramePixel(page, probe.x, probe.y);
  const shown = await panelProbe(page);
  const expected = expectedProbe(args, data, probe);
  check(shown.x === probe.x && shown.y === probe.y && shown.exact === 'true',
        `clicking (${probe.x}, ${probe.y}) shows that probe exactly (got ${shown.x}, ${shown.y}, exact ${shown.exact})`);
  check(sameNumbers(shown.rgba, expected.rgba), `rgba ${JSON.stringify(shown.rgba)} = focal probe's ${JSON.stringify(expected.rgba)}`);
  // `focal probe` renders no reference; when it prints none, steps.json's is the one to match.
  const reference = expected.reference_rgba || probe.reference_rgba;
  check(sameNumbers(shown.reference, reference),
        `reference_rgba ${JSON.stringify(shown.reference)} = ${JSON.stringify(reference)}`);
  check(sameNumbers(probe.rgba, expected.rgba), 'steps.json and focal probe agree on rgba');
  // Its shapes for this stage, and the crosshair, are drawn over the image.
  const wanted = (probe.draw || []).filter((d) => (d.stages || []).includes('*') || (d.stages || []).includes(stage.id)).length;
  const drawn = await page.locator('#stage-overlay .shape, #stage-overlay .point').count();
  check(drawn === wanted, `${wanted} shapes of the probe drawn on ${stage.id} (got ${drawn})`);
  check(await page.locator('#stage-overlay .crosshair').count() > 0, 'a crosshair on the probed pixel');
  check(await page.locator('#compare-difference-overlay .crosshair').count() > 0, 'the crosshair on the difference image too');
  const fragments = await page.locator('#probe-fragments tr').count();
  check(fragments === Math.max(1, (probe.fragments || []).length + ((probe.fragments || []).length ? 1 : 0)),
        `the fragments table has a row per fragment (${fragments} rows)`);

  // A pixel that was not probed: the nearest probe, and the command to probe the clicked one.
  const isProbed = (x, y) => probes.some((p) => p.x === x && p.y === y);
  const cx = probe.x + 1 < data.width && !isProbed(probe.x + 1, probe.y) ? probe.x + 1 : probe.x - 1;
  await clickFramePixel(page, cx, probe.y);
  const near = await panelProbe(page);
  check(near.exact === 'false', `clicking (${cx}, ${probe.y}) says it is not a probed pixel`);
  check(near.x === probe.x && near.y === probe.y, `and selects the nearest probe (${near.x}, ${near.y})`);
  const command = await page.locator('#probe-command').innerText();
  check(command.includes(` ${cx},${probe.y} `) || command.endsWith(` ${cx},${probe.y}`),
        `the probe command names the clicked pixel: ${command}`);

  // Next / previous probed pixel, in (y, x) order.
  const expectAt = async (key, index) => {
    await page.keyboard.press(key);
    const p = await panelProbe(page);
    check(p.index === index && p.x === probes[index].x && p.y === probes[index].y,
          `${key} selects probe ${index} (${probes[index].x}, ${probes[index].y}); got ${p.index} (${p.x}, ${p.y})`);
  };
  await expectAt('n', pick + 1);
  await expectAt('p', pick);
  await expectAt('ArrowDown', pick + 1);
  await expectAt('ArrowUp', pick);

  // Every probe, stepped through from the first: the panel shows steps.json's numbers exactly.
  for (let i = pick; i > 0; --i) await page.keyboard.press('p');
  for (let i = 0; i < probes.length; ++i) {
    const p = await panelProbe(page);
    check(p.index === i && p.x === probes[i].x && p.y === probes[i].y &&
          sameNumbers(p.rgba, probes[i].rgba) && sameNumbers(p.reference, probes[i].reference_rgba),
          `probe ${i} (${probes[i].x}, ${probes[i].y}) shows steps.json's rgba and reference_rgba exactly`);
    await page.keyboard.press('n');
  }
  check((await panelProbe(page)).index === probes.length - 1, 'n stops at the last probe');
}

async function checkZoom(page) {
  const zoomNow = async () => Number(await attr(page, '#zoom-level', 'data-zoom'));
  const imageFits = async (z) => {
    const [shown, natural, scale] = await page.locator('#stage-image').evaluate(
      (e) => [e.getBoundingClientRect().width, e.naturalWidth, Number(e.getAttribute('data-scale'))]);
    return check(shown === natural * scale * z, `the image is ${natural}×${scale}×${z} px wide (${shown})`);
  };
  const z0 = await zoomNow();
  check(Number.isInteger(z0) && z0 >= 1, `the fitted zoom is a whole number (${z0})`);
  await page.keyboard.press('+');
  check(await zoomNow() === z0 + 1, `+ zooms to ${z0 + 1}`);
  await imageFits(z0 + 1);
  await page.keyboard.press('-');
  await page.keyboard.press('-');
  check(await zoomNow() === Math.max(1, z0 - 1), `- zooms out to ${Math.max(1, z0 - 1)}`);
  await page.keyboard.press('0');
  check(await zoomNow() === z0, `0 fits again (${z0})`);
  const rendering = await page.locator('#stage-image').evaluate((e) => getComputedStyle(e).imageRendering);
  check(rendering === 'pixelated', `nearest-neighbour pixels (image-rendering: ${rendering})`);
  // The pixel under the mouse: the centre of frame pixel (3, 2).
  await page.locator('#stage-image').hover({ position: { x: 3.5 * z0, y: 2.5 * z0 } });
  check(await attr(page, '#hover-xy', 'data-x') === '3' && await attr(page, '#hover-xy', 'data-y') === '2',
        'the frame pixel under the mouse is shown');
}

async function testFolder(browser, args, method, dir) {
  const data = JSON.parse(fs.readFileSync(path.join(dir, 'steps.json'), 'utf8'));
  const page = await browser.newPage({ viewport: { width: 1280, height: 860 } });
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warning') errors.push(`console ${m.type()}: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  await page.goto('file://' + path.join(dir, 'index.html'));
  await page.waitForSelector('#stage-list li[data-stage-id]');
  await checkEveryStageByClick(page, data);
  await checkKeyboardStepping(page);
  await checkProbes(page, args, data);
  await checkZoom(page);
  const messages = await page.locator('#messages .message[data-kind="error"], #messages .message[data-kind="warning"]').allInnerTexts();
  check(messages.length === 0, `no error or warning messages on the page: ${messages.join(' | ')}`);
  check(errors.length === 0, `no console or page errors: ${errors.join(' | ')}`);
  // The docs show focal's real output, never the fixture's.
  if (process.env.FOCAL_UPDATE_SCREENSHOTS === '1' && !args.fixture) await screenshot(page, data, method);
  await page.close();
}

// A damaged folder (fixture mode): a missing image, malformed stages and probes, and no
// steps_data.js at all must each give a visible message and no page error. (Chromium itself logs
// the failed file:// load of a missing file as a console error; the page cannot prevent that.)
async function checkDamagedFolders(browser, dir) {
  const data = JSON.parse(fs.readFileSync(path.join(dir, 'steps.json'), 'utf8'));
  const first = data.stages[0].images[0].file;
  fs.rmSync(path.join(dir, first));
  data.stages.splice(1, 0, 42);                     // not an object
  data.stages[2].images = 'not a list';
  data.probes.push({ x: 'a' });                     // no integer x, y
  fs.writeFileSync(path.join(dir, 'steps_data.js'), `window.FOCAL_STEPS = ${JSON.stringify(data)};\n`);
  const expect = [`Could not load ${first}`, 'stages[1] is not an object', '"images" is not a list',
                  'has no integer x, y'];
  const page = await browser.newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto('file://' + path.join(dir, 'index.html'));
  await page.waitForSelector('#stage-image[data-loaded]', { state: 'attached' });
  const shown = (await page.locator('#messages').innerText());
  for (const text of expect) check(shown.includes(text), `damaged folder: the page says "${text}"`);
  check(await page.locator('#stage-viewport .image-error').count() === 1, 'damaged folder: the missing image is replaced by a message');
  fs.rmSync(path.join(dir, 'steps_data.js'));
  await page.reload();
  check((await page.locator('#messages').innerText()).includes('steps_data.js is missing'),
        'no steps_data.js: the page says so');
  check(pageErrors.length === 0, `damaged folders: no page errors (${pageErrors.join(' | ')})`);
  await page.close();
}

// The docs' picture: the stage the middle probe draws on (else the method's first stage in frame
// pixels), with that probe selected.
async function screenshot(page, data, method) {
  const probe = data.probes[Math.floor(data.probes.length / 2)];
  const stage = frameStage(data, probe);
  await page.locator(`#stage-list li[data-stage-id="${stage.id}"]`).click();
  await page.waitForSelector('#stage-image[data-loaded="true"]', { state: 'attached' });
  await page.keyboard.press('0');
  await clickFramePixel(page, probe.x, probe.y);
  const out = path.join(root, 'docs', 'images', 'steps');
  fs.mkdirSync(out, { recursive: true });
  const file = path.join(out, `${method}.png`);
  await page.screenshot({ path: file });
  console.log(`  wrote ${path.relative(root, file)}`);
}

// playwright-core is installed by `npm ci` in tests/browser (tools/install-deps.sh does it).
async function loadChromium() {
  try {
    return (await import('playwright-core')).chromium;
  } catch (e) {
    throw new Error(`playwright-core is not installed: run tools/install-deps.sh (or npm ci in ${here})`);
  }
}

async function main() {
  const args = parseArgs(process.argv.slice(2));
  const chromium = await loadChromium();
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    // Root needs --no-sandbox; the rest keeps Chromium off the (closed) network.
    args: ['--no-sandbox', '--disable-gpu', '--disable-background-networking', '--disable-component-update',
           '--disable-sync', '--no-first-run', '--disable-quic'],
  });
  try {
    for (const method of args.fixture ? ['fixture'] : kMethods) {
      context = method;
      console.log(`${method}: ${args.fixture ? 'make_fixture.py' : 'focal steps'} -> ${path.join(args.work, method)}`);
      const dir = makeFolder(args, method);
      if (!dir) continue;
      await testFolder(browser, args, method, dir);
      if (args.fixture) await checkDamagedFolders(browser, dir);
    }
  } finally {
    await browser.close();
  }
  if (failures.length) {
    console.log(`\n${failures.length} check(s) failed; folders kept in ${args.work}`);
    process.exit(1);
  }
  console.log('steps page: every check passed');
}

main().catch((e) => {
  console.log(`steps page test: ${e.stack || e}`);
  process.exit(1);
});
