/// @file ours_peer.h
/// @brief Our samplers as methods of the peers experiment (peer.h): each table row of ours
/// (peer_registry.cpp) names the sampler it runs; ours_peer.cpp runs it through MeshSdf, the
/// build-once object of `sdf-query` and the Python module, whose construction is the build
/// the row times.
#pragma once

#include <memory>
#include <string>

#include "experiments/peers/peer.h"

namespace sdf::peers {

/// Which of our samplers a method row runs.
struct OurSampler {
    const char* backend;  ///< "cpu" or "cuda" (sampler_table.h)
    const char* method;   ///< "bvh" or "brute_force"
    const char* kernel;   ///< "" = the row's default kernel
    /// True: the case's sign (PeerInput::our_sign: "point_set_sign" on point sets); false: always
    /// the exact sign (PeerOptions::exact_sign), as the reference and the checks of it need.
    bool case_sign;
    const char* about;    ///< what the query time is, for the row's notes
};

/// The adapter of `sampler`; null with `why_not` ("unavailable ...") for a GPU sampler
/// where this build has no CUDA backend or no device is present.
std::unique_ptr<PeerAdapter> make_our_peer(const OurSampler& sampler, const PeerOptions& options, std::string& why_not);

}  // namespace sdf::peers
