// polydyn — the replay page generator: run directories in, one self-contained HTML file out.
//
// A page holds one copy of the viewer bundle (viewer/dist/viewer.js, three.js inside) and any number of
// replays. A replay shows one run or several runs of the same scene overlaid (e.g. soft, ODE, Bullet):
// the first run solid in the scene's colours, the others ghosted in a key colour each.
//
// What a run directory gives (docs/outputs.md): summary.json (bodies with name, colour, fixed, initial pose,
// mass, inertia and the polyhedron in the body frame — origin at the centre of mass, axes of the
// object's own frame), trajectory.csv (x = centre of mass, q maps the body frame to the world) and,
// optionally, contacts.csv. The geometry comes from summary.json: no scene file is read.
//
// Embedding in a report (the Gedanken report, `polydyn compare`): write the page's head, then one
// pd_view_write_replay per experiment wherever it belongs in the document, then pd_view_write_bundle
// once, anywhere (the bundle mounts every replay element when the document has loaded). Replays in a
// page with several of them open on a click, so a long report does not hold a WebGL context per replay.
//
// Data in the page: per run a JSON block (bodies, geometry, settings) and a base64 block of
// little-endian arrays: sample times and poses as float64 (exact: what the page draws at a sample time
// is the trajectory.csv value, to float32 GPU precision), velocities and contacts as float32. Not
// compressed: with zlib the 1000-body × 10 s page halved (108 → 55 MB) but opened slower (inflating
// 80 MB in the page took 2.1–2.8 s, more than the HTML parser saved; base64 alone decodes in 0.07 s).
#pragma once

#include <stdbool.h>
#include <stdio.h>

#include "polydyn/error.h"

typedef struct pdViewRun pdViewRun;

// Reads and checks a run directory. Returns NULL and fills err on bad input (a missing or malformed
// file: FILE:LINE:COL for a CSV, FILE: message for summary.json).
pdViewRun* pd_view_run_load(const char* dir, pdError* err);
void pd_view_run_free(pdViewRun* run);

// Simulated time range of the run's samples, s.
double pd_view_run_t_first(const pdViewRun* run);
double pd_view_run_t_last(const pdViewRun* run);

// True when `b` can be overlaid on `a`: the same bodies (names, order, fixed or moving). Otherwise
// fills err (file = b's directory) with what differs.
bool pd_view_runs_compatible(const pdViewRun* a, const pdViewRun* b, pdError* err);

// Path of the bundle: $POLYDYN_VIEWER_DIR/dist/viewer.js, else <source dir>/viewer/dist/viewer.js
// (compile definition PD_VIEWER_DIR). Static storage.
const char* pd_view_bundle_path(void);
// Directory of the viewer (the bundle's dist/ and scripts/ are in it). Static storage.
const char* pd_view_dir(void);

// Writes `<!doctype html>…<body>` with the page's style; `title` is escaped.
void pd_view_write_head(FILE* out, const char* title);
// Writes one replay element with its data. `id` names it within the page ([A-Za-z0-9_-], unique);
// `title` (nullable) is shown above it. `runs[0]` is drawn solid, the others ghosted; they must be
// pd_view_runs_compatible with runs[0]. `standalone` makes it fill the window and open at once.
bool pd_view_write_replay(FILE* out, const char* id, const char* title, pdViewRun* const* runs, int count,
                          bool standalone, pdError* err);
// Writes the bundle as one inline script element (once per page). False, with err, when the bundle
// cannot be read (not built: run scripts/setup).
bool pd_view_write_bundle(FILE* out, pdError* err);
// Writes `</body></html>`.
void pd_view_write_tail(FILE* out);

// The whole page for one replay, written to `path` atomically (a temporary name, then renamed).
bool pd_view_write_page(const char* path, const char* title, pdViewRun* const* runs, int count, pdError* err);
