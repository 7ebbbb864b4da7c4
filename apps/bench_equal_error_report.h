// The equal-error part of `focal bench`'s results: for each scene, error target and layered
// method, accum's cost of reaching the target and the method's speed-up over it
// (apps/equal_error.h computes them), as JSON (results.json "equal_error") and as a table
// (equal_error.md, index.html, stdout). Consumes the result rows; produces values the caller owns.
#pragma once

#include "apps/bench_rows.h"
#include "apps/report_table.h"

#include <cstddef>
#include <string>
#include <vector>

namespace focal {

// How the speed-up is defined, written beside every table of it.
extern const char* const kEqualErrorDefinition;

// One scene's equal-error results: per target accum's cost and per layered method the speed-up,
// for render and whole-process time, from the main rows `idx` of `rows`.
Json equalErrorOfScene(const std::string& spec, const Json& rows, const std::vector<size_t>& idx,
                       const std::vector<std::string>& layered);

// The header of results.json's "equal_error": the definition, the targets, the methods.
Json equalErrorHeader(const std::vector<std::string>& layered, uint32_t process_repeat);

// One row per scene and target: accum's N and times, each layered method's speed-ups.
Table equalErrorTable(const Json& scenes, const std::vector<std::string>& layered);

} // namespace focal
