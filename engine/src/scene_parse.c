// polydyn — the scene file parser (docs/scene-language.md).
//
// Design note. One lexer reads bytes from a source that is either a FILE* (read in fixed 64 KiB
// chunks) or a caller's buffer (read in place), so pd_scene_parse_file and pd_scene_parse_buffer
// run the same code on the same bytes. The lexer hands out one token at a time with its 1-based
// line and byte column, ends a command at a newline unless a backslash is the last thing on the
// line before blanks and a comment, and refuses NUL and control bytes anywhere (comments too).
//
// Memory stays bounded by what the scene holds, never by the length of a line: a token is at most
// TOKEN_MAX bytes in a fixed buffer, a fixed-arity command keeps at most thirteen tokens and stops
// at the first extra one, hull coordinates are converted as they arrive, and blanks and comments are
// skipped without being stored. Junk therefore ends the parse at its first bad token.
//
// First error wins: every check returns false after filling the pdError once, and the caller
// unwinds, freeing what was built. Nothing is global; the parse is deterministic.
//
// Numbers go through strtod on the whole token (C locale assumed: the engine never calls
// setlocale). Hex floats such as 0x1p-3 are accepted, since strtod reads them exactly; nan and inf in
// every spelling, and overflow such as 1e999, are refused as not finite. Columns count bytes.
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "pdutil/utf8.h"
#include "polydyn/scene.h"

enum {
  TOKEN_MAX = 4096,         // bytes in one token; longer is an error
  CHUNK_BYTES = 64 * 1024,     // file read size
  MAX_ARGS = 11,               // most arguments of a fixed-arity command (force with ramp and at)
  MAX_OBJECTS = 1 << 24,       // keeps counts and indices far from int overflow
  SHOWN_CHARS = 40,            // user text quoted in messages
  SHOWN_BUF = SHOWN_CHARS * 4 + 4,
};

#define MAX_SIZE 1e6      // m, sanity bound on sizes and hull coordinates
#define MAX_SAMPLES 1e8   // tend × sample
#define DEG_TO_RAD (3.14159265358979323846 / 180.0)

// ---------------------------------------------------------------------------------------------
// messages

// User text for a message: at most SHOWN_CHARS bytes, bytes outside printable ASCII as \xNN.
static const char* shown(char buf[SHOWN_BUF], const char* s, size_t len) {
  static const char hex[] = "0123456789ABCDEF";
  size_t n = len < SHOWN_CHARS ? len : SHOWN_CHARS, o = 0;
  for (size_t i = 0; i < n; ++i) {
    unsigned char c = (unsigned char)s[i];
    if (c >= 0x20 && c < 0x7f) {
      buf[o++] = (char)c;
    } else {
      buf[o++] = '\\';
      buf[o++] = 'x';
      buf[o++] = hex[c >> 4];
      buf[o++] = hex[c & 15];
    }
  }
  if (len > n) {
    memcpy(buf + o, "...", 3);
    o += 3;
  }
  buf[o] = '\0';
  return buf;
}

// ---------------------------------------------------------------------------------------------
// lexer

typedef struct Token {
  pdSourceLoc loc;
  size_t len;
  char text[TOKEN_MAX + 1];
} Token;

typedef enum TokenKind { tk_word, tk_eol, tk_eof, tk_error } TokenKind;

enum { C_EOF = -1, C_BAD = -2 };

typedef struct Lexer {
  FILE* file;                // NULL when reading a buffer
  unsigned char* chunk;      // CHUNK_BYTES read buffer for a file
  const unsigned char* p;    // next byte
  const unsigned char* end;  // end of the bytes at hand
  int line, col;             // of the next byte
  const char* name;          // file name for messages
  pdError* err;
  bool failed;
} Lexer;

static pdSourceLoc here(const Lexer* lx) { return (pdSourceLoc){lx->line, lx->col}; }

static bool refill(Lexer* lx) {
  if (!lx->file || lx->failed) return false;
  size_t n = fread(lx->chunk, 1, CHUNK_BYTES, lx->file);
  if (n == 0) {
    if (ferror(lx->file)) {
      pd_error_set(lx->err, lx->name, lx->line, lx->col, "read error: %s", strerror(errno));
      lx->failed = true;
    }
    return false;
  }
  lx->p = lx->chunk;
  lx->end = lx->chunk + n;
  return true;
}

