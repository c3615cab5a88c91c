// polydyn — run directories: trajectory.csv, contacts.csv and summary.json, written atomically.
//
// Design note. Printing the samples (17 significant digits per number, engine/src/number_format.h) and writing
// them to the files was up to 40 % of a small scene's run (reports/bench/cost.md: the 10-box stack, one cube on
// a vertex), all of it on the simulation's thread. pd_run_observe therefore only copies a sample's numbers
// (time, each moving body's pose and velocities, each contact's ids and force) into a block of a small ring;
// a writer thread, started by pd_run_open, takes the filled blocks in order and prints them with the same
// functions as pd_write_trajectory_rows and pd_write_contact_rows, so the files hold the same bytes, and the
// simulation goes on meanwhile (on a second core, if there is one). The observer waits only when every block
// is full, and wakes the writer only when several blocks wait (PD_OUTPUT_WAKE_BLOCKS). pd_run_drain waits until
// everything observed is written (`polydyn run` times the run up to there, so its wall_seconds includes the
// printing not hidden behind the simulation); pd_run_finish drains and joins
// the thread; pd_run_abort stops it. A write error seen by the writer makes the next pd_run_observe return
// false. Blocks grow (at the first samples) to hold the largest sample seen; after that nothing is allocated. The
// writer copies the text of a number it printed recently instead of forming it again (numberCache).
#include "polydyn/output.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "model_contact.h"
#include "pdutil/csv.h"
#include "pdutil/files.h"
#include "pdutil/json.h"
#include "number_format.h"

// The ring: blocks of at least PD_OUTPUT_BLOCK_BYTES, as many as fit PD_OUTPUT_RING_BYTES with the first sample
// (at least PD_OUTPUT_BLOCKS_MIN, at most PD_OUTPUT_BLOCKS_MAX). The block being filled at the end is printed after
// the simulation is done (pd_run_drain), so its size is the wait at the end: four blocks of 256 KiB (29 samples of a
// 10-box stack, 8.75 KiB each) left 2.3 ms of 40 to print after the last step (cases/hard/stack_10.scene); blocks of
// 16 KiB leave 0.3 ms. A scene whose samples are larger than a block gets fewer blocks, one sample each, so that the
// ring stays near its size (a pile of 1 000 boxes at rest: ~0.7 MB a sample).
#define PD_OUTPUT_BLOCK_BYTES (16 * 1024)
#define PD_OUTPUT_RING_BYTES (1024 * 1024)
#define PD_OUTPUT_BLOCKS_MIN 4
#define PD_OUTPUT_BLOCKS_MAX 64
// The writer is woken when this many blocks wait for it (or the ring is full, or the run drains or stops), and then
// prints every block that waits: it prints faster than the samples come, so woken at every block it slept and woke
// once per sample, two context switches each (cases/hard/stack_10.scene: 676 for 301 samples, each a kernel's
// round trip on both threads). Eight blocks are at most eight samples left to print after the last step.
#define PD_OUTPUT_WAKE_BLOCKS 8
// The stdio buffer of trajectory.csv and of contacts.csv: glibc ignores setvbuf's size when it is given no buffer and
// writes in blocks of the file system's (4 KiB: 1 572 write calls for cases/hard/stack_10.scene's 6.4 MB), so the
// buffers are ours.
#define PD_OUTPUT_STREAM_BUFFER_BYTES (1 << 20)

typedef struct outputBlock {
  unsigned char* data;
  size_t used, capacity;
} outputBlock;

struct pdRunWriter {
  char* dir;         // final name
  char* tmp;         // temporary directory being written
  FILE* trajectory;  // tmp/trajectory.csv
  FILE* contacts;    // tmp/contacts.csv
  char* streamBuffers[2];  // trajectory's and contacts' stdio buffers (PD_OUTPUT_STREAM_BUFFER_BYTES each)
  atomic_bool ioError;  // a write failed (set by the writer thread)
  struct numberCache* numbers;  // the writer thread's (print_block)
  struct rowText* rows;         // the model's names and the writer's line (print_block), with the model
  // the ring (design note): blocks filled = produced − consumed, in order
  const pdModel* model;  // the model of the samples (the same for every one; the writer reads its names)
  outputBlock blocks[PD_OUTPUT_BLOCKS_MAX];
  int ringBlocks;  // blocks in the ring, set by the first sample (0 before it)
  long produced;  // blocks handed to the writer so far
  long consumed;  // blocks the writer has printed so far
  bool quit;      // the writer stops when the ring is empty (finish) or at once (abort, with `discard`)
  bool discard;
  bool threadStarted;
  pthread_t thread;
  pthread_mutex_t lock;
  pthread_cond_t filled;  // produced grew, or quit
  pthread_cond_t freed;   // consumed grew
};

// Appends x to text at n (at most PD_G17_MAX − 1 characters); returns the new length. The engine never lets a
// non-finite number reach an output; should one get here, it is written "null", so JSON stays valid.
static size_t append_number(char* text, size_t n, double x) {
  if (isfinite(x)) return n + (size_t)pd_format_g17(x, text + n);
  memcpy(text + n, "null", 4);
  return n + 4;
}

static void write_number(FILE* out, double x) {
  char text[PD_G17_MAX];
  fwrite(text, 1, append_number(text, 0, x), out);
}

