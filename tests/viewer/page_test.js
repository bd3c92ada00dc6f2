// Debian's chromium, headless through playwright-core (never a downloaded browser), opens the
// built-in page of a running semap-onboard (viewer_test.sh starts it): two screenshots some
// seconds apart; the map canvas holds pixels in the palette's class colours, the pose moved
// between them, the camera JPEG decoded, the health table filled; the page fetched nothing off
// loopback and threw no error; on a phone-sized screen the map still fills the width.
//
//   node page_test.js --url http://127.0.0.1:PORT/ --palette config/sim-classes.yaml --out DIR
//        [--chromium /usr/bin/chromium] [--docs-screenshot docs/viewer-screenshot.png]
'use strict';
const fs = require('fs');
const os = require('os');
const path = require('path');
const { chromium } = require('playwright-core');
const lib = require('./lib.js');
const { check, fail, log } = lib;

const a = lib.args();
const out = a.out || '.';
const palette = lib.readPalette(a.palette);

// Pixels of a PNG by palette class (exact RGB), and how many differ from the background.
function classPixels(png, background) {
  const counts = palette.map(() => 0);
  const key = new Map(palette.map((c, i) => [(c.rgb[0] << 16) | (c.rgb[1] << 8) | c.rgb[2], i]));
  let other = 0;
  for (let p = 0; p < png.width * png.height; ++p) {
    const o = p * png.channels;
    const rgb = (png.pixels[o] << 16) | (png.pixels[o + 1] << 8) | png.pixels[o + 2];
    const i = key.get(rgb);
    if (i !== undefined) counts[i]++;
    else if (rgb !== background) other++;
  }
  return { counts, other };
}

