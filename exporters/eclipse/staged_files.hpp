// All-or-nothing writing of a set of files (an Eclipse deck and its includes, an OpenFOAM case):
// every file is first written under a temporary name in its final directory; only when all of
// them are written are they renamed, the "main" file last; any failure removes the temporary
// files and rolls back the renames, so a failed export never leaves complete-looking files.
#pragma once
#include <string>
#include <vector>

namespace hm {

class StagedFiles {
 public:
  StagedFiles() = default;
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;
  /// Removes any temporary file left over (a set never committed leaves nothing behind).
  ~StagedFiles();

  /// Creates `dir` (and parents) if needed. False with `error` set when it cannot.
  static bool make_directory(const std::string& dir, std::string* error);

  /// Writes `content` to `final_path + ".tmp"`. False with `error()` set on failure; the set is
  /// then cleaned up and every later call fails too.
  bool stage(const std::string& final_path, const std::string& content);

  /// Renames every staged file to its final name, in staging order (stage the main file last).
  /// On a failure, renames already done are undone (the new files are removed) and false is
  /// returned with `error()` set.
  bool commit();

  const std::string& error() const { return error_; }
  /// Final paths, in staging order.
  std::vector<std::string> paths() const;

 private:
  void discard();
  struct Entry {
    std::string final_path, tmp_path;
  };
  std::vector<Entry> entries_;
  std::string error_;
  bool committed_ = false;
};

}  // namespace hm
