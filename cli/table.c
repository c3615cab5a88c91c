// polydyn CLI — cells of the tables a person reads on the terminal.
#include <math.h>
#include <stdio.h>

#include "cli.h"

// A dash for "does not apply": one column wide on the terminal, three bytes of UTF-8.
static const char* const notApplicable = "\u2014";

void pd_cli_table_number(FILE* out, int width, const char* format, double value) {
  char text[64];
  int columns;
  if (isfinite(value)) {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
    columns = snprintf(text, sizeof text, format, value);
#pragma GCC diagnostic pop
  } else {
    columns = snprintf(text, sizeof text, "%s", notApplicable) - 2;
  }
  fprintf(out, "%*s%s", width - columns > 0 ? width - columns : 1, "", text);
}
