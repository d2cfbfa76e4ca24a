#include "cli.hpp"

#include <filesystem>
#include <system_error>

namespace hm {

std::string take_case_argument(const std::string& arg, std::string* case_path) {
  if (!arg.empty() && arg[0] == '-') return "unknown option '" + arg + "'";
  if (!case_path->empty()) return "more than one case file given";
  *case_path = arg;
  return "";
}

std::string check_case_and_output(const std::string& case_path, const std::string& out_dir) {
  if (case_path.empty()) return "no case file given";
  if (out_dir.empty()) return "no output directory given (-o OUTDIR)";
  return "";
}

std::string create_output_directory(const std::string& out_dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (!ec && fs::is_directory(out_dir, ec)) return "";
  return "-o: cannot create directory '" + out_dir + "'" + (ec ? ": " + ec.message() : ": not a directory");
}

}  // namespace hm
