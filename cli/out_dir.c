// polydyn CLI — output directories: default names, parents, and the write-then-rename of a whole
// directory (DIR.partial-PID, renamed to DIR when complete; a previous DIR replaced only when it is ours).
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "pdutil/files.h"
#include "pdrun/batch.h"

// out/NAME for scene path .../NAME.ext
char* pd_cli_default_out_dir(const char* scene) {
  const char* base = strrchr(scene, '/');
  base = base ? base + 1 : scene;
  size_t n = strlen(base);
  const char* dot = strrchr(base, '.');
  if (dot && dot != base) n = (size_t)(dot - base);
  char* dir = malloc(n + 5);
  if (!dir) abort();
  snprintf(dir, n + 5, "out/%.*s", (int)n, base);
  return dir;
}

// Only rank 0 removes: the directories are rank 0's (pd_cli_out_open)
void pd_cli_remove_tree(const char* path) {
  if (pd_batch_is_root()) pdu_remove_tree(path);
}

static bool out_open(const char* cmd, const char* out, const char* marker, char* tmp, size_t tmpSize);

// Under MPI rank 0 makes the directory and every rank learns its name ("" when it could not).
bool pd_cli_out_open(const char* cmd, const char* out, const char* marker, char* tmp, size_t tmpSize) {
  if (pd_batch_is_root() && !out_open(cmd, out, marker, tmp, tmpSize)) tmp[0] = '\0';
  pd_batch_share(tmp, tmpSize);
  return tmp[0] != '\0';
}

static bool out_open(const char* cmd, const char* out, const char* marker, char* tmp, size_t tmpSize) {
  struct stat st;
  char path[4200];
  snprintf(path, sizeof path, "%s/%s", out, marker);
  if (stat(out, &st) == 0 && stat(path, &st) != 0) {
    fprintf(stderr, "polydyn %s: %s exists and is not a %s directory (no %s); not replacing it\n", cmd, out, cmd, marker);
    return false;
  }
  snprintf(tmp, tmpSize, "%s.partial-%ld", out, (long)getpid());
  if (mkdir(tmp, 0777) != 0) {  // a fresh directory, not an existing one
    fprintf(stderr, "polydyn %s: cannot create %s: %s\n", cmd, tmp, strerror(errno));
    return false;
  }
  return true;
}

volatile sig_atomic_t pd_cli_interrupted = 0;
static void on_interrupt(int sig) {
  (void)sig;
  pd_cli_interrupted = 1;
}

void pd_cli_catch_interrupts(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_interrupt;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
}

bool pd_cli_out_close(const char* cmd, const char* tmp, const char* out) {
  if (!pd_batch_is_root()) return true;
  // no interrupt between moving the earlier result aside and the new one into place (delivered after)
  sigset_t held, saved;
  sigemptyset(&held);
  sigaddset(&held, SIGINT);
  sigaddset(&held, SIGTERM);
  sigaddset(&held, SIGHUP);
  sigprocmask(SIG_BLOCK, &held, &saved);
  struct stat st;
  char old[4200];
  snprintf(old, sizeof old, "%s.old-%ld", out, (long)getpid());
  bool hadOld = stat(out, &st) == 0;
  bool ok = (!hadOld || rename(out, old) == 0) && rename(tmp, out) == 0;
  if (ok && hadOld) pd_cli_remove_tree(old);
  if (!ok) {
    fprintf(stderr, "polydyn %s: cannot write %s: %s\n", cmd, out, strerror(errno));
    pd_cli_remove_tree(tmp);
  }
  sigprocmask(SIG_SETMASK, &saved, NULL);
  return ok;
}
