// polydyn gedanken — the catalogue: every experiment, in the order results are written; the names of the engines,
// statuses and kinds of experiment; which engine and variant judge an experiment (the suite and the work-precision
// runs both ask).
#include "gedanken_internal.h"

const char* const pdGkEngineNames[pd_gkEngineCount] = {"soft", "ode", "bullet"};
const char* const pdGkStatusNames[] = {"PASS", "FAIL", "REFUSED", "NOT_BUILT", "ERROR", "NOT_APPLICABLE"};
const char* const pdGkKindNames[] = {"law", "model_prediction"};

bool pd_gk_engine_named(const char* name, pdGkEngine* engine) {
  for (int e = 0; e < pd_gkEngineCount; ++e) {
    if (strcmp(name, pdGkEngineNames[e]) == 0) {
      *engine = (pdGkEngine)e;
      return true;
    }
  }
  return false;
}

unsigned pd_gk_variant_bit(pdGkEngine engine, bool matched) {
  switch (engine) {
    case pd_gkSoft: return PD_GK_SOFT;
    case pd_gkOde: return matched ? PD_GK_ODE_MATCHED : PD_GK_ODE_NATIVE;
    case pd_gkBullet: return matched ? PD_GK_BULLET_MATCHED : PD_GK_BULLET_NATIVE;
    default: PD_ASSERT(!"no such engine"); return 0;
  }
}

bool pd_gk_applies(const pdGkExperiment* e, pdGkEngine engine, bool matched) {
  return e->kind == pd_gkLaw || (e->appliesTo & pd_gk_variant_bit(engine, matched)) != 0;
}

static const pdGkExperiment* const catalogue[] = {
    &pd_gk_a1_restitution, &pd_gk_a2_restitution_contacts, &pd_gk_a3_sinkage, &pd_gk_a4_elastic_apex,
    &pd_gk_b1_incline_slide, &pd_gk_b1_incline_stick, &pd_gk_b2_stopping_distance, &pd_gk_b2_stop_time,
    &pd_gk_b2_friction_cone, &pd_gk_b3_ramp_onset, &pd_gk_b4_block_on_block, &pd_gk_b5_tip_or_slide,
    &pd_gk_b6_slide_spin, &pd_gk_c1_bounce_apex, &pd_gk_c2_momentum, &pd_gk_c3_eccentric_bar,
    &pd_gk_c4_velocity_exchange, &pd_gk_c5_oblique_impact, &pd_gk_c6_energy_gain, &pd_gk_d1_rimless_wheel,
    &pd_gk_d2_slide_to_roll, &pd_gk_d3_tumbling_cube, &pd_gk_d3_landing_energy, &pd_gk_e1_painleve,
    &pd_gk_e2_side_load_pitch, &pd_gk_f1_top_precession, &pd_gk_f2_euler_disk, &pd_gk_g1_stack_drift,
    &pd_gk_g1_stack_sinkage, &pd_gk_g2_domino, &pd_gk_g3_pushed_load,
};

int pd_gk_experiment_count(void) { return (int)(sizeof catalogue / sizeof catalogue[0]); }

const pdGkExperiment* pd_gk_experiment(int index) {
  PD_ASSERT(index >= 0 && index < pd_gk_experiment_count());
  return catalogue[index];
}

const pdGkExperiment* pd_gk_find(const char* name) {
  for (int i = 0; i < pd_gk_experiment_count(); ++i)
    if (strcmp(catalogue[i]->name, name) == 0) return catalogue[i];
  return NULL;
}

void pd_gk_input_label(const pdGkExperiment* e, double input, char* buf, int size) {
  if (e->inputName)
    snprintf(buf, (size_t)size, "%s=%g", e->inputName, input);
  else if (size > 0)
    buf[0] = '\0';
}
