// Scene colours: a scene names a body's colour with any word (docs/scene-language.md): a CSS colour
// name (red, grey, steelblue), or hex digits without '#' (88aaff, 8af). Any other word gets a colour
// of its own, the same every time (a hue from the word's hash), so that it still tells bodies apart.
import * as THREE from 'three';

export function sceneColor(word) {
  const w = String(word).trim().toLowerCase();
  const c = new THREE.Color();
  if (/^[0-9a-f]{6}$/.test(w) || /^[0-9a-f]{3}$/.test(w)) return c.setStyle(`#${w}`);
  if (Object.prototype.hasOwnProperty.call(THREE.Color.NAMES, w)) return c.setColorName(w);
  let h = 2166136261;
  for (let i = 0; i < w.length; ++i) h = Math.imul(h ^ w.charCodeAt(i), 16777619) >>> 0;
  return c.setHSL((h % 360) / 360, 0.6, 0.55);
}

export function cssColor(color) { return `#${color.getHexString()}`; }
