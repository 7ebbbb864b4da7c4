// Out-of-memory as a Status: what dof's entry points return instead of letting std::bad_alloc
// escape (docs/embedding.md, "Memory"). Consumes a description of what was being done; produces
// a failed raster::Status the caller owns.
#pragma once

#include <raster/status.h>

#include <string>

namespace dof::detail {

// Every out-of-memory Status says "out of memory" (these, raster::Renderer's, and those that
// prefix them with a method's name).
inline bool isOutOfMemory(const raster::Status& s) {
    return !s.ok() && s.message().find("out of memory") != std::string::npos;
}

// "out of memory while <what>". When even that message cannot be allocated, "out of memory"
// alone, which fits std::string's inline buffer, so this never throws.
inline raster::Status outOfMemory(const char* what) noexcept {
    try {
        return raster::Status::error(std::string("out of memory while ") + what);
    } catch (...) {
        return raster::Status::error("out of memory");
    }
}
// The same with `what()` (a std::string) built inside, for descriptions that allocate.
template <class What> raster::Status outOfMemoryWhile(const What& what) noexcept {
    try {
        return raster::Status::error("out of memory while " + what());
    } catch (...) {
        return raster::Status::error("out of memory");
    }
}

} // namespace dof::detail
