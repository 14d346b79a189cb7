// Output files are never left half-written: data goes to a temporary file in the same
// directory, which is renamed over the final name only when complete.
#pragma once

#include <stdexcept>
#include <string>

namespace flexure::present {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Writes `data` to `path` atomically; throws OutputError (and leaves nothing behind) on failure.
void writeFileAtomically(const std::string& path, const std::string& data);
// Creates `dir` and its parents if needed; throws OutputError.
void makeDirectories(const std::string& dir);

// The directory part of a path ("." for a bare name, "/" at the root).
std::string directoryOf(const std::string& path);
// The file name without directory and extension ("scenes/double_watt.toml": "double_watt").
std::string stemOf(const std::string& path);

// A file written by a library that takes a path (the video encoder): it writes to temp(), which
// is created at once (so a bad directory fails before any work), and commit() renames it to
// the final name. Without commit() the temporary file is removed.
class TemporaryOutput {
 public:
  explicit TemporaryOutput(std::string path);
  ~TemporaryOutput();
  TemporaryOutput(const TemporaryOutput&) = delete;
  TemporaryOutput& operator=(const TemporaryOutput&) = delete;
  const std::string& temp() const { return temp_; }
  void commit();

 private:
  std::string path_, temp_;
  bool committed_ = false;
};

}  // namespace flexure::present
