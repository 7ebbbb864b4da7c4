// Small text files (stats JSON, reports), written atomically like images.
#pragma once

#include <raster/status.h>

#include <string>

namespace focal {

raster::Status writeTextFile(const std::string& path, const std::string& text);

} // namespace focal
