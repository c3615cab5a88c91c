// pdutil — paths, directories and whole files (pdutil/files.h).
#include "pdutil/files.h"

#include <errno.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static void* checked(void* p) {
  if (!p) {
    fputs("pdutil: out of memory\n", stderr);
    abort();
  }
  return p;
}

char* pdu_path_join(const char* a, const char* b) {
  size_t n = strlen(a) + strlen(b) + 2;
  char* s = checked(malloc(n));
  snprintf(s, n, "%s/%s", a, b);
  return s;
}

char* pdu_path_suffix(const char* a, const char* suffix) {
  size_t n = strlen(a) + strlen(suffix) + 1;
  char* s = checked(malloc(n));
  snprintf(s, n, "%s%s", a, suffix);
  return s;
}

static int remove_entry(const char* path, const struct stat* sb, int flag, struct FTW* ftw) {
  (void)sb, (void)flag, (void)ftw;
  return remove(path) == 0 || errno == ENOENT ? 0 : -1;
}

bool pdu_remove_tree(const char* path) {
  struct stat st;
  if (lstat(path, &st) != 0) return errno == ENOENT;
  // 16 open directories at most: deeper trees are walked with fewer descriptors, not refused
  return nftw(path, remove_entry, 16, FTW_DEPTH | FTW_PHYS) == 0;
}

static bool is_dir(const char* path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

bool pdu_make_dir(const char* path) {
  if (mkdir(path, 0777) == 0) return true;
  if (errno != EEXIST) return false;
  if (is_dir(path)) return true;
  errno = EEXIST;
  return false;
}

bool pdu_make_parents(const char* path) {
  char* p = checked(malloc(strlen(path) + 1));
  strcpy(p, path);
  bool ok = true;
  for (char* slash = strchr(p + 1, '/'); slash && ok; slash = strchr(slash + 1, '/')) {
    *slash = '\0';
    ok = pdu_make_dir(p);
    *slash = '/';
  }
  int saved = errno;
  free(p);
  errno = saved;
  return ok;
}

bool pdu_make_dirs(const char* path) { return pdu_make_parents(path) && pdu_make_dir(path); }

char* pdu_read_file(const char* path, size_t* size) {
  FILE* in = fopen(path, "rb");
  if (!in) return NULL;
  size_t cap = 1 << 16, len = 0, n;
  char* text = checked(malloc(cap));
  while ((n = fread(text + len, 1, cap - len - 1, in)) > 0) {
    len += n;
    if (cap - len - 1 == 0) text = checked(realloc(text, cap *= 2));
  }
  bool bad = ferror(in) != 0;
  int saved = errno;
  fclose(in);
  if (bad) {
    free(text);
    errno = saved ? saved : EIO;
    return NULL;
  }
  text[len] = '\0';
  if (size) *size = len;
  return text;
}
