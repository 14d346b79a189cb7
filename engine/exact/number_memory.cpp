#include "engine/exact/number_memory.h"

#include <flint/flint.h>
#include <gmp.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <new>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <unordered_set>

namespace flexure::engine::exact {

namespace {

// GMP and FLINT call these from C code; the exception unwinds through their frames (Debian
// builds both with unwind tables). Whatever they had allocated in the interrupted call is lost,
// which is what an out-of-memory error costs anywhere.
// A cancelled worker of runCancellable (not a std::exception: nothing on the way catches it).
struct Cancelled {};

// In a worker of runCancellable: its cancel flag, and the blocks it allocated and has not freed.
thread_local std::atomic<bool>* t_cancel = nullptr;
thread_local std::unordered_set<void*>* t_live = nullptr;

void checkCancel() {
  if (t_cancel && t_cancel->load(std::memory_order_relaxed)) throw Cancelled{};
}

void track(void* p) {
  if (!t_live) return;
  try {
    t_live->insert(p);
  } catch (const std::bad_alloc&) {  // not tracked: it leaks if the worker is cancelled
  }
}

void untrack(void* p) {
  if (t_live) t_live->erase(p);
}

void* allocate(size_t n) {
  checkCancel();
  void* p = std::malloc(n == 0 ? 1 : n);
  if (!p) throw std::bad_alloc();
  track(p);
  return p;
}

// `grows`: a larger block is asked for (a cancelled worker stops there). A shrinking reallocation
// never stops: FLINT shrinks big integers as it clears them, in the destructors that the
// unwinding of a cancelled worker runs.
void* reallocate(void* p, size_t n, bool grows) {
  if (grows) checkCancel();
  untrack(p);  // before realloc: p is not to be used once it may have been freed
  void* q = std::realloc(p, n == 0 ? 1 : n);
  if (!q) {
    track(p);  // p is still valid: the error ends the work, which frees it
    throw std::bad_alloc();
  }
  track(q);
  return q;
}

void release(void* p) {
  untrack(p);
  std::free(p);
}

void* gmpAllocate(size_t n) { return allocate(n); }
void* gmpReallocate(void* p, size_t old, size_t n) { return reallocate(p, n, n > old); }
void gmpFree(void* p, size_t) { release(p); }

void* flintAllocate(size_t n) { return allocate(n); }
void* flintCallocate(size_t count, size_t size) {
  checkCancel();
  void* p = std::calloc(count == 0 ? 1 : count, size == 0 ? 1 : size);
  if (!p) throw std::bad_alloc();
  track(p);
  return p;
}
void* flintReallocate(void* p, size_t n) { return reallocate(p, n, false); }
void flintFree(void* p) { release(p); }

// GNU noreturn, not [[noreturn]]: with it the function's type is the noreturn pointer type that
// flint_set_abort takes (clang checks that; GCC does not).
__attribute__((noreturn)) void flintAbort() {
  throw std::logic_error("FLINT stopped on an internal error in the exact mode's linear algebra");
}

[[maybe_unused]] const bool g_installed_at_start = (installNumberAllocators(), true);

}  // namespace

void installNumberAllocators() {
  static std::once_flag once;
  std::call_once(once, [] {
    mp_set_memory_functions(gmpAllocate, gmpReallocate, gmpFree);
    __flint_set_memory_functions(flintAllocate, flintCallocate, flintReallocate, flintFree);
    flint_set_abort(flintAbort);
  });
}

void runCancellable(const std::function<void()>& work, const std::function<void()>& poll) {
  installNumberAllocators();
  std::atomic<bool> cancel{false};
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  std::exception_ptr error;
  auto body = [&] {
    std::unordered_set<void*> live;
    t_cancel = &cancel;
    t_live = &live;
    bool cancelled = false;
    try {
      work();
    } catch (const Cancelled&) {
      cancelled = true;
    } catch (...) {
      error = std::current_exception();
    }
    t_cancel = nullptr;
    if (cancelled) {
      // The unwinding ran the C++ destructors; FLINT's own caches of this thread go next (their
      // blocks leave `live` as they are freed), then whatever the interrupted C code held.
      flint_cleanup();
      t_live = nullptr;
      for (void* p : live) std::free(p);
    }
    t_live = nullptr;
    {
      std::lock_guard<std::mutex> lock(mutex);
      done = true;
    }
    finished.notify_one();
  };
  std::thread worker;
  try {
    worker = std::thread(body);
  } catch (const std::system_error&) {  // no thread (its stack does not fit under a memory cap): here, uncancellable
    work();
    return;
  }
  std::unique_lock<std::mutex> lock(mutex);
  while (!done) {
    finished.wait_for(lock, std::chrono::milliseconds(20));
    if (done) break;
    lock.unlock();
    try {
      poll();
    } catch (...) {
      cancel = true;
      worker.join();
      throw;
    }
    lock.lock();
  }
  lock.unlock();
  worker.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace flexure::engine::exact
