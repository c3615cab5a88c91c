// libFuzzer target for the cube-toss CSV reader (validation/cubetoss_data.c: pd_toss_parse_buffer, the code of
// pd_toss_read) and the toss lists of --tosses (pd_toss_select). The input is the CSV, optionally followed by
// a NUL byte and a toss list (the reader refuses a NUL byte anyway, so the list never reaches it). Any bytes
// must give either a set that keeps the reader's promises (cubetoss.h) or one well-formed error; a list,
// indices in file order or a reason; an accepted toss's scene must compile or be refused with an error.
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_checks.h"
#include "pdval/cubetoss.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static bool finite3(pdVec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

static void check_set(const pdTossSet* set) {
  if (!set->path || set->count < 1 || !set->tosses) __builtin_trap();
  for (int i = 0; i < set->count; ++i) {
    const pdToss* t = &set->tosses[i];
    if (t->sampleCount < 2 || !t->samples || t->line < 2 || (i > 0 && t->line <= set->tosses[i - 1].line))
      __builtin_trap();
    for (int j = 0; j < i; ++j)
      if (set->tosses[j].id == t->id) __builtin_trap();  // a toss's rows are consecutive
    for (int k = 0; k < t->sampleCount; ++k) {
      const pdBodyState* s = &t->samples[k];
      double norm = sqrt(s->q.w * s->q.w + s->q.x * s->q.x + s->q.y * s->q.y + s->q.z * s->q.z);
      if (!finite3(s->x) || !finite3(s->v) || !finite3(s->w) || !(fabs(norm - 1.0) < 1e-12)) __builtin_trap();
    }
  }
}

static void check_select(const pdTossSet* set, const char* list) {
  int* indices = NULL;
  int count = -1;
  char why[256] = "";
  if (pd_toss_select(set, list, &indices, &count, why, sizeof why)) {
    if (count < 1 || count > set->count || !indices) __builtin_trap();
    for (int k = 0; k < count; ++k)
      if (indices[k] < 0 || indices[k] >= set->count || (k > 0 && indices[k] <= indices[k - 1])) __builtin_trap();
  } else if (indices || count != 0 || !why[0]) {
    __builtin_trap();
  }
  free(indices);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const uint8_t* nul = memchr(data, '\0', size);
  size_t csvSize = nul ? (size_t)(nul - data) : size;
  pdError err;
  pdTossSet* set = pd_toss_parse_buffer("fuzz.csv", (const char*)data, csvSize, &err);
  if (!set) {
    fuzz_check_error(&err, 0);
    return 0;
  }
  check_set(set);
  if (nul) {
    // the list after the NUL, as a C string (it ends at the next NUL, as an argv word would)
    size_t listSize = size - csvSize - 1;
    char* list = malloc(listSize + 1);
    if (!list) abort();
    memcpy(list, nul + 1, listSize);
    list[listSize] = '\0';
    check_select(set, list);
    free(list);
  }
  // the first toss's scene, as `polydyn cubetoss` makes it: compiled, or refused with a message
  pdTossParams params = pd_toss_default_params();
  pdModel* model = pd_toss_model(&set->tosses[0], &params, &err);
  if (model)
    pd_model_free(model);
  else
    fuzz_check_error(&err, 0);
  pd_toss_set_free(set);
  return 0;
}
