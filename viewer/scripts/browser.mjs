// Launches Debian's Chromium headless through playwright-core (never a downloaded browser).
// Used by the movie script, the browser test and the scale measurement.
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

// Returns { browser, close } with a fresh profile directory that close() removes.
export async function launch() {
  const profile = mkdtempSync(join(tmpdir(), 'polydyn-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: chromiumPath,
    headless: true,
    args: chromiumArgs,
    viewport: { width: 1280, height: 720 },
  });
  return {
    context,
    async close() {
      await context.close();
      rmSync(profile, { recursive: true, force: true });
    },
  };
}
