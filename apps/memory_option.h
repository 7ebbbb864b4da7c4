// --memory-budget: the text a user types ("auto", "8G", "512MiB", "25%") to a MemoryBudget.
#pragma once

#include <raster/memory_budget.h>
#include <raster/status.h>

#include <string>

namespace focal {

// "auto": raster::defaultMemoryBudget() (half of physical memory). "N" with an optional unit
// B, K/KiB, M/MiB, G/GiB, T/TiB (powers of 1024; N may have a fraction), or "P%" of physical
// memory. The result is at least 1 MiB; anything else is an error naming the option.
raster::Result<raster::MemoryBudget> parseMemoryBudget(const std::string& text);

} // namespace focal
