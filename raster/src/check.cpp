#include <raster/check.h>

#include <cstdio>
#include <cstdlib>

namespace raster::detail {

void checkFailed(const char* expr, const char* file, int line) {
    std::fprintf(stderr, "focal: internal error: CHECK(%s) failed at %s:%d\n", expr, file, line);
    std::abort();
}

} // namespace raster::detail
