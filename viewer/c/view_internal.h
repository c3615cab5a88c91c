// polydyn viewer — what a loaded run holds (internal to view_run.c and view_page.c).
#pragma once

#include <stdint.h>

#include "pdview/view.h"

// Columns of the data block (all little-endian; each array starts at a multiple of 8 bytes).
enum {
  PD_VIEW_POSE = 7,     // float64 per body per sample: x, y, z, qw, qx, qy, qz
  PD_VIEW_VEL = 6,      // float32 per body per sample: vx, vy, vz, wx, wy, wz
  PD_VIEW_CFLOAT = 6,   // float32 per contact: px, py, pz, Fx, Fy, Fz (force on body_a, N)
  PD_VIEW_CINT = 3,     // int32 per contact: body_a, body_b (indices into bodies), flags
  PD_VIEW_EDGE_EDGE = 1,  // flags: an EE contact (else VF)
  PD_VIEW_SLIP = 2,       // flags: slipping (else sticking)
};

struct pdViewRun {
  char* dir;
  char* metaJson;        // the run's JSON block (bodies, geometry, settings, block layout), printed
  int bodyCount;         // all bodies, scene order
  char** names;          // (bodyCount)
  bool* fixed;           // (bodyCount)
  int movingCount;
  int* moving;           // (movingCount) body index of each trajectory column, scene order
  int sampleCount;
  double* t;             // (sampleCount)
  double* pose;          // (sampleCount × movingCount × PD_VIEW_POSE)
  float* vel;            // (sampleCount × movingCount × PD_VIEW_VEL)
  int contactCount;
  uint32_t* contactStart;  // (sampleCount + 1): contacts of sample s are [start[s], start[s+1])
  float* contactFloat;     // (contactCount × PD_VIEW_CFLOAT)
  int32_t* contactInt;     // (contactCount × PD_VIEW_CINT)
  bool hasContacts;        // contacts.csv was present
};

// The data block's arrays in order: t, pose, vel, contactStart, contactFloat, contactInt.
enum { PD_VIEW_BLOCKS = 6 };
typedef struct pdViewLayout {
  size_t offset[PD_VIEW_BLOCKS];  // bytes from the block's start, multiples of 8
  size_t bytes[PD_VIEW_BLOCKS];   // bytes of each array
  size_t total;                   // bytes of the whole block
} pdViewLayout;
pdViewLayout pd_view_layout(const pdViewRun* run);
