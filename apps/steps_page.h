// The stage-stepper page (apps/steps_page: index.html, steps.css, steps.js), compiled into focal
// so `focal steps` can write it into every folder without reading the source tree at run time.
// The contents are static storage generated at build time (cmake/EmbedStepsPage.cmake); the
// folder format they read is docs/steps-format.md.
#pragma once

#include <span>
#include <string_view>

namespace focal {

struct StepsPageFile {
    const char* name;         // file name inside the steps folder, e.g. "index.html"
    std::string_view content; // the file's bytes (UTF-8 text)
};

// The page's files, in the order index.html, steps.css, steps.js. Valid for the program's lifetime.
std::span<const StepsPageFile> stepsPageFiles();

} // namespace focal
