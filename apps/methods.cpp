#include "apps/dof_method.h"
#include "apps/method_gather.h"
#include "apps/method_multilayer.h"
#include "apps/method_multiview.h"

namespace focal {

// One line per method: `entries.push_back(makeXxxMethod());`, declared in apps/method_xxx.h.
std::vector<MethodEntry> makeMethodTable() {
    std::vector<MethodEntry> entries;
    entries.push_back(makeGatherMethod());
    entries.push_back(makeMultilayerMethod());
    entries.push_back(makeMultiviewMethod());
    return entries;
}

std::vector<std::string> methodNames() {
    std::vector<std::string> names = {"pinhole", "accum"};
    for (const MethodEntry& m : makeMethodTable())
        names.push_back(m.name);
    return names;
}

const MethodEntry* findMethod(const std::vector<MethodEntry>& table, const std::string& name) {
    for (const MethodEntry& m : table)
        if (m.name == name)
            return &m;
    return nullptr;
}

} // namespace focal
