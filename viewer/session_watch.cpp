// Session::checkFile: the scene file watched by its time stamp and size (a catalog entry's
// text read once), read again when it changed, a recompute when its text changed.
#include <sys/stat.h>
#include <ctime>

#include <exception>
#include <string>

#include "viewer/session.h"
#include "viewer/session_internal.h"

namespace flexure::viewer {

bool Session::checkFile() {
  if (catalog_) {  // the entry's text, once; save as writes an editable copy
    std::lock_guard<std::mutex> lock(mutex_);
    if (next_job_ > 1) return false;
    text_ = catalog_->text;
    submitLocked();
    return true;
  }
  struct stat st {};
  if (::stat(path_.c_str(), &st) != 0) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (read_error_.empty()) {
      read_error_ = "cannot read " + path_ + " (it was moved or deleted); waiting for it to come back";
      mtime_ns_ = size_ = -1;
      ++revision_;
      changed_.notify_all();
    }
    return false;
  }
  const long long mtime = static_cast<long long>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (mtime == mtime_ns_ && static_cast<long long>(st.st_size) == size_) return false;
  }
  // A save that truncates the file and then writes it (Python's open(..., "w"), many editors)
  // shows an empty file for a moment: an empty file younger than half a second is waited for,
  // not reported as a scene without a [system] table.
  if (st.st_size == 0) {
    timespec now{};
    ::clock_gettime(CLOCK_REALTIME, &now);
    const long long now_ns = static_cast<long long>(now.tv_sec) * 1000000000LL + now.tv_nsec;
    if (now_ns - mtime < 500000000LL) return false;
  }
  std::string text, read_error;
  try {
    text = scenes::sceneTextOfFile(path_, scenes::readSceneFile(path_));  // a mesh, graph or path JSON too
  } catch (const std::exception& e) {  // SceneError; ResourceError for a file too large to parse
    read_error = e.what();
  }
  // Written to while it was read: the next check reads it again.
  struct stat after {};
  if (::stat(path_.c_str(), &after) == 0 &&
      (after.st_size != st.st_size || after.st_mtim.tv_sec != st.st_mtim.tv_sec ||
       after.st_mtim.tv_nsec != st.st_mtim.tv_nsec))
    return false;
  std::lock_guard<std::mutex> lock(mutex_);
  mtime_ns_ = mtime, size_ = static_cast<long long>(st.st_size);
  if (!read_error.empty()) {
    read_error_ = read_error;
    ++revision_;
    changed_.notify_all();
    return false;
  }
  if (!read_error_.empty()) {
    read_error_.clear();
    ++revision_;
    changed_.notify_all();
  }
  if (text == text_ && next_job_ > 1) return false;
  text_ = text;
  submitLocked();
  return true;
}

}  // namespace flexure::viewer
