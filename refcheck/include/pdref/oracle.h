// polydyn refcheck — the interference oracle: our separating-axis test (engine/src/interference.h)
// against libccd's GJK, MPR and EPA (Debian libccd-dev, double) on the same posed polyhedra.
//
// Conventions
// - A pdOracleBody is a polyhedron in its own frame placed in the world: x_world = x + R(q) · x_body
//   (q unit, w first, as everywhere in polydyn). Nothing is copied: the polyhedron must outlive the call.
// - Depths are in metres and positive when the bodies overlap (the shortest translation of B that
//   separates them). Our SAT also gives a negative depth for a separated pair: minus the largest gap
//   along a face normal of the Minkowski difference (a lower bound of the distance). libccd gives no
//   depth for a separated pair (libccd 2.1 has no distance query).
// - The verdicts: ours is pd_interference (touching counts as overlapping); libccd's is ccdGJKIntersect;
//   ccdMPRIntersect is a second opinion, reported on its own (it has false positives on near-degenerate
//   portals, e.g. a cube falling vertex first onto a cube's vertex, 1 mm apart).
// - Scales: `scale` = r_A + r_B, the radii about each body's vertex average; libccd works in coordinates
//   divided by it (so its absolute epsilons become relative), and the touching band is relative to it.
//   `size` = the smaller body's average dimension (mean of its bounding-box extents, as pdBody.size);
//   depth errors are reported relative to it.
//
// libccd traps handled here (shared/reference/reference-engines.md §3):
// - epa_tolerance is compared with squared distances and products of distances; ours is tight, in the
//   scaled coordinates, and EPA's answer is used only when it is finite and >= 0 (exact touching gives
//   depth 0 and a NaN direction, which we never read);
// - MPR needs a centre strictly inside each body: the vertex average is;
// - GJK and MPR declare touching when a squared distance is below DBL_EPSILON, i.e. within about
//   1.5e-8 × scale: verdicts closer to touching than the band below are not comparable;
// - the EPA and MPR loops have no iteration bound: the support function counts its calls and, past
//   PD_ORACLE_SUPPORT_CAP, answers the body's centre, which ends every libccd loop; EPA is then retried
//   at a looser tolerance (below), and a pair with no usable answer is `ccd_stalled`, not compared;
// - when GJK calls a separated pair touching (a gap below ~2e-8 × scale), EPA's depth is meaningless
//   (measured up to 0.59 × scale): the touching band takes the smaller of the two depths.
// - pkg-config reports libccd as version 2.0 although Debian ships 2.1 (upstream never bumped it).
#pragma once

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "polydyn/polyhedron.h"
#include "polydyn/scene.h"
#include "polydyn/vecmath.h"

// Touching band, relative to the pair's scale r_A + r_B: a pair whose |depth| by either method is
// below PD_ORACLE_TOUCH_REL × scale is "touching", and a verdict mismatch there is counted apart, not
// as a failure. libccd's touching tests (ccdIsZero on squared distances, DBL_EPSILON) decide within
// sqrt(2.2e-16) ≈ 1.5e-8 of the scaled Minkowski difference; the largest mismatch measured on 100 000
// random pairs was at 1.9e-8 × scale (GJK calling a separated pair intersecting), so 1e-7 leaves a
// factor 5.
#define PD_ORACLE_TOUCH_REL 1e-7

