#pragma once
#include "contact_force.h"
#include "polydyn/model.h"
// Contact parameters of a contact whose body 1 is `body1` and body 2 is `body2` (model body indices,
// not both fixed). Side labels follow the arguments (k1n is body1's side). O(1), no allocation.
pdContactParams pd_model_contact_params(const pdModel* model, int body1, int body2);
// Shortest contact time constant of the scene over all class pairs that can touch, s: min over pairs of
// 2π sqrt(mMinPair / kSeries) with mMinPair the smaller of the two sides' mMin and kSeries = k1n k2n/(k1n+k2n)
// (normal; same with kt if both kt > 0). INFINITY when nothing can touch. Used to size step refinement.
double pd_model_contact_period_min(const pdModel* model);

// ---------------------------------------------------------------- for pd_model_compile only
// (model_materials.c)

// Derives every body's material (body->used) and the material-class table from the scene's requests and
// the model's settings (vmax, deflection, dtmin), which must be final. Returns false and fills err at the
// object's line for an unreachable restitution or any other material the contact model refuses.
bool pd_model_build_materials(pdModel* model, const pdScene* scene, pdError* err);

void pd_material_table_free(struct pdMaterialTable* table);
