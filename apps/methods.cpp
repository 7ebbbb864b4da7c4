#include "apps/dof_method.h"
#include "apps/method_gather.h"
#include "apps/method_multilayer.h"
#include "apps/method_multiview.h"

namespace focal {

// One line per method: `entries.push_back(makeXxxMethod());`, declared in apps/method_xxx.h.
std::vector<MethodEntry>& methodTable() {
    static std::vector<MethodEntry> entries = [] {
        std::vector<MethodEntry> e;
        e.push_back(makeGatherMethod());
        e.push_back(makeMultilayerMethod());
        e.push_back(makeMultiviewMethod());
        return e;
    }();
    return entries;
}

} // namespace focal