static bool is_blank(int c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// The next byte without consuming it, C_EOF at the end, or C_BAD after an error (reported).
static int peek(Lexer* lx) {
  if (lx->failed) return C_BAD;
  if (lx->p == lx->end && !refill(lx)) return lx->failed ? C_BAD : C_EOF;
  unsigned char c = *lx->p;
  if ((c < 0x20 && c != '\n' && !is_blank(c)) || c == 0x7f) {
    pd_error_set(lx->err, lx->name, lx->line, lx->col, "not a text file (byte 0x%02X)", c);
    lx->failed = true;
    return C_BAD;
  }
  return c;
}

// Consumes the byte peek just returned; counters saturate instead of overflowing on huge files.
static void advance(Lexer* lx) {
  if (*lx->p++ == '\n') {
    if (lx->line < INT_MAX) lx->line++;
    lx->col = 1;
  } else if (lx->col < INT_MAX) {
    lx->col++;
  }
}

// Skips a comment up to (not including) its newline. The hot loop of comment-heavy files.
static bool skip_comment(Lexer* lx) {
  for (;;) {
    int c = peek(lx);
    if (c == C_BAD) return false;
    if (c == C_EOF || c == '\n') return true;
    advance(lx);
  }
}

// After a backslash followed by a blank, '#', newline or the end: is the rest of the line only
// blanks and a comment? Then the newline is consumed (continuation) and the result is 1; 0 when
// more text follows on the line; -1 on error.
static int continues(Lexer* lx) {
  for (;;) {
    int c = peek(lx);
    if (c == C_BAD) return -1;
    if (c == C_EOF) return 1;
    if (c == '\n') {
      advance(lx);
      return 1;
    }
    if (c == '#') {
      if (!skip_comment(lx)) return -1;
    } else if (is_blank(c)) {
      advance(lx);
    } else {
      return 0;
    }
  }
}

static bool append(Lexer* lx, Token* tok, char c) {
  if (tok->len == TOKEN_MAX) {
    pd_error_set(lx->err, lx->name, tok->loc.line, tok->loc.col, "token too long (more than %d bytes)",
                 TOKEN_MAX);
    lx->failed = true;
    return false;
  }
  tok->text[tok->len++] = c;
  tok->text[tok->len] = '\0';
  return true;
}

// The next token of the current command: a word, the end of the command, the end of the input.
static TokenKind lex(Lexer* lx, Token* tok) {
  for (;;) {
    int c = peek(lx);
    if (c == C_BAD) return tk_error;
    if (c == C_EOF) return tk_eof;
    if (c == '\n') {
      advance(lx);
      return tk_eol;
    }
    if (is_blank(c)) {
      advance(lx);
      continue;
    }
    if (c == '#') {
      if (!skip_comment(lx)) return tk_error;
      continue;
    }
    // a word, which may turn out to be a lone continuation backslash
    tok->loc = here(lx);
    tok->len = 0;
    tok->text[0] = '\0';
    bool continued = false;
    for (;;) {
      c = peek(lx);
      if (c == C_BAD) return tk_error;
      if (c == C_EOF || c == '\n' || c == '#' || is_blank(c)) break;
      advance(lx);
      if (c == '\\') {
        int d = peek(lx);
        if (d == C_BAD) return tk_error;
        if (d == C_EOF || d == '\n' || d == '#' || is_blank(d)) {
          int r = continues(lx);
          if (r < 0) return tk_error;
          if (r == 1) {
            continued = true;
            break;
          }
          // text follows on this line: the backslash ends this word
          return append(lx, tok, '\\') ? tk_word : tk_error;
        }
      }
      if (!append(lx, tok, (char)c)) return tk_error;
    }
    if (continued && tok->len == 0) continue;
    return tk_word;
  }
}

// ---------------------------------------------------------------------------------------------
// commands

typedef enum CommandId {
  cmd_gravity, cmd_tend, cmd_tol, cmd_dt, cmd_dtmin, cmd_dtmax, cmd_sample, cmd_vmax, cmd_deflection, cmd_sleep,
  cmd_cube, cmd_prism, cmd_tprism, cmd_sphere, cmd_hull,
  cmd_fixed, cmd_loc, cmd_vel, cmd_spgrav, cmd_mu, cmd_kn, cmd_kt, cmd_cn, cmd_ct, cmd_restitution, cmd_force,
  cmd_planar,
} CommandId;

typedef enum CommandClass { class_setting, class_object, class_property } CommandClass;

typedef struct Command {
  const char* name;
  CommandId id;
  CommandClass cls;
  int minArgs, maxArgs;  // loc and vel take 3 or 7, force 3, 7 or 11; hull streams its coordinates
  const char* usage;
} Command;

static const Command commands[] = {
    {"gravity", cmd_gravity, class_setting, 3, 3, "gx gy gz"},
    {"tend", cmd_tend, class_setting, 1, 1, "T"},
    {"tol", cmd_tol, class_setting, 1, 1, "E"},
    {"dt", cmd_dt, class_setting, 1, 1, "H"},
    {"dtmin", cmd_dtmin, class_setting, 1, 1, "H"},
    {"dtmax", cmd_dtmax, class_setting, 1, 1, "H"},
    {"sample", cmd_sample, class_setting, 1, 1, "HZ"},
    {"vmax", cmd_vmax, class_setting, 1, 1, "V"},
    {"deflection", cmd_deflection, class_setting, 1, 1, "F"},
    {"sleep", cmd_sleep, class_setting, 1, 1, "on|off"},
    {"cube", cmd_cube, class_object, 5, 5, "NAME COLOR sx sy sz"},
    {"prism", cmd_prism, class_object, 6, 6, "NAME COLOR n sx sy sz"},
    {"tprism", cmd_tprism, class_object, 7, 7, "NAME COLOR n sx sy sz taper"},
    {"sphere", cmd_sphere, class_object, 6, 6, "NAME COLOR level sx sy sz"},
    {"hull", cmd_hull, class_object, 2, -1, "NAME COLOR x y z x y z ..."},
    {"fixed", cmd_fixed, class_property, 0, 0, ""},
    {"loc", cmd_loc, class_property, 3, 7, "x y z [theta u v w]"},
    {"vel", cmd_vel, class_property, 3, 7, "x y z [theta u v w]"},
    {"spgrav", cmd_spgrav, class_property, 1, 1, "s"},
    {"mu", cmd_mu, class_property, 1, 1, "m"},
    {"kn", cmd_kn, class_property, 1, 1, "k"},
    {"kt", cmd_kt, class_property, 1, 1, "k"},
    {"cn", cmd_cn, class_property, 1, 1, "c"},
    {"ct", cmd_ct, class_property, 1, 1, "c"},
    {"restitution", cmd_restitution, class_property, 1, 1, "e"},
    {"force", cmd_force, class_property, 3, 11, "fx fy fz [ramp rx ry rz] [at x y z]"},
    {"planar", cmd_planar, class_property, 0, 0, ""},
};

static const Command* find_command(const Token* tok) {
  for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i) {
    if (strcmp(commands[i].name, tok->text) == 0) return &commands[i];
  }
  return NULL;
}

