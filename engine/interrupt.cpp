#include "engine/interrupt.h"

namespace flexure::engine {

namespace {
thread_local std::function<bool()> t_check;
}

InterruptCheck::InterruptCheck(std::function<bool()> check) : previous_(std::move(t_check)) {
  t_check = std::move(check);
}

InterruptCheck::~InterruptCheck() { t_check = std::move(previous_); }

void interruptionPoint() {
  if (t_check && t_check()) throw Interrupted{};
}

}  // namespace flexure::engine
