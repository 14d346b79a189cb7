#include "render/reproducible.h"

#include <cerrno>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace flexure::render {

long long sourceDateEpoch() {
  const char* epoch = std::getenv("SOURCE_DATE_EPOCH");
  if (!epoch || !*epoch) return -1;
  const std::string text = epoch;
  errno = 0;
  char* end = nullptr;
  const long long t = std::strtoll(epoch, &end, 10);
  // Up to 9999-12-31T23:59:59Z: gmtime and the PDF date have four-digit years.
  if (text.find_first_not_of("0123456789") != std::string::npos || errno == ERANGE || *end || t > 253402300799LL)
    throw std::invalid_argument("SOURCE_DATE_EPOCH is '" + text.substr(0, 40) +
                                "': it must be a number of seconds since 1970-01-01 (a nonnegative integer), or unset");
  return t;
}

}  // namespace flexure::render