// ---------------------------------------------------------------------------------------------
// parser

typedef struct Parser {
  Lexer lx;
  pdScene* scene;
  int objectCap;
  int* names;       // open-addressing hash of object indices by name, -1 = empty
  size_t nameCap;   // power of two
  Token toks[MAX_ARGS + 2];  // command, arguments, and the first extra one
} Parser;

static bool fail(Parser* ps, pdSourceLoc at, const char* fmt, ...) __attribute__((format(printf, 3, 4)));
static bool fail(Parser* ps, pdSourceLoc at, const char* fmt, ...) {
  char message[PD_ERROR_MESSAGE_MAX];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(message, sizeof message, fmt, ap);
  va_end(ap);
  pd_error_set(ps->lx.err, ps->lx.name, at.line, at.col, "%s", message);
  return false;
}

static bool out_of_memory(Parser* ps, pdSourceLoc at) { return fail(ps, at, "out of memory"); }

static char* copy_text(const char* s, size_t len) {
  char* c = malloc(len + 1);
  if (c) {
    memcpy(c, s, len);
    c[len] = '\0';
  }
  return c;
}

// A finite number filling the whole token.
static bool number(Parser* ps, const Token* t, const char* what, double* out) {
  char buf[SHOWN_BUF];
  char* end = NULL;
  double v = strtod(t->text, &end);
  if (t->len == 0 || end != t->text + t->len) {
    return fail(ps, t->loc, "not a number: '%s' (for %s)", shown(buf, t->text, t->len), what);
  }
  if (!isfinite(v)) {
    return fail(ps, t->loc, "not a finite number: '%s' (for %s)", shown(buf, t->text, t->len), what);
  }
  *out = v;
  return true;
}

typedef enum Range { range_any, range_pos, range_nonneg, range_open01, range_half01, range_closed01, range_mu } Range;

static bool ranged(Parser* ps, const Token* t, const char* what, Range r, double* out) {
  double v = 0.0;
  if (!number(ps, t, what, &v)) return false;
  const char* need = NULL;
  switch (r) {
    case range_any: break;
    case range_pos: need = v > 0 ? NULL : "> 0"; break;
    case range_nonneg: need = v >= 0 ? NULL : ">= 0"; break;
    case range_open01: need = v > 0 && v < 1 ? NULL : "in (0, 1)"; break;
    case range_half01: need = v > 0 && v <= 1 ? NULL : "in (0, 1]"; break;
    case range_closed01: need = v >= 0 && v <= 1 ? NULL : "in [0, 1]"; break;
    case range_mu: need = v >= 0 && v <= 10 ? NULL : "in [0, 10]"; break;
  }
  if (need) {
    char buf[SHOWN_BUF];
    return fail(ps, t->loc, "%s must be %s, got %s", what, need, shown(buf, t->text, t->len));
  }
  *out = v;
  return true;
}

// A switch: the word `on` or `off`.
static bool on_off(Parser* ps, const Token* t, const char* what, bool* out) {
  bool on = strcmp(t->text, "on") == 0;
  if (!on && strcmp(t->text, "off") != 0) {
    char buf[SHOWN_BUF];
    return fail(ps, t->loc, "%s must be on or off, got '%s'", what, shown(buf, t->text, t->len));
  }
  *out = on;
  return true;
}

static bool size_arg(Parser* ps, const Token* t, double* out) {
  double v = 0.0;
  if (!ranged(ps, t, "size", range_pos, &v)) return false;
  if (v > MAX_SIZE) {
    char buf[SHOWN_BUF];
    return fail(ps, t->loc, "size must be at most 1e6 m (a sanity bound), got %s", shown(buf, t->text, t->len));
  }
  *out = v;
  return true;
}

