// polydyn — a state's contacts as the caller and the steppers see them: how many, each one's read-out
// (pd_state_contact, state.h), and how many the state's vectors hold (state_layout.h).
#include "polydyn/state.h"

#include "contact_force.h"
#include "contact_list.h"
#include "state_layout.h"

int pd_state_contact_room(const pdModel* model, const pdState* s) {
  return (s->capacity - spring_base(model)) / PD_CONTACT_STATE_SIZE;
}

int pd_state_contact_count(const pdState* s) { return s->contacts ? s->contacts->count : 0; }

pdContactReport pd_state_contact(const pdState* s, int i) {
  PD_ASSERT(s->contacts != NULL && i >= 0 && i < s->contacts->count);
  pd_contact_set_settle(s->contacts, s->y);  // a presented state's contacts are evaluated at their first read
  const contactSlot* c = &s->contacts->items[i];
  pdContactReport r;
  r.bodyA = c->id.body1;
  r.bodyB = c->id.body2;
  r.edgeEdge = c->id.kind == pd_contactEE;
  r.featureA = c->id.feat1;
  r.featureB = c->id.feat2;
  r.point = c->point;
  r.normal = c->normal;
  r.depth = c->depth;
  bool pulls = pd_contact_force_pulls(&c->force);
  r.fn = pulls ? 0.0 : c->force.fn;
  r.ft = pulls ? (pdVec3){0, 0, 0} : c->force.ft;
  r.slip = c->force.slip;
  r.springScale = c->loadScale;
  return r;
}
