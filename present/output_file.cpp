#include "present/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>

namespace flexure::present {

namespace {

// Temporary names that exist right now, for removePendingOutputs(): fixed storage, claimed and
// released with atomics, read by a signal handler without locks or allocation.
constexpr int kSlots = 16;
constexpr size_t kNameMax = 4096;
struct Slot {
  std::atomic<int> state{0};  // 0 free, 1 being filled, 2 holds a name
  char name[kNameMax] = {};  // initialized: the table is zero-filled at load, not by a constructor
};
Slot g_slots[kSlots];

int claimSlot(const std::string& name) {
  if (name.size() >= kNameMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (!g_slots[i].state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(g_slots[i].name, name.c_str(), name.size() + 1);
    g_slots[i].state.store(2);
    return i;
  }
  return -1;
}

void releaseSlot(int& slot) {
  if (slot >= 0) g_slots[slot].state.store(0);
  slot = -1;
}

// A fresh name beside `path`: PATH.tmp-PID-XXXXXXXX.
std::string temporaryName(const std::string& path) {
  thread_local std::mt19937_64 rng{std::random_device{}()};  // names only: not the scene's seed
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, "%08llx", static_cast<unsigned long long>(rng() & 0xffffffffu));
  return path + ".tmp-" + std::to_string(::getpid()) + "-" + suffix;
}

std::string procPath(int fd) { return "/proc/self/fd/" + std::to_string(fd); }

}  // namespace

void checkReplaceable(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode)) return;
  const char* kind = S_ISLNK(st.st_mode)  ? "a symbolic link"
                     : S_ISDIR(st.st_mode) ? "a directory"
                     : S_ISFIFO(st.st_mode) ? "a FIFO"
                     : S_ISCHR(st.st_mode) ? "a character device"
                     : S_ISBLK(st.st_mode) ? "a block device"
                     : S_ISSOCK(st.st_mode) ? "a socket"
                                            : "not a regular file";
  throw OutputError("cannot write " + path + ": it is " + std::string(kind) +
                    ", and flexure only replaces regular files (write to a new name, or to - for standard output "
                    "where the command offers it)");
}

void removePendingOutputs() noexcept {
  for (Slot& s : g_slots)
    if (s.state.load() == 2) ::unlink(s.name);
}

TemporaryOutput::TemporaryOutput(std::string path) : path_(std::move(path)) {
  // The system cuts a name at its first NUL: "a.csv\0.json" would be the file a.csv, written in
  // the format of the extension the caller read, .json. Every output is opened here.
  if (path_.find('\0') != std::string::npos) {
    std::string shown;
    for (char c : path_) shown += c == '\0' ? std::string("\\0") : std::string(1, c);
    throw OutputError("cannot write " + shown + ": a file name cannot contain a NUL byte");
  }
  checkReplaceable(path_);
  const std::string dir = directoryOf(path_);
  fd_ = ::open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
  if (fd_ < 0 && (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL)) {
    // No O_TMPFILE here: a name of our own, created exclusively, never through a link.
    for (int attempt = 0; attempt < 100 && fd_ < 0; ++attempt) {
      named_ = temporaryName(path_);
      slot_ = claimSlot(named_);
      fd_ = ::open(named_.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_NOFOLLOW | O_CLOEXEC, 0666);
      if (fd_ < 0) releaseSlot(slot_);
      if (fd_ < 0 && errno != EEXIST) break;
    }
  }
  if (fd_ < 0) fail(errno);
  temp_ = procPath(fd_);
}

TemporaryOutput::~TemporaryOutput() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && !named_.empty()) ::unlink(named_.c_str());
  releaseSlot(slot_);
}

void TemporaryOutput::fail(int error) const {
  throw OutputError("cannot write " + path_ + ": " + std::strerror(error));
}

void TemporaryOutput::write(std::string_view data) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd_, data.data(), data.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(errno);
    data.remove_prefix(static_cast<size_t>(n));
  }
}

void TemporaryOutput::commit() {
  // Whatever a library wrote through temp() is in the same file; make it durable first.
  if (::fsync(fd_) != 0) fail(errno);
  checkReplaceable(path_);  // again: it may have been made since the output was opened
  if (named_.empty()) {
    // Name the unnamed file: link it under a fresh temporary name (link never replaces), then
    // rename that over the final name. Only between the two does a name exist to clean up.
    for (int attempt = 0; attempt < 100 && named_.empty(); ++attempt) {
      std::string name = temporaryName(path_);
      slot_ = claimSlot(name);
      if (::linkat(AT_FDCWD, temp_.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) == 0) {
        named_ = std::move(name);
        break;
      }
      const int e = errno;
      releaseSlot(slot_);
      if (e != EEXIST) fail(e);
    }
    if (named_.empty()) fail(EEXIST);
  }
  if (std::rename(named_.c_str(), path_.c_str()) != 0) {
    const int e = errno;
    ::unlink(named_.c_str());
    releaseSlot(slot_);
    named_.clear();
    fail(e);
  }
  committed_ = true;
  releaseSlot(slot_);
}

void writeFileAtomically(const std::string& path, const std::string& data) {
  TemporaryOutput out(path);
  out.write(data);
  out.commit();
}

void makeDirectories(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw OutputError("cannot create directory " + dir + ": " + ec.message());
  if (!std::filesystem::is_directory(dir)) throw OutputError(dir + " is not a directory");
}

void checkWritable(const std::string& path, const std::vector<std::string>& inputs) {
  makeDirectories(directoryOf(path));
  checkReplaceable(path);
  struct stat out {};
  if (::stat(path.c_str(), &out) == 0) {
    for (const std::string& in : inputs) {
      struct stat st {};
      if (::stat(in.c_str(), &st) == 0 && st.st_dev == out.st_dev && st.st_ino == out.st_ino)
        throw OutputError("cannot write " + path + ": it is the input " + in + " (choose another output name)");
    }
  }
  TemporaryOutput probe(path);  // the directory takes a new file; dropped without a trace
}

std::string directoryOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
}

std::string stemOf(const std::string& path) {
  std::string stem = path.substr(path.find_last_of('/') + 1);
  const auto dot = stem.rfind('.');
  if (dot != std::string::npos && dot > 0) stem = stem.substr(0, dot);
  return stem;
}

std::string extensionOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace flexure::present
