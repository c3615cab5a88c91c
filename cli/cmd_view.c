// polydyn view — a self-contained HTML replay of run directories, and movies of it.
#include <errno.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli.h"
#include "options.h"
#include "pdview/view.h"

extern char** environ;

static const char* const help =
    "usage: polydyn view DIR [DIR ...] [-o FILE.html] [--title TEXT]\n"
    "       polydyn view DIR [DIR ...] --movie OUT.mp4 [--fps N] [--speed S] [-o FILE.html]\n"
    "\n"
    "Writes one self-contained HTML file that replays the run directories in 3-D: it opens from disk in\n"
    "a browser, with no server and no network. Several DIRs must be runs of the same scene (e.g. soft,\n"
    "ODE and Bullet): the first is drawn solid in the scene's colours, the others ghosted in a key colour\n"
    "each, every one can be switched off.\n"
    "\n"
    "  -o FILE.html     the page (default: DIR.html beside the first DIR; with --movie: none)\n"
    "  --title TEXT     the page's title (default: the scene and the engines)\n"
    "  --movie OUT.mp4  render the replay frame by frame in headless Chromium (playwright-core) and\n"
    "                   encode it with ffmpeg (H.264)\n"
    "  --fps N          movie frames per second (default 60)\n"
    "  --speed S        simulated seconds per movie second, 0.01 to 100 (default 1; 0.1 = slow motion)\n"
    "\n"
    "The viewer bundle is read from $POLYDYN_VIEWER_DIR/dist/viewer.js, by default the source tree's\n"
    "viewer/dist/viewer.js (built by scripts/setup). Movies need node ($POLYDYN_NODE, default node on\n"
    "PATH), Chromium ($POLYDYN_CHROMIUM, default /usr/bin/chromium) and ffmpeg.\n"
    "\n"
    "Exit status: 0 ok, 1 the movie could not be made, 2 bad input (arguments, run directories),\n"
    "130 interrupted (nothing written).\n";

enum { MAX_RUNS = 16 };

// DIR.html for DIR (trailing slashes dropped)
static char* default_page(const char* dir) {
  size_t n = strlen(dir);
  while (n > 1 && dir[n - 1] == '/') --n;
  char* page = malloc(n + 6);
  if (!page) abort();
  snprintf(page, n + 6, "%.*s.html", (int)n, dir);
  return page;
}

// "demo — polydyn-soft, ode" from the runs' summaries is built by the page itself; here only the file name
static char* default_title(const char* dir) {
  size_t n = strlen(dir);
  while (n > 1 && dir[n - 1] == '/') --n;
  const char* base = dir;
  for (size_t i = 0; i + 1 < n; ++i)
    if (dir[i] == '/') base = dir + i + 1;
  size_t len = n - (size_t)(base - dir);
  char* title = malloc(len + 24);
  if (!title) abort();
  snprintf(title, len + 24, "polydyn replay: %.*s", (int)len, base);
  return title;
}

// Runs node on the viewer's movie script; returns its exit status (or -1 when it could not start).
static int run_movie_script(const char* html, const char* mp4, const char* fps, const char* speed) {
  char script[4096];
  snprintf(script, sizeof script, "%s/scripts/movie.mjs", pd_view_dir());
  const char* node = getenv("POLYDYN_NODE");
  if (!node || !*node) node = "node";
  char* argv[] = {(char*)node, script, "--html", (char*)html, "--out", (char*)mp4, "--fps", (char*)fps,
                  "--speed", (char*)speed, NULL};
  // Ctrl-C stops the child (it keeps the default action) while this process waits and then cleans up
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF);
  struct sigaction ignore = {.sa_handler = SIG_IGN}, oldInt, oldTerm;
  sigaction(SIGINT, &ignore, &oldInt);
  sigaction(SIGTERM, &ignore, &oldTerm);
  pid_t pid;
  int rc = posix_spawnp(&pid, node, NULL, &attr, argv, environ);
  posix_spawnattr_destroy(&attr);
  int status = 0;
  if (rc == 0)
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) continue;
  sigaction(SIGINT, &oldInt, NULL);
  sigaction(SIGTERM, &oldTerm, NULL);
  if (rc != 0) {
    fprintf(stderr, "polydyn view: cannot start %s: %s\n", node, strerror(rc));
    return -1;
  }
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static int make_movie(pdViewRun* const* runs, int count, const char* title, const char* movie, const char* fps,
                      const char* speed) {
  const char* tmpdir = getenv("TMPDIR");
  char dir[4096];
  snprintf(dir, sizeof dir, "%s/polydyn-movie-XXXXXX", tmpdir && *tmpdir ? tmpdir : "/tmp");
  if (!mkdtemp(dir)) {
    fprintf(stderr, "polydyn view: cannot create a temporary directory: %s\n", strerror(errno));
    return PD_EXIT_FAILURE;
  }
  char html[4200];
  snprintf(html, sizeof html, "%s/replay.html", dir);
  // the movie is encoded beside its final name and renamed when complete
  size_t n = strlen(movie) + 24;
  char* partial = malloc(n);
  if (!partial) abort();
  snprintf(partial, n, "%s.partial-%ld.mp4", movie, (long)getpid());
  pdError err = {0};
  int status = PD_EXIT_OK;
  if (!pd_view_write_page(html, title, runs, count, &err)) {
    pd_error_print(&err, stderr);
    status = PD_EXIT_FAILURE;
  } else {
    int rc = run_movie_script(html, partial, fps, speed);
    if (rc == 128 + SIGINT || rc == 128 + SIGTERM || rc == 130) {
      fprintf(stderr, "polydyn view: interrupted; no movie written\n");
      status = 130;
    } else if (rc != 0) {
      fprintf(stderr, "polydyn view: the movie could not be made (%s/scripts/movie.mjs exited with %d)\n",
              pd_view_dir(), rc);
      status = PD_EXIT_FAILURE;
    } else if (rename(partial, movie) != 0) {
      fprintf(stderr, "polydyn view: %s: cannot write: %s\n", movie, strerror(errno));
      status = PD_EXIT_FAILURE;
    }
  }
  if (status != PD_EXIT_OK) unlink(partial);
  free(partial);
  pd_cli_remove_tree(dir);
  return status;
}

