// The sweeps of `focal bench`: for each method, the parameter settings it is timed and compared
// at, and the setting each study (thread scaling, temporal stability) uses. Consumes a method
// name; produces `focal render` option lists the caller owns. No I/O.
#pragma once

#include <string>
#include <vector>

namespace focal {

// One parameter setting of a method: a label and the `focal render` options it adds, spelled from
// the method's settings table (apps/settings_options.h) so that a sweep names settings fields.
struct Setting {
    std::string label;
    std::vector<std::string> args;
    bool scaling = false;  // the setting of the thread-scaling study (else the first)
    bool temporal = false; // the setting of the temporal study (else the last)
};

// The settings `method` is benchmarked at (fewer with `quick`, the CI smoke run).
std::vector<Setting> settingsFor(const std::string& method, bool quick);

// The setting a study uses: the one flagged by `flag`, else the first (scaling) or last.
Setting studySetting(const std::string& method, bool quick, bool Setting::*flag);

} // namespace focal
