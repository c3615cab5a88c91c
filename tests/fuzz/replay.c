// Runs a libFuzzer target's function on files, without libFuzzer: `replay_NAME FILE|DIR...` calls
// LLVMFuzzerTestOneInput once per file (a directory: every regular file in it, in name order). CTest runs it
// on each target's committed corpus (tests/fuzz/CMakeLists.txt), so the seeds and the reproducers of fixed
// crashes are regression tests in every build, gcc and ASan + UBSan included. A failed check traps.
#include <dirent.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

// Reads a whole file (malloc'd, size bytes); NULL when it cannot be read.
static uint8_t* read_file(const char* path, size_t* size) {
  FILE* f = fopen(path, "rb");
  if (!f) return NULL;
  uint8_t* data = NULL;
  size_t n = 0, capacity = 0;
  for (;;) {
    if (n == capacity) {
      capacity = capacity ? 2 * capacity : 4096;
      if (!(data = realloc(data, capacity))) abort();
    }
    size_t got = fread(data + n, 1, capacity - n, f);
    n += got;
    if (got == 0) break;
  }
  bool ok = !ferror(f);
  fclose(f);
  if (!ok) {
    free(data);
    return NULL;
  }
  *size = n;
  return data;
}

static int replay_file(const char* path) {
  size_t size = 0;
  uint8_t* data = read_file(path, &size);
  if (!data) {
    fprintf(stderr, "%s: cannot read\n", path);
    return 0;
  }
  LLVMFuzzerTestOneInput(data, size);
  free(data);
  return 1;
}

static int only_files(const struct dirent* e) { return e->d_name[0] != '.'; }

int main(int argc, char** argv) {
  long replayed = 0;
  bool ok = argc > 1;
  for (int i = 1; i < argc; ++i) {
    struct stat st;
    if (stat(argv[i], &st) != 0) {
      fprintf(stderr, "%s: no such file or directory\n", argv[i]);
      ok = false;
    } else if (S_ISDIR(st.st_mode)) {
      struct dirent** names = NULL;
      int n = scandir(argv[i], &names, only_files, alphasort);
      if (n < 0) {
        fprintf(stderr, "%s: cannot list\n", argv[i]);
        ok = false;
      }
      for (int k = 0; k < n; ++k) {
        size_t len = strlen(argv[i]) + strlen(names[k]->d_name) + 2;
        char* path = malloc(len);
        if (!path) abort();
        snprintf(path, len, "%s/%s", argv[i], names[k]->d_name);
        if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) {
          int done = replay_file(path);
          replayed += done;
          ok = ok && done;
        }
        free(path);
        free(names[k]);
      }
      free(names);
    } else {
      int done = replay_file(argv[i]);
      replayed += done;
      ok = ok && done;
    }
  }
  printf("%s: %ld inputs replayed%s\n", argc > 0 ? argv[0] : "replay", replayed, ok ? "" : " (some unreadable)");
  return ok ? 0 : 1;
}
