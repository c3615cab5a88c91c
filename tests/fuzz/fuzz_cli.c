// libFuzzer target for the command line (cli/*.c: every subcommand's argument parsing). The input is split at
// NUL bytes into the words after `polydyn` (the first names the subcommand; at most MAX_WORDS). With
// pd_cli_parse_only set, each subcommand returns as soon as its arguments are accepted, before it touches a
// file, so no word list can make this target read, write or run anything. Every list must end in exit status
// 0 with nothing on stderr (help, or arguments accepted) or in 2 with a message on stderr that starts with
// "polydyn" (or "usage: polydyn") and ends the line; never anything else. stdout and stderr are captured in
// memory (glibc lets a program assign them).
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

enum { MAX_WORDS = 64 };

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pd_cli_parse_only = true;
  // the words, each NUL-terminated in a copy of the input
  char* text = malloc(size + 1);
  if (!text) abort();
  memcpy(text, data, size);
  text[size] = '\0';
  char* argv[MAX_WORDS + 2] = {"polydyn"};
  int argc = 1;
  for (size_t at = 0; at < size && argc <= MAX_WORDS; at += strlen(text + at) + 1) argv[argc++] = text + at;
  argv[argc] = NULL;

  char *outText = NULL, *errText = NULL;
  size_t outSize = 0, errSize = 0;
  FILE *out = open_memstream(&outText, &outSize), *err = open_memstream(&errText, &errSize);
  if (!out || !err) abort();
  FILE *savedOut = stdout, *savedErr = stderr;
  stdout = out;
  stderr = err;
  int status = pd_cli_dispatch(argc, argv);
  stdout = savedOut;
  stderr = savedErr;
  fclose(out);
  fclose(err);

  if (status == PD_EXIT_OK) {
    if (errSize != 0) __builtin_trap();
  } else if (status == PD_EXIT_BAD_INPUT) {
    bool named = strncmp(errText, "polydyn", 7) == 0 || strncmp(errText, "usage: polydyn", 14) == 0;
    if (errSize < 9 || !named || errText[errSize - 1] != '\n') __builtin_trap();
  } else {
    __builtin_trap();  // a command ran, or failed, instead of parsing
  }
  free(outText);
  free(errText);
  free(text);
  return 0;
}
