// GMP's and FLINT's memory functions (issue 62): an allocation that fails throws std::bad_alloc,
// which every front end reports as it reports any other out-of-memory (the command line:
// "flexure: out of memory", exit 1; Python: MemoryError), instead of GMP's and FLINT's own
// handlers, which abort the process (FLINT after printing its message on stdout). FLINT's abort
// on an internal error throws std::logic_error. Installed once, before main, by this file's
// static initializer; exact_linear_algebra.cpp calls installNumberAllocators() too, which both
// links this file into every program that uses the exact mode and makes the installation
// certain whatever the order of static initialisation.
#pragma once

#include <functional>

namespace flexure::engine::exact {

// Idempotent and thread-safe.
void installNumberAllocators();

// Runs `work` (GMP and FLINT calls that can take long, such as one dense elimination) on a
// worker thread while this thread calls `poll` every 20 ms. When `poll` throws (an
// interruption: engine/interrupt.h), the worker is cancelled at its next GMP or FLINT
// allocation (every step of an elimination over the integers allocates), the blocks it had
// allocated and not freed are freed, and poll's exception is rethrown once the worker has
// ended. An exception of `work` is rethrown here.
void runCancellable(const std::function<void()>& work, const std::function<void()>& poll);

}  // namespace flexure::engine::exact
