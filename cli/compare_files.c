// polydyn compare — series.csv, impacts.csv, friction.csv and divergence.csv (see compare_files.h).
#include "compare_files.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pdutil/csv.h"

static const char* body_name(const pdModel* model, int movingIndex) {
  return model->bodies[model->movingBodies[movingIndex]].name;
}

static FILE* open_in(const char* dir, const char* name) {
  char path[8192];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  return fopen(path, "w");
}

static bool close_checked(FILE* out, bool ok) {
  ok = !ferror(out) && ok;
  return fclose(out) == 0 && ok;
}

static void write_series(FILE* out, const pdModel* model, const pdCompareRunData* run, const pdTrajectory* reference) {
  const pdTrajectory* tr = run->trajectory;
  long stride = (tr->samples + PD_COMPARE_SERIES_SAMPLES - 1) / PD_COMPARE_SERIES_SAMPLES;
  if (stride < 1) stride = 1;
  long* index = malloc((size_t)(tr->samples / stride + 2) * sizeof *index);
  if (!index) abort();
  long count = 0;
  for (long s = 0; s < tr->samples; s += stride) index[count++] = s;
  if (count && index[count - 1] != tr->samples - 1) index[count++] = tr->samples - 1;
  pdBodySample* samples = pd_compare_body_samples(model, tr, reference, index, count);
  bool tallied = run->contacts && run->contacts->samples == tr->samples;
  int m = tr->movingCount;
  for (int k = 0; k < m; ++k)
    for (long i = 0; i < count; ++i) {
      const pdBodySample* b = &samples[(size_t)i * (size_t)m + (size_t)k];
      fprintf(out, "%s,%s,", run->engine, run->variant);
      pdu_csv_text(out, body_name(model, k));
      fprintf(out, ",%.9g,", tr->t[index[i]]);
      const double values[] = {b->posErr, b->rotErr, b->energy, b->penetration};
      for (size_t v = 0; v < sizeof values / sizeof values[0]; ++v) {
        pdu_csv_number(out, values[v], 9);
        fputc(',', out);
      }
      if (tallied) {
        const pdContactTally* c = &run->contacts->tallies[(size_t)index[i] * (size_t)m + (size_t)k];
        fprintf(out, "%d,", c->contacts);
        pdu_csv_number(out, c->normalForce, 9);
        fputc(',', out);
        pdu_csv_number(out, c->slipSpeed, 9);
      } else {
        fputs(",,", out);
      }
      fputc('\n', out);
    }
  free(samples);
  free(index);
}

static void write_impact_rows(FILE* out, const char* scene, const pdModel* model, const pdCompareRunData* run,
                              const pdImpact* impacts, int count) {
  for (int i = 0; i < count; ++i) {
    const pdImpact* p = &impacts[i];
    pdu_csv_text(out, scene);
    fprintf(out, ",%s,%s,%d,", run->engine, run->variant, i);
    pdu_csv_text(out, model->bodies[p->bodyA].name);
    fputc(',', out);
    pdu_csv_text(out, model->bodies[p->bodyB].name);
    const double values[] = {p->t, p->vnBefore, p->vnAfter, p->restitution, p->restitutionRequested, p->tangentialChange};
    for (size_t v = 0; v < sizeof values / sizeof values[0]; ++v) {
      fputc(',', out);
      pdu_csv_number(out, values[v], 9);
    }
    fputc(',', out);
    if (p->match >= 0) fprintf(out, "%d", p->match);
    fputc('\n', out);
  }
}

static void write_friction(FILE* out, const pdModel* model, const pdCompareRunData* run) {
  const pdContactLog* log = run->contacts;
  if (!log || log->points == 0) return;
  long stride = (log->points + PD_COMPARE_FRICTION_POINTS - 1) / PD_COMPARE_FRICTION_POINTS;
  for (long i = 0; i < log->points; i += stride) {
    const pdFrictionPoint* p = &log->friction[i];
    fprintf(out, "%s,%s,%.9g,", run->engine, run->variant, p->t);
    pdu_csv_text(out, model->bodies[p->bodyA].name);
    fputc(',', out);
    pdu_csv_text(out, model->bodies[p->bodyB].name);
    fprintf(out, ",%.9g,%.9g,%.9g,%s\n", p->fn, p->ft, p->slipSpeed, p->slip ? "slip" : "stick");
  }
}

