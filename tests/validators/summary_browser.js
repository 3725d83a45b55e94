// Opens a summary.html in headless Chromium (playwright-core, the browser at
// $G2P_CHROMIUM or /usr/bin/chromium) and checks its 3D view as a person
// would see it: the canvas shows the object (not blank), and unticking a
// part, showing the collision hulls, the centre of mass or the input's look
// each changes the picture; hovering over the object shows the part's
// details. Pixels come from screenshots of the page, not from the page's own code.
//
//   node summary_browser.js PAGE.html [--screenshot OUT.png] [--screenshot-top OUT.png] [--no-webgl | --draw-only]
//
// --screenshot saves the whole page at the end; --screenshot-top the first
// 1280 x 900 pixels while the mouse rests on a part (the picture in README.md).
//
// --correct PART:CLASS[:DENSITY[:FILLED]] --download OUT.json uses the correction
// control as a person would: clicks part PART in the list, chooses CLASS (and
// types DENSITY in kg/m^3 and FILLED, the percent of its cavity a fill of
// water takes, which the form refuses until the part is made hollow), adds the correction, checks that the picture
// changes (the part takes its new class's colour) and saves the overrides file
// the page downloads as OUT.json (instead of the toggle checks); with
// --screenshot-top, the picture is taken once the correction is listed.
//
// --draw-only checks only that the view draws, and times it: the seconds from
// opening the page to a ready view (ready_s) and one frame (frame_ms).
// --no-webgl starts Chromium without WebGL and checks that the page says so
// and keeps its static content. Prints one JSON line; exits 1 with the reason
// on stderr when a check fails, 2 when the browser cannot be started.
'use strict';
const path = require('path');
const { chromium } = require('playwright-core');

const args = process.argv.slice(2);
const page_path = args.find((a, i) => !a.startsWith('--') &&
  !/^--(screenshot|correct|download|object)/.test(args[i - 1] || ''));
const option = (name) => (args.includes(name) ? args[args.indexOf(name) + 1] : null);
const shot = option('--screenshot');
const top_shot = option('--screenshot-top');
const no_webgl = args.includes('--no-webgl');
const draw_only = args.includes('--draw-only');
const correct = option('--correct');
const download_to = option('--download');
const object_kind = option('--object');  // with --correct: also correct what the object is
if (!page_path) {
  console.error('usage: node summary_browser.js PAGE.html [--screenshot OUT.png] [--screenshot-top OUT.png] [--no-webgl | --draw-only]');
  process.exit(2);
}

class CheckFailed extends Error {}
function check(ok, message) {
  if (!ok) throw new CheckFailed(message);
}

// Decodes a PNG in a blank page and compares it with the background colour
// and, when given, with an earlier picture.
// The pictures stay in the decoder page under `key`.
async function pixels(decoder, png, key, previous) {
  return decoder.evaluate(async ([b64, name, prevName]) => {
    window.shots = window.shots || {};
    const prev = prevName ? window.shots[prevName] : null;
    const img = new Image();
    img.src = 'data:image/png;base64,' + b64;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width;
    c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    const bg = [d[0], d[1], d[2]];  // a corner: the view's background
    let object = 0, changed = 0;
    let sx = 0, sy = 0;
    for (let i = 0; i < d.length; i += 4) {
      const p = i / 4;
      if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 24) {
        ++object;
        sx += p % c.width;
        sy += Math.floor(p / c.width);
      }
      if (prev && Math.abs(d[i] - prev[i]) + Math.abs(d[i + 1] - prev[i + 1]) + Math.abs(d[i + 2] - prev[i + 2]) > 24)
        ++changed;
    }
    window.shots[name] = d;
    const n = c.width * c.height;
    return {
      width: c.width, height: c.height,
      object: object / n, changed: prev ? changed / n : null,
      centroid: object ? [sx / object, sy / object] : null,
    };
  }, [png.toString('base64'), key, previous || null]);
}

async function frames(page, n = 3) {
  await page.evaluate((k) => new Promise((done) => {
    const step = () => (k-- > 0 ? requestAnimationFrame(step) : done());
    step();
  }), n);
}

