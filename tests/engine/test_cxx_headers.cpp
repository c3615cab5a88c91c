// The public headers are usable from C++ (polydyn/api.h: PD_EXTERN_C_BEGIN/END): every one compiles as C++17 with
// -Wpedantic, and their functions link with C names — a call through a header without the guards would look for a
// C++-mangled symbol and fail to link.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

extern "C" {  // cmocka 1.1's header declares its functions without C linkage
#include <cmocka.h>
}

#include <cmath>
#include <cstring>

#include "polydyn/api.h"
#include "polydyn/error.h"
#include "polydyn/model.h"
#include "polydyn/output.h"
#include "polydyn/polyhedron.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"
#include "polydyn/vecmath.h"

static void test_a_cxx_program_links_and_steps_a_scene(void** unused) {
  (void)unused;
  assert_string_equal(pd_version(), PD_EXPECTED_VERSION);
  pdVec3 v = pd_v3_cross(pd_v3(1, 0, 0), pd_v3(0, 1, 0));  // x × y = z
  assert_true(v.x == 0 && v.y == 0 && v.z == 1);
  static const char text[] =
      "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\ncube block red 0.1 0.1 0.1\nloc 0 0 0.2\n";
  pdError err;
  pdScene* scene = pd_scene_parse_buffer("cxx", text, std::strlen(text), &err);
  assert_non_null(scene);
  pdModel* model = pd_model_compile(scene, &err);
  assert_non_null(model);
  pdState* state = pd_state_create(model, NULL);
  assert_true(pd_advance(model, state, 0.1, nullptr, nullptr));
  // 0.1 s of free fall from rest, 0.2 m up: z = 0.2 m + g t² / 2 (g < 0); 1 µm is far above the stepper's error
  pdBodyState b = pd_state_body(model, state, 1);
  assert_true(std::fabs(b.x.z - (0.2 + 0.5 * PD_DEFAULT_GRAVITY_Z * 0.01)) < 1e-6);
  pd_state_free(state);
  pd_model_free(model);
  pd_scene_free(scene);
}

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_cxx_program_links_and_steps_a_scene),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
