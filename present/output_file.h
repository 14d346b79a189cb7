// Output files are never left half-written and never written through a link planted by someone
// else: data goes to an unnamed file (O_TMPFILE) in the target's directory, which gets a name
// only when complete (linked under a fresh temporary name, renamed over the final one). Where
// the file system has no O_TMPFILE, a temporary name is created exclusively (O_EXCL,
// O_NOFOLLOW) and removed on every exit path, the second Ctrl-C included.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "render/video.h"

namespace flexure::present {

// What an output took.
struct Written {
  std::string file;
  std::string summary;  // e.g. "501 frames, 1000x1000, 25 fps, 20.04 s"
  double seconds = 0;
  render::VideoStats video;
};

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Writes `data` to `path` atomically; throws OutputError (and leaves nothing behind) on failure.
void writeFileAtomically(const std::string& path, const std::string& data);
// Creates `dir` and its parents if needed; throws OutputError.
void makeDirectories(const std::string& dir);

// Throws OutputError unless `path` can be written: its directory exists (or is created) and
// takes a new file, and `path` is not a directory and not the same file as any of `inputs`.
// Called before a computation so that a bad output is found before the work.
void checkWritable(const std::string& path, const std::vector<std::string>& inputs = {});

// Throws OutputError unless `path` is absent or a regular file: a symbolic link, a FIFO, a
// device or a socket named as an output is never replaced by the rename (run as root, that
// would replace /dev/null) nor written through.
void checkReplaceable(const std::string& path);

// Removes the temporary names of outputs being committed or written without O_TMPFILE.
// Async-signal-safe: for a signal handler that is about to _exit.
void removePendingOutputs() noexcept;

// The directory part of a path ("." for a bare name, "/" at the root).
std::string directoryOf(const std::string& path);
// The file name without directory and extension ("scenes/double_watt.toml": "double_watt").
std::string stemOf(const std::string& path);
// The lower-case extension of a file name ("" without one).
std::string extensionOf(const std::string& path);

// A file being written: opened at once (so a bad directory fails before any work); write()
// appends, or a library that takes a path writes to temp(); commit() gives it the final name.
// Without commit() nothing is left.
class TemporaryOutput {
 public:
  explicit TemporaryOutput(std::string path);
  ~TemporaryOutput();
  TemporaryOutput(const TemporaryOutput&) = delete;
  TemporaryOutput& operator=(const TemporaryOutput&) = delete;
  // A path that opens this very file (/proc/self/fd/N, never a name someone could replace).
  const std::string& temp() const { return temp_; }
  void write(std::string_view data);
  void commit();

 private:
  [[noreturn]] void fail(int error) const;
  std::string path_, temp_, named_;  // named_: the temporary name, when there is one
  int fd_ = -1;
  int slot_ = -1;  // in the table removePendingOutputs() reads
  bool committed_ = false;
};

}  // namespace flexure::present
