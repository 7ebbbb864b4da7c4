// `focal hash IMAGE...`: prints the pixel hash (apps/pixel_hash.h) of each image, one
// "HEX16  PATH" line per image, like sha256sum. With --expect HEX16 it is a gate for one image:
// exit 0 when the hash matches, 1 when it does not, 2 on usage or I/O errors.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace focal {

struct HashArgs {
    std::vector<std::string> images;
    std::string expect; // 16 hex digits; empty: just print
};

// Registers the subcommand; `args` must outlive parsing.
CLI::App* addHashCommand(CLI::App& app, HashArgs& args);

// Runs it; returns the exit code (errors are printed).
int runHash(const HashArgs& args);

} // namespace focal
