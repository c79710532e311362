// Signed GET URLs for effectd (--url-signing-key-file; docs/serving.md, "Facing the internet"),
// for a game's back end that hands URLs to its clients: the key never leaves that back end.
// Web Crypto only, so it runs in Node (pass require('node:crypto').webcrypto.subtle on Node 18)
// and in workers alike; it does not import three.
//
//   const url = await signedUrl('/v1/render', scene, key, { expires: Date.now() / 1000 + 3600 });
//   img.src = `https://effects.example${url}`;

const base64url = (bytes) => {
  let s = '';
  for (const b of new Uint8Array(bytes)) s += String.fromCharCode(b);
  return btoa(s).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
};

// The path and query of `body` POSTed to `path` as a GET, signed with `key` (a string), valid
// until `expires` (Unix seconds) when given.
export async function signedUrl(path, body, key, { expires, subtle = globalThis.crypto?.subtle } = {}) {
  if (!subtle) throw new Error('signedUrl needs Web Crypto: pass { subtle } (Node 18: require("node:crypto").webcrypto.subtle)');
  let target = `${path}?r=${base64url(new TextEncoder().encode(JSON.stringify(body)))}`;
  if (expires !== undefined) target += `&exp=${Math.floor(expires)}`;
  const hmac = await subtle.importKey('raw', new TextEncoder().encode(key), { name: 'HMAC', hash: 'SHA-256' }, false, ['sign']);
  const sig = await subtle.sign('HMAC', hmac, new TextEncoder().encode(target));
  return `${target}&sig=${base64url(sig)}`;
}
