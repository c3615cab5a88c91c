// polydyn refcheck — the driver shared by the reference engines: step, sample, write the run directory.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <time.h>

#include "pdref/refcheck.h"
#include "pdutil/clock.h"


extern const pdRefAdapter pd_ode_adapter;
extern const pdRefAdapter pd_bullet_adapter;

static const pdRefAdapter* const adapters[] = {
#ifdef PD_HAVE_ODE_ADAPTER
    &pd_ode_adapter,
#endif
#ifdef PD_HAVE_BULLET_ADAPTER
    &pd_bullet_adapter,
#endif
    NULL};

const pdRefAdapter* pd_ref_adapter(const char* name) {
  for (int i = 0; adapters[i]; ++i)
    if (strcmp(adapters[i]->name, name) == 0) return adapters[i];
  return NULL;
}

// Writes body states into the state vector's body part (layout: engine/include/polydyn/state.h).
static void store_bodies(const pdModel* model, const pdRefAdapter* adapter, const pdRefWorld* world,
                         pdState* state) {
  for (int i = 0; i < model->movingCount; ++i) {
    pdBodyState b = adapter->body(world, i);
    double* y = state->y + (size_t)i * PD_BODY_STATE_SIZE;
    const double values[PD_BODY_STATE_SIZE] = {b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z, b.x.x,
                                               b.x.y, b.x.z, b.q.w, b.q.x, b.q.y, b.q.z};
    memcpy(y, values, sizeof values);
  }
}

static bool bodies_finite(const pdState* state, int movingCount) {
  for (int i = 0; i < movingCount * PD_BODY_STATE_SIZE; ++i)
    if (!isfinite(state->y[i])) return false;
  return true;
}

// Step actually used and samples per step: the step is shortened to divide the sample interval so every
// sample falls on a step; a step longer than the interval makes every step a sample.
typedef struct sampling {
  double step;            // s
  long stepsPerSample;    // >= 1
  double sampleInterval;  // s
} sampling;

static sampling plan_sampling(double requestedStep, double sampleRate) {
  double interval = 1.0 / sampleRate;
  sampling s = {requestedStep, 1, interval};
  if (requestedStep <= interval * (1.0 + 1e-12)) {
    s.stepsPerSample = (long)ceil(interval / requestedStep * (1.0 - 1e-12));
    s.step = interval / (double)s.stepsPerSample;
  } else {
    s.sampleInterval = requestedStep;
  }
  return s;
}

// The engine's contacts at a sample for options->contactObserver: their mode from the slip speed of the point.
typedef struct contactBuffer {
  pdContactReport* items;
  int capacity;
} contactBuffer;

pdVec3 pd_ref_point_velocity(const pdModel* model, const pdState* state, int body, pdVec3 p) {
  pdBodyState b = pd_state_body(model, state, body);
  return pd_v3_add(b.v, pd_v3_cross(b.w, pd_v3_sub(p, b.x)));
}

static void report_contacts(const pdModel* model, const pdRefAdapter* adapter, const pdRefWorld* world,
                            const pdRefOptions* options, const pdState* state, contactBuffer* buffer) {
  int count = adapter->contacts(world, buffer->items, buffer->capacity);
  if (count > buffer->capacity) {  // grown to the most contacts seen: a sample's work, not a step's
    buffer->capacity = 2 * count;
    buffer->items = realloc(buffer->items, (size_t)buffer->capacity * sizeof *buffer->items);
    if (!buffer->items) abort();
    count = adapter->contacts(world, buffer->items, buffer->capacity);
  }
  for (int i = 0; i < count; ++i) {
    pdContactReport* c = &buffer->items[i];
    pdVec3 rel = pd_v3_sub(pd_ref_point_velocity(model, state, c->bodyA, c->point),
                           pd_ref_point_velocity(model, state, c->bodyB, c->point));
    c->slip = pd_v3_norm(pd_v3_sub(rel, pd_v3_scale(c->normal, pd_v3_dot(rel, c->normal)))) > PD_REF_SLIP_SPEED;
  }
  options->contactObserver(model, state, buffer->items, count, options->contactUser);
}