static const char* verdict(const pdDivergence* d, bool isChaos) {
  if (isChaos) return "own_divergence";
  if (!d->diverged) return "agrees";
  return isnan(d->beyondChaos) ? "chaos" : "model";
}

static void write_divergence_row(FILE* out, const char* scene, const pdModel* model, const pdCompareRunData* run,
                                 const pdDivergence* d, double horizon, bool isChaos, bool chaosKnown) {
  pdu_csv_text(out, scene);
  fprintf(out, ",%s,%s,%g,%g,", run->engine, run->variant, PD_COMPARE_DIVERGENCE_THRESHOLD, PD_COMPARE_CHAOS_FACTOR);
  if (d->diverged) {
    fprintf(out, "%.9g,", d->t);
    pdu_csv_text(out, body_name(model, d->body));
    fprintf(out, ",%s,%.9g,", d->rotation ? "rotation" : "position", d->error);
  } else {
    fputs(",,,,", out);
  }
  pdu_csv_number(out, horizon, 9);
  fputc(',', out);
  if (!isChaos) pdu_csv_number(out, d->beyondChaos, 9);
  // without a chaos run nothing tells chaos from model
  fprintf(out, ",%s\n", chaosKnown || !d->diverged || isChaos ? verdict(d, isChaos) : "unknown");
}

bool pd_compare_write_details(const char* dir, const char* scene, const pdModel* model, const pdCompareRunData* runs,
                              int count, int chaos, pdDivergence* divergences) {
  const pdTrajectory* reference = runs[0].trajectory;
  const pdTrajectory* chaosTrajectory = chaos > 0 ? runs[chaos].trajectory : NULL;
  divergences[0] = (pdDivergence){.t = NAN, .error = NAN, .beyondChaos = NAN};
  for (int i = 1; i < count; ++i)
    divergences[i] = pd_compare_divergence(model, runs[i].trajectory, reference,
                                           i == chaos ? NULL : chaosTrajectory, PD_COMPARE_DIVERGENCE_THRESHOLD);
  double horizon = chaos > 0 && divergences[chaos].diverged ? divergences[chaos].t : NAN;

  bool ok = true;
  FILE* out = open_in(dir, "series.csv");
  if (!out) return false;
  fputs("engine,variant,body,t,pos_err,rot_err_rad,energy,max_penetration_over_size,contacts,normal_force,"
        "slip_speed\n", out);
  for (int i = 0; i < count; ++i) write_series(out, model, &runs[i], i == 0 ? NULL : reference);
  if (!close_checked(out, ok)) return false;

  if (!(out = open_in(dir, "impacts.csv"))) return false;
  fputs("scene,engine,variant,impact,body_a,body_b,t,vn_before,vn_after,restitution,restitution_requested,"
        "tangential_speed_change,reference_impact\n", out);
  pdImpact* referenceImpacts = NULL;
  int referenceCount = pd_compare_impacts(model, reference, &referenceImpacts);
  for (int i = 0; i < referenceCount; ++i) referenceImpacts[i].match = i;
  write_impact_rows(out, scene, model, &runs[0], referenceImpacts, referenceCount);
  for (int i = 1; i < count; ++i) {
    pdImpact* impacts = NULL;
    int n = pd_compare_impacts(model, runs[i].trajectory, &impacts);
    pd_compare_match_impacts(impacts, n, referenceImpacts, referenceCount);
    write_impact_rows(out, scene, model, &runs[i], impacts, n);
    free(impacts);
  }
  free(referenceImpacts);
  if (!close_checked(out, ok)) return false;

  if (!(out = open_in(dir, "friction.csv"))) return false;
  fputs("engine,variant,t,body_a,body_b,fn,ft,slip_speed,mode\n", out);
  for (int i = 0; i < count; ++i) write_friction(out, model, &runs[i]);
  if (!close_checked(out, ok)) return false;

  if (!(out = open_in(dir, "divergence.csv"))) return false;
  fputs("scene,engine,variant,threshold,chaos_factor,first_t,first_body,first_kind,first_error,chaos_horizon,beyond_chaos_from,"
        "verdict\n", out);
  for (int i = 1; i < count; ++i)
    write_divergence_row(out, scene, model, &runs[i], &divergences[i], horizon, i == chaos, chaos > 0);
  return close_checked(out, ok);
}
