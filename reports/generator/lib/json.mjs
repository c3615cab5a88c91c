// JSON reader that remembers the line each object and array starts on, so that a schema error can be
// reported as FILE:LINE. Values are what JSON.parse gives (strings and numbers are decoded by
// JSON.parse itself); lineOf(value) is the line of an object or array, 0 for anything else.
import { InputError } from './errors.mjs';

const lines = new WeakMap();

export function lineOf(value) {
  return (value && typeof value === 'object' && lines.get(value)) || 0;
}

const STRING = /"(?:[^"\\\u0000-\u001f]|\\(?:["\\/bfnrt]|u[0-9a-fA-F]{4}))*"/y;
const NUMBER = /-?(?:0|[1-9][0-9]*)(?:\.[0-9]+)?(?:[eE][+-]?[0-9]+)?/y;
const SPACE = /[ \t\n\r]*/y;

export function parseJson(text, file) {
  let i = 0;
  let line = 1;
  if (text.charCodeAt(0) === 0xfeff) i = 1;
  const fail = (message) => { throw new InputError(file, line, message); };
  const skip = () => {
    SPACE.lastIndex = i;
    const m = SPACE.exec(text);
    for (let k = i; k < i + m[0].length; ++k) if (text.charCodeAt(k) === 10) line++;
    i += m[0].length;
  };
  const token = (re, what) => {
    re.lastIndex = i;
    const m = re.exec(text);
    if (!m) fail(`malformed JSON: expected ${what}`);
    i += m[0].length;
    return m[0];
  };
  const value = (depth) => {
    if (depth > 200) fail('malformed JSON: nested too deeply');
    skip();
    const c = text[i];
    if (c === '{') {
      const obj = {};
      lines.set(obj, line);
      i++;
      skip();
      if (text[i] === '}') { i++; return obj; }
      for (;;) {
        skip();
        if (text[i] !== '"') fail('malformed JSON: expected a member name in double quotes');
        const key = JSON.parse(token(STRING, 'a string'));
        skip();
        if (text[i] !== ':') fail(`malformed JSON: expected ':' after "${key}"`);
        i++;
        if (Object.prototype.hasOwnProperty.call(obj, key)) fail(`duplicate member "${key}"`);
        Object.defineProperty(obj, key, { value: value(depth + 1), enumerable: true, writable: true, configurable: true });
        skip();
        if (text[i] === ',') { i++; continue; }
        if (text[i] === '}') { i++; return obj; }
        fail("malformed JSON: expected ',' or '}'");
      }
    }
    if (c === '[') {
      const arr = [];
      lines.set(arr, line);
      i++;
      skip();
      if (text[i] === ']') { i++; return arr; }
      for (;;) {
        arr.push(value(depth + 1));
        skip();
        if (text[i] === ',') { i++; continue; }
        if (text[i] === ']') { i++; return arr; }
        fail("malformed JSON: expected ',' or ']'");
      }
    }
    if (c === '"') return JSON.parse(token(STRING, 'a string (control characters must be escaped)'));
    if (c === '-' || (c >= '0' && c <= '9')) return Number(token(NUMBER, 'a number'));
    for (const [word, v] of [['true', true], ['false', false], ['null', null]])
      if (text.startsWith(word, i)) { i += word.length; return v; }
    fail(i >= text.length ? 'malformed JSON: unexpected end of file' : `malformed JSON: unexpected '${text[i]}'`);
  };
  const v = value(0);
  skip();
  if (i < text.length) fail('malformed JSON: text after the end of the value');
  return v;
}
