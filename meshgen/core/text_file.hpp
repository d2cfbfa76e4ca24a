// Writing a small text file so that a failure never leaves a complete-looking file.
#pragma once
#include <string>

namespace hm {

/// Writes text to path through path + ".tmp" and a rename. Returns false and sets *error
/// on failure.
bool write_text_file(const std::string& path, const std::string& text, std::string* error);

/// `s` with & < > " ' replaced by XML entities (VTU attributes, HTML reports).
std::string xml_escape(const std::string& s);

}  // namespace hm
