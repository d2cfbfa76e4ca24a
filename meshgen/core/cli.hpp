// Command-line handling shared by the executables (meshgen, solver_demo): the positional
// case file, the required output directory, and its creation. Each returns "" when all is
// well, else the one-line reason the executable prints before its usage (exit code 2).
#pragma once
#include <string>

namespace hm {

/// An argument that no program option matched: the case file if it is the first positional
/// one; "unknown option 'X'" if it starts with '-'; "more than one case file given" else.
std::string take_case_argument(const std::string& arg, std::string* case_path);

/// After the option loop: "no case file given" / "no output directory given (-o OUTDIR)".
std::string check_case_and_output(const std::string& case_path, const std::string& out_dir);

/// Creates the output directory (and its parents):
/// "-o: cannot create directory 'X': reason" on failure.
std::string create_output_directory(const std::string& out_dir);

}  // namespace hm
