#pragma once
#include "contact_force.h"
#include "polydyn/model.h"
// Contact parameters of a contact whose body 1 is `body1` and body 2 is `body2` (model body indices,
// not both fixed). Side labels follow the arguments (k1n is body1's side). O(1), no allocation.
pdContactParams pd_model_contact_params(const pdModel* model, int body1, int body2);
// Shortest contact period of the scene over all class pairs that can touch, s: min over pairs of
// 2π sqrt(m_min / k_s) with m_min the pair's minimum effective mass (both sides in series) and k_s =
// k1n k2n/(k1n+k2n) (normal; the same with kt when the pair has friction). INFINITY when nothing can touch,
// NAN past PD_MATERIAL_PERIOD_CLASSES classes (not computed). Reported in summary.json and check.
double pd_model_contact_period_min(const pdModel* model);

// ---------------------------------------------------------------- for pd_model_compile only
// (model_materials.c)

// Derives every body's material (body->used) and the material-class table from the scene's requests and
// the model's settings (vmax, deflection, dtmin), which must be final. Returns false and fills err at the
// object's line for an unreachable restitution or any other material the contact model refuses.
bool pd_model_build_materials(pdModel* model, const pdScene* scene, pdError* err);

void pd_material_table_free(struct pdMaterialTable* table);

// A table for a model made of some of `table`'s bodies (islands.c): body i of the new model is body bodies[i]
// of the old (0 <= i < count), with its class and contact info; the classes, pair constants and adjustments
// are shared with `table`, which must outlive the view. Freed by pd_material_table_free.
struct pdMaterialTable* pd_material_table_view(const struct pdMaterialTable* table, const int* bodies, int count);
