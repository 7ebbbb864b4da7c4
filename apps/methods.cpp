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

std::vector<std::string> methodNames() {
    std::vector<std::string> names = {"pinhole", "accum"};
    for (const MethodEntry& m : methodTable())
        names.push_back(m.name);
    return names;
}

const MethodEntry* findMethod(const std::string& name) {
    for (const MethodEntry& m : methodTable())
        if (m.name == name)
            return &m;
    return nullptr;
}

} // namespace focal
