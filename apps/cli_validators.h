// Number validators for every tool's options. CLI11's PositiveNumber and NonNegativeNumber
// name their upper bound, DBL_MAX, in the message with all 309 digits ("Value -1 not in
// range 0.000000 to 1797693134862315708...0.000000") and let "nan" and "inf" through
// (no comparison fails for NaN); these say what was expected in words and refuse both.
#pragma once

#include <CLI/CLI.hpp>

#include <cmath>
#include <string>

namespace sdf {

/// A finite number, and > 0 where `positive`, else >= 0.
inline CLI::Validator finite_number_at_least_zero(bool positive) {
    return CLI::Validator(
        [positive](std::string& input) -> std::string {
            double value = 0;
            if (!CLI::detail::lexical_cast(input, value)) return "'" + input + "' is not a number";
            const char* expected = positive ? "; expected a finite number > 0" : "; expected a finite number >= 0";
            if (!std::isfinite(value)) return "'" + input + "' is not finite" + expected;
            if (positive ? !(value > 0) : !(value >= 0)) return "'" + input + "' is out of range" + expected;
            return {};
        },
        positive ? "POSITIVE" : "NONNEGATIVE");
}

inline const CLI::Validator kPositiveNumber = finite_number_at_least_zero(true);
inline const CLI::Validator kNonNegativeNumber = finite_number_at_least_zero(false);

}  // namespace sdf