// The writer thread's texts of the numbers it printed last, by a hash of their bits (direct-mapped): a sample repeats
// many of the last one's numbers bit for bit (the corners and normals of resting contacts, exact zeros and ones), and
// copying a text costs a fraction of forming it (~75 ns a number by std::to_chars). On cases/hard/stack_10.scene 58 %
// of contacts.csv's numbers came from here. The same bytes as append_number's.
#define NUMBER_CACHE_BITS 12
#define NUMBER_CACHE_EMPTY 0x7ff8000000000001ull  // a NaN: no finite number has these bits
typedef struct numberCache {
  uint64_t bits[1 << NUMBER_CACHE_BITS];
  unsigned char length[1 << NUMBER_CACHE_BITS];
  char text[1 << NUMBER_CACHE_BITS][PD_G17_MAX];
} numberCache;

static void number_cache_clear(numberCache* cache) {
  for (int i = 0; i < 1 << NUMBER_CACHE_BITS; ++i) cache->bits[i] = NUMBER_CACHE_EMPTY;
}

// append_number through the cache (NULL: none).
static size_t append_number_cached(numberCache* cache, char* text, size_t n, double x) {
  if (!cache || !isfinite(x)) return append_number(text, n, x);
  uint64_t bits;
  memcpy(&bits, &x, sizeof bits);
  size_t slot = (size_t)((bits * 0x9e3779b97f4a7c15ull) >> (64 - NUMBER_CACHE_BITS));  // Fibonacci hashing
  if (cache->bits[slot] != bits) {
    cache->bits[slot] = bits;
    cache->length[slot] = (unsigned char)pd_format_g17(x, cache->text[slot]);
  }
  // the whole slot, whatever the number's length: a copy of constant size is two moves, one of the number's length a
  // `rep movs` (text has PD_G17_MAX bytes of room after any number: rowText)
  memcpy(text + n, cache->text[slot], PD_G17_MAX);
  return n + cache->length[slot];
}

// Appends ",x,y,…" (a row's numbers as write_number writes them) to text at n; returns the new length.
static size_t append_numbers(numberCache* cache, char* text, size_t n, const double* x, int count) {
  for (int k = 0; k < count; ++k) {
    text[n++] = ',';
    n = append_number_cached(cache, text, n, x[k]);
  }
  return n;
}

// Appends ",k" for a non-negative k (a feature index) to text at n; returns the new length.
static size_t append_index(char* text, size_t n, int k) {
  char digits[12];
  int d = 0;
  do digits[d++] = (char)('0' + k % 10);
  while ((k /= 10) > 0);
  text[n++] = ',';
  while (d > 0) text[n++] = digits[--d];
  return n;
}

// The CSV texts of the bodies' names (pdu_csv_text's bytes, formed once) and a line long enough for any row with them:
// a row is assembled whole and written with one fwrite (printed in six stdio calls, two of them scanning a name for
// characters to quote, the rows took a fifth of the writer's instructions on cases/hard/stack_10.scene).
typedef struct rowText {
  char** name;          // (bodyCount)
  size_t* nameLength;   // (bodyCount)
  char* line;           // (lineCapacity)
  size_t lineCapacity;  // a time, two names, kind and features, 13 numbers, commas, the mode, and PD_G17_MAX spare
} rowText;

static void row_text_init(rowText* r, const pdModel* model) {
  int n = model->bodyCount;
  r->name = malloc((size_t)(n > 0 ? n : 1) * sizeof *r->name);
  r->nameLength = malloc((size_t)(n > 0 ? n : 1) * sizeof *r->nameLength);
  PD_ASSERT(r->name != NULL && r->nameLength != NULL);
  size_t longest = 0;
  for (int i = 0; i < n; ++i) {
    FILE* text = open_memstream(&r->name[i], &r->nameLength[i]);
    PD_ASSERT(text != NULL);
    pdu_csv_text(text, model->bodies[i].name);
    PD_ASSERT(fclose(text) == 0);
    if (r->nameLength[i] > longest) longest = r->nameLength[i];
  }
  r->lineCapacity = PD_G17_MAX + 2 * longest + 2 * 12 + 16 + 13 * (PD_G17_MAX + 1) + PD_G17_MAX;
  r->line = malloc(r->lineCapacity);
  PD_ASSERT(r->line != NULL);
}

static void row_text_free(rowText* r, const pdModel* model) {
  for (int i = 0; i < model->bodyCount; ++i) free(r->name[i]);
  free(r->name);
  free(r->nameLength);
  free(r->line);
}

// Appends body i's name's CSV text to r->line at n; returns the new length.
static size_t append_name(const rowText* r, size_t n, int i) {
  memcpy(r->line + n, r->name[i], r->nameLength[i]);
  return n + r->nameLength[i];
}

// A sample time's text, formatted once for all of the sample's rows.
typedef struct timeText {
  char text[PD_G17_MAX];
  size_t length;
} timeText;

static timeText time_text(double t) {
  timeText r;
  r.length = (size_t)pd_format_g17(t, r.text);
  return r;
}

void pd_write_contacts_header(FILE* out) {
  fputs("t,body_a,body_b,kind,feat_a,feat_b,px,py,pz,nx,ny,nz,fn,ftx,fty,ftz,mode\n", out);
}

// One contact's numbers as a sample record holds them (pd_run_observe) and as contacts.csv prints them.
typedef struct contactRecord {
  int32_t bodyA, bodyB, featureA, featureB;
  int32_t edgeEdge, slip;
  double row[10];  // point, normal, fn, ft
} contactRecord;

