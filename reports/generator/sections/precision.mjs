// Work-precision per Gedanken experiment, against the closed form: for each experiment one
// log–log diagram (its own error measure against the wall time per simulated second, one curve per
// engine-variant and knob, the tolerance as a dashed line) and one table; before them the table "cost to reach
// the experiment's tolerance" per engine-variant, or "never" with the floor the error stalls at and why.
import { esc, num, errText, table } from '../lib/html.mjs';
import { logLogLine, logLogOption } from '../lib/charts.mjs';
import { costProtocolText } from '../lib/precision.mjs';

const KIND_TEXT = { law: 'law (every engine judged)', model_prediction: 'prediction of the soft model' };

function settingText(c) {
  return c.setting === 'tol' ? 'tol' : c.setting === 'step' ? 'step (s)' : '';
}

// The cell of one (experiment, curve) in the cost table: HTML and a one-line text for the CSV and the title.
export function costCell(e, c) {
  if (!c) return { html: '—', cls: 'n muted', title: 'not run', text: '' };
  const t = c.to_tolerance;
  if (t.kind === 'not_built') return { html: 'not built', cls: 'n muted', title: c.points[0].note, text: 'not built' };
  if (!c.judged) {
    const reach = t.kind === 'never' ? 'never reaches it' : `reaches it at ${num(t.wall_per_sim_second)} s/s`;
    return { html: 'n/a', cls: 'n muted', title: `not applicable: ${e.not_applicable_reason || 'a prediction of the soft model'} (measured anyway: ${reach})`,
      text: 'not applicable' };
  }
  if (t.kind === 'never') {
    const why = c.never.why === 'stalls' ? 'stalls' : c.never.why === 'still_falling' ? 'still falling' : 'no result';
    return { html: `never <span class="muted">(${c.floor === null ? why : `floor ${errText(c.floor, e.relative)}, ${why}`})</span>`, cls: 'n bad',
      title: c.never.text, text: `never: ${c.never.text}` };
  }
  const atMost = t.kind === 'at_most';
  return { html: (atMost ? '≤ ' : '') + num(t.wall_per_sim_second), cls: 'n',
    title: atMost ? `within the tolerance from ${settingText(c)} ${num(t.setting_value)}: the loosest setting, or the one before gave no answer` : 'interpolated log–log between the settings on either side',
    text: `${atMost ? '<= ' : ''}${t.wall_per_sim_second}` };
}

// "tol 0.01 … 1e-10", "step 0.0167 … 6.25e-5 s"
function knobText(c) {
  if (!c.setting) return '—';
  const a = num(c.points[0].value), b = num(c.points[c.points.length - 1].value);
  return `${c.setting} ${a} … ${b}${c.setting === 'step' ? ' s' : c.setting === 'iterations' ? ' (step 1 ms)' : ''}`;
}

// The points of a curve that the diagram cannot show, in one phrase: "error 0 at every setting", or each one.
function undrawnText(c) {
  const missing = c.points.filter((p) => !drawable(p));
  if (!missing.length) return '';
  const zero = missing.filter((p) => p.status === 'ok');
  if (zero.length === c.points.length) return `${c.label}: error 0 at every setting`;
  return `${c.label} ` + missing.map((p) => `${c.setting}=${num(p.value)}: ${p.status === 'ok' ? `error ${num(p.error)}` :
    `${p.status.replace('_', ' ')}${p.note ? ` (${p.note})` : ''}`}`).join(', ');
}

function drawable(p) {
  return p.status === 'ok' && Number.isFinite(p.error) && p.error > 0 && Number.isFinite(p.wall_per_sim_second) && p.wall_per_sim_second > 0;
}

