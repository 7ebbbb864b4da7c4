// The `focal` command line: parses arguments, runs a subcommand, returns the exit code
// (0 success, 1 failure with one "focal: error: ..." line on stderr, 2 usage error).
#pragma once

namespace focal {

int runCli(int argc, char** argv);

} // namespace focal