static contactRecord contact_record(const pdContactReport* c) {
  contactRecord r = {c->bodyA, c->bodyB, c->featureA, c->featureB, c->edgeEdge, c->slip, {0}};
  const double row[10] = {c->point.x, c->point.y, c->point.z, c->normal.x, c->normal.y, c->normal.z,
                          c->fn,      c->ft.x,    c->ft.y,    c->ft.z};
  memcpy(r.row, row, sizeof row);
  return r;
}

static void write_contact_row(FILE* out, numberCache* cache, const rowText* r, const timeText* t,
                              const contactRecord* c) {
  // "t,a,b,EE,3,7" (time, names, kind, features), 10 numbers, ",slip\n"
  PD_ASSERT(c->featureA >= 0 && c->featureB >= 0);
  char* text = r->line;
  memcpy(text, t->text, t->length);
  size_t n = t->length;
  text[n++] = ',';
  n = append_name(r, n, c->bodyA);
  text[n++] = ',';
  n = append_name(r, n, c->bodyB);
  memcpy(text + n, c->edgeEdge ? ",EE" : ",VF", 3);
  n = append_index(text, n + 3, (int)c->featureA);
  n = append_index(text, n, (int)c->featureB);
  n = append_numbers(cache, text, n, c->row, 10);
  const char* mode = c->slip ? ",slip\n" : ",stick\n";
  size_t modeLength = strlen(mode);
  memcpy(text + n, mode, modeLength);
  fwrite(text, 1, n + modeLength, out);
}

void pd_write_contact_rows(FILE* out, const pdModel* model, const pdState* state) {
  int count = pd_state_contact_count(state);
  timeText t = time_text(state->t);
  rowText names;
  row_text_init(&names, model);
  for (int i = 0; i < count; ++i) {
    pdContactReport c = pd_state_contact(state, i);
    contactRecord r = contact_record(&c);
    write_contact_row(out, NULL, &names, &t, &r);
  }
  row_text_free(&names, model);
}

void pd_write_trajectory_header(FILE* out) { fputs("t,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n", out); }

// A moving body's 13 numbers in trajectory.csv's order: x, q, v, ω.
static void body_row(const pdModel* model, const pdState* state, int i, double row[13]) {
  pdBodyState b = pd_state_body(model, state, i);
  const double r[13] = {b.x.x, b.x.y, b.x.z, b.q.w, b.q.x, b.q.y, b.q.z, b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z};
  memcpy(row, r, sizeof r);
}

static void write_trajectory_row(FILE* out, numberCache* cache, const rowText* r, const timeText* t, int i,
                                 const double row[13]) {
  char* text = r->line;
  memcpy(text, t->text, t->length);
  size_t n = t->length;
  text[n++] = ',';
  n = append_name(r, n, i);
  n = append_numbers(cache, text, n, row, 13);
  text[n++] = '\n';
  fwrite(text, 1, n, out);
}

void pd_write_trajectory_rows(FILE* out, const pdModel* model, const pdState* state) {
  timeText t = time_text(state->t);
  rowText names;
  row_text_init(&names, model);
  for (int k = 0; k < model->movingCount; ++k) {
    int i = model->movingBodies[k];
    double row[13];
    body_row(model, state, i, row);
    write_trajectory_row(out, NULL, &names, &t, i, row);
  }
  row_text_free(&names, model);
}

// ---------------------------------------------------------------- the writer thread (design note)

// A sample record: t, the contact count, then each moving body's 13 numbers (scene order), then the contacts.
typedef struct sampleHead {
  double t;
  int32_t contacts;
  int32_t pad;
} sampleHead;

static size_t sample_bytes(const pdModel* model, int contacts) {
  return sizeof(sampleHead) + (size_t)model->movingCount * 13 * sizeof(double) +
         (size_t)contacts * sizeof(contactRecord);
}

// Prints one block's samples; returns false on a write error.
static bool print_block(pdRunWriter* run, const outputBlock* b) {
  const pdModel* model = run->model;
  size_t at = 0;
  while (at < b->used) {
    sampleHead h;
    memcpy(&h, b->data + at, sizeof h);
    at += sizeof h;
    timeText t = time_text(h.t);
    for (int k = 0; k < model->movingCount; ++k) {
      double row[13];
      memcpy(row, b->data + at, sizeof row);
      at += sizeof row;
      write_trajectory_row(run->trajectory, run->numbers, run->rows, &t, model->movingBodies[k], row);
    }
    for (int i = 0; i < h.contacts; ++i) {
      contactRecord c;
      memcpy(&c, b->data + at, sizeof c);
      at += sizeof c;
      write_contact_row(run->contacts, run->numbers, run->rows, &t, &c);
    }
  }
  return !ferror(run->trajectory) && !ferror(run->contacts);
}

static void* writer_main(void* user) {
  pdRunWriter* run = user;
  pthread_mutex_lock(&run->lock);
  for (;;) {
    while (!run->quit && run->consumed == run->produced) pthread_cond_wait(&run->filled, &run->lock);
    if (run->discard || run->consumed == run->produced) break;  // aborted, or finished and empty
    outputBlock* b = &run->blocks[run->consumed % run->ringBlocks];
    pthread_mutex_unlock(&run->lock);
    if (!atomic_load(&run->ioError) && !print_block(run, b)) atomic_store(&run->ioError, true);
    pthread_mutex_lock(&run->lock);
    b->used = 0;
    ++run->consumed;
    pthread_cond_signal(&run->freed);
  }
  pthread_mutex_unlock(&run->lock);
  return NULL;
}