async function main() {
  const browser = await chromium.launch({
    executablePath: a.chromium || '/usr/bin/chromium',
    headless: true,
    chromiumSandbox: false,
    args: ['--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync'],
    env: { ...process.env, HOME: fs.mkdtempSync(path.join(os.tmpdir(), 'semap-chromium-')) },
  });
  const errors = [];
  const offLoopback = [];
  try {
    const context = await browser.newContext({ viewport: { width: 1280, height: 800 }, deviceScaleFactor: 1 });
    // Nothing but the robot: any other request is refused and fails the test.
    await context.route('**/*', (route) => {
      const host = new URL(route.request().url()).hostname;
      if (host === '127.0.0.1' || host === 'localhost' || host === '[::1]') return route.continue();
      offLoopback.push(route.request().url());
      return route.abort();
    });
    const page = await context.newPage();
    page.on('pageerror', (e) => errors.push('pageerror: ' + e.message));
    page.on('console', (m) => m.type() === 'error' && errors.push('console: ' + m.text()));

    await page.goto(a.url, { waitUntil: 'load' });
    const ready = () => window.semapViewer && window.semapViewer.connected && window.semapViewer.cells > 50 &&
      window.semapViewer.pose && window.semapViewer.images.camera > 0 && window.semapViewer.health;
    try {
      await page.waitForFunction(ready, null, { timeout: 30000, polling: 250 });
    } catch (e) {
      fail('the page did not get connected, map, pose, camera and health in 30 s: ' +
        JSON.stringify(await page.evaluate(() => window.semapViewer && { ...window.semapViewer, health: !!window.semapViewer.health })));
    }
    await page.waitForTimeout(1000); // a frame drawn after the last message
    const state1 = await page.evaluate(() => ({ ...window.semapViewer, health: undefined }));
    const shot1 = path.join(out, 'viewer-1.png');
    await page.screenshot({ path: shot1 });
    // The map canvas alone, the translucent costmap layer switched off for it (it tints cells).
    const mapShot = async (file) => {
      await page.uncheck('#layer-costmap');
      await page.waitForTimeout(200);
      const png = await page.locator('#map').screenshot();
      await page.check('#layer-costmap');
      fs.writeFileSync(path.join(out, file), png);
      return png;
    };
    const map1 = await mapShot('map-1.png');

    await page.waitForTimeout(5000);
    const state2 = await page.evaluate(() => ({ ...window.semapViewer, health: undefined }));
    const shot2 = path.join(out, 'viewer-2.png');
    await page.screenshot({ path: shot2 });
    const map2 = await mapShot('map-2.png');
    log('state at the first screenshot: ' + JSON.stringify(state1));

    // The map canvas: class colours drawn, on its background.
    const background = await page.evaluate(() => {
      const c = getComputedStyle(document.getElementById('map')).backgroundColor.match(/\d+/g).map(Number);
      return (c[0] << 16) | (c[1] << 8) | c[2];
    });
    for (const [name, png] of [['first', lib.decodePng(map1)], ['second', lib.decodePng(map2)]]) {
      const { counts, other } = classPixels(png, background);
      const drawn = counts.reduce((s, c) => s + c, 0);
      const classes = palette.filter((c, i) => counts[i] > 20).map((c) => c.name);
      log(name + ' map screenshot ' + png.width + 'x' + png.height + ': ' + drawn + ' pixels in class colours (' +
        palette.map((c, i) => c.name + ' ' + counts[i]).join(', ') + '), ' + other + ' other non-background pixels');
      check(drawn > 500, 'only ' + drawn + ' pixels of the ' + name + ' map screenshot in class colours');
      check(classes.length >= 3, 'the ' + name + ' map screenshot shows ' + classes.length + ' classes: ' + classes.join(' '));
    }

    // The pose moved between the two.
    const moved = Math.hypot(state2.pose.x - state1.pose.x, state2.pose.y - state1.pose.y);
    log('pose (' + state1.pose.x.toFixed(2) + ', ' + state1.pose.y.toFixed(2) + ') -> (' + state2.pose.x.toFixed(2) +
      ', ' + state2.pose.y.toFixed(2) + '): moved ' + moved.toFixed(2) + ' m in 5 s; trail ' + state2.trailLength);
    check(moved > 3, 'the pose moved ' + moved.toFixed(2) + ' m between the screenshots');
    check(state2.trailLength > state1.trailLength, 'the trail did not grow');
    const pixelsChanged = Buffer.compare(map1, map2) !== 0;
    check(pixelsChanged, 'the two map screenshots are identical');

    // What else the page shows.
    const page1 = await page.evaluate(() => ({
      camera: document.getElementById('camera').naturalWidth,
      overlay: document.getElementById('overlay').naturalWidth,
      legend: [...document.querySelectorAll('#legend li')].map((li) => li.textContent),
      stages: [...document.querySelectorAll('#stages tbody tr')].map((tr) => tr.cells[0].textContent),
      costmapLayer: window.semapViewer.costmap,
    }));
    log('page: ' + JSON.stringify(page1));
    check(page1.camera > 0 && page1.overlay > 0, 'camera / overlay JPEG not decoded by chromium');
    check(page1.legend.length >= palette.length - 1, 'legend: ' + page1.legend.join(', '));
    check(['estimation', 'perception', 'mapping'].every((s) => page1.stages.includes(s)), 'health table: ' + page1.stages.join(', '));
    check(page1.costmapLayer && page1.costmapLayer.width > 0, 'no costmap on the page');
    check(state2.errors.length === 0, 'the page noted errors: ' + state2.errors.join('; '));

    // Phone-sized: the map spans the screen's width, nothing scrolls sideways.
    await page.setViewportSize({ width: 390, height: 844 });
    await page.waitForTimeout(700);
    const phone = await page.evaluate(() => ({
      map: document.getElementById('map').getBoundingClientRect().toJSON(),
      scrollWidth: document.documentElement.scrollWidth,
    }));
    await page.screenshot({ path: path.join(out, 'viewer-phone.png'), fullPage: true });
    log('phone-sized: map ' + Math.round(phone.map.width) + 'x' + Math.round(phone.map.height) + ', page width ' + phone.scrollWidth);
    check(phone.map.width >= 350 && phone.map.height >= 250 && phone.scrollWidth <= 390, 'phone layout: ' + JSON.stringify(phone));

    check(offLoopback.length === 0, 'the page asked for something off loopback: ' + offLoopback.join(' '));
    check(errors.length === 0, 'errors in the page: ' + errors.join('; '));
    if (a['docs-screenshot']) {
      fs.copyFileSync(shot2, a['docs-screenshot']);
      log('screenshot copied to ' + a['docs-screenshot']);
    }
    log('PASS');
  } finally {
    await browser.close();
  }
}

main().catch((e) => fail(e.stack || e.message));