// EPA's stopping rule, in libccd's units (scaled coordinates): it stops when the new support point gains
// less than `tol` over the nearest face, the gain multiplied by the current depth d (units²), or lies
// within √tol of that face. Its depth, a lower bound, is then short by at most
//     epaBound = scale · max(tol / d, √tol)       (d in scaled lengths, at least PD_ORACLE_TOUCH_REL)
// (libccd's default, 1e-4, allows a whole shallow depth). We ask for PD_ORACLE_EPA_TOL. On some face–face
// contacts (a block resting on a slab) libccd's EPA, which does not keep its polytope convex, adds the
// same Minkowski vertex again and again and never stops at that tolerance: when a query runs out of
// support calls it is retried PD_ORACLE_EPA_RETRIES times, each 100 times looser, up to 1e-7
// (cases/hard/mass_ratio, block on floor: at t = 0.14 s it cycles at 1e-15 and answers at 1e-13, short
// by 5.6e-8 m, bound 4.5e-7 m; at t = 0.164 s it cycles up to 1e-9 and answers at 1e-7, short by 1e-8 m,
// bound 1.4e-3 m: at such a tolerance EPA says little).
// At 1e-15 the random pairs agree with our depth to 1.4e-14 × size (docs/validation.md).
#define PD_ORACLE_EPA_TOL 1e-15
#define PD_ORACLE_EPA_RETRIES 4
// MPR stops refining its portal when a new support point moves it by less than this, in scaled
// lengths (1e-12 × scale; libccd's default 1e-4 stops that far from the boundary).
#define PD_ORACLE_MPR_TOL 1e-12
// Support calls per libccd query before the support function stops moving (see the top of this file).
// A converging EPA or MPR query took at most 60 on 5000 random pairs; a cycling EPA's polytope search
// costs O(calls²), about 5 ms at this cap.
#define PD_ORACLE_SUPPORT_CAP 1000
// GJK's own iteration limit (libccd's default is unbounded; at the limit it silently answers "separate"):
// two support calls per iteration, so the support cap above ends a stuck GJK first and marks it stalled.
#define PD_ORACLE_GJK_ITERATIONS 1000

typedef struct pdOracleBody {
  const pdPolyhedron* shape;  // in the body's own frame
  pdVec3 x;                   // world position of the body frame's origin, m
  pdQuat q;                   // body → world, unit
} pdOracleBody;

// The outcome of one pair, in order of precedence (a pair gets the first that applies).
typedef enum pdOracleKind {
  pd_oracleAgreeOverlap,   // both overlap (depths compared)
  pd_oracleAgreeSeparate,  // both separate
  pd_oracleWeOverlap,      // we overlap, GJK separates, outside the touching band
  pd_oracleWeSeparate,     // we separate, GJK overlaps, outside the touching band
  pd_oracleTouching,       // verdicts differ (ours vs GJK or vs MPR) inside the touching band
  pd_oracleMprDiffers,     // ours and GJK agree, MPR differs, outside the band
  pd_oracleDepth,          // both overlap, our depth outside the band; |EPA − ours| > epaBound
  pd_oracleStalled,        // GJK or MPR ran out of support calls, or EPA did at every tolerance or gave
                           // no depth: not compared
  pd_oracleKindCount
} pdOracleKind;

// Short names of the kinds, as in the CSV's `kind` column ("agree_overlap", "we_overlap", ...).
extern const char* const pdOracleKindNames[pd_oracleKindCount];

typedef struct pdOracleResult {
  double scale;        // m: r_A + r_B (radii about the vertex averages)
  double size;         // m: the smaller body's average dimension
  bool ours;           // our verdict: overlap (touching included)
  double ourDepth;     // m: > 0 overlap depth, < 0 minus the best gap (see the conventions)
  bool gjk;            // ccdGJKIntersect
  bool mpr;            // ccdMPRIntersect
  bool hasEpa;         // epaDepth is valid: GJK overlaps and EPA returned a finite depth >= 0
  double epaDepth;     // m: ccdGJKPenetration's depth (0 when !hasEpa)
  double epaTol;       // the EPA tolerance that answered (PD_ORACLE_EPA_TOL or a retry's; 0 when !hasEpa)
  double epaBound;     // m: how far EPA's stopping rule lets its depth fall short (see above)
  bool hasMprDepth;    // mprDepth is valid
  double mprDepth;     // m: ccdMPRPenetration's depth along its portal (not the minimum) (0 when not)
  bool stalled;        // GJK or MPR (verdict) ran out of support calls, or EPA did at every tolerance
  bool touching;       // min(|ourDepth|, epaDepth) < PD_ORACLE_TOUCH_REL × scale
  pdOracleKind kind;
  double secondsOurs, secondsCcd;  // CPU time of our SAT and of the four libccd queries, s
} pdOracleResult;