// Hands the block being filled to the writer (if it holds anything), waking it when PD_OUTPUT_WAKE_BLOCKS wait (at
// most the whole ring, so that an observer waiting for a free block has woken it) or when `wake`.
static void hand_over(pdRunWriter* run, bool wake) {
  if (run->ringBlocks == 0) return;  // no sample yet
  outputBlock* b = &run->blocks[run->produced % run->ringBlocks];
  if (b->used == 0 && !wake) return;
  pthread_mutex_lock(&run->lock);
  if (b->used > 0) ++run->produced;
  long waiting = run->produced - run->consumed;
  if (wake || waiting >= (run->ringBlocks < PD_OUTPUT_WAKE_BLOCKS ? run->ringBlocks : PD_OUTPUT_WAKE_BLOCKS))
    pthread_cond_signal(&run->filled);
  pthread_mutex_unlock(&run->lock);
}

// The size of a block that holds a sample of `bytes`.
static size_t block_bytes(size_t bytes) { return bytes > PD_OUTPUT_BLOCK_BYTES ? bytes : PD_OUTPUT_BLOCK_BYTES; }

// The block to fill next, with room for `bytes`: the current one, or the next once the writer has freed it.
static outputBlock* block_with_room(pdRunWriter* run, size_t bytes) {
  if (run->ringBlocks == 0) {  // the first sample: before any block is handed over, so the writer sees it set
    size_t fit = PD_OUTPUT_RING_BYTES / block_bytes(bytes);
    run->ringBlocks = fit < PD_OUTPUT_BLOCKS_MIN ? PD_OUTPUT_BLOCKS_MIN
                                                 : (fit > PD_OUTPUT_BLOCKS_MAX ? PD_OUTPUT_BLOCKS_MAX : (int)fit);
  }
  outputBlock* b = &run->blocks[run->produced % run->ringBlocks];
  if (b->used > 0 && b->used + bytes > b->capacity) {
    hand_over(run, false);
    pthread_mutex_lock(&run->lock);
    while (run->produced - run->consumed >= run->ringBlocks) pthread_cond_wait(&run->freed, &run->lock);
    pthread_mutex_unlock(&run->lock);
    b = &run->blocks[run->produced % run->ringBlocks];
  }
  if (bytes > b->capacity) {  // a sample larger than any so far (the first samples only)
    size_t capacity = block_bytes(bytes);
    unsigned char* data = realloc(b->data, capacity);
    PD_ASSERT(data != NULL);
    b->data = data;
    b->capacity = capacity;
  }
  return b;
}

void pd_run_drain(pdRunWriter* run) {
  hand_over(run, true);
  pthread_mutex_lock(&run->lock);
  while (run->consumed < run->produced) pthread_cond_wait(&run->freed, &run->lock);
  pthread_mutex_unlock(&run->lock);
}

// Stops the writer thread: after printing what it holds (finish), or at once (abort).
static void writer_stop(pdRunWriter* run, bool discard) {
  if (!run->threadStarted) return;
  if (!discard) hand_over(run, false);
  pthread_mutex_lock(&run->lock);
  run->quit = true;
  run->discard = discard;
  pthread_cond_signal(&run->filled);
  pthread_mutex_unlock(&run->lock);
  pthread_join(run->thread, NULL);
  pthread_cond_destroy(&run->filled);
  pthread_cond_destroy(&run->freed);
  pthread_mutex_destroy(&run->lock);
  run->threadStarted = false;
  for (int k = 0; k < PD_OUTPUT_BLOCKS_MAX; ++k) free(run->blocks[k].data);
  free(run->numbers);
  if (run->rows) {
    row_text_free(run->rows, run->model);
    free(run->rows);
    run->rows = NULL;
  }
}

pdRunWriter* pd_run_open(const char* dir, pdError* err) {
  struct stat st;
  if (stat(dir, &st) == 0) {
    char* summary = pdu_path_join(dir, "summary.json");
    bool isRun = S_ISDIR(st.st_mode) && access(summary, F_OK) == 0;
    free(summary);
    if (!isRun) {
      pd_error_set(err, dir, 0, 0, "exists and is not a polydyn run directory (no summary.json); not replacing it");
      return NULL;
    }
  }
  pdRunWriter* run = calloc(1, sizeof *run);
  PD_ASSERT(run != NULL);
  run->dir = pdu_path_suffix(dir, "");
  run->tmp = pdu_path_suffix(dir, ".partial-XXXXXX");
  if (mkdtemp(run->tmp)) {
    // mkdtemp makes the directory private; a finished run directory gets the usual permissions
    mode_t mask = umask(0);
    umask(mask);
    chmod(run->tmp, 0777 & ~mask);
  } else {
    pd_error_set(err, dir, 0, 0, "cannot create the output directory: %s", strerror(errno));
    free(run->dir);
    free(run->tmp);
    free(run);
    return NULL;
  }
  char* path = pdu_path_join(run->tmp, "trajectory.csv");
  run->trajectory = fopen(path, "w");
  free(path);
  path = pdu_path_join(run->tmp, "contacts.csv");
  run->contacts = fopen(path, "w");
  free(path);
  if (!run->trajectory || !run->contacts) {
    pd_error_set(err, dir, 0, 0, "cannot write %s: %s", run->trajectory ? "contacts.csv" : "trajectory.csv",
                 strerror(errno));
    pd_run_abort(run);
    return NULL;
  }
  // large buffers: trajectory and contacts are the bulk of the output
  for (int k = 0; k < 2; ++k) {
    run->streamBuffers[k] = malloc(PD_OUTPUT_STREAM_BUFFER_BYTES);
    PD_ASSERT(run->streamBuffers[k] != NULL);
  }
  setvbuf(run->trajectory, run->streamBuffers[0], _IOFBF, PD_OUTPUT_STREAM_BUFFER_BYTES);
  setvbuf(run->contacts, run->streamBuffers[1], _IOFBF, PD_OUTPUT_STREAM_BUFFER_BYTES);
  pd_write_trajectory_header(run->trajectory);
  pd_write_contacts_header(run->contacts);
  atomic_init(&run->ioError, false);
  run->numbers = malloc(sizeof *run->numbers);
  PD_ASSERT(run->numbers != NULL);
  number_cache_clear(run->numbers);
  PD_ASSERT(pthread_mutex_init(&run->lock, NULL) == 0 && pthread_cond_init(&run->filled, NULL) == 0 &&
            pthread_cond_init(&run->freed, NULL) == 0);
  PD_ASSERT(pthread_create(&run->thread, NULL, writer_main, run) == 0);
  run->threadStarted = true;
  return run;
}

