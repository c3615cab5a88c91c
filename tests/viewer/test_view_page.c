// The page generator's C API as a report uses it (viewer/include/pdview/view.h): several replays in
// one page sharing one copy of the bundle; the data block round-trips exactly (float64 poses).
//
// Writes PD_BINARY_DIR/tests/viewer/report.html, which the browser test opens (CTest fixture).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <cmocka.h>

#include "pdview/view.h"
#include "test_files.h"

static const char* const summary =
    "{\"engine\": \"polydyn-soft\", \"scene\": \"synthetic.scene\", \"settings\": {\"gravity\": [0, 0, -9.81]},\n"
    " \"completed\": true, \"bodies\": [\n"
    "  {\"name\": \"floor\", \"color\": \"grey\", \"fixed\": true, \"mass\": 10, \"size\": 1,\n"
    "   \"inertia\": [[1,0,0],[0,1,0],[0,0,1]], \"initial\": {\"x\": [0,0,-0.05], \"q\": [1,[0,0,0]]},\n"
    "   \"shape\": {\"vertices\": [[-1,-1,-0.05],[1,-1,-0.05],[-1,1,-0.05],[1,1,-0.05],[-1,-1,0.05],[1,-1,0.05],"
    "[-1,1,0.05],[1,1,0.05]],\n"
    "   \"faces\": [[0,1,5,4],[0,2,3,1],[0,4,6,2],[1,3,7,5],[2,6,7,3],[4,5,7,6]]}},\n"
    "  {\"name\": \"cube\", \"color\": \"88aaff\", \"fixed\": false, \"mass\": 1, \"size\": 0.1,\n"
    "   \"inertia\": [[0.001,0,0],[0,0.001,0],[0,0,0.001]], \"initial\": {\"x\": [0,0,1], \"q\": [1,[0,0,0]]},\n"
    "   \"shape\": {\"vertices\": [[-0.05,-0.05,-0.05],[0.05,-0.05,-0.05],[-0.05,0.05,-0.05],[0.05,0.05,-0.05],"
    "[-0.05,-0.05,0.05],[0.05,-0.05,0.05],[-0.05,0.05,0.05],[0.05,0.05,0.05]],\n"
    "   \"faces\": [[0,1,5,4],[0,2,3,1],[0,4,6,2],[1,3,7,5],[2,6,7,3],[4,5,7,6]]}}]}\n";

// x of the cube at sample k: a value with every mantissa bit in use, to see float64 survive the page
static double cube_x(int k) { return 0.1 * k + 1.0 / 3.0; }

static void write_text(const char* path, const char* text) {
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
}

static void make_run(const char* dir, const char* engine) {
  mkdir(dir, 0777);
  char path[1024];
  snprintf(path, sizeof path, "%s/summary.json", dir);
  char* text = strdup(summary);
  char* at = strstr(text, "polydyn-soft");
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  fprintf(f, "%.*s%s%s", (int)(at - text), text, engine, at + strlen("polydyn-soft"));
  fclose(f);
  free(text);
  snprintf(path, sizeof path, "%s/trajectory.csv", dir);
  f = fopen(path, "w");
  assert_non_null(f);
  fputs("t,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n", f);
  for (int k = 0; k <= 10; ++k) fprintf(f, "%.17g,cube,%.17g,0,%.17g,1,0,0,0,1,0,0,0,0,0\n", 0.1 * k, cube_x(k), 1.0 - 0.05 * k);
  fclose(f);
  snprintf(path, sizeof path, "%s/contacts.csv", dir);
  write_text(path, "t,body_a,body_b,kind,feat_a,feat_b,px,py,pz,nx,ny,nz,fn,ftx,fty,ftz,mode\n"
                   "0.5,cube,floor,VF,0,5,0,0,0,0,0,1,9.81,0,0,0,stick\n");
}

// The bytes of `path` as a string.
static char* read_all(const char* path) {
  size_t size;
  return test_read_file(path, &size);
}

static int count(const char* text, const char* needle) {
  int n = 0;
  for (const char* p = strstr(text, needle); p; p = strstr(p + 1, needle)) ++n;
  return n;
}

static int base64_value(char c) {
  const char* a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const char* p = strchr(a, c);
  return p && c ? (int)(p - a) : -1;
}

// Decodes the base64 text from `s` up to '<' into out; returns the byte count.
static size_t base64_decode(const char* s, unsigned char* out, size_t cap) {
  size_t n = 0;
  uint32_t acc = 0;
  int bits = 0;
  for (; *s && *s != '<'; ++s) {
    int v = base64_value(*s);
    if (v < 0) continue;  // '=' padding
    acc = acc << 6 | (uint32_t)v;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      if (n < cap) out[n] = (unsigned char)(acc >> bits & 0xff);
      ++n;
    }
  }
  return n;
}

