// JSON form of an FvReport (nlohmann::json; shape documented in docs/fvcheck.md).
#pragma once
#include <nlohmann/json.hpp>

#include "report.hpp"

namespace hm {

nlohmann::json report_json(const FvReport& r);

}  // namespace hm
