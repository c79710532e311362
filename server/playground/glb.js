// Reads the first primitive of a binary glTF 2.0 file (what /v1/tangents answers to a GLB):
// POSITION, NORMAL and TANGENT as floats, and the triangle indices (0..n-1 when it has none).
const COMPONENTS = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };
const TYPES = { 5120: Int8Array, 5121: Uint8Array, 5122: Int16Array, 5123: Uint16Array, 5125: Uint32Array, 5126: Float32Array };

export function readGlb(buffer) {
  const view = new DataView(buffer);
  if (buffer.byteLength < 20 || view.getUint32(0, true) !== 0x46546c67) throw new Error('not a binary glTF file');
  let offset = 12, gltf = null, bin = null;
  while (offset + 8 <= buffer.byteLength) {
    const length = view.getUint32(offset, true), type = view.getUint32(offset + 4, true);
    const chunk = new Uint8Array(buffer, offset + 8, length);
    if (type === 0x4e4f534a) gltf = JSON.parse(new TextDecoder().decode(chunk));
    else if (type === 0x004e4942) bin = chunk;
    offset += 8 + length;
  }
  if (!gltf || !gltf.meshes || !gltf.meshes.length) throw new Error('the glTF has no mesh');
  const accessor = (index) => {
    const a = gltf.accessors[index], v = gltf.bufferViews[a.bufferView];
    const Type = TYPES[a.componentType], n = COMPONENTS[a.type];
    const stride = v.byteStride || Type.BYTES_PER_ELEMENT * n;
    const start = bin.byteOffset + (v.byteOffset || 0) + (a.byteOffset || 0);
    const out = new Float32Array(a.count * n);
    const data = new DataView(bin.buffer);
    const get = { 5120: 'getInt8', 5121: 'getUint8', 5122: 'getInt16', 5123: 'getUint16', 5125: 'getUint32', 5126: 'getFloat32' }[a.componentType];
    for (let i = 0; i < a.count; ++i)
      for (let k = 0; k < n; ++k) out[i * n + k] = data[get](start + i * stride + k * Type.BYTES_PER_ELEMENT, true);
    return out;
  };
  const prim = gltf.meshes[0].primitives[0], at = prim.attributes;
  const positions = accessor(at.POSITION);
  return {
    positions,
    normals: at.NORMAL !== undefined ? accessor(at.NORMAL) : null,
    tangents: at.TANGENT !== undefined ? accessor(at.TANGENT) : null,
    indices: prim.indices !== undefined ? Uint32Array.from(accessor(prim.indices))
                                         : Uint32Array.from({ length: positions.length / 3 }, (_, i) => i),
  };
}
