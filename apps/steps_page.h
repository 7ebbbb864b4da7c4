// The stage-stepper page (apps/steps_page: index.html, steps.css, steps.js), compiled into focal
// so `focal steps` can write it into every folder without reading the source tree at run time.
// The contents are static storage generated at build time (cmake/EmbedStepsPage.cmake); the
// folder format they read is docs/steps-format.md.
#pragma once

#include <raster/status.h>

#include <span>
#include <string>
#include <string_view>

namespace focal {

struct StepsPageFile {
    const char* name;         // file name inside the steps folder, e.g. "index.html"
    std::string_view content; // the file's bytes (UTF-8 text)
};

// The page's files, in the order index.html, steps.css, steps.js. Valid for the program's lifetime.
std::span<const StepsPageFile> stepsPageFiles();

// Writes every file of stepsPageFiles() into the existing folder `dir` (each atomically, like
// writeTextFile), so the folder opens in a browser once steps_data.js and images/ are there.
raster::Status writeStepsPage(const std::string& dir);

} // namespace focal
