// The sections of the report, in page order. A section is a module whose default export is
//   { id, title, inputs, build(ctx) }
// build returns null when its inputs are absent (the section then does not appear), or
//   { html, data, csv: [{name, header, rows}] }
// html goes into the page under the section's title, data into report.json under the section's id,
// each csv into report-NAME.csv beside the page. Charts are made with ctx.chart(echartsOption).
// To add a section, write sections/NAME.mjs and list it here.
import summary from './summary.mjs';
import against from './against.mjs';
import verdict from './verdict.mjs';
import precision from './precision.mjs';
import matrix from './matrix.mjs';
import restitution from './restitution.mjs';
import frictionCone from './friction_cone.mjs';
import workPrecision from './work_precision.mjs';
import cost from './cost.mjs';
import compare from './compare.mjs';
import differ from './differ.mjs';
import scenes from './scenes.mjs';
import experiments from './experiments.mjs';
import parameters from './parameters.mjs';
import cubetoss, { planarDrops } from './cubetoss.mjs';

export const sections = [differ, scenes, against, summary, verdict, matrix, restitution, frictionCone, precision, workPrecision, cost, compare, cubetoss, planarDrops, experiments, parameters];