bool pd_run_observe(const pdModel* model, const pdState* state, void* user) {
  pdRunWriter* run = user;
  PD_ASSERT(run->model == NULL || run->model == model);  // one run directory holds one model's samples
  if (atomic_load(&run->ioError)) return false;
  if (!run->model) {  // set before the first block is handed over, read-only after
    run->model = model;
    run->rows = malloc(sizeof *run->rows);
    PD_ASSERT(run->rows != NULL);
    row_text_init(run->rows, model);
  }
  int contacts = pd_state_contact_count(state);
  outputBlock* b = block_with_room(run, sample_bytes(model, contacts));
  sampleHead h = {state->t, contacts, 0};
  memcpy(b->data + b->used, &h, sizeof h);
  b->used += sizeof h;
  for (int k = 0; k < model->movingCount; ++k) {
    double row[13];
    body_row(model, state, model->movingBodies[k], row);
    memcpy(b->data + b->used, row, sizeof row);
    b->used += sizeof row;
  }
  for (int i = 0; i < contacts; ++i) {
    pdContactReport c = pd_state_contact(state, i);
    contactRecord r = contact_record(&c);
    memcpy(b->data + b->used, &r, sizeof r);
    b->used += sizeof r;
  }
  return true;
}


static void write_vec(FILE* out, pdVec3 v) {
  fputc('[', out);
  write_number(out, v.x);
  fputc(',', out);
  write_number(out, v.y);
  fputc(',', out);
  write_number(out, v.z);
  fputc(']', out);
}

static void write_mat(FILE* out, const pdMat3* m) {
  fputc('[', out);
  for (int i = 0; i < 3; ++i) {
    if (i) fputc(',', out);
    write_vec(out, (pdVec3){m->m[i][0], m->m[i][1], m->m[i][2]});
  }
  fputc(']', out);
}

// A number, or null when it is negative (a value not set or not applicable) or not finite.
static void write_optional(FILE* out, double x) {
  if (x >= 0.0)
    write_number(out, x);
  else
    fputs("null", out);
}

// The material as the scene asked for it: null for what it did not set.
static void write_requested(FILE* out, const pdMaterial* m) {
  const struct {
    const char* name;
    double value;
  } fields[] = {{"mu", m->mu}, {"kn", m->kn}, {"kt", m->kt},
                {"cn", m->cn}, {"ct", m->ct}, {"restitution", m->restitution}};
  for (size_t i = 0; i < sizeof fields / sizeof fields[0]; ++i) {
    fprintf(out, "%s\"%s\": ", i ? ", " : "{", fields[i].name);
    write_optional(out, fields[i].value);
  }
  fputc('}', out);
}

// The material as used: what the body itself decides (μ, e with its default, the constants the scene
// gave; null where the pair derives them) and its masses. The contact constants are the pairs' (below).
static void write_used(FILE* out, const pdMaterial* m, const pdBodyContactInfo* info) {
  const struct {
    const char* name;
    double value;
  } fields[] = {{"mu", m->mu},   {"kn", m->kn},   {"kt", m->kt},          {"cn", m->cn},
                {"ct", m->ct},   {"restitution", m->restitution},          {"zeta", info->zeta},
                {"mass", info->mass}, {"m_min", info->mMin}};
  for (size_t i = 0; i < sizeof fields / sizeof fields[0]; ++i) {
    fprintf(out, "%s\"%s\": ", i ? ", " : "{", fields[i].name);
    write_optional(out, fields[i].value);
  }
  fputc('}', out);
}

// At most this many pairs of material classes are written (a scene of many body sizes has many).
#define PD_OUTPUT_CONTACT_PAIRS_MAX 100

