#include "present/output_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace flexure::present {

namespace {
std::string temporaryName(const std::string& path) { return path + ".tmp-" + std::to_string(::getpid()); }
}  // namespace

void writeFileAtomically(const std::string& path, const std::string& data) {
  const std::string tmp = temporaryName(path);
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw OutputError("cannot write " + path + ": " + std::strerror(errno));
  const bool written = std::fwrite(data.data(), 1, data.size(), f) == data.size();
  const int saved = errno;
  const bool flushed = std::fflush(f) == 0 && ::fsync(::fileno(f)) == 0;
  const int saved2 = errno;
  const bool closed = std::fclose(f) == 0;
  if (!written || !flushed || !closed) {
    std::remove(tmp.c_str());
    throw OutputError("cannot write " + path + ": " + std::strerror(!written ? saved : saved2));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    std::remove(tmp.c_str());
    throw OutputError("cannot write " + path + ": " + std::strerror(e));
  }
}

void makeDirectories(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw OutputError("cannot create directory " + dir + ": " + ec.message());
  if (!std::filesystem::is_directory(dir)) throw OutputError(dir + " is not a directory");
}

TemporaryOutput::TemporaryOutput(std::string path) : path_(std::move(path)), temp_(temporaryName(path_)) {
  std::FILE* f = std::fopen(temp_.c_str(), "wb");
  if (!f) throw OutputError("cannot write " + path_ + ": " + std::strerror(errno));
  std::fclose(f);
}

TemporaryOutput::~TemporaryOutput() {
  if (!committed_) std::remove(temp_.c_str());
}

void TemporaryOutput::commit() {
  if (std::rename(temp_.c_str(), path_.c_str()) != 0)
    throw OutputError("cannot write " + path_ + ": " + std::strerror(errno));
  committed_ = true;
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

}  // namespace flexure::present
