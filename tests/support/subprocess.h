// Runs a program as a child process and captures its exit code, stdout and stderr, for tests of
// the `focal` command line. Consumes an argument vector; produces a ProcessResult owned by the
// caller. POSIX only (fork/exec); no shell is involved, so arguments need no quoting.
#pragma once

#include <string>
#include <vector>

namespace focal::test {

struct ProcessResult {
    int exit_code = -1; // the child's exit status; 128 + signal number if it was killed
    std::string out;    // everything written to stdout
    std::string err;    // everything written to stderr
};

// Runs argv[0] with arguments argv[1..] in working directory `cwd` (empty: the current one).
// stdin is /dev/null. Blocks until the child exits.
ProcessResult runProcess(const std::vector<std::string>& argv, const std::string& cwd = {});

// The lines of `text` (split at '\n'; a trailing newline does not start an empty line).
std::vector<std::string> splitLines(const std::string& text);

} // namespace focal::test