// An integral number in lo..hi; anything else gets one message saying what is expected.
static bool int_arg(Parser* ps, const Token* t, const char* what, int lo, int hi, int* out) {
  char* end = NULL;
  double v = strtod(t->text, &end);
  if (t->len == 0 || end != t->text + t->len || !isfinite(v) || v != floor(v) || v < lo || v > hi) {
    char buf[SHOWN_BUF];
    return fail(ps, t->loc, "%s must be an integer in %d..%d, got %s", what, lo, hi, shown(buf, t->text, t->len));
  }
  *out = (int)v;
  return true;
}

static uint64_t hash_name(const char* s) {
  uint64_t h = 1469598103934665603u;  // FNV-1a
  for (; *s; ++s) h = (h ^ (unsigned char)*s) * 1099511628211u;
  return h;
}

// Index of the object called name, or -1; *slot is where it is or would go.
static int find_name(const Parser* ps, const char* name, size_t* slot) {
  size_t mask = ps->nameCap - 1;
  for (size_t i = (size_t)hash_name(name) & mask;; i = (i + 1) & mask) {
    int k = ps->names[i];
    if (k < 0 || strcmp(ps->scene->objects[k].name, name) == 0) {
      *slot = i;
      return k;
    }
  }
}

static bool check_name(Parser* ps, const Token* t) {
  size_t slot;
  int k = find_name(ps, t->text, &slot);
  if (k >= 0) {
    char buf[SHOWN_BUF];
    return fail(ps, t->loc, "duplicate name '%s' (first defined at line %d)", shown(buf, t->text, t->len),
                ps->scene->objects[k].where.line);
  }
  return true;
}

// A name or a colour is any word (docs/names-and-files.md) that is valid UTF-8: every file that carries it
// (CSV, JSON, the replay page) then shows it as written. The error points at the first bad byte.
static bool check_utf8(Parser* ps, const Token* t, const char* what) {
  size_t valid = pdu_utf8_valid_length(t->text, t->len);
  if (valid == t->len) return true;
  pdSourceLoc at = t->loc;
  at.col += (int)valid;
  return fail(ps, at, "%s is not valid UTF-8 (byte 0x%02X)", what, (unsigned char)t->text[valid]);
}

// Appends a new object with its name and colour (checked unique) and the language's defaults.
static pdSceneObject* add_object(Parser* ps, pdSourceLoc at, const Token* name, const Token* color) {
  pdScene* sc = ps->scene;
  if (!check_utf8(ps, name, "the name") || !check_utf8(ps, color, "the colour")) return NULL;
  if (sc->objectCount == MAX_OBJECTS) {
    fail(ps, at, "too many objects (at most %d)", MAX_OBJECTS);
    return NULL;
  }
  // keep the hash table at most half full
  if ((size_t)(sc->objectCount + 1) * 2 > ps->nameCap) {
    size_t cap = ps->nameCap * 2;
    int* names = malloc(cap * sizeof *names);
    if (!names) {
      out_of_memory(ps, at);
      return NULL;
    }
    free(ps->names);
    ps->names = names;
    ps->nameCap = cap;
    for (size_t i = 0; i < cap; ++i) names[i] = -1;
    for (int k = 0; k < sc->objectCount; ++k) {
      size_t slot;
      find_name(ps, sc->objects[k].name, &slot);
      names[slot] = k;
    }
  }
  if (sc->objectCount == ps->objectCap) {
    int cap = ps->objectCap ? ps->objectCap * 2 : 16;
    pdSceneObject* objects = realloc(sc->objects, (size_t)cap * sizeof *objects);
    if (!objects) {
      out_of_memory(ps, at);
      return NULL;
    }
    sc->objects = objects;
    ps->objectCap = cap;
  }
  char* nameCopy = copy_text(name->text, name->len);
  char* colorCopy = copy_text(color->text, color->len);
  if (!nameCopy || !colorCopy) {
    free(nameCopy);
    free(colorCopy);
    out_of_memory(ps, at);
    return NULL;
  }
  size_t slot;
  find_name(ps, nameCopy, &slot);
  ps->names[slot] = sc->objectCount;
  pdSceneObject* o = &sc->objects[sc->objectCount++];
  *o = (pdSceneObject){
      .name = nameCopy,
      .color = colorCopy,
      .scale = {1, 1, 1},
      .taper = 1,
      .locAxis = {0, 0, 1},
      .spinAxis = {0, 0, 1},
      .spgrav = PD_DEFAULT_SPGRAV,
      .mu = PD_DEFAULT_MU,
      .where = at,
  };
  return o;
}

// `cube`, `prism`, `tprism`, `sphere`: toks[1] name, toks[2] colour, then the numbers.
static bool primitive_command(Parser* ps, const Command* cmd) {
  const Token* t = ps->toks;
  if (!check_name(ps, &t[1])) return false;
  int n = 0, a = 3;
  double scale[3], taper = 1;
  if (cmd->id == cmd_prism || cmd->id == cmd_tprism) {
    if (!int_arg(ps, &t[a++], "prism sides", 3, PD_PRISM_MAX_SIDES, &n)) return false;
  } else if (cmd->id == cmd_sphere) {
    if (!int_arg(ps, &t[a++], "sphere level", 0, PD_SPHERE_MAX_LEVEL, &n)) return false;
  }
  for (int i = 0; i < 3; ++i) {
    if (!size_arg(ps, &t[a++], &scale[i])) return false;
  }
  if (cmd->id == cmd_tprism && !ranged(ps, &t[a++], "taper", range_half01, &taper)) return false;
  pdSceneObject* o = add_object(ps, t[0].loc, &t[1], &t[2]);
  if (!o) return false;
  static const pdPrimitiveKind kinds[] = {
      [cmd_cube] = pd_primCube, [cmd_prism] = pd_primPrism, [cmd_tprism] = pd_primTprism,
      [cmd_sphere] = pd_primSphere};
  o->kind = kinds[cmd->id];
  o->n = n;
  memcpy(o->scale, scale, sizeof scale);
  o->taper = taper;
  return true;
}

