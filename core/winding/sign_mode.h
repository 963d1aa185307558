/// @file sign_mode.h
/// @brief The sign modes (config key "sign", tool option --sign) and their one name table.
///
/// "pseudonormal": the thesis's angle-weighted pseudonormal of the closest feature
/// (Baerentzen & Aanaes 2005), exact for closed, manifold, consistently oriented meshes
/// without self-intersections; "winding": inside where the generalized winding number
/// exceeds 1/2 (Jacobson et al. 2013), right also for overlapping closed parts, small holes
/// and self-intersections; "auto" (the default): pseudonormal where the mesh report shows it
/// is exact, winding otherwise (choose_sign_mode, winding_sign.h).
#pragma once

#include <string>
#include <vector>

namespace sdf {

enum class SignMode { Auto, Pseudonormal, Winding };

struct NamedSignMode {
    const char* name;
    SignMode mode;
};

/// The one table of sign-mode names; the first is the default.
inline constexpr NamedSignMode kSignModes[] = {
    {"auto", SignMode::Auto},
    {"pseudonormal", SignMode::Pseudonormal},
    {"winding", SignMode::Winding},
};

const char* sign_mode_name(SignMode mode);
/// Every name of kSignModes, in order (for config choices and CLI checks).
std::vector<std::string> sign_mode_names();
/// "auto", "pseudonormal" or "winding"; throws std::invalid_argument naming the value and `where`.
SignMode sign_mode_from_name(const std::string& name, const std::string& where);

}  // namespace sdf
