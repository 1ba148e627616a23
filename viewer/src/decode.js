// Decoding of the base64 geometry arrays that tools/html_report.cpp writes (little-endian).

// Returns the bytes of a base64 string in a fresh ArrayBuffer (offset 0, so typed views align).
export function decodeBase64(text) {
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

// Typed arrays assume the platform's byte order; every browser that runs WebGL is little-endian
// in practice, but a big-endian one would show garbage, so refuse it clearly instead.
export function assertLittleEndian() {
  if (new Uint8Array(new Uint16Array([1]).buffer)[0] !== 1)
    throw new Error('this viewer needs a little-endian platform');
}

export function decodeFloat32(text) {
  return new Float32Array(decodeBase64(text).buffer);
}

export function decodeIndices(text, bytesPerIndex) {
  const bytes = decodeBase64(text);
  return bytesPerIndex === 2 ? new Uint16Array(bytes.buffer) : new Uint32Array(bytes.buffer);
}
