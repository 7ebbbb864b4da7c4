// FOCAL_CHECK: an always-on invariant check for bugs and broken contracts (never for bad input,
// which gets a Status). Prints the expression with file:line and aborts.
#pragma once

namespace raster::detail {
[[noreturn]] void checkFailed(const char* expr, const char* file, int line);
}

#define FOCAL_CHECK(expr)                                                                          \
    do {                                                                                           \
        if (!(expr))                                                                               \
            ::raster::detail::checkFailed(#expr, __FILE__, __LINE__);                              \
    } while (0)
