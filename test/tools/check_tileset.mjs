// Checks a 3D Tiles tile set on disk against the rules of OGC 3D Tiles 1.1 that a streaming
// viewer relies on, and runs the Khronos glTF validator on every GLB content. Prints one JSON
// line: {"tiles","contents","content_bytes","gltf_validated","errors":[first 50],"error_count",
// "warnings":[first 50],"warning_count"}.
// Exit status: 0 without errors, 1 with errors, 77 when the glTF validator is not installed
// (`npm install` in this folder) and --no-gltf was not given.
//
// Usage: node check_tileset.mjs DIR/tileset.json [--no-gltf]
//
// The rules, each from the 3D Tiles 1.1 specification (tileset.schema.json, tile.schema.json,
// boundingVolume.schema.json, content.schema.json and the section "Bounding volumes"):
// - the tileset has `asset.version` (a string; "1.0" and "1.1" are known), a `geometricError`
//   >= 0 and a `root`; `extensionsRequired` are all in `extensionsUsed`;
// - every tile has exactly one bounding volume (a box of 12, a region of 6 or a sphere of 4
//   finite numbers; a sphere's radius >= 0), a `geometricError` >= 0 and not above its
//   parent's, `refine` of "ADD" or "REPLACE" (required at the root), a `transform` of 16 finite
//   numbers where given, not both `content` and `contents`, and `children` with at least one
//   tile where given;
// - every content has a `uri` that names an existing file beside the tileset; a GLB content
//   has glTF 2's binary header and passes the Khronos validator; an external tileset
//   (`.json`) is checked in turn;
// - where the tile and its parent are untransformed boxes along the axes (what featsense
//   writes), the child's box lies inside its parent's and the content's positions (glTF's
//   Y up turned to the tiles' Z up, node translations applied) inside the tile's box: a viewer
//   that culls by the box would otherwise drop visible geometry. The rule is a "should" in the
//   specification; its breaches are errors here because they make tiles vanish.
import { existsSync, readFileSync, statSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';

const SKIP = 77;
const MAX_LISTED = 50;
const TOLERANCE_M = 1e-3;

const args = process.argv.slice(2);
const tilesetPath = args.find((a) => !a.startsWith('--'));
const checkGltf = !args.includes('--no-gltf');
if (!tilesetPath) {
  console.error('usage: node check_tileset.mjs DIR/tileset.json [--no-gltf]');
  process.exit(2);
}

let validator = null;
if (checkGltf) {
  try {
    validator = (await import('gltf-validator')).default;
  } catch {
    console.error('gltf-validator is not installed (npm install in test/tools)');
    process.exit(SKIP);
  }
}

const errors = [];
const warnings = [];
const counts = { tiles: 0, contents: 0, content_bytes: 0, gltf_validated: 0 };
const error = (where, message) => errors.push(`${where}: ${message}`);
const warn = (where, message) => warnings.push(`${where}: ${message}`);
const isNumber = (v) => typeof v === 'number' && Number.isFinite(v);
const numbers = (v, n) => Array.isArray(v) && v.length === n && v.every(isNumber);

// An axis-aligned box {min, max} from a 3D Tiles box whose half-axes lie along x, y and z, or
// null for any other bounding volume.
function axisBox(volume) {
  const b = volume?.box;
  if (!numbers(b, 12)) return null;
  const offAxis = [b[4], b[5], b[6], b[8], b[9], b[10]];
  if (offAxis.some((v) => v !== 0)) return null;
  const half = [Math.abs(b[3]), Math.abs(b[7]), Math.abs(b[11])];
  return {
    min: [b[0] - half[0], b[1] - half[1], b[2] - half[2]],
    max: [b[0] + half[0], b[1] + half[1], b[2] + half[2]],
  };
}

const inside = (inner, outer) =>
  [0, 1, 2].every(
    (i) => inner.min[i] >= outer.min[i] - TOLERANCE_M && inner.max[i] <= outer.max[i] + TOLERANCE_M,
  );

function checkBoundingVolume(where, volume) {
  if (typeof volume !== 'object' || volume === null) {
    error(where, 'boundingVolume is missing');
    return;
  }
  const kinds = ['box', 'region', 'sphere'].filter((k) => k in volume);
  if (kinds.length !== 1) error(where, `boundingVolume needs exactly one of box, region, sphere`);
  if ('box' in volume && !numbers(volume.box, 12)) error(where, 'box is not 12 finite numbers');
  if ('region' in volume && !numbers(volume.region, 6))
    error(where, 'region is not 6 finite numbers');
  if ('sphere' in volume) {
    if (!numbers(volume.sphere, 4)) error(where, 'sphere is not 4 finite numbers');
    else if (volume.sphere[3] < 0) error(where, 'sphere radius < 0');
  }
}

// The GLB's JSON chunk, or null (with an error) when the header is not glTF 2's.
function glbJson(where, bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (bytes.length < 20 || view.getUint32(0, true) !== 0x46546c67) {
    error(where, 'not a GLB (magic "glTF" missing)');
    return null;
  }
  if (view.getUint32(4, true) !== 2) error(where, `GLB version ${view.getUint32(4, true)}, not 2`);
  if (view.getUint32(8, true) !== bytes.length)
    error(where, `GLB length ${view.getUint32(8, true)} but the file has ${bytes.length} bytes`);
  const jsonLength = view.getUint32(12, true);
  if (view.getUint32(16, true) !== 0x4e4f534a || 20 + jsonLength > bytes.length) {
    error(where, 'GLB without a JSON chunk first');
    return null;
  }
  return JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
}

// The box of the GLB's POSITION accessors' min/max, through each mesh node's translation and
// glTF's Y up turned to Z up ((x, y, z)_gltf -> (x, -z, y)); null where a node rotates or
// scales (then the check is skipped).
function contentBox(gltf) {
  let box = null;
  const visit = (nodeIndex, offset) => {
    const node = gltf.nodes?.[nodeIndex] ?? {};
    if (node.matrix || node.rotation || node.scale) return false;
    const t = node.translation ?? [0, 0, 0];
    const here = [offset[0] + t[0], offset[1] + t[1], offset[2] + t[2]];
    if (node.mesh !== undefined) {
      for (const primitive of gltf.meshes?.[node.mesh]?.primitives ?? []) {
        const accessor = gltf.accessors?.[primitive.attributes?.POSITION];
        if (!accessor || !numbers(accessor.min, 3) || !numbers(accessor.max, 3)) continue;
        const corners = [accessor.min, accessor.max].map((p) => [
          p[0] + here[0],
          -(p[2] + here[2]),
          p[1] + here[1],
        ]);
        const min = [0, 1, 2].map((i) => Math.min(corners[0][i], corners[1][i]));
        const max = [0, 1, 2].map((i) => Math.max(corners[0][i], corners[1][i]));
        box = box
          ? { min: box.min.map((v, i) => Math.min(v, min[i])), max: box.max.map((v, i) => Math.max(v, max[i])) }
          : { min, max };
      }
    }
    return (node.children ?? []).every((child) => visit(child, here));
  };
  const scene = gltf.scenes?.[gltf.scene ?? 0];
  const roots = scene?.nodes ?? [];
  return roots.every((n) => visit(n, [0, 0, 0])) ? box : null;
}

async function checkContent(where, content, tileBox, baseDir) {
  if (typeof content?.uri !== 'string' || content.uri === '') {
    error(where, 'content without a uri');
    return;
  }
  if (content.boundingVolume) checkBoundingVolume(`${where}/boundingVolume`, content.boundingVolume);
  const file = join(baseDir, decodeURIComponent(content.uri));
  if (!existsSync(file) || !statSync(file).isFile()) {
    error(where, `content ${content.uri} does not exist`);
    return;
  }
  ++counts.contents;
  counts.content_bytes += statSync(file).size;
  if (file.endsWith('.json')) {
    await checkTileset(file, `${where}(${content.uri})`);
    return;
  }
  if (!file.endsWith('.glb')) {
    warn(where, `content ${content.uri} is neither GLB nor an external tileset: not looked into`);
    return;
  }
  const bytes = new Uint8Array(readFileSync(file));
  const gltf = glbJson(`${where} ${content.uri}`, bytes);
  if (!gltf) return;
  if (tileBox) {
    const box = contentBox(gltf);
    if (box && !inside(box, tileBox))
      error(where, `${content.uri}'s positions reach outside the tile's box`);
  }
  if (validator) {
    const report = await validator.validateBytes(bytes, { uri: content.uri });
    ++counts.gltf_validated;
    for (const m of report.issues.messages.filter((m) => m.severity === 0))
      error(`${where} ${content.uri}`, `glTF ${m.code} ${m.pointer ?? ''} ${m.message}`);
  }
}

async function checkTile(where, tile, parent, baseDir) {
  ++counts.tiles;
  if (typeof tile !== 'object' || tile === null) {
    error(where, 'a tile is not an object');
    return;
  }
  checkBoundingVolume(`${where}/boundingVolume`, tile.boundingVolume);
  if (!isNumber(tile.geometricError) || tile.geometricError < 0)
    error(where, 'geometricError is missing or < 0');
  else if (parent && isNumber(parent.geometricError) && tile.geometricError > parent.geometricError)
    error(where, `geometricError ${tile.geometricError} above its parent's ${parent.geometricError}`);
  if (tile.refine !== undefined && tile.refine !== 'ADD' && tile.refine !== 'REPLACE')
    error(where, `refine is ${JSON.stringify(tile.refine)}, not ADD or REPLACE`);
  if (!parent && tile.refine === undefined) error(where, 'the root has no refine');
  if (tile.transform !== undefined && !numbers(tile.transform, 16))
    error(where, 'transform is not 16 finite numbers');
  const box = tile.transform === undefined ? axisBox(tile.boundingVolume) : null;
  if (box && parent?.box && !inside(box, parent.box))
    error(where, "the tile's box reaches outside its parent's");
  if (tile.content !== undefined && tile.contents !== undefined)
    error(where, 'both content and contents');
  const contents = tile.contents ?? (tile.content !== undefined ? [tile.content] : []);
  for (let i = 0; i < contents.length; ++i)
    await checkContent(`${where}/content${tile.contents ? `s/${i}` : ''}`, contents[i], box, baseDir);
  if (tile.children !== undefined) {
    if (!Array.isArray(tile.children) || tile.children.length === 0) {
      error(where, 'children is not an array of at least one tile');
      return;
    }
    const here = { geometricError: tile.geometricError, box };
    for (let i = 0; i < tile.children.length; ++i)
      await checkTile(`${where}/children/${i}`, tile.children[i], here, baseDir);
  }
}

async function checkTileset(path, where) {
  let tileset;
  try {
    tileset = JSON.parse(readFileSync(path, 'utf8'));
  } catch (e) {
    error(where, `cannot read ${path}: ${e.message}`);
    return;
  }
  const version = tileset.asset?.version;
  if (typeof version !== 'string') error(where, 'asset.version is missing');
  else if (version !== '1.0' && version !== '1.1') warn(where, `asset.version ${version} is unknown`);
  if (!isNumber(tileset.geometricError) || tileset.geometricError < 0)
    error(where, 'the tileset geometricError is missing or < 0');
  for (const name of tileset.extensionsRequired ?? [])
    if (!(tileset.extensionsUsed ?? []).includes(name))
      error(where, `extension ${name} is required but not in extensionsUsed`);
  if (typeof tileset.root !== 'object' || tileset.root === null) {
    error(where, 'no root tile');
    return;
  }
  // A root whose error is above the tileset's is refined before it is needed: legal, but odd.
  if (isNumber(tileset.geometricError) && tileset.root.geometricError > tileset.geometricError)
    warn(where, "the root's geometricError is above the tileset's");
  await checkTile(`${where}/root`, tileset.root, null, dirname(path));
}

await checkTileset(resolve(tilesetPath), 'tileset');
console.log(
  JSON.stringify({
    ...counts,
    errors: errors.slice(0, MAX_LISTED),
    error_count: errors.length,
    warnings: warnings.slice(0, MAX_LISTED),
    warning_count: warnings.length,
  }),
);
process.exit(errors.length > 0 ? 1 : 0);