// --fps: frames per second of the movie, kept as written (the movie script reads it).
static bool accept_fps(const char* cmd, const char* v, void* target) {
  double x;
  if (!pd_cli_positive(v, &x) || x > 240) {
    pd_cli_usage_error(cmd, "--fps needs a number in (0, 240]");
    return false;
  }
  *(const char**)target = v;
  return true;
}

// --speed: simulated seconds per second of the movie, kept as written.
static bool accept_speed(const char* cmd, const char* v, void* target) {
  double x;
  if (!pd_cli_positive(v, &x) || x < 0.01 || x > 100) {
    pd_cli_usage_error(cmd, "--speed needs a number from 0.01 to 100");
    return false;
  }
  *(const char**)target = v;
  return true;
}

int pd_cmd_view(int argc, char** argv) {
  const char* dirs[MAX_RUNS];
  int dirCount = 0;
  const char* page = NULL;
  const char* title = NULL;
  const char* movie = NULL;
  const char* fps = "60";
  const char* speed = "1";
  char tooMany[64];
  snprintf(tooMany, sizeof tooMany, "at most %d run directories", MAX_RUNS);
  const pdCliOption table[] = {
      {.name = "-o", .kind = pd_optText, .target = &page, .message = "-o needs a file name", .min = 1},
      {.name = "--title", .kind = pd_optText, .target = &title},
      {.name = "--movie", .kind = pd_optText, .target = &movie, .message = "--movie needs a file name", .min = 1},
      {.name = "--fps", .kind = pd_optAccept, .target = &fps, .accept = accept_fps},
      {.name = "--speed", .kind = pd_optAccept, .target = &speed, .accept = accept_speed},
  };
  pdCliPositionals positionals = {.values = dirs, .max = MAX_RUNS, .tooMany = tooMany};
  int parsed = pd_cli_parse_options("view", argc, argv, table, sizeof table / sizeof table[0], &positionals, help);
  if (parsed >= 0) return parsed;
  dirCount = positionals.count;
  if (dirCount == 0) return pd_cli_usage_error("view", "no run directory given");
  if ((strcmp(fps, "60") != 0 || strcmp(speed, "1") != 0) && !movie)
    return pd_cli_usage_error("view", "--fps and --speed are for --movie");
  if (pd_cli_parse_only) return PD_EXIT_OK;

  pdViewRun* runs[MAX_RUNS];
  int loaded = 0, status = PD_EXIT_OK;
  pdError err = {0};
  for (; loaded < dirCount; ++loaded) {
    runs[loaded] = pd_view_run_load(dirs[loaded], &err);
    if (!runs[loaded] || (loaded > 0 && !pd_view_runs_compatible(runs[0], runs[loaded], &err))) {
      if (runs[loaded]) ++loaded;
      pd_error_print(&err, stderr);
      status = PD_EXIT_BAD_INPUT;
      break;
    }
  }
  char* defaultTitle = default_title(dirs[0]);
  if (!title) title = defaultTitle;
  char* defaultPage = NULL;
  if (status == PD_EXIT_OK && !page && !movie) page = defaultPage = default_page(dirs[0]);
  if (status == PD_EXIT_OK && access(pd_view_bundle_path(), R_OK) != 0) {
    // a failure of this installation, not of the input
    fprintf(stderr, "polydyn view: the viewer bundle %s is missing; build it with scripts/setup\n",
            pd_view_bundle_path());
    status = PD_EXIT_FAILURE;
  }
  if (status == PD_EXIT_OK && page && !pd_view_write_page(page, title, runs, dirCount, &err)) {
    pd_error_print(&err, stderr);  // -o names a file that cannot be written
    status = PD_EXIT_BAD_INPUT;
  }
  if (status == PD_EXIT_OK && movie) status = make_movie(runs, dirCount, title, movie, fps, speed);
  for (int i = 0; i < loaded; ++i) pd_view_run_free(runs[i]);
  free(defaultTitle);
  free(defaultPage);
  return status;
}
