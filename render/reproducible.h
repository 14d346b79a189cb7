// Reproducible files: the date a PDF carries, fixed by SOURCE_DATE_EPOCH
// (https://reproducible-builds.org/specs/source-date-epoch/).
#pragma once

namespace flexure::render {

// The seconds since 1970 SOURCE_DATE_EPOCH fixes, or -1 when it is unset or empty. Throws
// std::invalid_argument for any other value than a decimal integer from 0 to the end of the year
// 9999 (a typo must not silently give today's date).
long long sourceDateEpoch();

}  // namespace flexure::render
