// node draco_gltf.mjs NODE_MODULES OUT_DIR TEXTURE.png: writes OUT_DIR/sphere.gltf and
// sphere.bin, a textured sphere (positions, normals, texture coordinates) whose one primitive
// is held only in a KHR_draco_mesh_compression mesh, encoded by Google's Draco encoder (npm's
// draco3d, the same package as the page's decoder), and OUT_DIR/sphere-q10.gltf with its
// positions quantized to 10 bits. The material's base colour is TEXTURE.png, copied beside
// them. For tests/web_obj_test.py: kit-render decodes these with libdraco, the page with
// draco3d's WebAssembly decoder.
import {copyFileSync, mkdirSync, writeFileSync} from "node:fs";
import {createRequire} from "node:module";
import {join, resolve} from "node:path";

const [modules, out, texture] = process.argv.slice(2);
const require = createRequire(join(resolve(modules), "draco3d", "package.json"));
const createEncoderModule = require("./draco_encoder_nodejs.js");

// A UV sphere of radius 1: rings from the north pole, u around, v from the top.
function sphere(rings, segments) {
  const positions = [], normals = [], uvs = [], indices = [];
  for (let r = 0; r <= rings; ++r) {
    const theta = Math.PI * r / rings;
    for (let s = 0; s <= segments; ++s) {
      const phi = 2 * Math.PI * s / segments;
      const n = [Math.sin(theta) * Math.cos(phi), Math.cos(theta), -Math.sin(theta) * Math.sin(phi)];
      positions.push(...n);
      normals.push(...n);
      uvs.push(s / segments, r / rings);
    }
  }
  for (let r = 0; r < rings; ++r)
    for (let s = 0; s < segments; ++s) {
      const a = r * (segments + 1) + s, b = a + segments + 1;
      indices.push(a, b, a + 1, a + 1, b, b + 1);
    }
  return {positions: new Float32Array(positions), normals: new Float32Array(normals), uvs: new Float32Array(uvs),
          indices: new Uint32Array(indices)};
}

const mesh = sphere(24, 48);
const points = mesh.positions.length / 3;

function encode(draco, positionBits) {
  const builder = new draco.MeshBuilder();
  const dracoMesh = new draco.Mesh();
  builder.AddFacesToMesh(dracoMesh, mesh.indices.length / 3, mesh.indices);
  const ids = {
    POSITION: builder.AddFloatAttributeToMesh(dracoMesh, draco.POSITION, points, 3, mesh.positions),
    NORMAL: builder.AddFloatAttributeToMesh(dracoMesh, draco.NORMAL, points, 3, mesh.normals),
    TEXCOORD_0: builder.AddFloatAttributeToMesh(dracoMesh, draco.TEX_COORD, points, 2, mesh.uvs),
  };
  const encoder = new draco.Encoder();
  encoder.SetEncodingMethod(draco.MESH_SEQUENTIAL_ENCODING);
  // 0 bits: not quantized; the other attributes never are.
  encoder.SetAttributeQuantization(draco.POSITION, positionBits);
  encoder.SetAttributeQuantization(draco.NORMAL, 0);
  encoder.SetAttributeQuantization(draco.TEX_COORD, 0);
  const data = new draco.DracoInt8Array();
  const length = encoder.EncodeMeshToDracoBuffer(dracoMesh, data);
  if (length <= 0) throw new Error("the Draco encoder wrote nothing");
  const bytes = new Uint8Array(length);
  for (let i = 0; i < length; ++i) bytes[i] = data.GetValue(i) & 0xff;
  for (const o of [data, encoder, dracoMesh, builder]) draco.destroy(o);
  return {bytes, ids};
}

// No top-level await: node 12 (Ubuntu 22.04's) runs this too.
async function main() {
  const draco = await createEncoderModule({});
  mkdirSync(out, {recursive: true});
  copyFileSync(texture, join(out, "texture.png"));
  for (const [name, bits] of [["sphere", 0], ["sphere-q10", 10]]) writeModel(name, encode(draco, bits));
}

function writeModel(name, {bytes, ids}) {
  writeFileSync(join(out, `${name}.bin`), bytes);
  const accessor = (type, componentType, count, extra = {}) => ({type, componentType, count, ...extra});
  const gltf = {
    asset: {version: "2.0", generator: "tests/draco_gltf.mjs (draco3d)"},
    extensionsUsed: ["KHR_draco_mesh_compression"], extensionsRequired: ["KHR_draco_mesh_compression"],
    scene: 0, scenes: [{nodes: [0]}], nodes: [{mesh: 0}],
    meshes: [{primitives: [{
      attributes: {POSITION: 0, NORMAL: 1, TEXCOORD_0: 2}, indices: 3, material: 0,
      extensions: {KHR_draco_mesh_compression: {bufferView: 0, attributes: ids}},
    }]}],
    accessors: [accessor("VEC3", 5126, points, {min: [-1, -1, -1], max: [1, 1, 1]}), accessor("VEC3", 5126, points),
                accessor("VEC2", 5126, points), accessor("SCALAR", 5125, mesh.indices.length)],
    bufferViews: [{buffer: 0, byteOffset: 0, byteLength: bytes.length}],
    buffers: [{uri: `${name}.bin`, byteLength: bytes.length}],
    materials: [{pbrMetallicRoughness: {baseColorTexture: {index: 0}, metallicFactor: 0, roughnessFactor: 0.6}}],
    textures: [{source: 0}], images: [{uri: "texture.png"}],
  };
  writeFileSync(join(out, `${name}.gltf`), JSON.stringify(gltf, null, 1) + "\n");
}

main().catch((e) => {
  console.error(`draco_gltf.mjs: ${e.message || e}`);
  process.exit(1);
});