static void report_page_shares_one_bundle_and_keeps_poses_exact(void** state) {
  (void)state;
  char dir[1024], soft[1100], ghost[1100], page[1100];
  snprintf(dir, sizeof dir, "%s/tests/viewer", PD_BINARY_DIR);
  snprintf(soft, sizeof soft, "%s/report-soft", dir);
  snprintf(ghost, sizeof ghost, "%s/report-ode", dir);
  snprintf(page, sizeof page, "%s/report.html", dir);
  make_run(soft, "polydyn-soft");
  make_run(ghost, "ode");
  pdError err = {0};
  pdViewRun* a = pd_view_run_load(soft, &err);
  assert_non_null(a);
  pdViewRun* b = pd_view_run_load(ghost, &err);
  assert_non_null(b);
  assert_true(pd_view_runs_compatible(a, b, &err));
  assert_true(pd_view_run_t_last(a) == 1.0);

  // a report: text, experiment 1 (one run), text, experiment 2 (two runs overlaid), the bundle once
  FILE* out = fopen(page, "w");
  assert_non_null(out);
  pd_view_write_head(out, "Gedanken report <test>");
  fputs("<h1>Report</h1><p>Experiment 1</p>\n", out);
  pdViewRun* one[] = {a};
  assert_true(pd_view_write_replay(out, "exp1", "Experiment 1: soft", one, 1, false, &err));
  fputs("<p>Experiment 2</p>\n", out);
  pdViewRun* two[] = {a, b};
  assert_true(pd_view_write_replay(out, "exp2", "Experiment 2: soft and ode", two, 2, false, &err));
  bool bundled = pd_view_write_bundle(out, &err);
  pd_view_write_tail(out);
  fclose(out);
  if (!bundled) {
    pd_view_run_free(a);
    pd_view_run_free(b);
    fail_msg("the bundle is not built (viewer/scripts/setup): %s", err.message);
  }

  char* html = read_all(page);
  assert_int_equal(count(html, "<section class=\"pd-replay\""), 2);
  assert_int_equal(count(html, "\n<script>\n"), 1);
  assert_int_equal(count(html, "type=\"application/octet-stream\""), 3);
  assert_int_equal(count(html, "Gedanken report &lt;test&gt;"), 1);
  // the data block of experiment 1: t[0..10] then the poses, float64, bit for bit
  const char* block = strstr(html, "id=\"pd-replay-exp1-run-0\">");
  assert_non_null(block);
  block = strchr(block, '>') + 1;
  unsigned char bytes[4096];
  size_t n = base64_decode(block, bytes, sizeof bytes);
  assert_true(n >= 11 * 8 + 11 * 7 * 8);
  for (int k = 0; k <= 10; ++k) {
    double t, x;
    memcpy(&t, bytes + 8 * k, 8);
    memcpy(&x, bytes + 11 * 8 + 7 * 8 * k, 8);
    assert_true(t == 0.1 * k);
    assert_true(x == cube_x(k));
  }
  free(html);

  // runs of another scene are refused for an overlay
  FILE* f = tmpfile();
  assert_non_null(f);
  char other[1100];
  snprintf(other, sizeof other, "%s/report-other", dir);
  make_run(other, "bullet");
  char path[1200];
  snprintf(path, sizeof path, "%s/summary.json", other);
  char* text = read_all(path);
  char* name = strstr(text, "\"cube\"");
  memcpy(name, "\"cubf\"", 6);
  write_text(path, text);
  snprintf(path, sizeof path, "%s/trajectory.csv", other);
  free(text);
  text = read_all(path);
  for (char* p = strstr(text, ",cube,"); p; p = strstr(p + 1, ",cube,")) memcpy(p, ",cubf,", 6);
  write_text(path, text);
  free(text);
  snprintf(path, sizeof path, "%s/contacts.csv", other);
  remove(path);  // optional: reference engines may write none
  pdViewRun* c = pd_view_run_load(other, &err);
  assert_non_null(c);
  assert_false(pd_view_runs_compatible(a, c, &err));
  assert_non_null(strstr(err.message, "not the same scene"));
  pdViewRun* mixed[] = {a, c};
  assert_false(pd_view_write_replay(f, "bad", NULL, mixed, 2, false, &err));
  assert_int_equal(ftell(f), 0);  // nothing written
  fclose(f);
  pd_view_run_free(c);
  pd_view_run_free(a);
  pd_view_run_free(b);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(report_page_shares_one_bundle_and_keeps_poses_exact)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