// The contact constants of every pair of material classes that can touch, named by two of their bodies.
static void write_contact_pairs(FILE* out, const pdModel* model) {
  int a[PD_OUTPUT_CONTACT_PAIRS_MAX], b[PD_OUTPUT_CONTACT_PAIRS_MAX];
  int total = pd_model_contact_class_pairs(model, a, b, PD_OUTPUT_CONTACT_PAIRS_MAX);
  int listed = total < PD_OUTPUT_CONTACT_PAIRS_MAX ? total : PD_OUTPUT_CONTACT_PAIRS_MAX;
  fputs("  \"contact_pairs\": [", out);
  for (int i = 0; i < listed; ++i) {
    pdPairContact p = pd_model_pair_contact(model, a[i], b[i]);
    fputs(i ? ",\n    {\"bodies\": [" : "\n    {\"bodies\": [", out);
    pdu_json_string(out, model->bodies[a[i]].name);
    fputs(", ", out);
    pdu_json_string(out, model->bodies[b[i]].name);
    fputs("], \"restitution_source\": ", out);
    pdu_json_string(out, p.restitutionSource);
    fprintf(out, ", \"damping\": {\"n\": \"%s\", \"t\": \"%s\"}", p.modalN ? "modal" : "explicit",
            p.modalT ? "modal" : "explicit");
    const struct {
      const char* name;
      double value;
    } fields[] = {{"mu", p.mu},           {"restitution", p.restitution}, {"zeta_n", p.zetaN}, {"zeta_t", p.zetaT},
                  {"kn", p.kn},           {"kt", p.kt},                   {"cn", p.cn},        {"ct", p.ct},
                  {"m_pair", p.massPair}, {"m_min", p.massMin},           {"period", p.period},
                  {"delta_max", p.deltaMax}};
    for (size_t k = 0; k < sizeof fields / sizeof fields[0]; ++k) {
      fprintf(out, ", \"%s\": ", fields[k].name);
      write_number(out, fields[k].value);
    }
    fputc('}', out);
  }
  fprintf(out, "%s],\n  \"contact_pairs_total\": %d,\n", listed ? "\n  " : "", total);
}

static const char* primitive_name(pdPrimitiveKind kind) {
  switch (kind) {
    case pd_primCube: return "cube";
    case pd_primPrism: return "prism";
    case pd_primTprism: return "tprism";
    case pd_primSphere: return "sphere";
    case pd_primHull: return "hull";
  }
  return "?";
}

static void write_body(FILE* out, const pdModel* model, int index) {
  const pdBody* b = &model->bodies[index];
  pdBodyContactInfo info = pd_model_body_contact_info(model, index);
  fputs("    {\"name\": ", out);
  pdu_json_string(out, b->name);
  fputs(", \"color\": ", out);
  pdu_json_string(out, b->color);
  fprintf(out, ", \"primitive\": \"%s\", \"fixed\": %s,\n", primitive_name(b->kind), b->fixed ? "true" : "false");
  fputs("     \"mass\": ", out);
  write_number(out, b->mass);
  fputs(", \"volume\": ", out);
  write_number(out, b->volume);
  fputs(", \"density\": ", out);
  write_number(out, b->density);
  fputs(", \"size\": ", out);
  write_number(out, b->size);
  fputs(",\n     \"geometric_centre\": ", out);
  write_vec(out, b->geometricCentre);
  fputs(", \"inertia\": ", out);
  write_mat(out, &b->inertia);
  fputs(",\n     \"principal_moments\": ", out);
  write_vec(out, (pdVec3){b->principal[0], b->principal[1], b->principal[2]});
  fputs(", \"principal_axes\": ", out);
  write_mat(out, &b->principalAxes);
  fputs(",\n     \"initial\": {\"x\": ", out);
  write_vec(out, b->x0);
  fputs(", \"q\": [", out);
  write_number(out, b->q0.w);
  fputc(',', out);
  write_vec(out, (pdVec3){b->q0.x, b->q0.y, b->q0.z});
  fputs("], \"v\": ", out);
  write_vec(out, b->v0);
  fputs(", \"w\": ", out);
  write_vec(out, b->w0);
  fputs("},\n     \"material\": {\"requested\": ", out);
  write_requested(out, &b->requested);
  fputs(",\n                  \"used\": ", out);
  write_used(out, &b->used, &info);
  fputs("},\n", out);
  if (b->hasForce) {
    // the scene's applied force, so a run directory says what pushed the body
    fputs("     \"applied_force\": {\"force\": ", out);
    write_vec(out, b->force0);
    fputs(", \"rate\": ", out);
    write_vec(out, b->forceRate);
    fputs(", \"point\": ", out);
    write_vec(out, b->forcePoint);
    fputs(", \"law\": \"F(t) = force + t rate (N, N/s, world frame) at point (m, body frame from the centre of "
          "mass)\"},\n", out);
  }
  // the shape in the body frame (origin at the centre of mass), for viewers and other engines
  fprintf(out, "     \"shape\": {\"V\": %d, \"E\": %d, \"F\": %d, \"vertices\": [", b->shape.vertexCount,
          b->shape.edgeCount, b->shape.faceCount);
  for (int v = 0; v < b->shape.vertexCount; ++v) {
    if (v) fputc(',', out);
    write_vec(out, b->shape.vertices[v]);
  }
  fputs("], \"faces\": [", out);
  for (int f = 0; f < b->shape.faceCount; ++f) {
    const pdFace* face = &b->shape.faces[f];
    fputs(f ? ",[" : "[", out);
    for (int i = 0; i < face->count; ++i) fprintf(out, i ? ",%d" : "%d", b->shape.faceVertices[face->first + i]);
    fputc(']', out);
  }
  fputs("]}}", out);
}

