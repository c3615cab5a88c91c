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
