// `focal bench`: run time against error. For each scene x method x parameter setting it renders
// in-process through the same code path as `focal render` (parse + runRender), times it, compares
// it with a cached `accum` reference and writes results.csv, results.json, gnuplot plots of time
// against error (Pareto front marked), the speed-up over accum at equal error (apps/equal_error.h),
// a temporal-stability table, a thread-scaling table and an index.html into the output folder.
// Everything it writes is owned by the caller's folder.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace focal {

struct BenchArgs {
    std::vector<std::string> scenes;  // empty: every built-in scene + --scene-dir's glTF files
    std::vector<std::string> methods; // empty: every method
    std::string output;               // -o DIR
    std::string ref_cache;            // empty: DIR/refs
    std::string scene_dir = "../shared/scenes"; // extra glTF scenes, used when present
    bool quick = false;
    uint32_t width = 400;
    uint32_t height = 300;
    uint32_t repeat = 5;          // timed runs per setting (median, min, max)
    uint32_t process_repeat = 3;  // timed `focal render` processes per setting (0: none)
    uint32_t ref_samples = 1024;  // accum views of the reference
    uint32_t temporal_frames = 8; // K frames of the focus pull + camera move
    uint32_t temporal_ref_samples = 256;
    uint32_t threads = 0; // main runs; set to the hardware thread count
    bool no_temporal = false;
    bool no_scaling = false;
    bool no_plots = false;
};

// Registers the subcommand; `args` must outlive parsing.
CLI::App* addBenchCommand(CLI::App& app, BenchArgs& args);

// Runs it; returns the exit code (errors are printed; 2 for usage errors).
int runBench(BenchArgs args);

} // namespace focal