bool pd_ref_run(const pdModel* model, const pdRefAdapter* adapter, const pdRefOptions* options,
                pdRunWriter* writer, pdObserverFcn* observer, void* user, pdRefRunStats* stats, pdError* err) {
  PD_ASSERT(model && adapter && options && stats && options->step > 0.0);
  memset(stats, 0, sizeof *stats);
  sampling plan = plan_sampling(options->step, model->settings.sampleRate);
  // The harness's own state (the samples handed to the observer) is made before the clock starts: the span is
  // the engine's, from its world created out of the compiled model to the last sample, as a soft run's from
  // pd_state_create to the end of pd_advance (docs/validation.md, "The cost's span").
  pdState* state = pd_state_create(model, NULL);
  double energyStart = pd_state_energy(model, state);
  double wall0 = pd_wall_seconds(), cpu0 = pd_thread_cpu_seconds();
  pdRefWorld* world = adapter->create(model, options, err);
  if (!world) {
    pd_state_free(state);
    stats->refused = true;
    if (writer) pd_run_abort(writer);
    return false;
  }
  double tend = model->settings.tend;
  long sampleCount = (long)floor(tend / plan.sampleInterval * (1.0 + 1e-12));
  bool ok = true, stopped = false;
  contactBuffer contacts = {0};
  for (long k = 0; k <= sampleCount && ok && !stopped; ++k) {
    if (k > 0) {
      for (long j = 0; j < plan.stepsPerSample; ++j) {
        if (!adapter->step(world, plan.step)) {
          ok = false;
          break;
        }
        ++stats->steps;
        int contacts = adapter->contact_count(world);
        if (contacts > 0) ++stats->contactSteps;
        if (contacts > stats->maxContacts) stats->maxContacts = contacts;
      }
    }
    state->t = (double)k * plan.sampleInterval;
    store_bodies(model, adapter, world, state);
    if (!ok || !bodies_finite(state, model->movingCount)) {
      ok = false;
      break;
    }
    ++state->count.samples;
    if (writer && !pd_run_observe(model, state, writer)) stopped = true;
    if (observer && !observer(model, state, user)) stopped = true;
    if (options->contactObserver && adapter->contacts) report_contacts(model, adapter, world, options, state, &contacts);
  }
  free(contacts.items);
  if (writer) pd_run_drain(writer);  // the samples printed by the writer thread count too (engine/src/output.c)
  stats->wallSeconds = pd_wall_seconds() - wall0;
  stats->cpuSeconds = pd_thread_cpu_seconds() - cpu0;
  stats->completed = ok && !stopped;
  state->count.accepted = stats->steps;

  if (stopped) {  // the caller asked to stop (an interrupt): leave nothing behind
    double t = state->t;
    adapter->destroy(world);
    pd_state_free(state);
    if (writer) pd_run_abort(writer);
    pd_error_set(err, model->scenePath, 0, 0, "stopped at t = %.6g s; nothing written", t);
    return false;
  }
  char* settings = NULL;
  size_t settingsSize = 0;
  FILE* mem = open_memstream(&settings, &settingsSize);
  if (!mem) abort();
  fprintf(mem, "{\"engine\": \"%s\", \"library_version\": \"%s\", \"variant\": \"%s\", \"step_requested\": %.17g, "
          "\"step_used\": %.17g, \"sample_interval_used\": %.17g, \"steps\": %ld, \"steps_with_contact\": %ld, "
          "\"max_contacts\": %ld, ",
          adapter->name, adapter->version, options->variant == pd_refMatched ? "matched" : "native", options->step,
          plan.step, plan.sampleInterval, stats->steps, stats->contactSteps, stats->maxContacts);
  if (pd_model_has_applied_force(model)) fputs("\"applied_force\": \"" PD_REF_APPLIED_FORCE_SAMPLING "\", ", mem);
  fputs("\"adapter\": ", mem);
  adapter->settings_json(world, mem);
  fputc('}', mem);
  fclose(mem);
  adapter->destroy(world);

  char stepper[64];
  snprintf(stepper, sizeof stepper, "%s-%s", adapter->name, options->variant == pd_refMatched ? "matched" : "native");
  char engine[64];
  snprintf(engine, sizeof engine, "%s", adapter->name);
  pdRunInfo info = {.engine = engine,
                    .energyStart = energyStart,
                    .energyEnd = pd_state_energy(model, state),
                    .wallSeconds = stats->wallSeconds,
                    .completed = stats->completed,
                    .stepper = stepper,
                    .engineSettingsJson = settings};
  if (!ok) state->failed = true;
  bool written = writer ? pd_run_finish(writer, model, state, &info, err) : true;
  free(settings);
  pd_state_free(state);
  return written;
}
