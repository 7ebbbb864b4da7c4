// Memory budget: the most bytes one request (an import, a render, a method's scratch) may ask
// for. Every large allocation is checked against it before it is made, so an impossible request
// fails fast with a Status naming what needed how much instead of ending in std::bad_alloc.
// A plain value: the caller (the CLI's --memory-budget) chooses it and passes it down.
#pragma once

#include <raster/status.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>

namespace raster {

struct MemoryBudget {
    uint64_t bytes = 0; // 0: unlimited (only the machine limits allocations)

    bool limited() const { return bytes > 0; }
};

// Physical memory of this machine in bytes (0 when it cannot be read).
uint64_t physicalMemoryBytes();

// What the command line uses unless told otherwise: half of physical memory (a render holds a
// few buffers at once, and the machine is shared), or 4 GiB when physical memory is unknown.
MemoryBudget defaultMemoryBudget();

// "1.5 GiB", "512 MiB", "300 KiB", "17 bytes": for messages.
std::string formatBytes(uint64_t bytes);

// Ok when `needed` bytes fit the budget, else an error such as
// "multiview scratch needs 12.3 GiB, more than the memory budget of 8 GiB (--memory-budget)".
// `what` names the buffer(s) in words the user knows.
Status checkMemory(const MemoryBudget& budget, std::string_view what, uint64_t needed);
// The same with `what()` building the words only when the check fails, so a request that fits
// allocates nothing for its message (a frame rendered again allocates nothing at all).
template <class Describe>
requires std::is_invocable_r_v<std::string, Describe&>
    Status checkMemory(const MemoryBudget& budget, Describe&& what, uint64_t needed) {
    if (!budget.limited() || needed <= budget.bytes)
        return {};
    return checkMemory(budget, std::string_view(what()), needed);
}

// Saturating arithmetic for byte estimates: a product or sum that would overflow is
// UINT64_MAX, which no budget admits.
uint64_t mulBytes(uint64_t a, uint64_t b);
uint64_t addBytes(uint64_t a, uint64_t b);

} // namespace raster
