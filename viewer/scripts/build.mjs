// Bundles the viewer (src/main.js, three.js inside) into one script: dist/viewer.js.
// `polydyn view` inlines that file into every page it writes.
import { build } from 'esbuild';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const result = await build({
  entryPoints: [join(root, 'src/main.js')],
  outfile: join(root, 'dist/viewer.js'),
  bundle: true,
  minify: true,
  format: 'iife',
  target: 'es2020',
  loader: { '.css': 'text' },
  legalComments: 'eof',
  metafile: true,
  logLevel: 'warning',
});
const bytes = Object.values(result.metafile.outputs).reduce((n, o) => n + o.bytes, 0);
console.log(`viewer: dist/viewer.js (${(bytes / 1024).toFixed(0)} KiB)`);
