// Sharing a run as a link: the scenario and its seed in the page's URL.
//
// Two forms, both in the URL's fragment (after `#`, so the static server
// never sees them and a long scenario costs no request):
//
//   #preset=thesis&seed=7[&duration=150]
//       an unedited preset with its seed (and its duration when it was
//       changed): short, and it follows later fixes of the preset file;
//   #z=<base64url of the deflated scenario JSON>[&from=thesis]
//   #s=<base64url of the scenario JSON>[&from=thesis]
//       any scenario, whole (its seed is inside). `z` is used where the
//       browser can compress (CompressionStream), `s` otherwise; both are
//       read. `from` names the preset the scenario was edited from, so
//       "Reset to preset" still works for whoever opens the link.
//
// Opening such a link restores exactly that scenario and seed. The query
// form `?preset=thesis&seed=7` is read too, for links typed by hand.
//
// Everything here is a pure function of its arguments (no DOM), so the
// page and its tests share it.

/** Preset names are file names in scenarios/: keep them to safe characters. */
const PRESET_NAME = /^[a-z0-9_-]{1,40}$/i;

/** Base64url (RFC 4648 §5, no padding) of bytes. */
export function toBase64Url(bytes) {
  let bin = '';
  for (let i = 0; i < bytes.length; i += 0x8000) bin += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(bin).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
}

/** Bytes of a base64url string (padding optional); throws on bad input. */
export function fromBase64Url(text) {
  const b64 = text.replace(/-/g, '+').replace(/_/g, '/');
  const bin = atob(b64 + '='.repeat((4 - (b64.length % 4)) % 4));
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

const canCompress = () => typeof CompressionStream === 'function' && typeof DecompressionStream === 'function';

async function pipe(bytes, stream) {
  const out = new Response(new Blob([bytes]).stream().pipeThrough(stream));
  return new Uint8Array(await out.arrayBuffer());
}

/**
 * The fragment (without `#`) that restores `scenario`.
 *
 * @param {object} scenario the scenario object (as the page holds it)
 * @param {{preset?: string, presetDuration?: number, origin?: string}} from
 *   `preset`: the preset the scenario still is (only its seed or duration
 *   changed), '' once edited; `presetDuration`: that preset's own duration;
 *   `origin`: the preset it was edited from, if any.
 * @returns {Promise<string>}
 */
export async function encodeShare(scenario, { preset = '', presetDuration, origin = '' } = {}) {
  if (preset && PRESET_NAME.test(preset)) {
    const p = new URLSearchParams({ preset, seed: String(scenario.seed) });
    if (presetDuration === undefined || scenario.duration_s !== presetDuration) p.set('duration', String(scenario.duration_s));
    return p.toString();
  }
  const bytes = new TextEncoder().encode(JSON.stringify(scenario));
  const p = new URLSearchParams();
  if (canCompress()) p.set('z', toBase64Url(await pipe(bytes, new CompressionStream('deflate-raw'))));
  else p.set('s', toBase64Url(bytes));
  if (origin && PRESET_NAME.test(origin)) p.set('from', origin);
  return p.toString();
}

/**
 * What a URL's fragment (or query) asks for, or null when it holds no
 * shared run. Throws, saying what is wrong, on a malformed link.
 *
 * @param {string} hash `location.hash` (with or without `#`)
 * @param {string} [search] `location.search`, read when the hash has nothing
 * @returns {Promise<null | {kind: 'preset', preset: string, seed: number|null, duration: number|null}
 *                         | {kind: 'scenario', text: string, origin: string}>}
 */
export async function decodeShare(hash, search = '') {
  let p = new URLSearchParams(hash.replace(/^#/, ''));
  if (!['preset', 's', 'z'].some((k) => p.has(k))) p = new URLSearchParams(search.replace(/^\?/, ''));
  const number = (key) => {
    if (!p.has(key)) return null;
    const v = Number(p.get(key));
    if (p.get(key).trim() === '' || !Number.isFinite(v)) throw new Error(`the link's ${key} “${p.get(key)}” is not a number`);
    return v;
  };
  if (p.has('preset')) {
    const preset = p.get('preset');
    if (!PRESET_NAME.test(preset)) throw new Error(`the link names no preset we know (“${preset}”)`);
    return { kind: 'preset', preset, seed: number('seed'), duration: number('duration') };
  }
  const origin = PRESET_NAME.test(p.get('from') ?? '') ? p.get('from') : '';
  if (p.has('z')) {
    if (!canCompress()) throw new Error('this browser cannot read a compressed link (no DecompressionStream)');
    let bytes;
    try {
      bytes = await pipe(fromBase64Url(p.get('z')), new DecompressionStream('deflate-raw'));
    } catch {
      throw new Error('the link is damaged (its scenario does not decompress); was it cut short?');
    }
    return { kind: 'scenario', text: new TextDecoder().decode(bytes), origin };
  }
  if (p.has('s')) {
    let bytes;
    try {
      bytes = fromBase64Url(p.get('s'));
    } catch {
      throw new Error('the link is damaged (its scenario is not base64url)');
    }
    return { kind: 'scenario', text: new TextDecoder().decode(bytes), origin };
  }
  return null;
}