// `hull NAME COLOR x y z ...`: coordinates are converted as they stream in, so a hull of any
// length on one physical line costs only its points.
static bool hull_command(Parser* ps) {
  Token* t = ps->toks;
  int got = 0;
  for (; got < 2; ++got) {
    TokenKind k = lex(&ps->lx, &t[1 + got]);
    if (k == tk_error) return false;
    if (k != tk_word) break;
  }
  if (got < 2) {
    return fail(ps, t[0].loc, "'hull' expects NAME COLOR x y z ... (at least 4 points), got %d argument%s", got,
                got == 1 ? "" : "s");
  }
  if (!check_name(ps, &t[1])) return false;
  double* coords = NULL;
  size_t count = 0, cap = 0;
  for (;;) {
    TokenKind k = lex(&ps->lx, &t[3]);
    if (k == tk_error) goto refuse;
    if (k != tk_word) break;
    if (count == (size_t)PD_HULL_MAX_POINTS * 3) {
      fail(ps, t[3].loc, "hull has more than %d points", PD_HULL_MAX_POINTS);
      goto refuse;
    }
    double v = 0.0;
    if (!number(ps, &t[3], "hull coordinate", &v)) goto refuse;
    if (fabs(v) > MAX_SIZE) {
      char buf[SHOWN_BUF];
      fail(ps, t[3].loc, "hull coordinate must be within +-1e6 m (a sanity bound), got %s",
           shown(buf, t[3].text, t[3].len));
      goto refuse;
    }
    if (count == cap) {
      cap = cap ? cap * 2 : 48;
      double* grown = realloc(coords, cap * sizeof *grown);
      if (!grown) {
        out_of_memory(ps, t[3].loc);
        goto refuse;
      }
      coords = grown;
    }
    coords[count++] = v;
  }
  if (count % 3 != 0) {
    fail(ps, t[0].loc, "hull coordinates must come in x y z triples, got %zu numbers", count);
    goto refuse;
  }
  if (count < 12) {
    fail(ps, t[0].loc, "hull needs at least 4 points, got %zu", count / 3);
    goto refuse;
  }
  pdSceneObject* o = add_object(ps, t[0].loc, &t[1], &t[2]);
  if (!o) goto refuse;
  o->kind = pd_primHull;
  o->points = coords;
  o->pointCount = (int)(count / 3);
  return true;
refuse:
  free(coords);
  return false;
}

// `loc` and `vel`: three numbers, or seven with an angle in degrees and a non-zero axis.
static bool pose_command(Parser* ps, const Command* cmd, int nargs, pdSceneObject* o) {
  const Token* t = ps->toks;
  double v[3], angle = 0, axis[3] = {0, 0, 1};
  for (int i = 0; i < 3; ++i) {
    if (!number(ps, &t[1 + i], cmd->id == cmd_loc ? "loc" : "vel", &v[i])) return false;
  }
  if (nargs == 7) {
    if (!number(ps, &t[4], "angle", &angle)) return false;
    for (int i = 0; i < 3; ++i) {
      if (!number(ps, &t[5 + i], "axis", &axis[i])) return false;
    }
    if (axis[0] == 0 && axis[1] == 0 && axis[2] == 0) {
      if (angle != 0) return fail(ps, t[5].loc, "rotation axis must be non-zero when the angle is not 0");
      axis[2] = 1;  // keep the default so later normalising never divides by zero
    }
  }
  if (cmd->id == cmd_loc) {
    memcpy(o->loc, v, sizeof v);
    o->locAngle = angle * DEG_TO_RAD;
    memcpy(o->locAxis, axis, sizeof axis);
    o->setMask |= PD_SET_LOC;
  } else {
    memcpy(o->vel, v, sizeof v);
    o->spin = angle * DEG_TO_RAD;
    memcpy(o->spinAxis, axis, sizeof axis);
    o->setMask |= PD_SET_VEL;
  }
  return true;
}

// Three numbers from t[0], each finite and, when `bounded`, within the size sanity bound.
static bool triple(Parser* ps, const Token* t, const char* what, bool bounded, double out[3]) {
  for (int i = 0; i < 3; ++i) {
    if (!number(ps, &t[i], what, &out[i])) return false;
    if (bounded && fabs(out[i]) > MAX_SIZE) {
      char buf[SHOWN_BUF];
      return fail(ps, t[i].loc, "%s must be within +-1e6 m (a sanity bound), got %s", what,
                  shown(buf, t[i].text, t[i].len));
    }
  }
  return true;
}

