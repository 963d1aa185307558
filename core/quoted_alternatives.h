/// @file quoted_alternatives.h
/// @brief The one way messages list the values a key or option accepts: "a", "b" or "c".
#pragma once

#include <string>
#include <vector>

namespace sdf {

/// "a", "b" or "c" ("a" for one name, "" for none).
inline std::string quoted_alternatives(const std::vector<std::string>& names) {
    std::string s;
    for (size_t i = 0; i < names.size(); ++i)
        s += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + ("\"" + names[i] + "\"");
    return s;
}

}  // namespace sdf