// Checks one pair: our SAT (minimum-depth mode, no cache) and libccd's four queries. Never fails; a
// libccd answer that cannot be used is reported in the result (kind pd_oracleStalled).
void pd_oracle_check(const pdOracleBody* a, const pdOracleBody* b, pdOracleResult* out);

// ---------------------------------------------------------------- statistics over many pairs

typedef struct pdOracleSample {
  double* v;
  long count, capacity;
} pdOracleSample;

typedef struct pdOracleStats {
  long pairs;
  long kinds[pd_oracleKindCount];
  long inBand;            // pairs inside the touching band (whatever their verdicts)
  long gjkMprDiffer;      // GJK and MPR verdicts differ (any band)
  long mprDepthMissing;   // all three overlap outside the band but ccdMPRPenetration gave no depth
  long epaRetried;        // EPA answered only at a looser tolerance
  long depthMprAgrees;    // depth outliers where MPR's depth is within EPA's bound of ours (EPA is off)
  // over the pairs ours, GJK and EPA call overlapping, our depth outside the touching band:
  pdOracleSample epaError;  // (EPA − ours)/size
  pdOracleSample mprError;  // (MPR − ours)/size, where MPR overlaps and gave a depth
  pdOracleSample ourDepth;  // ours/size (to read the errors against)
  // and our depth inside it:
  pdOracleSample epaErrorInBand;  // (EPA − ours)/size
  double secondsOurs, secondsCcd;  // CPU time
} pdOracleStats;

void pd_oracle_stats_init(pdOracleStats* s);
void pd_oracle_stats_add(pdOracleStats* s, const pdOracleResult* r);
void pd_oracle_stats_free(pdOracleStats* s);
// Pairs whose verdict disagrees with libccd's (GJK's) outside the touching band: the failures. (MPR
// differing from both ours and GJK is libccd against itself: listed, not a failure.)
long pd_oracle_stats_failures(const pdOracleStats* s);
// The summary: counts by kind, the band, depth error statistics (max, median, 99th percentile of
// |error|/size, and the signed extremes), time. Deterministic except the line starting with "time".
void pd_oracle_stats_print(const pdOracleStats* s, FILE* out);

// ---------------------------------------------------------------- timing (polydyn oracle --timing)
// Our SAT against libccd's queries on the same random pairs (refcheck/oracle_timing.c), each mode timed over
// whole batches of pairs, R times, medians quoted. libccd's tolerances are its defaults here (1e-4 in its
// scaled coordinates, as an engine calling it would use), not the oracle's tight ones above.
typedef enum pdOracleTimingMode {
  pd_oracleTimingFirst,          // ours as the engine calls it: PD_SAT_FIRST_SEPARATING, no cache
  pd_oracleTimingCached,         // the same with the cache of a previous call at the same pose (best case)
  pd_oracleTimingMinDepth,       // PD_SAT_MIN_DEPTH (every axis; the oracle's check)
  pd_oracleTimingGjk,            // ccdGJKIntersect
  pd_oracleTimingGjkEpa,         // ccdGJKPenetration: GJK, then EPA when overlapping
  pd_oracleTimingMpr,            // ccdMPRIntersect
  pd_oracleTimingFirstOverlap,   // ours, first-separating, over the pairs GJK calls overlapping only
  pd_oracleTimingGjkEpaOverlap,  // ccdGJKPenetration over those pairs only
  pd_oracleTimingVerdict,        // ours as the contact search calls it: PD_SAT_VERDICT, no cache
  pd_oracleTimingVerdictOverlap,  // the same over the pairs GJK calls overlapping only
  pd_oracleTimingModeCount
} pdOracleTimingMode;
extern const char* const pdOracleTimingModeNames[pd_oracleTimingModeCount];  // "ours_first", ...

