#pragma once
// Heap allocations counted for the tests that prove a tick allocates nothing (docs/core.md,
// "Determinism and no allocation per tick"): tests/alloc_count.cpp replaces every form of
// operator new for the whole test program.

#include <cstdint>

namespace tubeplan::testing {

/// Allocations made by the calling thread so far; per thread, so that a test measuring one
/// thread's ticks is not disturbed by another thread.
extern thread_local std::int64_t g_allocations;

}  // namespace tubeplan::testing
