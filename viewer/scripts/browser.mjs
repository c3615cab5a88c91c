// Launches Debian's Chromium headless through playwright-core (never a downloaded browser).
// Used by the movie script, the browser tests (the viewer's, a compared scene's report) and the scale measurement.
import { mkdtempSync, rmSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';

export const chromiumPath = process.env.POLYDYN_CHROMIUM || '/usr/bin/chromium';

// Flags for a closed network and a machine without a GPU: WebGL runs on SwiftShader (software).
export const chromiumArgs = [
  '--headless=new', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--ignore-gpu-blocklist',
  '--allow-file-access-from-files',
];

export function haveChromium() { return existsSync(chromiumPath); }

// Returns { context, close }: a persistent context on a fresh profile directory that close() removes.
export async function launch() {
  const profile = mkdtempSync(join(tmpdir(), 'polydyn-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: chromiumPath,
    headless: true,
    args: chromiumArgs,
    viewport: { width: 1280, height: 720 },
    // the scripts handle Ctrl-C themselves (movie.mjs removes its unfinished output first)
    handleSIGINT: false, handleSIGTERM: false, handleSIGHUP: false,
  });
  return {
    context,
    async close() {
      let died = false;
      await context.close().catch(() => { died = true; });
      // a browser that died on its own (Ctrl-C reaches it too) may still write its profile while it
      // goes: remove the profile again once it has had time to finish
      rmSync(profile, { recursive: true, force: true, maxRetries: 20, retryDelay: 100 });
      if (died) {
        await new Promise((res) => setTimeout(res, 1500));
        rmSync(profile, { recursive: true, force: true, maxRetries: 20, retryDelay: 100 });
      }
    },
  };
}

// Statistics of a replay's 3-D view (the element `locator` finds, e.g. its canvas) in a screenshot of it: the share
// of its pixels that differ from the clear colour (0x20242b), how many colours (5 bits each) it has, and every
// 16th pixel's bytes.
export async function viewStats(page, locator) {
  const png = await page.screenshot({ clip: await locator.boundingBox() });
  return page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width; c.height = img.height;
    const ctx = c.getContext('2d');
    ctx.drawImage(img, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    let drawn = 0;
    const colours = new Set();
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - 0x20) + Math.abs(d[i + 1] - 0x24) + Math.abs(d[i + 2] - 0x2b) > 12) drawn++;
      colours.add((d[i] >> 3) << 10 | (d[i + 1] >> 3) << 5 | (d[i + 2] >> 3));
    }
    return { drawn: drawn / (d.length / 4), colours: colours.size, data: Array.from(d.filter((_, i) => i % 64 === 0)) };
  }, png.toString('base64'));
}