// Groups by the larger body's vertex count (the costs differ by orders of magnitude).
typedef enum pdOracleTimingGroupKind {
  pd_oracleTimingCubeCube,  // both cubes
  pd_oracleTimingSmall,     // any other pair, V <= 32 (prisms, tapered prisms, hulls, icosahedra)
  pd_oracleTimingMedium,    // V <= 162 (geodesic spheres of levels 1 and 2)
  pd_oracleTimingLarge,     // V > 162 (geodesic spheres of level 3, 642 vertices)
  pd_oracleTimingAll,       // every pair (a batch's time: the sum over the groups)
  pd_oracleTimingGroupCount
} pdOracleTimingGroupKind;
extern const char* const pdOracleTimingGroupNames[pd_oracleTimingGroupCount];  // "cube-cube", ...

typedef struct pdOracleTimingGroup {
  long pairs, overlapping;                     // overlapping: GJK's verdict (the _overlap modes' batch)
  double meanVertices, meanEdges;              // per body
  double usPerPair[pd_oracleTimingModeCount];  // median over the repeats, µs
  double usMin[pd_oracleTimingModeCount], usMax[pd_oracleTimingModeCount];
} pdOracleTimingGroup;

// The widest gap, in PD_GJK_MARGIN_REL × the pair's scale (the bodies' radii about their origins and the
// origins' distances from the world's), that PD_SAT_VERDICT may call touching: its margin is relative to a size
// of at most 3 such scales, and GJK certifies every gap above 1.001 margins.
#define PD_ORACLE_VERDICT_BAND_MAX 3.01

typedef struct pdOracleTiming {
  long pairCount;
  int repeats;
  long oursOverlap, gjkOverlap, ccdStalled;
  bool oursAgree;            // our three searches give the same verdicts (and the same depths where overlapping), and
                             // the verdict mode separates only what they separate, and calls touching only pairs
                             // they call apart by at most PD_ORACLE_VERDICT_BAND_MAX margins
  long verdictWithinMargin;  // pairs the verdict mode calls touching and the searches apart
  double verdictBandMax;     // the widest of their gaps, in PD_GJK_MARGIN_REL × the pair's scale
  uint64_t resultHash;  // FNV-1a over every field of our three modes' results but the work counter
  double checksum;      // a sum of all timed answers (keeps them from being optimised away)
  pdOracleTimingGroup groups[pd_oracleTimingGroupCount];
} pdOracleTiming;

// Draws n pairs from `seed` (as --random) and times every mode over them, `repeats` times. Returns
// out->oursAgree.
bool pd_oracle_timing(long n, uint64_t seed, int repeats, pdOracleTiming* out);
// The summary table (µs per pair by group and mode, ratios to GJK), and the CSV (one row per group and mode).
void pd_oracle_timing_print(const pdOracleTiming* t, FILE* out);
void pd_oracle_timing_csv(const pdOracleTiming* t, FILE* out);

// ---------------------------------------------------------------- shapes written as text (replayable)

// A shape spec is a scene object command without NAME and COLOR (docs/scene-language.md):
//   cube sx sy sz | prism n sx sy sz | tprism n sx sy sz taper | sphere level sx sy sz | hull x y z ...
// The polyhedron is the primitive in its own frame (before any shift to the centre of mass).
typedef struct pdOracleShape {
  pdPolyhedron poly;
  char* spec;  // owned, as given
} pdOracleShape;

// Parses and builds a shape. On bad input returns false and fills why (the scene parser's message, or
// the reason the polyhedron is degenerate); nothing to free then.
bool pd_oracle_shape_parse(const char* spec, pdOracleShape* out, char* why, int whySize);
void pd_oracle_shape_free(pdOracleShape* s);
// The spec of a scene object (numbers with %.17g, so the shape is rebuilt bit for bit). Free with free().
char* pd_oracle_object_spec(const pdSceneObject* o);

// ---------------------------------------------------------------- random pairs near touching

