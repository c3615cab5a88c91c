// polydyn tests — a fixed-seed random generator, reproducible on every libc (no rand()).
#pragma once

#include <stdint.h>

// Linear congruential generator with Knuth's MMIX constants.
typedef struct lcg {
  uint64_t s;
} lcg;

static inline double lcg_uniform(lcg* g) {  // [0, 1)
  g->s = g->s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(g->s >> 11) * (1.0 / 9007199254740992.0);
}

static inline double lcg_range(lcg* g, double lo, double hi) { return lo + (hi - lo) * lcg_uniform(g); }
