#include "apps/dof_method.h"

namespace focal {

// One line per method: `entries.push_back(makeXxxMethod());`, declared in apps/method_xxx.h.
std::vector<MethodEntry>& methodTable() {
    static std::vector<MethodEntry> entries = [] {
        std::vector<MethodEntry> e;
        return e;
    }();
    return entries;
}

}  // namespace focal