// `force fx fy fz [ramp rx ry rz] [at x y z]`: one applied force per body, never on a fixed one (it could not
// move); `ramp` and `at` in either order, each at most once.
static bool force_command(Parser* ps, int nargs, pdSceneObject* o) {
  const Token* t = ps->toks;
  if (o->fixed) return fail(ps, t[0].loc, "'force' on the fixed body '%s': a fixed body cannot be pushed", o->name);
  if (o->setMask & PD_SET_FORCE) {
    return fail(ps, t[0].loc, "body '%s' already has a force (line %d): at most one force per body", o->name,
                o->forceWhere.line);
  }
  double f[3], rate[3] = {0, 0, 0}, point[3] = {0, 0, 0};
  if (!triple(ps, &t[1], "force", false, f)) return false;
  bool sawRamp = false, sawAt = false;
  for (int a = 4; a <= nargs; a += 4) {
    char buf[SHOWN_BUF];
    bool isRamp = strcmp(t[a].text, "ramp") == 0, isAt = strcmp(t[a].text, "at") == 0;
    if (!isRamp && !isAt) {
      return fail(ps, t[a].loc, "expected 'ramp' or 'at' after the force, got '%s'", shown(buf, t[a].text, t[a].len));
    }
    if ((isRamp && sawRamp) || (isAt && sawAt)) return fail(ps, t[a].loc, "'%s' given twice", t[a].text);
    if (a + 3 > nargs) {
      return fail(ps, t[a].loc, "'%s' expects 3 numbers (%s), got %d", t[a].text, isRamp ? "rx ry rz" : "x y z",
                  nargs - a);
    }
    if (isRamp) {
      sawRamp = true;
      if (!triple(ps, &t[a + 1], "force ramp", false, rate)) return false;
    } else {
      sawAt = true;
      if (!triple(ps, &t[a + 1], "force point", true, point)) return false;
    }
  }
  memcpy(o->force, f, sizeof f);
  memcpy(o->forceRate, rate, sizeof rate);
  memcpy(o->forcePoint, point, sizeof point);
  o->forceWhere = t[0].loc;
  o->setMask |= PD_SET_FORCE;
  return true;
}

static bool property_command(Parser* ps, const Command* cmd, int nargs) {
  pdSceneObject* o = &ps->scene->objects[ps->scene->objectCount - 1];
  const Token* arg = &ps->toks[1];
  switch (cmd->id) {
    case cmd_fixed:
      if (o->setMask & PD_SET_FORCE) {
        return fail(ps, ps->toks[0].loc, "'fixed' on body '%s', which has a force (line %d): a fixed body cannot "
                    "be pushed", o->name, o->forceWhere.line);
      }
      if (o->setMask & PD_SET_PLANAR) {
        return fail(ps, ps->toks[0].loc, "'fixed' on body '%s', which is planar (line %d): a fixed body has no "
                    "motion to constrain", o->name, o->planarWhere.line);
      }
      o->fixed = true;
      return true;
    case cmd_planar:
      if (o->fixed) return fail(ps, ps->toks[0].loc, "'planar' on the fixed body '%s': it has no motion to constrain", o->name);
      if (o->setMask & PD_SET_PLANAR) {
        return fail(ps, ps->toks[0].loc, "body '%s' is already planar (line %d)", o->name, o->planarWhere.line);
      }
      o->planarWhere = ps->toks[0].loc;
      o->setMask |= PD_SET_PLANAR;
      return true;
    case cmd_force: return force_command(ps, nargs, o);
    case cmd_loc:
    case cmd_vel: return pose_command(ps, cmd, nargs, o);
    case cmd_spgrav: o->setMask |= PD_SET_SPGRAV; return ranged(ps, arg, "spgrav", range_pos, &o->spgrav);
    case cmd_mu: o->setMask |= PD_SET_MU; return ranged(ps, arg, "mu", range_mu, &o->mu);
    case cmd_kn: o->setMask |= PD_SET_KN; return ranged(ps, arg, "kn", range_pos, &o->kn);
    case cmd_kt: o->setMask |= PD_SET_KT; return ranged(ps, arg, "kt", range_pos, &o->kt);
    case cmd_cn: o->setMask |= PD_SET_CN; return ranged(ps, arg, "cn", range_nonneg, &o->cn);
    case cmd_ct: o->setMask |= PD_SET_CT; return ranged(ps, arg, "ct", range_nonneg, &o->ct);
    case cmd_restitution:
      o->setMask |= PD_SET_RESTITUTION;
      return ranged(ps, arg, "restitution", range_closed01, &o->restitution);
    default: return false;
  }
}

