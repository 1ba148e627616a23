// Bundles three.js and viewer/src into one browser script for tools/html_report.cpp to embed.
// Usage: node build.mjs OUTFILE   (run by the CMake build; scripts/setup.sh installs esbuild)
import { build } from 'esbuild';
import { readFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const outfile = process.argv[2];
if (!outfile) {
  console.error('usage: node build.mjs OUTFILE');
  process.exit(2);
}

await build({
  entryPoints: [join(here, 'src', 'main.js')],
  bundle: true,
  format: 'iife',
  target: 'es2020',
  minify: true,
  legalComments: 'eof',  // keeps three.js's MIT licence notice in the report
  charset: 'utf8',
  outfile,
  logLevel: 'warning',
});

// The script is inlined into a <script> element: a literal "</script" in it would end the element.
const text = readFileSync(outfile, 'utf8');
if (/<\/script/i.test(text)) {
  console.error(`${outfile}: the bundle contains "</script"; it cannot be inlined into the HTML report`);
  process.exit(1);
}
