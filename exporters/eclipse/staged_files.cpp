#include "staged_files.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace hm {

namespace fs = std::filesystem;

StagedFiles::~StagedFiles() {
  if (!committed_) discard();
}

bool StagedFiles::make_directory(const std::string& dir, std::string* error) {
  if (dir.empty()) {
    *error = "empty output directory";
    return false;
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    *error = "cannot create directory '" + dir + "': " + (ec ? ec.message() : std::string("not a directory"));
    return false;
  }
  return true;
}

bool StagedFiles::stage(const std::string& final_path, const std::string& content) {
  if (!error_.empty()) return false;
  const std::string tmp = final_path + ".tmp";
  // C stdio: the one place where a short write or a failing close (e.g. a full disk) is reported.
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) {
    error_ = "cannot write '" + final_path + "': " + std::strerror(errno);
    discard();
    return false;
  }
  entries_.push_back({final_path, tmp});
  const size_t written = content.empty() ? 0 : std::fwrite(content.data(), 1, content.size(), f);
  const int write_errno = errno;
  const bool close_ok = std::fclose(f) == 0;
  if (written != content.size() || !close_ok) {
    error_ = "cannot write '" + final_path + "': " + std::strerror(written != content.size() ? write_errno : errno);
    discard();
    return false;
  }
  return true;
}

bool StagedFiles::commit() {
  if (!error_.empty()) return false;
  for (size_t i = 0; i < entries_.size(); ++i) {
    std::error_code ec;
    fs::rename(entries_[i].tmp_path, entries_[i].final_path, ec);
    if (ec) {
      error_ = "cannot rename '" + entries_[i].tmp_path + "' to '" + entries_[i].final_path + "': " + ec.message();
      // Undo: the files already renamed are new and incomplete as a set.
      for (size_t j = 0; j < i; ++j) fs::remove(entries_[j].final_path, ec);
      for (size_t j = i; j < entries_.size(); ++j) fs::remove(entries_[j].tmp_path, ec);
      entries_.clear();
      return false;
    }
  }
  committed_ = true;
  return true;
}

std::vector<std::string> StagedFiles::paths() const {
  std::vector<std::string> out;
  for (const Entry& e : entries_) out.push_back(e.final_path);
  return out;
}

void StagedFiles::discard() {
  std::error_code ec;
  for (const Entry& e : entries_) fs::remove(e.tmp_path, ec);
  entries_.clear();
}

}  // namespace hm
