// polydyn viewer: mounts every replay element (section.pd-replay) of the page that polydyn view wrote.
//
// A page with one replay (data-standalone) opens it at once, filling the window. A report with several
// opens each on a click, and keeps at most MAX_OPEN open (each holds a WebGL context).
//
// window.pdViewer is the hook for scripts (the movie maker, the browser test):
//   pdViewer.ready          Promise of the standalone replay, resolved after its first frame
//   pdViewer.main           that Replay (see replay.js: setTime, play, pause, bodyMatrix, runs, ...)
//   pdViewer.replays        every open Replay by id
//   pdViewer.open(id)       opens a replay of a report; a Promise of it
//   pdViewer.setTime(t)     the main replay at time t, drawn before it returns
//   pdViewer.loadMs         ms from navigation start to the main replay's first frame
//   pdViewer.main.timings   ms: start (document parsed), decode (base64 → arrays), build (geometry, UI)
//
// window.PolydynViewer is the report's hook (reports/generator/README.md, "Replay hook"):
//   PolydynViewer.mount(element, { run, summary, trajectory, contacts })
//                           builds one replay in element from a run directory's files (summary.json
//                           parsed, the CSV texts) and returns it; on bad input, null (the error is shown in element)
//   PolydynViewer.mount(element, { title, runs: [{ run, summary, trajectory, contacts }, ...] })
//                           several runs of one scene in one replay: the first solid, the others overlaid
//                           (as polydyn view DIR DIR...), e.g. a recorded cube toss and each engine's run
import css from './style.css';
import { readReplay, readRunFiles } from './data.js';
import { Replay } from './replay.js';

const MAX_OPEN = 6;
const MOUNT_HEIGHT = 600;  // px, of a replay PolydynViewer.mount builds
const opened = [];
const api = {
  version: 1,
  replays: {},
  main: null,
  loadMs: null,
  open,
  setTime(t) {
    api.main.setTime(t);
    api.main.renderNow();
    return api.main.t;
  },
};
let resolveReady, rejectReady;
api.ready = new Promise((res, rej) => { resolveReady = res; rejectReady = rej; });
window.pdViewer = api;

const pending = {};
function open(id) {
  if (api.replays[id]) return Promise.resolve(api.replays[id]);
  pending[id] ??= mount(id).finally(() => { delete pending[id]; });
  return pending[id];
}

async function mount(id) {
  const section = document.getElementById(`pd-replay-${id}`);
  const t0 = performance.now();
  const data = await readReplay(id);
  const t1 = performance.now();
  const holder = section.querySelector('.pdv-holder') || section;
  section.querySelector('.pdv-open')?.remove();
  const replay = new Replay(holder, data);
  replay.timings = { start: t0, decode: t1 - t0, build: performance.now() - t1 };
  api.replays[id] = replay;
  opened.push(id);
  while (opened.length > MAX_OPEN) close(opened[0]);
  return replay;
}

function close(id) {
  const replay = api.replays[id];
  if (!replay) return;
  replay.dispose();
  delete api.replays[id];
  opened.splice(opened.indexOf(id), 1);
  addOpenButton(document.getElementById(`pd-replay-${id}`), id);
}

function addOpenButton(section, id) {
  const meta = JSON.parse(document.getElementById(`pd-replay-${id}-meta`).textContent);
  const r = meta.runs[0];
  const engines = meta.runs.map((x) => x.engine).join(', ');
  const button = document.createElement('button');
  button.className = 'pdv-open';
  button.textContent = `▶ Open the 3-D replay (${r.bodies.length} bodies, ${r.samples} samples; ${engines})`;
  button.addEventListener('click', () => {
    button.disabled = true;
    open(id).catch((e) => showError(section, e));
  });
  section.append(button);
}

function showError(section, e) {
  const p = document.createElement('p');
  p.className = 'pdv-error';
  p.textContent = `The replay cannot be shown: ${e.message}`;
  section.append(p);
}

let styled = false;
function addStyle() {
  if (styled) return;
  styled = true;
  const style = document.createElement('style');
  style.textContent = css;
  document.head.append(style);
}

window.PolydynViewer = {
  version: 1,
  mount(element, files) {
    addStyle();
    try {
      const t0 = performance.now();
      const data = readRunFiles(files);
      const t1 = performance.now();
      // the replay's own height (as in a report of polydyn view), whatever the element's
      const holder = document.createElement('div');
      holder.className = 'pdv-holder';
      holder.style.height = `${MOUNT_HEIGHT}px`;
      element.style.height = 'auto';
      element.append(holder);
      const replay = new Replay(holder, data);
      replay.timings = { start: t0, decode: t1 - t0, build: performance.now() - t1 };
      return replay;
    } catch (e) {
      showError(element, e);
      return null;
    }
  },
};

function start() {
  addStyle();
  let standalone = false;
  for (const section of document.querySelectorAll('section.pd-replay')) {
    const id = section.id.replace(/^pd-replay-/, '');
    const holder = document.createElement('div');
    holder.className = 'pdv-holder';
    section.append(holder);
    if (section.dataset.standalone) {
      standalone = true;
      document.body.classList.add('pdv-standalone');
      open(id).then((replay) => {
        api.main = replay;
        replay.renderNow();
        requestAnimationFrame(() => {
          api.loadMs = performance.now();
          resolveReady(replay);
        });
      }).catch((e) => {
        showError(section, e);
        rejectReady(e);
      });
    } else {
      addOpenButton(section, id);
    }
  }
  if (!standalone) resolveReady(null);
}

if (document.readyState === 'loading') document.addEventListener('DOMContentLoaded', start);
else start();