void pd_write_summary_json(FILE* out, const pdModel* model, const pdState* state, const pdRunInfo* info) {
  const pdSettings* s = &model->settings;
  fputs("{\n  \"engine\": ", out);
  pdu_json_string(out, info->engine);
  fputs(",\n  \"version\": \"" PD_VERSION "\",\n  \"scene\": ", out);
  pdu_json_string(out, model->scenePath);
  fputs(",\n  \"stepper\": ", out);
  pdu_json_string(out, info->stepper ? info->stepper : pd_stepper_name(state->stepper));
  if (!info->stepper) {  // the soft engine's own state: how contacts that begin inside a step join
    fputs(",\n  \"onsets\": ", out);
    pdu_json_string(out, pd_onsets_name(state->onsets));
    fputs(",\n  \"islands\": ", out);
    pdu_json_string(out, pd_islands_name(state->islands));
    // sleeping is a matter of the islands: with islands off there is one system, never at rest while any body moves
    fputs(",\n  \"sleep\": ", out);
    pdu_json_string(out, state->islands == pd_islandsOn && s->sleep ? "on" : "off");
  }
  fputs(",\n", out);
  if (info->engineSettingsJson) fprintf(out, "  \"engine_settings\": %s,\n", info->engineSettingsJson);
  fputs("  \"settings\": {\"gravity\": ", out);
  write_vec(out, s->gravity);
  const struct {
    const char* name;
    double value;
  } scalars[] = {{"tend", s->tend}, {"tol", s->tol},          {"dt", s->dt},     {"dtmin", s->dtmin},
                 {"dtmax", s->dtmax}, {"sample", s->sampleRate}, {"vmax", s->vmax}, {"deflection", s->deflection}};
  for (size_t i = 0; i < sizeof scalars / sizeof scalars[0]; ++i) {
    fprintf(out, ", \"%s\": ", scalars[i].name);
    write_number(out, scalars[i].value);
  }
  fprintf(out, ", \"vmax_estimated\": %s},\n", s->vmaxEstimated ? "true" : "false");
  fputs("  \"bodies\": [\n", out);
  for (int i = 0; i < model->bodyCount; ++i) {
    write_body(out, model, i);
    fputs(i + 1 < model->bodyCount ? ",\n" : "\n", out);
  }
  fputs("  ],\n", out);
  // the contact model's constants per pair of material classes, derived from the bodies' above; what the
  // §3.3 time-constant checks changed is listed after them, one line each, never silently
  write_contact_pairs(out, model);
  fprintf(out, "  \"material_classes\": %d, \"contact_period_min\": ", pd_model_material_class_count(model));
  write_number(out, pd_model_contact_period_min(model));
  fputs(",\n  \"adjustments\": [", out);
  char line[1024];
  for (int i = 0, count = pd_model_adjustment_count(model); i < count; ++i) {
    pd_model_adjustment_describe(model, i, line, sizeof line);
    fputs(i ? ",\n    " : "\n    ", out);
    pdu_json_string(out, line);
  }
  fprintf(out, "%s],\n  \"adjustments_dropped\": %d,\n", pd_model_adjustment_count(model) ? "\n  " : "",
          pd_model_adjustments_dropped(model));
  fprintf(out,
          "  \"counts\": {\"accepted_steps\": %ld, \"rejected_steps\": %ld, \"derivative_evaluations\": %ld, "
          "\"samples\": %ld, \"travel_retries\": %ld, \"onset_retries\": %ld, \"onset_cuts\": %ld, "
          "\"onsets_interpolated\": %ld, "
          "\"refinements\": %ld, \"stability_tight\": %ld, \"implicit_steps\": %ld, \"searches_skipped\": %ld, "
          "\"contacts_made\": %ld, "
          "\"contacts_virtual\": %ld, \"contacts_transferred\": %ld, \"breaks_force\": %ld, "
          "\"breaks_geometry\": %ld, \"contacts_at_end\": %d},\n",
          state->count.accepted, state->count.rejected, state->count.derivatives, state->count.samples,
          state->count.travelRetries, state->count.eventRetries, state->count.onsetCuts,
          state->count.onsetsInterpolated,
          state->count.refinements, state->count.stabilityTight, state->count.implicitSteps,
          state->count.searchesSkipped, state->count.contactsMade, state->count.contactsVirtual,
          state->count.contactsTransferred, state->count.breaksForce, state->count.breaksGeometry,
          pd_state_contact_count(state));
  if (!info->stepper) {  // the soft engine's own: what it located, what it corrected and what that may cost (docs/events.md)
    const pdCounters* c = &state->count;
    // what set the accepted steps' sizes: what the step count was spent on (docs/integration.md)
    fputs("  \"steps_limited_by\": {", out);
    for (int k = 0; k < pd_limitCount; ++k)
      fprintf(out, "%s\"%s\": %ld", k ? ", " : "", pd_step_limit_name((pdStepLimit)k), c->stepsLimited[k]);
    fputs("},\n", out);
    fprintf(out,
            "  \"events\": {\"onsets_located\": %ld, \"onsets_corrected\": %ld, \"onset_bound_max\": ",
            c->contactsMade + c->contactsVirtual - c->onsetsInterpolated, c->onsetsInterpolated);
    write_number(out, c->onsetBoundMax);
    fputs(", \"onset_bound_sum\": ", out);
    write_number(out, c->onsetBoundSum);
    fprintf(out, ", \"transitions_unlocated\": %ld, \"transition_bound_max\": ", c->transitionsUnlocated);
    write_number(out, c->transitionBoundMax);
    fputs(", \"transition_bound_sum\": ", out);
    write_number(out, c->transitionBoundSum);
    fprintf(out, ", \"releases_corrected\": %ld, \"release_bound_max\": ", c->releasesCorrected);
    write_number(out, c->releaseBoundMax);
    fputs(", \"release_bound_sum\": ", out);
    write_number(out, c->releaseBoundSum);
    fprintf(out, ", \"breaks\": %ld, \"history_kept\": %ld, \"body_seconds_asleep\": ", c->breaksForce + c->breaksGeometry,
            c->historyKept);
    write_number(out, c->bodySecondsAsleep);
    fprintf(out, ", \"implicit_steps\": %ld, \"explicit_steps\": %ld},\n", c->implicitSteps,
            c->accepted - c->implicitSteps);
  }
  if (!info->stepper && state->islands == pd_islandsOn) {  // the soft engine's islands only
    fprintf(out,
            "  \"island_counts\": {\"islands_formed\": %ld, \"largest_island\": %ld, \"island_intervals\": %ld, "
            "\"island_redos\": %ld, \"island_strays\": %ld, \"islands_slept\": %ld, \"islands_woken\": %ld, "
            "\"body_seconds_asleep\": ",
            state->count.islandsFormed, state->count.islandsLargest, state->count.islandIntervals,
            state->count.islandRedos, state->count.islandStrays, state->count.islandsSlept, state->count.islandsWoken);
    write_number(out, state->count.bodySecondsAsleep);
    fputs("},\n", out);
  }
  fputs("  \"warnings\": {", out);
  for (int w = 0; w < pd_warnCount; ++w) fprintf(out, "%s\"%s\": %ld", w ? ", " : "", pdWarningNames[w], state->warnings[w]);
  fputs("},\n  \"t_reached\": ", out);
  write_number(out, state->t);
  fprintf(out, ", \"completed\": %s,\n  \"energy\": {\"start\": ", info->completed ? "true" : "false");
  write_number(out, info->energyStart);
  fputs(", \"end\": ", out);
  write_number(out, info->energyEnd);
  // the energy is kinetic + gravitational + springs: the work of an applied force is not in it
  if (pd_model_has_applied_force(model)) fputs(", \"excludes_applied_work\": true", out);
  // timing last: the only part of a run directory that differs between two identical runs
  fputs("},\n  \"timing\": {", out);
  // the soft engine's threads change its wall time, never its numbers (islands.c, "Threads"): they belong here
  if (!info->stepper) fprintf(out, "\"threads\": %d, ", state->islands == pd_islandsOn ? state->threads : 1);
  fputs("\"wall_seconds\": ", out);
  write_number(out, info->wallSeconds);
  fputs(", \"stages\": {", out);
  for (int k = 0; k < pd_stageCount; ++k) {
    fprintf(out, "%s\"%s\": ", k ? ", " : "", pdStageNames[k]);
    // the integration stage is the step's time less a sampled estimate of the derivative's: never below zero
    write_number(out, fmax(0.0, state->stageSeconds[k]));
  }
  fputs("}}\n}\n", out);
}