async function main() {
  const start = Date.now();
  const browser = await chromium.launch({
    executablePath: process.env.G2P_CHROMIUM || '/usr/bin/chromium',
    // SwiftShader: WebGL without a GPU, as on CI machines.
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader']
      .concat(no_webgl ? ['--disable-webgl', '--disable-3d-apis'] : []),
  }).catch((e) => {
    console.error(`cannot start Chromium: ${e.message.split('\n')[0]}`);
    process.exit(2);
  });
  const result = { page: page_path, checks: [] };
  try {
    const page = await browser.newPage({ viewport: { width: 1280, height: 900 }, acceptDownloads: true });
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
    // Offline: any request that leaves the folder fails the check.
    const outside = [];
    await page.route('**/*', (route) => {
      const url = route.request().url();
      if (!url.startsWith('file://') && !url.startsWith('data:') && !url.startsWith('blob:')) {
        outside.push(url);
        return route.abort();
      }
      return route.continue();
    });
    const opened = Date.now();
    await page.goto('file://' + path.resolve(page_path));
    const section = page.locator('#g2p-3d');
    check(await section.count() === 1, 'the page has no 3D view section (#g2p-3d)');
    await page.waitForFunction(() => document.getElementById('g2p-3d').dataset.state, null, { timeout: 20000 })
      .catch(() => { throw new CheckFailed('the 3D view never started (no data-state after 20 s)'); });
    const state = await section.getAttribute('data-state');
    result.ready_s = (Date.now() - opened) / 1000;
    check(outside.length === 0, `the page asked the network for ${outside.join(', ')}`);
    check(await page.locator('h2', { hasText: 'Parts' }).count() === 1, 'the static parts table is missing');
    if (no_webgl) {
      check(state === 'no-webgl', `without WebGL the view's state is "${state}", not "no-webgl"`);
      const status = await section.locator('.g2p-status').innerText();
      check(/no WebGL/.test(status), `without WebGL the page does not say so: "${status}"`);
      result.checks.push('no WebGL: the page says so and keeps its static content');
    } else {
      check(state === 'ready', `the 3D view did not start: state "${state}"; errors: ${errors.join('; ')}`);
      check(errors.length === 0, `the page reported errors: ${errors.join('; ')}`);
      const canvas = section.locator('canvas');
      await frames(page);
      const decoder = await browser.newPage();
      const first = await pixels(decoder, await canvas.screenshot(), 'first');
      result.canvas = [first.width, first.height];
      result.object_fraction = Number(first.object.toFixed(4));
      check(first.object > 0.01, `the 3D view is blank: ${(100 * first.object).toFixed(2)} % of the canvas differs ` +
        'from its background');
      result.checks.push('the 3D view draws the object');
      result.frame_ms = await page.evaluate(() => {
        const t = performance.now();
        const gl = window.g2pViewer.gl();
        const pixel = new Uint8Array(4);
        for (let i = 0; i < 5; ++i) {
          window.g2pViewer.render();
          gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);  // waits for the frame
        }
        return (performance.now() - t) / 5;
      });
      if (draw_only) {
        result.seconds = (Date.now() - start) / 1000;
        console.log(JSON.stringify(result));
        return;
      }

      // Hover over the object: the part's details appear.
      const box = await canvas.boundingBox();
      await page.mouse.move(box.x + first.centroid[0] * box.width / first.width,
        box.y + first.centroid[1] * box.height / first.height);
      await frames(page);
      const info = await section.locator('.g2p-info').innerText();
      check(/density/.test(info) && /mass/.test(info) && /wall thickness/.test(info), `hovering over the object shows no part details (class, structure, wall thickness, density, mass): "${info}"`);
      result.hover = info.split('\n')[0];
      if (top_shot) await page.screenshot({ path: top_shot });  // the view with a part's details, for the docs
      result.checks.push('hovering shows a part\'s details');
      await page.mouse.move(box.x + 2, box.y + 2);  // away, so the highlight goes
      await frames(page);
      const base = await pixels(decoder, await canvas.screenshot(), 'base');

      async function toggled(selector, what, least = 0.002) {
        const input = section.locator(selector);
        check(await input.count() === 1, `no control for ${what} (${selector})`);
        await input.click();
        await frames(page);
        const after = await pixels(decoder, await canvas.screenshot(), 'after', 'base');
        check(after.changed > least, `${what}: the picture did not change (${(100 * after.changed).toFixed(3)} % ` +
          'of the pixels)');
        await input.click();
        await frames(page);
        result.checks.push(`${what} changes the picture (${(100 * after.changed).toFixed(1)} % of the pixels)`);
        return after;
      }
      if (correct) {
        const [part, cls, density, filled] = correct.split(':');
        const item = section.locator('.g2p-parts li').nth(Number(part));
        check(await item.count() === 1, `the parts list has no part ${part}`);
        await item.locator('span').last().click();  // pins the part: its correction form appears
        const form = section.locator('.g2p-fix');
        check(await form.count() === 1, 'clicking a part shows no correction form (.g2p-fix)');
        await form.locator('select[name=g2p-fix-class]').selectOption(cls);
        if (density) await form.locator('input[name=g2p-fix-density]').fill(density);
        if (filled) {
          // A solid part holds nothing: the form says so until the part is made hollow.
          await form.locator('input[name=g2p-fix-fill]').fill(filled);
          await form.locator('button.g2p-fix-add').click();
          const said = await form.locator('.warn').innerText();
          check(said.includes('choose hollow'), `a fill of a solid part was not refused (the form says "${said}")`);
          check(await section.locator('.g2p-fixes li').count() === 0, 'a refused correction was listed');
          await form.locator('select[name=g2p-fix-structure]').selectOption('hollow');
        }
        await form.locator('button.g2p-fix-add').click();
        await page.mouse.move(box.x + 2, box.y + 2);
        await frames(page);
        const recoloured = await pixels(decoder, await canvas.screenshot(), 'recoloured', 'base');
        check(recoloured.changed > 0.002, `the corrected part did not take its new colour (${(100 * recoloured.changed).toFixed(3)} % of the pixels changed)`);
        result.checks.push(`a correction recolours the part (${(100 * recoloured.changed).toFixed(1)} % of the pixels)`);
        if (top_shot) await page.screenshot({ path: top_shot });  // the correction control, for the docs
        const listed = await section.locator('.g2p-fixes li').allInnerTexts();
        check(listed.length === 1 && listed[0].includes(cls), `the corrections list shows ${JSON.stringify(listed)}`);
        if (density) {
          check(listed[0].includes(`${density} kg/m\u00b3`), `the corrections list shows ${JSON.stringify(listed)}, ` +
            `not the density ${density}`);
        }
        if (filled) {
          check(listed[0].includes(`${filled} % full (1000 kg/m\u00b3)`), `the corrections list shows ` +
            `${JSON.stringify(listed)}, not ${filled} % full of water`);
        }
        if (object_kind) {  // What it is: another kind of the object table joins the corrections
          const field = section.locator('.g2p-object-fix input');
          check(await field.count() === 1, 'the page has no "What it is" field (.g2p-object-fix)');
          await field.fill(object_kind);
          await field.dispatchEvent('change');
          const now = await section.locator('.g2p-fixes li').allInnerTexts();
          check(now.length === 2 && now[0].includes(`the object is a ${object_kind}`),
            `after correcting what the object is, the corrections list shows ${JSON.stringify(now)}`);
          result.checks.push('a correction of what the object is is listed');
        }
        const [download] = await Promise.all([
          page.waitForEvent('download', { timeout: 10000 }),
          section.locator('button.g2p-fix-download').click(),
        ]).catch(() => { throw new CheckFailed('the download button gave no file'); });
        check(download.suggestedFilename() === 'overrides.json', `the file is called ${download.suggestedFilename()}`);
        if (download_to) await download.saveAs(download_to);
        result.download = download_to;
        result.checks.push('the correction downloads as overrides.json');
        result.seconds = (Date.now() - start) / 1000;
        console.log(JSON.stringify(result));
        return;
      }
      const hidden = await toggled('input[name=part0]', 'unticking part 0');
      check(hidden.object < base.object, 'unticking part 0 did not take anything away from the picture');
      await toggled('input[name=hulls]', 'showing the collision hulls');
      await toggled('input[name=com]', 'showing the centre of mass', 0.001);  // a small mark
      await toggled('input[name=look]', "showing the input's own look");
    }
    if (shot) {
      await page.screenshot({ path: shot, fullPage: true });
      result.screenshot = shot;
    }
    result.seconds = (Date.now() - start) / 1000;
    console.log(JSON.stringify(result));
  } finally {
    await browser.close();
  }
}

main().catch((e) => {
  console.error(e instanceof CheckFailed ? `summary_browser: ${e.message}` : e.stack);
  process.exit(1);
});
