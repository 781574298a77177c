// Google's Draco decoder (npm's draco3d, its WebAssembly build) for glTF's
// KHR_draco_mesh_compression in the page: kit-web's loader calls it through Module.kitDraco
// (common/scene/draco_mesh_web.cpp), where the desktop's calls libdraco (draco_mesh.cpp), so the
// loader's checks of a decoded mesh are the same. Bundled apart, as kit-draco.js beside
// kit-draco-decoder.wasm, and loaded at the first model that needs it (models.js): a first
// visit does not wait for them.
import createDecoderModule from "draco3d/draco_decoder_nodejs.js";

// glTF's componentType and bytes per component by Draco's data type; 0 for one glTF has no
// accessor for (as draco_mesh.cpp's gltf_component_type).
function gltfType(draco, type) {
  const types = [[draco.DT_INT8, 5120, 1], [draco.DT_UINT8, 5121, 1], [draco.DT_INT16, 5122, 2],
                 [draco.DT_UINT16, 5123, 2], [draco.DT_UINT32, 5125, 4], [draco.DT_FLOAT32, 5126, 4]];
  const found = types.find(([t]) => t === type);
  return found ? {componentType: found[1], size: found[2], dracoType: type} : {componentType: 0, size: 0, dracoType: type};
}

// The decoder's calls as kit-web makes them: a mesh decoded from bytes is a handle (0: it is
// no Draco mesh, lastError says why); its attributes and triangles are read by handle.
function decoderCalls(draco) {
  const meshes = new Map();
  let next = 1;
  // A decoded mesh's attribute by unique id with what kit-web asks of it, or null (lastError).
  function attributeOf(handle, id) {
    const {decoder, mesh} = meshes.get(handle);
    const attribute = decoder.GetAttributeByUniqueId(mesh, id);
    if (!attribute || attribute.ptr === 0) {
      calls.lastError = `the Draco mesh has no attribute with unique id ${id}`;
      return null;
    }
    const type = gltfType(draco, attribute.data_type());
    const info = {...type, components: attribute.num_components(),
                  byteLength: mesh.num_points() * attribute.num_components() * type.size};
    return {decoder, mesh, attribute, info};
  }
  const calls = {
    lastError: "",
    decode(bytes) {
      const decoder = new draco.Decoder();
      const mesh = new draco.Mesh();
      try {
        const status = decoder.DecodeArrayToMesh(new Int8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength),
                                                 bytes.byteLength, mesh);
        if (!status.ok() || mesh.ptr === 0) {
          calls.lastError = status.error_msg() || "it decoded to nothing";
          draco.destroy(mesh);
          draco.destroy(decoder);
          return 0;
        }
        meshes.set(next, {decoder, mesh});
        return next++;
      } catch (e) {
        calls.lastError = String(e && e.message ? e.message : e);
        draco.destroy(mesh);
        draco.destroy(decoder);
        return 0;
      }
    },
    points: (handle) => meshes.get(handle).mesh.num_points(),
    // {componentType, components, byteLength} of the attribute with that unique id, or null
    // (lastError says why: kit-web's message names the attribute).
    attributeInfo(handle, id) {
      const found = attributeOf(handle, id);
      return found && found.info;
    },
    // The attribute's values for every point, in its own type (dequantized, as libdraco's
    // decoder gives them by default), tightly packed.
    attributeBytes(handle, id) {
      const found = attributeOf(handle, id);
      if (!found || !found.info.componentType) return null;
      const {decoder, mesh, attribute, info} = found;
      const at = draco._malloc(info.byteLength);
      try {
        if (!decoder.GetAttributeDataArrayForAllPoints(mesh, attribute, info.dracoType, info.byteLength, at)) return null;
        return new Uint8Array(draco.HEAPU8.buffer, at, info.byteLength).slice();
      } finally {
        draco._free(at);
      }
    },
    // The triangles' corners, three point indices a face.
    triangles(handle) {
      const {decoder, mesh} = meshes.get(handle);
      const count = mesh.num_faces() * 3;
      const at = draco._malloc(count * 4);
      try {
        decoder.GetTrianglesUInt32Array(mesh, count * 4, at);
        return new Uint32Array(draco.HEAPU8.buffer, at, count).slice();
      } finally {
        draco._free(at);
      }
    },
    free(handle) {
      const found = meshes.get(handle);
      if (!found) return;
      draco.destroy(found.mesh);
      draco.destroy(found.decoder);
      meshes.delete(handle);
    },
  };
  return calls;
}

// The decoder made from the WebAssembly file at `wasmUrl` (the site's kit-draco-decoder.wasm).
window.kitCreateDraco = async (wasmUrl) => {
  const response = await fetch(wasmUrl);
  if (!response.ok) throw new Error(`${wasmUrl}: ${response.status} ${response.statusText}`);
  const draco = await createDecoderModule({wasmBinary: await response.arrayBuffer()});
  return decoderCalls(draco);
};