// After the streams are closed (a stream's buffer must outlive it).
static void free_stream_buffers(pdRunWriter* run) {
  for (int k = 0; k < 2; ++k) {
    free(run->streamBuffers[k]);
    run->streamBuffers[k] = NULL;
  }
}

bool pd_run_finish(pdRunWriter* run, const pdModel* model, const pdState* state, const pdRunInfo* info, pdError* err) {
  writer_stop(run, false);
  bool ok = !atomic_load(&run->ioError) && !ferror(run->trajectory) && !ferror(run->contacts);
  ok = (fclose(run->trajectory) == 0) && ok;
  ok = (fclose(run->contacts) == 0) && ok;
  run->trajectory = NULL;
  run->contacts = NULL;
  free_stream_buffers(run);
  char* path = pdu_path_join(run->tmp, "summary.json");
  FILE* out = ok ? fopen(path, "w") : NULL;
  free(path);
  if (out) {
    pd_write_summary_json(out, model, state, info);
    ok = !ferror(out);
    ok = (fclose(out) == 0) && ok;
  } else {
    ok = false;
  }
  if (ok) {
    // replace a previous run directory: move it aside, move ours in, then delete the old one
    struct stat st;
    char* old = NULL;
    if (stat(run->dir, &st) == 0) {
      old = pdu_path_suffix(run->dir, ".old-XXXXXX");
      ok = mkdtemp(old) != NULL && rename(run->dir, old) == 0;
    }
    ok = ok && rename(run->tmp, run->dir) == 0;
    if (old) {
      if (ok) pdu_remove_tree(old);
      free(old);
    }
  }
  if (!ok) {
    pd_error_set(err, run->dir, 0, 0, "cannot write the run directory: %s", strerror(errno));
    pd_run_abort(run);
    return false;
  }
  free(run->dir);
  free(run->tmp);
  free(run);
  return true;
}

void pd_run_abort(pdRunWriter* run) {
  if (!run) return;
  writer_stop(run, true);
  if (run->trajectory) fclose(run->trajectory);
  if (run->contacts) fclose(run->contacts);
  free_stream_buffers(run);
  pdu_remove_tree(run->tmp);
  free(run->dir);
  free(run->tmp);
  free(run);
}
