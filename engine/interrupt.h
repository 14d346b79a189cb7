// Stopping a computation that has no progress callback (the rigidity analysis) from outside:
// the caller installs a check for its thread; the analysis calls interruptionPoint() between its
// stages and at every step of its motion checks, which throws Interrupted once the check says
// so. Interrupted is not a std::exception: the handlers that keep a computation going past an
// ordinary failure (catch std::exception) let it through.
#pragma once

#include <functional>

namespace flexure::engine {

struct Interrupted {};

// Installs `check` for the calling thread for its lifetime (the previous one is restored).
class InterruptCheck {
 public:
  explicit InterruptCheck(std::function<bool()> check);
  ~InterruptCheck();
  InterruptCheck(const InterruptCheck&) = delete;
  InterruptCheck& operator=(const InterruptCheck&) = delete;

 private:
  std::function<bool()> previous_;
};

// Throws Interrupted when this thread's check returns true (no check: never).
void interruptionPoint();

}  // namespace flexure::engine