static bool setting_command(Parser* ps, const Command* cmd) {
  pdSceneSettings* s = &ps->scene->settings;
  const Token* arg = &ps->toks[1];
  bool ok = false;
  switch (cmd->id) {
    case cmd_gravity: {
      double g[3];
      ok = ranged(ps, &arg[0], "gravity", range_any, &g[0]) && ranged(ps, &arg[1], "gravity", range_any, &g[1]) &&
           ranged(ps, &arg[2], "gravity", range_any, &g[2]);
      if (ok) memcpy(s->gravity, g, sizeof g);
      break;
    }
    case cmd_tend: ok = ranged(ps, arg, "tend", range_pos, &s->tend); break;
    case cmd_tol: ok = ranged(ps, arg, "tol", range_open01, &s->tol); break;
    case cmd_dt: ok = ranged(ps, arg, "dt", range_pos, &s->dt); break;
    case cmd_dtmin: ok = ranged(ps, arg, "dtmin", range_pos, &s->dtmin); break;
    case cmd_dtmax: ok = ranged(ps, arg, "dtmax", range_pos, &s->dtmax); break;
    case cmd_sample: ok = ranged(ps, arg, "sample", range_pos, &s->sample); break;
    case cmd_vmax: ok = ranged(ps, arg, "vmax", range_pos, &s->vmax); break;
    case cmd_deflection: ok = ranged(ps, arg, "deflection", range_open01, &s->deflection); break;
    case cmd_sleep: ok = on_off(ps, arg, "sleep", &s->sleep); break;
    default: break;
  }
  if (ok) {
    int bit = (int)(cmd->id - cmd_gravity);  // settings come first in CommandId, in bit order
    s->setMask |= 1u << bit;
    s->where[bit] = ps->toks[0].loc;
  }
  return ok;
}

// One command whose keyword is in toks[0].
static bool command(Parser* ps, const Command* cmd) {
  Token* t = ps->toks;
  char buf[SHOWN_BUF];
  if (cmd->cls == class_property && ps->scene->objectCount == 0) {
    return fail(ps, t[0].loc, "property '%s' before any object", cmd->name);
  }
  if (cmd->id == cmd_hull) return hull_command(ps);
  // collect the arguments, stopping at the first one too many
  int nargs = 0;
  for (;;) {
    TokenKind k = lex(&ps->lx, &t[1 + nargs]);
    if (k == tk_error) return false;
    if (k != tk_word) break;
    if (nargs == cmd->maxArgs) {
      if (cmd->maxArgs == 0) {
        return fail(ps, t[1 + nargs].loc, "too many arguments: '%s' takes none, got '%s'", cmd->name,
                    shown(buf, t[1 + nargs].text, t[1 + nargs].len));
      }
      return fail(ps, t[1 + nargs].loc, "too many arguments: '%s' expects %s%d (%s)", cmd->name,
                  cmd->minArgs == cmd->maxArgs ? "" : "at most ", cmd->maxArgs, cmd->usage);
    }
    nargs++;
  }
  // force checks its optional parts itself, naming the part that is short
  if (cmd->id != cmd_force && cmd->minArgs != cmd->maxArgs && nargs != cmd->minArgs && nargs != cmd->maxArgs) {
    return fail(ps, t[0].loc, "'%s' expects %d or %d arguments (%s), got %d", cmd->name, cmd->minArgs, cmd->maxArgs,
                cmd->usage, nargs);
  }
  if (nargs < cmd->minArgs) {
    return fail(ps, t[0].loc, "'%s' expects %d argument%s (%s), got %d", cmd->name, cmd->minArgs,
                cmd->minArgs == 1 ? "" : "s", cmd->usage, nargs);
  }
  switch (cmd->cls) {
    case class_setting: return setting_command(ps, cmd);
    case class_object: return primitive_command(ps, cmd);
    case class_property: return property_command(ps, cmd, nargs);
  }
  return false;
}

// Where a check involving two settings should point: the one the file gave, or the later one.
static pdSourceLoc blame(const pdSceneSettings* s, unsigned a, unsigned b) {
  int ia = 0, ib = 0;
  while ((1u << ia) != a) ia++;
  while ((1u << ib) != b) ib++;
  bool ga = (s->setMask & a) != 0, gb = (s->setMask & b) != 0;
  if (ga && gb) {
    pdSourceLoc la = s->where[ia], lb = s->where[ib];
    return (la.line > lb.line || (la.line == lb.line && la.col > lb.col)) ? la : lb;
  }
  if (ga) return s->where[ia];
  if (gb) return s->where[ib];
  return (pdSourceLoc){0, 0};
}

// Checks that involve several settings, once the whole file is read.
static bool check_settings(Parser* ps) {
  const pdSceneSettings* s = &ps->scene->settings;
  if (s->dt < s->dtmin) {
    return fail(ps, blame(s, PD_SET_DT, PD_SET_DTMIN), "dt %g is below dtmin %g", s->dt, s->dtmin);
  }
  if (s->dt > s->dtmax) {
    return fail(ps, blame(s, PD_SET_DT, PD_SET_DTMAX), "dt %g is above dtmax %g", s->dt, s->dtmax);
  }
  if (s->dtmin > s->dtmax) {
    return fail(ps, blame(s, PD_SET_DTMIN, PD_SET_DTMAX), "dtmin %g is above dtmax %g", s->dtmin, s->dtmax);
  }
  if (s->tend * s->sample > MAX_SAMPLES) {
    return fail(ps, blame(s, PD_SET_TEND, PD_SET_SAMPLE),
                "too many output samples: tend*sample = %g is over 1e8", s->tend * s->sample);
  }
  return true;
}

