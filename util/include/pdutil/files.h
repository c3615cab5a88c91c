// pdutil — paths, directories and whole files: the file-system helpers every folder of polydyn shares.
//
// Below everything: nothing here includes polydyn's headers, so the engine may use it (privately, to write
// a run directory) as may the commands, the Gedanken suite, the reference checks and the viewer. Out of
// memory aborts (these helpers serve commands, never the step).
#pragma once

#include <stdbool.h>
#include <stddef.h>

// "a/b", newly allocated (free it).
char* pdu_path_join(const char* a, const char* b);

// "a" followed by `suffix` ("DIR.partial-123"), newly allocated (free it).
char* pdu_path_suffix(const char* a, const char* suffix);

// Removes `path` and everything under it without following symbolic links; true when nothing is left.
// A path that does not exist counts as removed.
bool pdu_remove_tree(const char* path);

// Creates the directory `path` (mode 0777 less the umask); true when it exists afterwards as a directory.
bool pdu_make_dir(const char* path);

// Creates each missing directory above `path` (its parents, not `path` itself); true when they all exist
// afterwards. Callers that go on to create `path` may ignore the result: that creation reports the failure.
bool pdu_make_parents(const char* path);

// Creates `path` and each missing parent (as `mkdir -p`); true when it exists afterwards as a directory.
bool pdu_make_dirs(const char* path);

// The whole file, NUL-terminated (the terminator is not counted in *size; size may be NULL), newly
// allocated; NULL with errno set when it cannot be read.
char* pdu_read_file(const char* path, size_t* size);
