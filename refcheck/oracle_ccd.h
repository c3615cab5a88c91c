// polydyn refcheck (internal) — a posed polyhedron as libccd sees it (the design note of oracle.c): shared
// by the oracle's check (oracle.c) and its timing (oracle_timing.c), so that both time the same queries.
#pragma once

#include <ccd/ccd.h>

#include "pdref/oracle.h"

// A body as libccd sees it: scaled world coordinates.
typedef struct ccdBody {
  const pdPolyhedron* shape;
  pdMat3 Rs;      // R / scale: body frame → scaled world, without the translation
  pdVec3 origin;  // the body origin, scaled world
  pdVec3 centre;  // the vertex average, scaled world (strictly inside: MPR's centre)
  long* calls;    // support calls of the current query (shared by the two bodies)
} ccdBody;

typedef struct shapeMeasures {
  pdVec3 average;  // vertex average, body frame
  double radius;   // largest vertex distance from it, m
  double size;     // mean of the bounding-box extents, m (as pdBody.size)
} shapeMeasures;

shapeMeasures pd_oracle_measure(const pdPolyhedron* p);
// libccd's support function over a ccdBody's vertices (a linear scan), counting its calls in *calls: past
// PD_ORACLE_SUPPORT_CAP it answers the centre. And the centre, for MPR.
void pd_oracle_ccd_support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out);
void pd_oracle_ccd_centre(const void* obj, ccd_vec3_t* out);
// Both bodies of a pair (rotation matrices RA, RB of their quaternions), in coordinates about the midpoint
// of their vertex averages divided by the pair's scale r_A + r_B, which it returns.
double pd_oracle_ccd_pair(const pdOracleBody* a, const pdOracleBody* b, const pdMat3* RA, const pdMat3* RB,
                          const shapeMeasures* ma, const shapeMeasures* mb, long* calls, ccdBody* A, ccdBody* B);
// CPU time of this process, s: what the check and the timing measure (the machine may be shared, and wall
// time would count the others).
double pd_oracle_cpu_seconds(void);
// CCD_INIT with our support and centre functions and GJK's iteration bound (PD_ORACLE_GJK_ITERATIONS); the
// tolerances stay libccd's defaults.
void pd_oracle_ccd_init(ccd_t* ccd);