static bool parse_all(Parser* ps) {
  Lexer* lx = &ps->lx;
  // a UTF-8 byte order mark is not part of the first command
  if (peek(lx) == 0xEF && lx->end - lx->p >= 3 && memcmp(lx->p, "\xEF\xBB\xBF", 3) == 0) lx->p += 3;
  for (;;) {
    TokenKind k = lex(lx, &ps->toks[0]);
    if (k == tk_error) return false;
    if (k == tk_eof) break;
    if (k == tk_eol) continue;
    const Command* cmd = find_command(&ps->toks[0]);
    if (!cmd) {
      char buf[SHOWN_BUF];
      return fail(ps, ps->toks[0].loc, "unknown command '%s'", shown(buf, ps->toks[0].text, ps->toks[0].len));
    }
    if (!command(ps, cmd)) return false;
  }
  return check_settings(ps);
}

// The shared driver: file is NULL for a buffer.
static pdScene* parse(const char* name, FILE* file, const unsigned char* text, size_t length, pdError* err) {
  pdScene* scene = calloc(1, sizeof *scene);
  Parser* ps = calloc(1, sizeof *ps);
  unsigned char* chunk = file ? malloc(CHUNK_BYTES) : NULL;
  int* names = malloc(16 * sizeof *names);
  char* path = copy_text(name, strlen(name));
  if (!scene || !ps || (file && !chunk) || !names || !path) {
    pd_error_set(err, name, 0, 0, "out of memory");
    free(scene);
    free(ps);
    free(chunk);
    free(names);
    free(path);
    return NULL;
  }
  scene->path = path;
  scene->settings = (pdSceneSettings){
      .gravity = {0, 0, PD_DEFAULT_GRAVITY_Z},
      .tend = PD_DEFAULT_TEND,
      .tol = PD_DEFAULT_TOL,
      .dt = PD_DEFAULT_DT,
      .dtmin = PD_DEFAULT_DTMIN,
      .dtmax = PD_DEFAULT_DTMAX,
      .sample = PD_DEFAULT_SAMPLE,
      .vmax = 0,
      .deflection = PD_DEFAULT_DEFLECTION,
      .sleep = PD_DEFAULT_SLEEP,
  };
  for (int i = 0; i < 16; ++i) names[i] = -1;
  ps->names = names;
  ps->nameCap = 16;
  ps->scene = scene;
  ps->lx = (Lexer){
      .file = file,
      .chunk = chunk,
      .p = file ? chunk : text,
      .end = file ? chunk : text + length,
      .line = 1,
      .col = 1,
      .name = name,
      .err = err,
  };
  // report into a local error so that err stays untouched on success
  pdError local = {.message = "invalid scene"};
  ps->lx.err = &local;
  bool ok = parse_all(ps);
  free(ps->names);
  free(ps);
  free(chunk);
  if (!ok) {
    if (err) *err = local;
    pd_scene_free(scene);
    return NULL;
  }
  if (scene->objectCount > 0) {
    // give back the slack of the doubling
    pdSceneObject* fit = realloc(scene->objects, (size_t)scene->objectCount * sizeof *fit);
    if (fit) scene->objects = fit;
  }
  return scene;
}

pdScene* pd_scene_parse_file(const char* path, pdError* err) {
  PD_ASSERT(path != NULL);
  FILE* f = fopen(path, "rb");
  if (!f) {
    pd_error_set(err, path, 0, 0, "cannot open: %s", strerror(errno));
    return NULL;
  }
  // fopen succeeds on a directory on Linux; reading it would fail with a less helpful message
  struct stat st;
  if (fstat(fileno(f), &st) == 0 && S_ISDIR(st.st_mode)) {
    pd_error_set(err, path, 0, 0, "cannot read: is a directory");
    fclose(f);
    return NULL;
  }
  pdScene* scene = parse(path, f, NULL, 0, err);
  fclose(f);
  return scene;
}

pdScene* pd_scene_parse_buffer(const char* name, const char* text, size_t length, pdError* err) {
  PD_ASSERT(text != NULL || length == 0);
  static const unsigned char empty[1] = {0};
  const unsigned char* bytes = text ? (const unsigned char*)text : empty;
  return parse(name ? name : "<buffer>", NULL, bytes, length, err);
}

double pd_default_dtmax(double tol) {
  PD_ASSERT(tol > 0.0);
  if (tol <= PD_DEFAULT_TOL) return PD_DEFAULT_DTMAX;
  // RK4's local error grows as h⁵: the step whose error is tol where PD_DEFAULT_DTMAX's is PD_DEFAULT_TOL
  return fmin(PD_DTMAX_DERIVED_CEILING, PD_DEFAULT_DTMAX * pow(tol / PD_DEFAULT_TOL, 0.2));
}

void pd_scene_free(pdScene* scene) {
  if (!scene) return;
  for (int i = 0; i < scene->objectCount; ++i) {
    free(scene->objects[i].name);
    free(scene->objects[i].color);
    free(scene->objects[i].points);
  }
  free(scene->objects);
  free(scene->path);
  free(scene);
}