// xoshiro256** seeded through splitmix64: the same sequence on every libc and platform.
typedef struct pdOracleRng {
  uint64_t s[4];
} pdOracleRng;

void pd_oracle_rng_seed(pdOracleRng* g, uint64_t seed);
uint64_t pd_oracle_rng_next(pdOracleRng* g);
double pd_oracle_rng_uniform(pdOracleRng* g);  // [0, 1), 53 bits

// How far B was placed from touching A.
typedef enum pdOraclePlacement {
  pd_placeNear,   // offset ±scale·10^U(−8, −1.3) along the direction from touching (85 %)
  pd_placeTouch,  // at the touching distance found by our SAT (5 %)
  pd_placeFar,    // centres scale·U(0.2, 1.05) apart: deep overlap to clearly apart (10 %)
} pdOraclePlacement;

typedef struct pdOraclePair {
  pdOracleShape a, b;
  pdOracleBody bodyA, bodyB;  // shapes point into a and b
  pdOraclePlacement placement;
  double offset;              // m, signed distance from touching along the placement direction (0 for far)
} pdOraclePair;

// Draws a random pair: shapes (cube, prism 3–12, tprism, geodesic sphere level 0–3, hull of 6–30
// points; dimensions 0.1–2 m, written with 6 significant digits), uniform random orientations, A
// within [-1, 1]³, and B along a random direction from A, placed as pdOraclePlacement says. The
// touching distance is found by Newton's method on our SAT's minimum depth, safeguarded by bisection.
void pd_oracle_random_pair(pdOracleRng* g, pdOraclePair* out);
void pd_oracle_pair_free(pdOraclePair* p);

// ---------------------------------------------------------------- the disagreement CSV

// One row: a checked pair with what is needed to replay it.
typedef struct pdOracleRow {
  const char* source;  // "random", or the scene file
  long index;          // random: pair number; scene: sample number
  double t;            // scene: time of the sample, s (random: 0)
  const char* nameA;   // scene: body names; random: "A", "B"
  const char* nameB;
  const char* specA;   // shape specs (pdOracleShape)
  const char* specB;
  pdVec3 xa, xb;       // poses of the specs' frames, world
  pdQuat qa, qb;
  pdOracleResult r;
} pdOracleRow;

// The CSV header line (with its newline) and one row; numbers with %.17g, fields quoted when they hold
// a comma or a quote.
void pd_oracle_csv_header(FILE* out);
void pd_oracle_csv_write(FILE* out, const pdOracleRow* row);

// Reads one data line of that CSV (no newline) into `fields` (borrowed pointers into `buf`, a copy of
// the line the caller owns) and the row's poses. Returns false with a message and the 1-based column
// of the bad field in *col.
enum { PD_ORACLE_CSV_FIELDS = 31 };
bool pd_oracle_csv_read(char* buf, pdOracleRow* row, int* col, char* why, int whySize);

// Called for each row of a replay in file order: the row (its text fields point into a copy of the line,
// valid during the call), both shapes built from its specs, and its 1-based line. Returns false to stop
// (an interrupt).
typedef bool pdOracleReplayFcn(const pdOracleRow* row, const pdOracleShape* a, const pdOracleShape* b, long line,
                               void* user);

// Goes through the text of such a CSV (`size` bytes, need not be NUL-terminated; `name`, nullable, stands for
// the file in messages): the header exactly as pd_oracle_csv_header writes it, then one row per line (blank
// lines skipped, CRLF accepted). Reads each row, builds both of its shapes and, when `visit` is not NULL,
// calls it. Returns false with `NAME:LINE:COL: message` in err at the first line that is not text (a NUL
// byte), another header, a malformed row or a shape that cannot be built; true at the end or when visit
// stopped. `polydyn oracle --replay` calls it once with visit NULL, so that a bad file is refused before
// anything is checked or written, then again to replay.
bool pd_oracle_replay_buffer(const char* name, const char* data, size_t size, pdOracleReplayFcn* visit, void* user,
                             pdError* err);
