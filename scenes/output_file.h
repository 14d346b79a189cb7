// Output files are never left half-written: data goes to a temporary file in the same
// directory, which is renamed over the final name only when complete.
#pragma once

#include <stdexcept>
#include <string>

namespace flexure::scenes {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Writes `data` to `path` atomically; throws OutputError (and leaves nothing behind) on failure.
void writeFileAtomically(const std::string& path, const std::string& data);
// Creates `dir` and its parents if needed; throws OutputError.
void makeDirectories(const std::string& dir);

}  // namespace flexure::scenes
