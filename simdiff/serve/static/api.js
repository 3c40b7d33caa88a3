// The viewer's JSON API (see simdiff/serve/server.py). Every call resolves to the decoded answer
// or rejects with an Error whose message is the server's one-line explanation.

async function request(url, options = {}) {
  let response;
  try {
    response = await fetch(url, options);
  } catch (err) {
    throw new Error("cannot reach the server: is `simdiff serve` still running?");
  }
  let body = null;
  try {
    body = await response.json();
  } catch (err) {
    throw new Error(`${response.status} ${response.statusText}: the server did not answer JSON`);
  }
  if (!response.ok) throw new Error(body && body.error ? body.error : `${response.status} ${response.statusText}`);
  return body;
}

const post = (url, body) => request(url, {
  method: "POST",
  headers: { "Content-Type": "application/json" },
  body: JSON.stringify(body),
});

let uploadLimit = Infinity;  // bytes; from /api/info: a larger file is refused here, before it is sent

export const api = {
  /** Model status, listed files, slider limits, defaults, skeleton. */
  info: async () => {
    const info = await request("/api/info");
    uploadLimit = info.limits.upload_bytes ?? Infinity;
    return info;
  },

  /** Generate one motion: {text, gravity, wind_x, wind_y, seconds, seed, simulate, alpha, env_guidance, guidance,
   *  foot_lock, pin_start?, pin_end?} → {joints, fps, parents, meta, motion, body}. */
  generate: (params) => post("/api/generate", params),

  /** Re-play a motion shown (its answer's `motion` number) under φ: {source, gravity, wind_x, wind_y, seed, ...} → same. */
  edit: (params) => post("/api/edit", params),

  /** One motion through a timeline: {segments: [{text, seconds, gravity?, wind?: [x, y]}], seed, ...} → same. */
  timeline: (params) => post("/api/timeline", params),

  /** Upload a motion file (.npy joints or features, .bvh, DeepMimic) → same shape as generate. */
  open: (file) => file.size > uploadLimit
    ? Promise.reject(new Error(`${file.name}: ${file.size} bytes is over the server's ${uploadLimit}-byte upload limit`))
    : request(`/api/open?name=${encodeURIComponent(file.name)}`, {
      method: "POST",
      headers: { "Content-Type": "application/octet-stream" },
      body: file,
    }),

  /** The index-th file named on the command line. */
  openListed: (index) => request(`/api/files/${index}`),

  /** The skinned body of an answer (its `body` address) → the .glb file's bytes (ArrayBuffer). */
  body: async (url) => {
    let response;
    try {
      response = await fetch(url);
    } catch (err) {
      throw new Error("cannot reach the server: is `simdiff serve` still running?");
    }
    if (response.ok) return response.arrayBuffer();
    let message = `${response.status} ${response.statusText}`;
    try { message = (await response.json()).error || message; } catch (err) { /* not JSON: keep the status */ }
    throw new Error(message);
  },
};
