/// @file lattice_kinds.h
/// @brief The one table of lattice kinds: {type, name, label, cosets, description}. Every
/// parse and write of a kind's name (configs, field files, flags, Python keywords, messages)
/// goes through it, and the most sampling blocks a sampler holds (kMaxSamplingBlocks,
/// sampling_grid.h) is its largest coset count.
///
/// Adding a kind: its LatticeType, its row, its case in lattice_kind() (no default: a type
/// without its case is a -Wswitch warning, an error with SDF_WARNINGS_AS_ERRORS), then its
/// geometry (docs/architecture-recipes.md).
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace sdf {

enum class LatticeType : int { CC = 0, BCC = 1 };

struct LatticeKind {
    LatticeType type;
    const char* name;         ///< in configs, field files, flags and keywords
    const char* label;        ///< in messages and figures
    int cosets;               ///< shifted CC grids that make the lattice (BCC: primary and secondary)
    const char* description;  ///< for help texts
};

inline constexpr LatticeKind kLatticeKinds[] = {
    {LatticeType::CC, "cc", "CC", 1, "Cartesian cubic: one grid of Rx x Ry x Rz points"},
    {LatticeType::BCC, "bcc", "BCC", 2,
     "body-centred cubic, Rx x Ry x 2Rz: a primary grid and a secondary one shifted by h/2 (thesis section 3.3)"},
};

/// The row of `type`.
constexpr const LatticeKind& lattice_kind(LatticeType type) {
    switch (type) {
        case LatticeType::CC: return kLatticeKinds[0];
        case LatticeType::BCC: return kLatticeKinds[1];
    }
    return kLatticeKinds[0];  // not reached: every enumerator has its case
}

namespace detail {
constexpr bool lattice_rows_match_their_types() {
    for (const LatticeKind& k : kLatticeKinds)
        if (&lattice_kind(k.type) != &k) return false;
    return true;
}
constexpr int max_lattice_cosets() {
    int m = 0;
    for (const LatticeKind& k : kLatticeKinds) m = k.cosets > m ? k.cosets : m;
    return m;
}
}  // namespace detail
static_assert(detail::lattice_rows_match_their_types(), "lattice_kind() must return each type's own row");

/// The most cosets of any kind: the most GridBlocks a lattice is sampled as.
inline constexpr int kMaxLatticeCosets = detail::max_lattice_cosets();

/// "cc", "bcc": the name configs, field files, flags and keywords use.
constexpr const char* lattice_type_name(LatticeType type) { return lattice_kind(type).name; }

/// "CC", "BCC": for messages and figures.
constexpr const char* lattice_type_label(LatticeType type) { return lattice_kind(type).label; }

/// The kind named `name`, or null.
constexpr const LatticeKind* find_lattice_kind(std::string_view name) {
    for (const LatticeKind& k : kLatticeKinds)
        if (name == k.name) return &k;
    return nullptr;
}

/// Every kind's name, in table order: the choices of a config key, flag or keyword.
inline std::vector<std::string> lattice_type_names() {
    std::vector<std::string> names;
    for (const LatticeKind& k : kLatticeKinds) names.emplace_back(k.name);
    return names;
}

/// The type named `name`; the caller has checked it against lattice_type_names() (a config
/// reader's choice(), a CLI validator): an unknown name throws std::invalid_argument.
inline LatticeType lattice_type_named(std::string_view name) {
    if (const LatticeKind* k = find_lattice_kind(name)) return k->type;
    std::string known;
    for (const LatticeKind& k : kLatticeKinds) known += std::string(known.empty() ? "" : ", ") + "\"" + k.name + "\"";
    throw std::invalid_argument("unknown lattice type \"" + std::string(name) + "\"; expected one of " + known);
}

}  // namespace sdf
