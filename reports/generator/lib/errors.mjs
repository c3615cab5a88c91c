// Errors of the report generator. InputError is bad input (exit status 2): a file that is missing a
// required part, malformed or inconsistent, reported as `FILE:LINE: message`; UsageError is a bad
// command line (exit 2); anything else is a failure of the generator itself (exit 1).

export class InputError extends Error {
  // file: the path as shown to the user; line: 1-based, or 0 when the message is about the whole file
  constructor(file, line, message) {
    super(line > 0 ? `${file}:${line}: ${message}` : `${file}: ${message}`);
    this.file = file;
    this.line = line;
  }
}

export class UsageError extends Error {}

// A failure of the set-up (charting library not installed, ...): exit status 1.
export class SetupError extends Error {}

// An output that could not be written (a full disk, a file-size limit, a directory without permission): exit 1,
// nothing of the report left behind.
export class WriteError extends Error {}
