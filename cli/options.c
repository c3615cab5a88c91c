// polydyn CLI — the option tables' parser (options.h).
#include "options.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

// The row's message with its "%s" replaced by the value, reported as a usage error.
static int bad_value(const char* cmd, const pdCliOption* o, const char* value) {
  const char* at = strstr(o->message, "%s");
  if (!at) return pd_cli_usage_error(cmd, "%s", o->message);
  return pd_cli_usage_error(cmd, "%.*s%s%s", (int)(at - o->message), o->message, value, at + 2);
}

// Takes one option's value; returns -1 when taken, else the exit status.
static int take(const char* cmd, const pdCliOption* o, const char* v) {
  switch (o->kind) {
    case pd_optFlag:
      return -1;  // taken by the caller
    case pd_optText:
      if (strlen(v) < (size_t)o->min || (o->max > 0 && strlen(v) > (size_t)o->max)) return bad_value(cmd, o, v);
      *(const char**)o->target = v;
      return -1;
    case pd_optPositive:
      return pd_cli_positive(v, o->target) ? -1 : bad_value(cmd, o, v);
    case pd_optWhole: {
      char* end = NULL;
      long n = strtol(v, &end, 10);
      if (!end || *end || n < o->min || n > o->max) return bad_value(cmd, o, v);
      *(long*)o->target = n;
      return -1;
    }
    case pd_optJobs: {
      int n;
      if (!pd_cli_jobs(v, &n) || (o->max > 0 && n > o->max)) return bad_value(cmd, o, v);
      *(int*)o->target = n;
      return -1;
    }
    case pd_optChoice:
      for (int i = 0; o->words[i]; ++i) {
        if (strcmp(v, o->words[i]) == 0) {
          *(int*)o->target = o->values[i];
          return -1;
        }
      }
      return bad_value(cmd, o, v);
    case pd_optAccept:
      return o->accept(cmd, v, o->target) ? -1 : PD_EXIT_BAD_INPUT;
  }
  return PD_EXIT_BAD_INPUT;
}

int pd_cli_parse_options(const char* cmd, int argc, char** argv, const pdCliOption* table, int count,
                         pdCliPositionals* positionals, const char* help) {
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    if (pd_cli_is_help(a)) {
      fputs(help, stdout);
      return PD_EXIT_OK;
    }
    const pdCliOption* o = NULL;
    for (int k = 0; k < count && !o; ++k)
      if (strcmp(a, table[k].name) == 0) o = &table[k];
    if (o && o->kind == pd_optFlag) {
      if (o->refuse) return pd_cli_usage_error(cmd, o->refuse, a);
      if (o->given) *o->given = true;
      if (o->accept && !o->accept(cmd, NULL, o->target)) return PD_EXIT_BAD_INPUT;
      if (!o->accept) *(bool*)o->target = true;
    } else if (o) {
      if (i + 1 >= argc) return pd_cli_usage_error(cmd, "%s needs a value", a);
      if (o->refuse) return pd_cli_usage_error(cmd, o->refuse, a);
      if (o->given) *o->given = true;
      int status = take(cmd, o, argv[++i]);
      if (status >= 0) return status;
    } else if (a[0] == '-' && (a[1] != '\0' || positionals->loneDashIsOption)) {
      const char* unknown = positionals->unknownOption ? positionals->unknownOption : "unknown option '%s'";
      return pd_cli_usage_error(cmd, unknown, a);
    } else if (positionals->count == positionals->max && positionals->max == 0) {
      return pd_cli_usage_error(cmd, positionals->tooMany, a);
    } else if (positionals->count == positionals->max) {
      return pd_cli_usage_error(cmd, positionals->tooMany, positionals->values[0], a);
    } else {
      positionals->values[positionals->count++] = a;
    }
  }
  return -1;
}
