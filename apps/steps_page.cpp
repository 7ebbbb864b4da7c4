#include "apps/steps_page.h"

#include "apps/text_file.h"

namespace focal {

raster::Status writeStepsPage(const std::string& dir) {
    for (const StepsPageFile& file : stepsPageFiles())
        if (raster::Status s = writeTextFile(dir + "/" + file.name, std::string(file.content));
            !s.ok())
            return s;
    return {};
}

} // namespace focal
