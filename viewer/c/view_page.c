// polydyn viewer — writing the HTML: head, replay elements with their data, the bundle, tail.
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "view_internal.h"

#ifndef PD_VIEWER_DIR
#error "PD_VIEWER_DIR (the viewer's source directory) must be defined by the build"
#endif

const char* pd_view_dir(void) {
  const char* env = getenv("POLYDYN_VIEWER_DIR");
  return env && *env ? env : PD_VIEWER_DIR;
}

const char* pd_view_bundle_path(void) {
  static char path[4096];
  snprintf(path, sizeof path, "%s/dist/viewer.js", pd_view_dir());
  return path;
}

static void write_html_text(FILE* out, const char* s) {
  for (; *s; ++s) {
    switch (*s) {
      case '<': fputs("&lt;", out); break;
      case '>': fputs("&gt;", out); break;
      case '&': fputs("&amp;", out); break;
      case '"': fputs("&quot;", out); break;
      default: fputc(*s, out);
    }
  }
}

// JSON inside a script element: '<' only occurs inside strings, where \u003c means the same
static void write_script_json(FILE* out, const char* json) {
  for (; *json; ++json) {
    if (*json == '<')
      fputs("\\u003c", out);
    else
      fputc(*json, out);
  }
}

void pd_view_write_head(FILE* out, const char* title) {
  fputs("<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>",
        out);
  write_html_text(out, title);
  fputs("</title>\n<meta name=\"generator\" content=\"polydyn view " PD_VERSION "\">\n</head>\n<body>\n", out);
}

void pd_view_write_tail(FILE* out) { fputs("</body>\n</html>\n", out); }

// ---------------------------------------------------------------- base64, streamed

typedef struct base64Writer {
  FILE* out;
  unsigned char carry[3];
  int carried;
  char line[4096];
  size_t used;
} base64Writer;

static const char base64Alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static void base64_emit(base64Writer* w, const unsigned char* b, int n) {
  if (w->used + 4 > sizeof w->line) {
    fwrite(w->line, 1, w->used, w->out);
    w->used = 0;
  }
  uint32_t v = (uint32_t)b[0] << 16 | (uint32_t)(n > 1 ? b[1] : 0) << 8 | (uint32_t)(n > 2 ? b[2] : 0);
  w->line[w->used++] = base64Alphabet[v >> 18 & 63];
  w->line[w->used++] = base64Alphabet[v >> 12 & 63];
  w->line[w->used++] = n > 1 ? base64Alphabet[v >> 6 & 63] : '=';
  w->line[w->used++] = n > 2 ? base64Alphabet[v & 63] : '=';
}

static void base64_write(base64Writer* w, const void* data, size_t n) {
  const unsigned char* p = data;
  while (n > 0 && w->carried > 0 && w->carried < 3) {
    w->carry[w->carried++] = *p++;
    --n;
    if (w->carried == 3) {
      base64_emit(w, w->carry, 3);
      w->carried = 0;
    }
  }
  for (; n >= 3; n -= 3, p += 3) base64_emit(w, p, 3);
  while (n-- > 0) w->carry[w->carried++] = *p++;
}

static void base64_finish(base64Writer* w) {
  if (w->carried) base64_emit(w, w->carry, w->carried);
  fwrite(w->line, 1, w->used, w->out);
  w->used = 0;
  w->carried = 0;
}

// An array of the data block, padded to its layout size (multiples of 8 bytes).
static void write_block(base64Writer* w, const void* data, size_t bytes) {
  static const unsigned char zeros[8] = {0};
  base64_write(w, data, bytes);
  base64_write(w, zeros, (8 - bytes % 8) % 8);
}

static void write_run_data(FILE* out, const pdViewRun* run) {
  // the page reads the arrays as little-endian typed arrays
  const uint16_t one = 1;
  PD_ASSERT(*(const unsigned char*)&one == 1);
  pdViewLayout l = pd_view_layout(run);
  base64Writer w = {.out = out};
  const void* arrays[PD_VIEW_BLOCKS] = {run->t, run->pose, run->vel, run->contactStart, run->contactFloat,
                                        run->contactInt};
  for (int i = 0; i < PD_VIEW_BLOCKS; ++i) write_block(&w, arrays[i], l.bytes[i]);
  base64_finish(&w);
}

static bool valid_id(const char* id) {
  if (!*id) return false;
  for (const char* p = id; *p; ++p)
    if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '-' || *p == '_'))
      return false;
  return true;
}