export default {
  id: 'precision',
  title: 'Work-precision against the closed form',
  inputs: ['precision.csv'],
  build(ctx) {
    const pr = ctx.precision;
    if (!pr) return null;
    const labels = pr.curves;
    let html = '<p>Each Gedanken experiment with a closed form, run at every setting of each engine’s accuracy knob (soft: ' +
      'tolerance of the default implicit stepper (step doubling switching to ROS34PW2 where contacts rest), of the adaptive RK4 (step doubling alone) and of the embedded RK4(3) pair, the step of fixed-step RK4; ODE and Bullet: the time step, native and matched). The error is the ' +
      'experiment’s own measure against its closed form — the same number the PASS/FAIL matrix judges — and the cost the wall time per ' +
      `simulated second (${esc(costProtocolText(pr.timing))}). Read a diagram from the right: a curve that falls below the dashed tolerance line reaches ` +
      'the answer, and how far left it does so is what it costs; a curve that flattens above the line has an error floor that a finer ' +
      'setting does not remove — the engine’s model or solver differs from the closed form, not its step.</p>';
    html += '<h3>Cost to reach each experiment’s tolerance (wall s per simulated s)</h3>';
    const rows = pr.experiments.map((e) => [
      `<a href="#precision-${esc(ctx.slug(e.experiment))}">${esc(e.experiment)}</a>${e.input ? ` <span class="muted">${esc(e.input)}</span>` : ''}`,
      { html: e.kind === 'law' ? 'law' : 'model', cls: 'muted', title: KIND_TEXT[e.kind] },
      { html: errText(e.tolerance, e.relative), cls: 'n' },
      ...labels.map((label) => {
        const c = costCell(e, e.curves.find((x) => x.label === label));
        return { html: c.html, cls: c.cls, title: c.title };
      }),
    ]);
    html += table(['experiment', 'kind', 'tolerance', ...labels.map(esc)], rows, 'precision-cost');
    html += '<p class="legend">Bullet has two knobs: its step, and its solver’s iterations at the default 1 ms step (ODE’s ' +
      'dWorldStep solves its LCP exactly: no iterations). The cost is where the curve reaches the tolerance and stays: the first setting within it whose next finer ' +
      'setting is within it too (one setting within it between two outside is luck, not accuracy), interpolated log–log with the setting before it; ' +
      '“≤”: the loosest setting already reaches it, or the one before gave no answer (a failed run, a measure that found nothing). “never”: no setting reaches it; the floor is the smallest error any setting gave, “stalls” when the two ' +
      'finest settings differ by less than 30 % (refining does not help), “still falling” when they do not. “n/a”: a prediction of the soft model ' +
      'that this variant does not have (measured anyway: hover).</p>';
    html += '<div class="charts multi wide">';
    for (const e of pr.experiments) {
      const series = e.curves.filter((c) => c.to_tolerance.kind !== 'not_built').map((c) => logLogLine(`${c.label}${c.judged ? '' : ' (n/a)'}`,
        ctx.color(c.ev), c.points.filter(drawable).map((p) => [p.wall_per_sim_second, p.error, `${c.setting}=${p.value}`]),
        !c.judged ? 'dotted' : c.setting === 'iterations' ? 'dashed' : 'solid'));
      html += `<div class="chartbox" id="precision-${esc(ctx.slug(e.experiment))}"><h3>${esc(e.experiment)}${e.input ? ` <span class="muted">${esc(e.input)}</span>` : ''}</h3>`;
      html += `<p class="muted">${esc(e.title)} — ${esc(e.quantity)}${e.unit ? ` (${esc(e.unit)})` : ''}, expected ${num(e.expected, 6)}, ` +
        `${e.relative ? 'relative ' : ''}error against it; ${esc(KIND_TEXT[e.kind])}</p>`;
      html += ctx.chart(logLogOption({ xName: 'wall time per simulated second (s/s)', series,
        yName: e.relative ? 'relative error' : `error${e.unit ? ` (${e.unit})` : ''}`,
        guide: { value: e.tolerance, label: `tolerance ${errText(e.tolerance, e.relative)}` } }), { height: 340 });
      html += table(['engine variant', 'knob', 'cost to tolerance (s/s)', 'error, loosest', 'error, finest', 'smallest error'],
        e.curves.map((c) => {
          const ok = c.points.filter((p) => p.status === 'ok');
          const cell = costCell(e, c);
          return [esc(c.label), { html: esc(knobText(c)), cls: 'nowrap' },
            { html: cell.html, cls: cell.cls, title: cell.title },
            { html: ok.length ? errText(ok[0].error, e.relative) : '—', cls: 'n' },
            { html: ok.length ? errText(ok[ok.length - 1].error, e.relative) : '—', cls: 'n' },
            { html: c.floor === null ? '—' : errText(c.floor, e.relative), cls: 'n' }];
        }), 'precision-curves');
      const undrawn = e.curves.filter((c) => c.to_tolerance.kind !== 'not_built').map((c) => undrawnText(c)).filter(Boolean);
      if (undrawn.length) html += `<p class="muted">Not drawn (an error of 0 or no result cannot be placed on a log axis): ${esc(undrawn.join('; '))}.</p>`;
      html += '</div>';
    }
    html += '</div>';
    return {
      html,
      data: pr,
      csv: [{ name: 'precision', header: ['experiment', 'kind', 'input', 'tolerance', 'relative', 'engine', 'variant', 'setting', 'judged',
        'to_tolerance', 'wall_per_sim_second', 'smallest_error', 'never_reason'],
      rows: pr.experiments.flatMap((e) => e.curves.map((c) => [e.experiment, e.kind, e.input, e.tolerance, e.relative, c.engine, c.variant,
        c.setting, c.judged, c.to_tolerance.kind, c.to_tolerance.wall_per_sim_second, c.floor, c.never ? c.never.why : ''])) }],
    };
  },
};
