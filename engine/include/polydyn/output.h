// polydyn — run directories (DESIGN §4.2): trajectory.csv and summary.json.
//
// contacts.csv: see pd_write_contact_rows.
//
// A run directory is written under a temporary name beside the target (`DIR.partial-PID`) and
// renamed to DIR only when complete, so an interrupted run never leaves a directory that looks
// complete. An existing DIR is replaced only if it is a previous run directory (has summary.json).
//
// trajectory.csv: header `t,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz`; one row per moving body per
// sample, bodies in scene order; numbers printed with %.17g so they round-trip exactly.
#pragma once

#include <stdbool.h>
#include <stdio.h>

#include "polydyn/api.h"
#include "polydyn/error.h"
#include "polydyn/model.h"
#include "polydyn/state.h"

typedef struct pdRunWriter pdRunWriter;

// Starts a run directory for `dir`: creates the temporary directory and opens trajectory.csv and
// contacts.csv in it. The caller owns the writer: pd_run_finish or pd_run_abort frees it. Returns NULL
// and fills err on failure (nothing left behind).
PD_API pdRunWriter* pd_run_open(const char* dir, pdError* err);

// Observer that appends the current sample to trajectory.csv and contacts.csv; `user` is the pdRunWriter.
// It copies the sample's numbers; a thread of the writer prints them (output.c, design note), so the files
// are complete only after pd_run_drain or pd_run_finish. Returns false once a write has failed. Every sample
// of one writer must come from the same model.
PD_API bool pd_run_observe(const pdModel* model, const pdState* state, void* user);

// Waits until every sample observed so far is in the files (their stdio buffers): for timing a run whole.
PD_API void pd_run_drain(pdRunWriter* run);

// Writes one trajectory row per moving body at the state's time.
PD_API void pd_write_trajectory_rows(FILE* out, const pdModel* model, const pdState* state);
PD_API void pd_write_trajectory_header(FILE* out);
// contacts.csv (DESIGN §4.2): header `t,body_a,body_b,kind,feat_a,feat_b,px,py,pz,nx,ny,nz,fn,ftx,fty,ftz,mode`;
// one row per active contact per sample, in contact-id order; kind VF or EE; body_a carries the vertex
// (VF) or the first edge (EE); n points from body_b into body_a; (fn, ft) is the force on body_a, N;
// mode stick or slip.
PD_API void pd_write_contact_rows(FILE* out, const pdModel* model, const pdState* state);
PD_API void pd_write_contacts_header(FILE* out);

typedef struct pdRunInfo {
  const char* engine;     // e.g. "polydyn-soft"
  double energyStart;     // J
  double energyEnd;       // J
  double wallSeconds;     // wall time of pd_advance
  bool completed;         // reached tend
  const char* stepper;    // nullable: the stepper's name when it is not the state's (reference engines)
  const char* engineSettingsJson;  // nullable: one JSON object written as "engine_settings" (refcheck)
} pdRunInfo;

// Writes summary.json, closes every file and renames the directory into place; frees `run` in every
// case. Returns false and fills err on an I/O failure (then the temporary directory is removed).
PD_API bool pd_run_finish(pdRunWriter* run, const pdModel* model, const pdState* state, const pdRunInfo* info,
                   pdError* err);

// Removes the temporary directory and frees the writer (an interrupted or failed run); NULL is allowed.
PD_API void pd_run_abort(pdRunWriter* run);

// Writes the summary JSON object to `out` (also used by `polydyn check --json` later).
PD_API void pd_write_summary_json(FILE* out, const pdModel* model, const pdState* state, const pdRunInfo* info);