bool pd_view_write_replay(FILE* out, const char* id, const char* title, pdViewRun* const* runs, int count,
                          bool standalone, pdError* err) {
  PD_ASSERT(valid_id(id) && count >= 1);
  for (int i = 1; i < count; ++i)
    if (!pd_view_runs_compatible(runs[0], runs[i], err)) return false;
  fprintf(out, "<section class=\"pd-replay\" id=\"pd-replay-%s\" data-runs=\"%d\"%s>\n", id, count,
          standalone ? " data-standalone=\"1\"" : "");
  if (title) {
    fputs("<h2 class=\"pd-replay-title\">", out);
    write_html_text(out, title);
    fputs("</h2>\n", out);
  }
  fputs("<noscript>The replay needs JavaScript.</noscript>\n</section>\n", out);
  fprintf(out, "<script type=\"application/json\" id=\"pd-replay-%s-meta\">{\"title\":", id);
  // the title as a JSON string: only printable text reaches here, quotes and backslashes escaped
  fputc('"', out);
  for (const char* p = title ? title : ""; *p; ++p) {
    if (*p == '"' || *p == '\\') fputc('\\', out);
    if (*p == '<')
      fputs("\\u003c", out);
    else if ((unsigned char)*p >= 0x20)
      fputc(*p, out);
  }
  fputs("\",\"runs\":[", out);
  for (int i = 0; i < count; ++i) {
    if (i) fputc(',', out);
    write_script_json(out, runs[i]->metaJson);
  }
  fputs("]}</script>\n", out);
  for (int i = 0; i < count; ++i) {
    fprintf(out, "<script type=\"application/octet-stream\" id=\"pd-replay-%s-run-%d\">", id, i);
    write_run_data(out, runs[i]);
    fputs("</script>\n", out);
  }
  return !ferror(out);
}

bool pd_view_write_bundle(FILE* out, pdError* err) {
  const char* path = pd_view_bundle_path();
  FILE* in = fopen(path, "rb");
  if (!in) {
    pd_error_set(err, path, 0, 0, "cannot read the viewer bundle (%s); build it with scripts/setup", strerror(errno));
    return false;
  }
  size_t cap = 1 << 20, len = 0, n;
  char* js = malloc(cap);
  PD_ASSERT(js != NULL);
  while ((n = fread(js + len, 1, cap - len - 1, in)) > 0)
    if ((len += n) == cap - 1) {
      js = realloc(js, cap *= 2);
      PD_ASSERT(js != NULL);
    }
  js[len] = '\0';
  bool bad = ferror(in);
  fclose(in);
  if (bad || len == 0) {
    free(js);
    pd_error_set(err, path, 0, 0, "cannot read the viewer bundle%s", bad ? "" : " (empty)");
    return false;
  }
  // a "</script" inside the bundle would end the element early: write it as "<\/script"
  fputs("<script>\n", out);
  for (size_t i = 0; i < len; ++i) {
    if (js[i] == '<' && strncasecmp(js + i, "</script", 8) == 0) {
      fputs("<\\", out);
      continue;
    }
    fputc(js[i], out);
  }
  fputs("\n</script>\n", out);
  free(js);
  return true;
}

bool pd_view_write_page(const char* path, const char* title, pdViewRun* const* runs, int count, pdError* err) {
  size_t n = strlen(path) + 16;
  char* tmp = malloc(n);
  PD_ASSERT(tmp != NULL);
  snprintf(tmp, n, "%s.tmp-XXXXXX", path);
  int fd = mkstemp(tmp);
  FILE* out = fd >= 0 ? fdopen(fd, "w") : NULL;
  if (!out) {
    pd_error_set(err, path, 0, 0, "cannot write: %s", strerror(errno));
    if (fd >= 0) close(fd), unlink(tmp);
    free(tmp);
    return false;
  }
  setvbuf(out, NULL, _IOFBF, 1 << 20);
  pd_view_write_head(out, title);
  bool ok = pd_view_write_replay(out, "main", NULL, runs, count, true, err) && pd_view_write_bundle(out, err);
  pd_view_write_tail(out);
  bool ioError = ferror(out);
  ok = (fclose(out) == 0) && ok && !ioError;
  if (ok) {
    // mkstemp makes the file private; the page gets the usual permissions
    mode_t mask = umask(0);
    umask(mask);
    chmod(tmp, 0666 & ~mask);
    ok = rename(tmp, path) == 0;
    if (!ok) pd_error_set(err, path, 0, 0, "cannot write: %s", strerror(errno));
  } else if (ioError) {
    pd_error_set(err, path, 0, 0, "cannot write: I/O error");
  }
  if (!ok) unlink(tmp);
  free(tmp);
  return ok;
}
